// The power figures (power.h) against the battery itself (label "slow"): a correct sampler with each standard
// alternative injected at the predicted eps is rejected, over 100 fixed seeds, in 90% of runs by the test the
// figure names, within three binomial standard deviations (sqrt(0.9 * 0.1 / 100) = 3%), when that test is a
// chi-square; in at least 90% - 9% when it is KS, whose figure rests on a lower bound of the power (power.h).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdio>
#include <random>

#include "tests/power_fixtures.h"
#include "warpcheck/validation/power.h"

namespace warpcheck::validation {
namespace {

// The sampler with its samples' density multiplied by 1 + eps g(t, phi / 2 pi) (its pdf unchanged), by rejection:
// a sample is kept with probability (1 + eps g) / (1 + eps bound), else the sampler is asked again at primary
// samples drawn from a stream seeded by (u0, u1), so that the sampler stays a function of (u0, u1).
SamplerUnderTest inject(SamplerUnderTest s, std::function<double(double, double)> g, double eps) {
  constexpr double kBound = 1.05;  // g <= 1 plus its re-centring (power.h)
  const auto base = s.sample;
  const Cap<Real> cap = s.bounding_cap;
  s.sample = [base, cap, g, eps](double u0, double u1) {
    std::mt19937_64 rng(std::bit_cast<std::uint64_t>(u0) * 0x9e3779b97f4a7c15ULL ^ std::bit_cast<std::uint64_t>(u1));
    auto uniform = [&rng] { return double(rng() >> 11) * 0x1.0p-53; };
    for (;;) {
      const Sample x = base(u0, u1);
      double keep = 1;
      if (x.valid) {
        Real t, phi;
        cap_coordinates(cap, x.direction, t, phi);
        keep = (1 + eps * g(double(t), double(phi / kTwoPi<Real>))) / (1 + eps * kBound);
      }
      if (uniform() < keep) return x;
      u0 = uniform(), u1 = uniform();
    }
  };
  s.sample_block = nullptr, s.sample_block_double = nullptr;  // the block forms would bypass the injected error
  return s;
}

TEST(PowerSimulation, EachAlternativeInjectedAtItsPredictedSizeIsRejectedInNinetyPercentOfRuns) {
  constexpr int kSeeds = 100;
  constexpr double kAlpha = 0.01;
  const SamplerUnderTest base = uniform_cone_case();
  BatteryOptions o;
  o.samples = 100'000;
  std::vector<std::uint64_t> seeds;
  for (int k = 1; k <= kSeeds; ++k) seeds.push_back(std::uint64_t(k));
  const GridMasses g = grid_masses(base, o);
  constexpr std::size_t kTests = 6;  // the statistical tests of one case: the run's m
  const double level = first_step_level(kAlpha, Correction::kHolm, kTests);
  const std::vector<PowerFigure> figures = power_figures(g, o.samples, level);
  for (std::size_t i = 0; i < figures.size(); ++i) {
    const PowerFigure& f = figures[i];
    ASSERT_TRUE(std::isfinite(f.eps)) << f.alternative;
    const SamplerUnderTest s = inject(base, relative_error(g, kAlternatives[i]), f.eps);
    int by_test = 0, by_battery = 0;
    for (const std::vector<TestResult>& run : run_battery_seeds(s, o, seeds)) {
      std::size_t m = 0;
      double min_p = 1;
      for (const TestResult& r : run) {
        if (!r.p_value) continue;
        ++m, min_p = std::min(min_p, *r.p_value);
        by_test += r.test == f.test && *r.p_value <= level;
      }
      ASSERT_EQ(m, kTests);
      by_battery += min_p <= level;  // Holm at alpha over m tests rejects exactly when the smallest p <= alpha / m
    }
    std::fprintf(stderr, "[power] %s: eps %.4g by %s; rejected by it in %d of %d runs, by the battery in %d\n",
                 f.alternative.c_str(), f.eps, f.test.c_str(), by_test, kSeeds, by_battery);
    RecordProperty(f.alternative + "_rejected_by_test", by_test);
    RecordProperty(f.alternative + "_rejected_by_battery", by_battery);
    // A chi-square figure is the non-central chi-square's 0.9 quantile: 90 +- 9. A KS figure is Massey's lower bound
    // of the power: at least 90 - 9 (a smooth tilt is rejected in about 99 of 100 runs at its KS figure).
    if (f.test.rfind("ks-", 0) == 0)
      EXPECT_GE(by_test, 81) << f.alternative << " at eps " << f.eps << " by " << f.test;
    else
      EXPECT_NEAR(by_test, 90, 9) << f.alternative << " at eps " << f.eps << " by " << f.test;
    EXPECT_GE(by_battery, by_test);
  }
}

}  // namespace
}  // namespace warpcheck::validation
