// The battery's tests (internal to the battery): the statistical ones in statistical_tests.cpp, the
// deterministic ones in deterministic_tests.cpp. battery.h says what each measures.
#pragma once

#include <string>
#include <vector>

#include "battery/drawing.h"
#include "warpcheck/validation/battery.h"

namespace warpcheck::validation::battery {

// A result named after the sampler's case and the test.
inline TestResult make_result(const SamplerUnderTest& s, std::string test) {
  TestResult r;
  r.kernel = s.kernel, r.scalar = s.scalar, r.config = s.config, r.test = std::move(test);
  return r;
}

// v with prec significant digits (printf's %g).
std::string format_g(double v, int prec);

// ---- Statistical (statistical_tests.cpp) ---------------------------------------------------------------------

// The two marginal CDFs of the KS tests, known at nodes (seed-independent: computed once per sampler).
struct KsCdfs {
  std::vector<Real> xr, Fr, xa, Fa;
};
// The nodes xr (t, Chebyshev-Lobatto) and xa (phi / 2 pi, equally spaced), without the CDFs.
KsCdfs ks_nodes(const BatteryOptions& o);

// ---- Expected counts (expected.cpp) ---------------------------------------------------------------------------

// How far errors `error` of the expected counts `expected` move the chi-square statistic's mean, pooling bins as
// chi_square does, and the most that is allowed: 1e-3 of the statistic's standard deviation sqrt(2 (bins - 1)).
Real chi_square_shift(const std::vector<Real>& expected, const std::vector<Real>& error, Real min_expected);
Real chi_square_shift_budget(int bins);
// The absolute accuracy of a KS CDF that moves D by at most 1e-3 of its critical value at n samples.
Real ks_cdf_tolerance(std::uint64_t n);

// The pdf's integrals the statistical tests compare with: the mass of each chi-square bin (row-major
// [radial][azimuth]) and the KS CDFs. By the grid quadrature (cap_grid.h) when the difference of its two orders of
// integration, taken as its error, is within the bounds above and leaves the pdf-integral test's decision alone,
// or for a float pdf, whose rounding no quadrature integrates better (the details then state the difference); else by
// reference_bin_masses and reference_ks_cdfs (or by those alone with options.reference_quadrature). Both with the
// rim's mass (Expected::rim) in the last ring.
struct Expected {
  std::vector<Real> mass;
  KsCdfs ks;
  std::string quadrature;  // which quadrature, and why, for the tests' details
  Real inside_error = 0;   // the grid's two estimates of the integral over the cap differ by this
  Real rim = 0;            // mass beyond the cap's edge where samples still count in the last ring (rounding_slack)
};
Expected expected_integrals(const SamplerUnderTest& s, const BatteryOptions& o);
// Adds the pdf's mass in the rim 1 < t <= 1 + rounding_slack beyond the cap's edge, where drawing counts samples in
// the outermost ring, to e's last ring and both KS CDFs, and sets e.rim (expected_integrals does).
void add_rim(const SamplerUnderTest& s, const BatteryOptions& o, Expected& e);
// The nested adaptive quadrature of each bin and of each KS slab (integrate_cap_region), to tolerance
// options.quadrature_tolerance: slow, and what the grid is tested against.
std::vector<Real> reference_bin_masses(const SamplerUnderTest& s, const BatteryOptions& o);
KsCdfs reference_ks_cdfs(const SamplerUnderTest& s, const BatteryOptions& o);

TestResult chi_square(const SamplerUnderTest& s, const BatteryOptions& o, const Draws& d, const Expected& e);
// Sorts (expected, x) cells by expected count and pools every cell expected to hold fewer than min_expected
// samples, x summed with them (x: the observed count, or an alternative's change of the expected count); a pool
// still below min_expected joins the smallest regular cell. `pooled`: how many cells were pooled.
std::vector<std::pair<Real, Real>> pool_low_expected(std::vector<std::pair<Real, Real>> cells, double min_expected,
                                                     std::size_t& pooled);
// A coarser partition of the R x A chi-square grid: bin (ring r, column a) joins cell
// (r * rows / R) * cols + a * cols / A. Tested by chi-square with the same outside cell and pooling as chi2:
// an error spread coherently over many bins (a ring too dense, a wedge, a smooth tilt) adds up in few cells, where
// the 512-bin statistic spreads it over 511 degrees of freedom.
struct GridAggregate {
  const char* test;
  int rows, cols;
  int cell(int r, int a, int R, int A) const { return (r * rows / R) * cols + a * cols / A; }
};
// chi2-rings (R x 1), chi2-columns (1 x A), chi2-coarse (4 x 8).
std::vector<GridAggregate> grid_aggregates(int radial_bins, int azimuth_bins);
// Appends one result per grid aggregate, from the same draws and bin masses as chi2.
void aggregate_chi_squares(const SamplerUnderTest& s, const BatteryOptions& o, const Draws& d, const Expected& e,
                           std::vector<TestResult>& out);
// Appends ks-radial and ks-azimuth, from the draws' counts per slab between c's nodes (drawn with c.xr and c.xa).
void ks_tests(const SamplerUnderTest& s, const KsCdfs& c, const Draws& d, std::vector<TestResult>& out);

// ---- Deterministic (deterministic_tests.cpp) -----------------------------------------------------------------

// The pdf's integral over the sphere beyond the bounding cap and its rim (nested adaptive quadrature).
Real outside_integral(const SamplerUnderTest& s, const BatteryOptions& o);
TestResult pdf_integral(const SamplerUnderTest& s, const BatteryOptions& o, const Expected& e, Real outside);
TestResult pdf_consistency(const SamplerUnderTest& s, const BatteryOptions& o);
// One result per declared Normalization.
std::vector<TestResult> normalizations(const SamplerUnderTest& s);
// For a sampler with an inverse (round_trip.cpp): inverse(sample(u)) == u on a 32 x 32 grid of u and
// sample(inverse(w)) == w on a 32 x 32 grid of directions over the bounding cap, to s.inverse_tolerance in units of u.
TestResult round_trip(const SamplerUnderTest& s);
// For geometry that has no sample: every draw declines and the pdf is zero at random directions.
TestResult no_sample(const SamplerUnderTest& s, const BatteryOptions& o);

}  // namespace warpcheck::validation::battery
