// The battery's orchestration: checks the options, does the seed-independent work once (quadrature of the
// chi-square bins and KS marginals, the deterministic tests), then draws and runs the statistical tests per
// seed. The tests themselves are in statistical_tests.cpp and deterministic_tests.cpp.
#include <algorithm>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "battery/drawing.h"
#include "battery/tests.h"
#include "warpcheck/validation/battery.h"

namespace warpcheck::validation {
namespace battery {

std::string format_g(double v, int prec) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", prec, v);
  return buf;
}

namespace {

// Validates the options and the sampler; returns the options the battery really uses.
BatteryOptions checked_options(const SamplerUnderTest& s, const BatteryOptions& options) {
  // A float pdf carries rounding noise of a few FLT_EPSILON relative; asking the quadrature for 1e-8 of it only
  // spends every line's panel budget on noise. The tolerance is raised to 16 epsilon of the sampler's scalar
  // type, 1.9e-6 for float: still 10^3 below the chi-square's resolution at 10^7 samples (a bin of 2e4 expected
  // has a relative standard deviation of 7e-3). Double and long double keep quadrature_tolerance.
  BatteryOptions o = options;
  o.quadrature_tolerance = std::max(o.quadrature_tolerance, 16 * double(scalar_epsilon(s.scalar)));
  if (!s.sample || !s.pdf) {
    if (!s.sample_u || !s.pdf) throw std::invalid_argument("SamplerUnderTest needs sample (or sample_u) and pdf");
  }
  if (s.uniforms < 2 || (s.uniforms > 2 && !s.sample_u))
    throw std::invalid_argument("SamplerUnderTest: uniforms >= 2, and sample_u for more than 2");
  if (s.inverse && (s.uniforms != 2 || !s.sample))
    throw std::invalid_argument("SamplerUnderTest: an inverse needs a sampler of two uniform numbers (sample)");
  if (!(s.bounding_cap.one_minus_cos > 0 && s.bounding_cap.one_minus_cos <= 2) || !all_finite(s.bounding_cap.axis))
    throw std::invalid_argument("SamplerUnderTest needs a bounding cap with 0 < 1 - cos(half-angle) <= 2");
  if (o.samples < 1000 || o.radial_bins < 1 || o.azimuth_bins < 1 || o.ks_cdf_nodes < 16)
    throw std::invalid_argument("battery options out of range (samples >= 1000, bins >= 1, ks_cdf_nodes >= 16)");
  check_block_forms(s);
  return o;
}

// Everything of a battery run that does not depend on the seed. The parts that run on one thread are started
// beside the grid quadrature and the draws, which use every thread.
struct Prepared {
  Expected expected;
  std::shared_future<Real> outside;                         // the pdf's integral beyond the cap and its rim
  std::shared_future<std::vector<TestResult>> independent;  // pdf-consistency, normalisations, weight, round-trip
};

Prepared prepare(const SamplerUnderTest& s, const BatteryOptions& o) {
  Prepared p;
  p.outside = beside(o, [&s, o] { return outside_integral(s, o); });
  p.independent = beside(o, [&s, o] {
    std::vector<TestResult> r{pdf_consistency(s, o)};
    for (TestResult& n : normalizations(s)) r.push_back(std::move(n));
    if (s.eval) r.push_back(weight_check(s, o));
    if (s.inverse) r.push_back(round_trip(s));
    return r;
  });
  if (o.progress) o.progress("quadrature", 0);
  p.expected = expected_integrals(s, o);
  return p;
}

// The seed's draws and the statistical tests on them, then the deterministic results: the order of run_battery.
std::vector<TestResult> run_seed(const SamplerUnderTest& s, const BatteryOptions& o, const Prepared& p) {
  std::vector<TestResult> out;
  const Draws d = draw(s, o, p.expected.ks.xr, p.expected.ks.xa);
  out.push_back(chi_square(s, o, d, p.expected));
  ks_tests(s, p.expected.ks, d, out);
  aggregate_chi_squares(s, o, d, p.expected, out);
  out.push_back(pdf_integral(s, o, p.expected, p.outside.get()));
  const std::vector<TestResult>& independent = p.independent.get();
  out.insert(out.end(), independent.begin(), independent.end());
  return out;
}

}  // namespace
}  // namespace battery

using namespace battery;

std::vector<TestResult> run_battery(const SamplerUnderTest& s, const BatteryOptions& options) {
  return run_battery_seeds(s, options, {options.seed}).front();
}

std::vector<std::vector<TestResult>> run_battery_seeds(const SamplerUnderTest& s, const BatteryOptions& options,
                                                       const std::vector<std::uint64_t>& seeds) {
  const BatteryOptions o = checked_options(s, options);
  std::vector<std::vector<TestResult>> runs;
  if (s.expect_no_sample) {
    for (std::uint64_t seed : seeds) {
      BatteryOptions os = o;
      os.seed = seed;
      runs.push_back({no_sample(s, os)});
    }
    return runs;
  }
  const Prepared p = prepare(s, o);
  for (std::uint64_t seed : seeds) {
    BatteryOptions os = o;
    os.seed = seed;
    runs.push_back(run_seed(s, os, p));
  }
  return runs;
}

std::string format_table(const std::vector<TestResult>& results) {
  // Each text column at least its usual width (so that the warpcheck command's tables, one per case, line up), wider
  // when an entry is longer.
  std::size_t w[4] = {38, 11, 24, 30};
  for (const auto& r : results)
    w[0] = std::max(w[0], r.kernel.size()), w[1] = std::max(w[1], r.scalar.size()),
    w[2] = std::max(w[2], r.config.size()), w[3] = std::max(w[3], r.test.size());
  std::ostringstream o;
  auto row = [&](const std::string& kernel, const std::string& scalar, const std::string& config,
                 const std::string& test, const std::string& statistic, const std::string& p, const char* verdict) {
    char line[64];
    std::snprintf(line, sizeof line, " %12s %10s  %s\n", statistic.c_str(), p.c_str(), verdict);
    o << kernel << std::string(w[0] - kernel.size() + 1, ' ') << scalar << std::string(w[1] - scalar.size() + 1, ' ')
      << config << std::string(w[2] - config.size() + 1, ' ') << test << std::string(w[3] - test.size(), ' ') << line;
  };
  row("kernel", "scalar", "config", "test", "statistic", "p-value", "verdict");
  for (const auto& r : results)
    row(r.kernel, r.scalar, r.config, r.test, format_g(r.statistic, 4), r.p_value ? format_g(*r.p_value, 3) : "-",
        r.passed ? "pass" : (r.known_limitation.empty() ? "FAIL" : "fail (known limitation)"));
  return o.str();
}

std::vector<TestResult> validate(const SamplerUnderTest& s, const BatteryOptions& options, double alpha, Correction c) {
  std::vector<TestResult> r = run_battery(s, options);
  apply_correction(r, alpha, c);
  return r;
}

}  // namespace warpcheck::validation
