// warpcheck/validation/power.h: the battery's power against standard alternatives, and sample-count planning.
//
// An alternative is a sampler whose samples follow q = p (1 + eps g) while its pdf reports p, g a fixed relative
// error shape with integral of p g over the bounding cap equal to 0 and max |g| = 1 where p has mass, so that eps
// is the largest relative density error. In the cap's frame (t, u = phi / 2 pi):
//   region  g = 1 on the innermost 10% of the mass (t <= t10), -1/9 beyond: a tenth of the support too dense
//   tilt    g = (t - mean t) / s, s the largest |t - mean t| on the support: a smooth radial tilt
//   wedge   g = 1 on the first column of the chi-square grid (u < 1 / A), -w / (mass - w) elsewhere, w its mass:
//           a thin azimuthal wedge
// The power of each statistical test is computed from the case's bin masses alone (the chi2 map's expected
// counts), each bin's mass spread uniformly over its (t, u) rectangle (exact for a pdf constant on the bin):
//   chi2, chi2-rings, chi2-columns, chi2-coarse: non-central chi-square with lambda = n sum (dq)^2 / p over the
//       cells after the test's own pooling, dof as the test has it; the eps where P(chi2'(dof, lambda) > the
//       critical value at `level`) = target (boost::math::non_central_chi_squared::find_non_centrality)
//   ks-radial, ks-azimuth: Massey's bound, P(D > d) >= P(|F_n(x) - F(x)| > d) at any one x, with F_n(x) normal of
//       mean F(x) + eps h(x) and variance F(1 - F) / n (h the CDF's change per unit eps); d the critical value of
//       boost::math::kolmogorov_smirnov_distribution at `level`; eps = min over x of (d + z_target sigma) / |h|
//       (a lower bound of the power: a KS figure errs on the large side; slow_power.cpp measures by how much)
// The battery rejects when any of its tests does at the correction's first-step level (Holm: alpha / m, Sidak:
// 1 - (1 - alpha)^(1/m)), so the most powerful single test's eps is what the battery reaches at least: the figure
// stated is that one, and the test that reaches it. docs/derivations/power.md derives the formulas.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "warpcheck/validation/battery.h"
#include "warpcheck/validation/results.h"

namespace warpcheck::validation {

enum class Alternative { kRegion, kTilt, kWedge };
inline constexpr Alternative kAlternatives[] = {Alternative::kRegion, Alternative::kTilt, Alternative::kWedge};
const char* to_string(Alternative a);

// The per-test level at which the run's correction makes its first rejection.
double first_step_level(double alpha, Correction c, std::size_t statistical_tests);

// The chi-square grid of one case: R x A bin masses (row-major [ring][column], the pdf's integral over each bin).
struct GridMasses {
  int rows = 0, cols = 0;
  std::vector<double> mass;
};
// The masses of a chi2 result's map at n samples (expected / n).
GridMasses grid_masses(const TestResult& chi2, std::uint64_t n);
// The masses by the battery's own quadrature (options.samples sets the accuracy it asks for).
GridMasses grid_masses(const SamplerUnderTest& s, const BatteryOptions& options);

// The smallest eps each statistical test rejects with probability `target` at n samples and `level`; +infinity
// when the test cannot see the alternative, NaN for every test when the alternative is not defined on the grid.
struct TestPower {
  std::string test;
  double eps = 0;
};
std::vector<TestPower> test_power(const GridMasses& g, Alternative a, std::uint64_t n, double level,
                                  double target = 0.9, double min_expected = 5);
// The best of test_power for each alternative.
std::vector<PowerFigure> power_figures(const GridMasses& g, std::uint64_t n, double level, double target = 0.9,
                                       double min_expected = 5);
// The alternative's relative error g at (t, u = phi / 2 pi) of the cap's frame, as the figures above assume it
// (re-centred on the grid's masses); empty when the alternative is not defined there. For injecting it into a
// sampler (the simulation test of the figures).
std::function<double(double, double)> relative_error(const GridMasses& g, Alternative a);
// One CasePower per chi2 result of a judged run, at run.samples and the first-step level of its correction over
// all its statistical tests; empty without run.samples.
std::vector<CasePower> run_power(const BatteryRun& run);

// The smallest sample count n at which the battery, its m statistical tests judged at alpha with correction c,
// rejects the alternative with relative error eps with probability `target` (by bisection on n over test_power,
// which also moves the pooling with n); 0 when no n up to 2^62 reaches it.
std::uint64_t samples_needed(const GridMasses& g, Alternative a, double eps, double alpha, Correction c,
                             std::size_t statistical_tests, double target = 0.9, double min_expected = 5);

}  // namespace warpcheck::validation
