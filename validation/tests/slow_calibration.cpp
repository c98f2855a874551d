// Calibration of the battery's false-positive control (label "slow"): on correct kernels, over 100 seeds,
//  (1) the p-values of each statistical test are uniform (a KS test of uniformity per test type), and
//  (2) the battery, judged at alpha with Holm's correction across all its tests, fails on at most 2 alpha of
//      the seeds.
// The seeds are fixed (1..100), so the verdict is reproducible; the calibration's own false-positive rate
// is stated at each check.
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/math/distributions/kolmogorov_smirnov.hpp>
#include <cmath>
#include <cstdio>
#include <map>

#include "warpcheck/validation/registry.h"

namespace warpcheck::validation {
namespace {

// One-sample KS test of uniformity on [0, 1]; returns the p-value.
double uniformity_p(std::vector<double> p) {
  std::sort(p.begin(), p.end());
  const double n = double(p.size());
  double d = 0;
  for (std::size_t i = 0; i < p.size(); ++i) d = std::max({d, (i + 1) / n - p[i], p[i] - i / n});
  boost::math::kolmogorov_smirnov_distribution<double> dist(n);
  return boost::math::cdf(boost::math::complement(dist, d));
}

TEST(Calibration, CorrectKernelsGiveUniformPValuesAndFailAtMostTwiceAlphaOfTheTime) {
  constexpr int kSeeds = 100;
  constexpr double kAlpha = 0.01;
  // Correct kernels, in double: both sphere kernels in a near (large cap, tilted normal) and a grazing
  // configuration. 1e5 samples per run keep the test to minutes; calibration is about the null distribution,
  // which the tests must get right at any sample count.
  const Registry reg = default_registry();
  std::vector<const Case*> cases;
  for (const Case* c : reg.select({"sphere-solid-angle", "sphere-visible-area"}, {"near", "grazing"}))
    if (c->scalar == "double") cases.push_back(c);
  ASSERT_EQ(cases.size(), 4u);
  std::map<std::string, std::vector<double>> p_by_test;
  int failed_runs = 0;
  // Seeds 1..100; the seed-independent quadrature is done once per case (run_battery_seeds).
  BatteryOptions o;
  o.samples = 100'000;
  std::vector<std::uint64_t> seeds;
  for (int seed = 1; seed <= kSeeds; ++seed) seeds.push_back(std::uint64_t(seed));
  std::vector<std::vector<std::vector<TestResult>>> by_case;  // [case][seed]
  for (const Case* c : cases) {
    by_case.push_back(run_battery_seeds(c->make(), o, seeds));
    std::fprintf(stderr, "[calibration] %s %s: %d seeds done\n", c->kernel.c_str(), c->config.c_str(), kSeeds);
  }
  for (int i = 0; i < kSeeds; ++i) {
    std::vector<TestResult> run;  // one battery run: the four cases at seed i + 1, corrected together
    for (const auto& runs : by_case) run.insert(run.end(), runs[i].begin(), runs[i].end());
    apply_correction(run, kAlpha, Correction::kHolm);
    failed_runs += !all_passed(run);
    for (const auto& r : run)
      if (r.p_value) p_by_test[r.test].push_back(*r.p_value);
  }
  std::fprintf(stderr, "[calibration] failed runs %d of %d\n", failed_runs, kSeeds);
  // (1) Six test types, 400 p-values each; each uniformity test at 1e-3 (calibration false-positive rate
  // at most 6e-3 for this check).
  for (const auto& [test, ps] : p_by_test) {
    const double p = uniformity_p(ps);
    RecordProperty("uniformity_p_" + test, std::to_string(p));
    std::fprintf(stderr, "[calibration] %s: %zu p-values, KS uniformity p = %.4g\n", test.c_str(), ps.size(), p);
    EXPECT_GT(p, 1e-3) << test << " p-values are not uniform";
  }
  EXPECT_EQ(p_by_test.size(), 6u);
  // (2) Failure rate at most 2 alpha: at most 2 of 100 runs. With an exact battery the number of failed runs
  // is Binomial(100, <= 0.01), which exceeds 2 with probability at most 0.079: the criterion, stated with its
  // own false-positive rate.
  RecordProperty("failed_runs", failed_runs);
  EXPECT_LE(failed_runs, int(2 * kAlpha * kSeeds));
}

}  // namespace
}  // namespace warpcheck::validation
