// warpcheck/validation/battery.h: the statistical battery.
//
// run_battery(sampler, options) draws options.samples directions with fixed seeds and runs:
//   chi2          chi-square on an equal-area grid over the sampler's bounding cap; expected counts from
//                 long double adaptive quadrature of the pdf; low-expected bins pooled; p from
//                 boost::math::chi_squared. A sample outside the bounding cap, or declined, where the pdf
//                 gives no mass is impossible under the null hypothesis: p = 0. A sample a rounding error beyond
//                 the cap's edge counts in the outermost ring, and so does the pdf's mass there.
//   chi2-rings, chi2-columns, chi2-coarse  the same counts and expected counts summed over the grid's rings, its
//                 columns and a 4 x 8 coarse grid, with the same outside cell and pooling: a coherent error (a ring
//                 or wedge too dense, a smooth tilt) adds up in few cells instead of spreading over 511 dof
//   ks-radial     Kolmogorov-Smirnov on t = (1 - cos theta) / (1 - cos theta_max) in the cap's frame
//   ks-azimuth    Kolmogorov-Smirnov on phi / 2 pi in the cap's frame; both CDFs from quadrature of the pdf
//                 (not renormalised: a pdf that integrates to 1.001 is a wrong CDF), p from
//                 boost::math::kolmogorov_smirnov_distribution.
//   pdf-integral  |integral of pdf over the sphere - 1| (deterministic; p_value null)
//   pdf-consistency  max relative error between a sample's pdf, pdf(direction), and the inverse area element
//                 of the (reference) warp by 4th-order central differences in long double (deterministic)
//   normalization:<what>  relative error of each declared Normalization (deterministic)
//   round-trip    for a sampler with an inverse: max error of inverse(sample(u)) == u and sample(inverse(w)) == w on
//                 grids, in units of u (deterministic; skipped, no row, without an inverse)
// Statistical tests (those with a p-value) are judged together by apply_correction: one significance level
// alpha for the whole run, Sidak or Holm corrected across all its statistical tests. The results and their
// JSON file: results.h; the power of the statistical tests against standard alternatives: power.h.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "warpcheck/validation/results.h"
#include "warpcheck/validation/sampler.h"

namespace warpcheck::validation {

struct BatteryOptions {
  // Per sampler: README.md, "Validate your own sampler", "Choosing the sample count".
  std::uint64_t samples = 10'000'000;
  std::uint64_t seed = 1;
  int radial_bins = 16, azimuth_bins = 32;  // chi-square grid: 512 equal-area bins over the bounding cap
  double min_expected = 5;                  // bins expected to hold fewer samples are pooled
  int ks_cdf_nodes = 1024;                  // nodes of the quadrature-computed marginal CDFs (D is taken there)
  double quadrature_tolerance = 1e-8;       // relative tolerance of every 1D rule of the quadrature
  bool reference_quadrature = false;        // nested adaptive quadrature of every bin and KS slab (slow)
  int consistency_points = 2048;            // primary-sample points of the pdf/Jacobian check
  // Worker threads: 1 by default, so that a user's test under `ctest -j N` takes one core, as ctest assumes; 0 uses
  // every core (std::thread::hardware_concurrency; the warpcheck command's default). The results are the same,
  // bit for bit, whatever the count.
  int threads = 1;
  // Called with (phase, fraction done) during long work; may be empty.
  std::function<void(const std::string&, double)> progress;
};

// Runs every test of the battery on one sampler. Statistical results come back with passed == false until
// apply_correction judges them.
std::vector<TestResult> run_battery(const SamplerUnderTest& s, const BatteryOptions& options);
// The same battery once per seed (options.seed is ignored), with the seed-independent work done once: the
// quadrature of the chi-square bins and of the KS marginals, and the deterministic tests (their results are
// repeated in every run). run_battery_seeds(s, o, {o.seed})[0] is run_battery(s, o). For calibration and for
// users who want several independent runs of an expensive pdf.
std::vector<std::vector<TestResult>> run_battery_seeds(const SamplerUnderTest& s, const BatteryOptions& options,
                                                       const std::vector<std::uint64_t>& seeds);

// Judges every statistical result at family-wise level alpha across all of them (Sidak: each p <= 1 - (1 -
// alpha)^(1/m); Holm: step-down). Returns the number m of statistical tests.
std::size_t apply_correction(std::vector<TestResult>& results, double alpha, Correction c);

// True when every result passed or is a documented known limitation.
bool all_passed(const std::vector<TestResult>& results);
// A table: kernel, scalar, config, test, statistic, p-value, verdict; each column as wide as its longest entry.
std::string format_table(const std::vector<TestResult>& results);

// Convenience for a user's own GoogleTest: run the battery on one sampler and judge it at alpha (on options.threads
// threads: one unless set).
std::vector<TestResult> validate(const SamplerUnderTest& s, const BatteryOptions& options = {}, double alpha = 0.01,
                                 Correction c = Correction::kHolm);

// ---- Building blocks, exposed for tests -----------------------------------------------------------------

struct QuadratureResult {
  Real value = 0, error = 0;  // error: the rule's own estimate (|K15 - G7| summed over panels)
};

// Globally adaptive Gauss-Kronrod on [a, b]: splits the panel with the largest error until the summed error
// is at most max(abs_tol, rel_tol |value|) or max_panels panels exist. Never loops forever on noisy f.
// initial_panels > 1 starts from that many equal panels (so a narrow feature of f cannot fall between the
// first rule's nodes); 1 starts from [a, b] split once.
QuadratureResult integrate_adaptive(const std::function<Real(Real)>& f, Real a, Real b, Real rel_tol, Real abs_tol,
                                    int max_panels, int initial_panels = 1);

// Integral of f over the region {w : t in [t0, t1], phi in [phi0, phi1]} of a cap's frame, where
// t = (1 - cos theta) / cap.one_minus_cos (so t in [0, 1] spans the cap; t up to 2 / one_minus_cos reaches
// the antipode), by nested globally adaptive Gauss-Kronrod in long double, to relative accuracy ~tol where the
// panel budget allows (a jump of f across the region, a light's edge, costs ~30 bisections per line).
// azimuth_panels: initial panels of the outer (azimuth) integral; wide regions of a thin support (a polygon's
// sliver of a corner inside a full ring) need one per chi-square column or the first rule misses the support.
// radial_panels: initial panels of each inner (radial) line integral, the same for regions spanning many rings:
// a narrow lobe on a line (a near-singular LTC's, 1e-4 rad wide) can fall between the nodes of a line's first
// two 15-point rules, which then agree on the tails and stop.
// abs_tol: an absolute accuracy of the region's integral that is enough (0: none, relative tol alone). Lines
// that barely touch the support have tiny values, and a relative tolerance there asks for ever more bisections of
// a jump that the pdf's own rounding blurs (a float pdf): see ks_cdfs.
// Where a pdf may jump or kink (SamplerUnderTest's boundary_planes and boundary_caps): the quadratures split their
// lines and rings there.
struct Boundary {
  std::vector<Vec3L> planes;
  std::vector<Cap<Real>> caps;
  Boundary(std::vector<Vec3L> p = {}, std::vector<Cap<Real>> c = {}) : planes(std::move(p)), caps(std::move(c)) {}
};
inline Boundary boundary_of(const SamplerUnderTest& s) { return Boundary(s.boundary_planes, s.boundary_caps); }

QuadratureResult integrate_cap_region_with_error(const std::function<Real(const Vec3L&)>& f, const Cap<Real>& cap,
                                                 Real t0, Real t1, Real phi0, Real phi1, Real tol = 1e-10L,
                                                 int azimuth_panels = 1, int radial_panels = 1,
                                                 const Boundary& boundary = {}, Real abs_tol = 0);
Real integrate_cap_region(const std::function<Real(const Vec3L&)>& f, const Cap<Real>& cap, Real t0, Real t1, Real phi0,
                          Real phi1, Real tol = 1e-10L, int azimuth_panels = 1, int radial_panels = 1,
                          const Boundary& boundary = {}, Real abs_tol = 0);

// The direction with coordinates (t, phi) in the cap's frame, and back.
Vec3L cap_direction(const Cap<Real>& cap, Real t, Real phi);
void cap_coordinates(const Cap<Real>& cap, const Vec3L& w, Real& t, Real& phi);

}  // namespace warpcheck::validation
