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

// Expected mass of each chi-square bin, by quadrature of the pdf (row-major [radial][azimuth]).
std::vector<Real> bin_masses(const SamplerUnderTest& s, const BatteryOptions& o);
TestResult chi_square(const SamplerUnderTest& s, const BatteryOptions& o, const Draws& d,
                      const std::vector<Real>& mass);

// The two marginal CDFs of the KS tests, known at nodes (seed-independent: computed once per sampler).
struct KsCdfs {
  std::vector<Real> xr, Fr, xa, Fa;
};
KsCdfs ks_cdfs(const SamplerUnderTest& s, const BatteryOptions& o);
// Appends ks-radial and ks-azimuth, from the draws' counts per slab between c's nodes (drawn with c.xr and c.xa).
void ks_tests(const SamplerUnderTest& s, const KsCdfs& c, const Draws& d, std::vector<TestResult>& out);

// ---- Deterministic (deterministic_tests.cpp) -----------------------------------------------------------------

// mass: bin_masses, the integral of the pdf over the bounding cap.
TestResult pdf_integral(const SamplerUnderTest& s, const BatteryOptions& o, const std::vector<Real>& mass);
TestResult pdf_consistency(const SamplerUnderTest& s, const BatteryOptions& o);
// One result per declared Normalization.
std::vector<TestResult> normalizations(const SamplerUnderTest& s);
// For geometry that has no sample: every draw declines and the pdf is zero at random directions.
TestResult no_sample(const SamplerUnderTest& s, const BatteryOptions& o);

}  // namespace warpcheck::validation::battery
