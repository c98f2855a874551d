// Specification of the Nelder-Mead optimizer and its multi-start driver (validation/.../nelder_mead.h) on
// standard test functions with known optima.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "warpcheck/validation/nelder_mead.h"

using namespace warpcheck::validation;

namespace {

template <class T> T rosenbrock(std::span<const T> x) {
  T s = 0;
  for (std::size_t i = 0; i + 1 < x.size(); ++i)
    s += T(100) * (x[i + 1] - x[i] * x[i]) * (x[i + 1] - x[i] * x[i]) + (T(1) - x[i]) * (T(1) - x[i]);
  return s;
}
template <class T> T sphere(std::span<const T> x) {
  T s = 0;
  for (std::size_t i = 0; i < x.size(); ++i) s += (x[i] - T(i) / T(10)) * (x[i] - T(i) / T(10));
  return s;
}
template <class T> T himmelblau(std::span<const T> x) {
  const T a = x[0] * x[0] + x[1] - T(11), b = x[0] + x[1] * x[1] - T(7);
  return a * a + b * b;
}
template <class T> Bounds<T> cube(std::size_t n, T lo, T hi) { return {std::vector<T>(n, lo), std::vector<T>(n, hi)}; }

}  // namespace

TEST(NelderMead, ConvergesToTheMinimumOfRosenbrockFromTheClassicStart) {
  NelderMeadOptions<double> o;
  o.max_iterations = 5000;
  o.initial_step = 0.05;
  o.x_tolerance = 1e-14;
  const auto r = nelder_mead(rosenbrock<double>, cube<double>(2, -5, 5), {-1.2, 1.0}, o);
  EXPECT_LT(r.f, 1e-20);
  EXPECT_NEAR(r.x[0], 1.0, 1e-9);
  EXPECT_NEAR(r.x[1], 1.0, 1e-9);
  EXPECT_LT(r.iterations, 5000);  // stopped by the tolerance, not the budget
}

TEST(NelderMead, ConvergesToTheMinimumOfASixDimensionalSphere) {
  NelderMeadOptions<double> o;
  o.max_iterations = 20000;
  o.x_tolerance = 1e-12;
  const auto r = nelder_mead(sphere<double>, cube<double>(6, -1, 1), std::vector<double>(6, 0.9), o);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(r.x[i], i / 10.0, 1e-9) << i;
  EXPECT_LT(r.f, 1e-18);
}

TEST(NelderMead, IteratesInLongDoubleBeyondDoublePrecision) {
  // The nearest double to 1/3 is 1.85e-17 away from it; a long double run must get closer than any double can.
  auto f = [](std::span<const long double> x) { return (x[0] - 1.0L / 3) * (x[0] - 1.0L / 3); };
  NelderMeadOptions<long double> o;
  o.max_iterations = 2000;
  o.x_tolerance = 1e-21L;
  const auto r = nelder_mead(f, cube<long double>(1, 0, 1), {0.9L}, o);
  EXPECT_LT(std::abs(r.x[0] - 1.0L / 3), 1e-18L);
  EXPECT_GT(std::abs(double(1.0L / 3) - 1.0L / 3), 1e-17L);
}

TEST(NelderMead, RespectsTheBoxAndFindsAMinimumOnItsFace) {
  // (x - 2)^2 + (y + 3)^2 on [-1, 1]^2 has its constrained minimum at the corner (1, -1).
  auto f = [](std::span<const double> x) { return (x[0] - 2) * (x[0] - 2) + (x[1] + 3) * (x[1] + 3); };
  long long outside = 0;
  auto counted = [&](std::span<const double> x) {
    outside += std::abs(x[0]) > 1 || std::abs(x[1]) > 1;
    return f(x);
  };
  NelderMeadOptions<double> o;
  o.max_iterations = 500;
  const auto r = nelder_mead(counted, cube<double>(2, -1, 1), {0.0, 0.0}, o);
  EXPECT_EQ(outside, 0);
  EXPECT_DOUBLE_EQ(r.x[0], 1.0);
  EXPECT_DOUBLE_EQ(r.x[1], -1.0);
}

TEST(NelderMead, MaximizesWhenAskedTo) {
  auto f = [](std::span<const double> x) {
    return std::exp(-(x[0] - 0.3) * (x[0] - 0.3) - (x[1] + 0.2) * (x[1] + 0.2));
  };
  NelderMeadOptions<double> o;
  o.goal = Goal::kMaximize;
  o.max_iterations = 1000;
  o.x_tolerance = 1e-12;
  const auto r = nelder_mead(f, cube<double>(2, -1, 1), {-0.8, 0.8}, o);
  EXPECT_NEAR(r.f, 1.0, 1e-15);
  EXPECT_NEAR(r.x[0], 0.3, 1e-7);
  EXPECT_NEAR(r.x[1], -0.2, 1e-7);
}

TEST(NelderMead, TreatsNaNAsInvalidAndNeverReportsIt) {
  // Valid only for x > 0; the unconstrained minimum (x = -0.5) is invalid, the valid infimum is at x -> 0.
  auto f = [](std::span<const double> x) { return x[0] > 0 ? (x[0] + 0.5) * (x[0] + 0.5) : std::nan(""); };
  NelderMeadOptions<double> o;
  o.max_iterations = 500;
  const auto r = nelder_mead(f, cube<double>(1, -1, 1), {0.7}, o);
  EXPECT_FALSE(std::isnan(r.f));
  EXPECT_GT(r.x[0], 0.0);
  EXPECT_LT(r.x[0], 1e-6);
}

TEST(MultiStart, FindsAGlobalMinimumOfHimmelblauFromEverySeed) {
  // Himmelblau has four global minima (value 0); every seed must reach one of them.
  const double minima[4][2] = {{3, 2}, {-2.805118, 3.131312}, {-3.779310, -3.283186}, {3.584428, -1.848126}};
  MultiStartOptions<double> o;
  o.local.max_iterations = 400;
  o.chain_length = 3;
  int found[4] = {0, 0, 0, 0};
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const auto r = multi_start(himmelblau<double>, cube<double>(2, -5, 5), o, seed, 1);
    ASSERT_LT(r.f, 1e-12) << "seed " << seed;
    int which = -1;
    for (int m = 0; m < 4; ++m)
      if (std::hypot(r.x[0] - minima[m][0], r.x[1] - minima[m][1]) < 1e-5) which = m;
    ASSERT_GE(which, 0) << "seed " << seed << " ended at " << r.x[0] << ", " << r.x[1];
    ++found[which];
  }
  // Random starts spread over the basins: each of the four minima is reached from some seed.
  for (int m = 0; m < 4; ++m) EXPECT_GT(found[m], 0) << "minimum " << m;
}

TEST(MultiStart, ChainsArePureFunctionsOfSeedAndIndex) {
  MultiStartOptions<long double> o;
  o.local.max_iterations = 50;
  const auto box = cube<long double>(4, -2, 2);
  const auto a = run_chain(rosenbrock<long double>, box, o, 7, 3);
  const auto b = run_chain(rosenbrock<long double>, box, o, 7, 3);
  const auto c = run_chain(rosenbrock<long double>, box, o, 7, 4);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.f, b.f);
  EXPECT_EQ(a.evaluations, b.evaluations);
  EXPECT_NE(a.x, c.x);
}

TEST(MultiStart, StartingFromTheBestOfCheapSamplesFindsANarrowSpikeMoreOften) {
  // A broad hill with a narrow spike near its top (the shape of rounding-error worst cases). One local run per
  // seed, from a single random point vs from the best of 32 random points; 100 fixed seeds.
  auto f = [](std::span<const double> x) {
    double r2 = 0, s2 = 0;
    for (double v : x) r2 += v * v, s2 += (v - 0.03) * (v - 0.03);
    return std::exp(-r2) + std::exp(-s2 / 1e-4);
  };
  MultiStartOptions<double> single, cheap;
  single.local.goal = cheap.local.goal = Goal::kMaximize;
  single.chain_length = cheap.chain_length = 1;
  single.cheap_samples = 1;
  cheap.cheap_samples = 32;
  int hits_single = 0, hits_cheap = 0;
  for (std::uint64_t seed = 1; seed <= 100; ++seed) {
    hits_single += multi_start(f, cube<double>(4, -1, 1), single, seed, 1).f > 1.5;
    hits_cheap += multi_start(f, cube<double>(4, -1, 1), cheap, seed, 1).f > 1.5;
  }
  EXPECT_GT(hits_cheap, 2 * hits_single + 5) << hits_single << " vs " << hits_cheap;
}

TEST(MultiStart, RestartsAroundTheBestBeatIndependentRestartsAtEqualLocalRuns) {
  // 6-D Rosenbrock, 100 iterations per local run: one chain of 6 runs (5 around its best) against 6 chains of
  // one run each. The refinements continue the climb where a 100-iteration run stops short.
  MultiStartOptions<double> independent, chained;
  independent.chain_length = 1;
  chained.chain_length = 6;
  int wins = 0;
  double log_independent = 0, log_chained = 0;
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    const double a = multi_start(rosenbrock<double>, cube<double>(6, -2, 2), independent, seed, 6).f;
    const double b = multi_start(rosenbrock<double>, cube<double>(6, -2, 2), chained, seed, 1).f;
    wins += b < a;
    log_independent += std::log10(a), log_chained += std::log10(b);
  }
  EXPECT_GT(wins, 15);
  EXPECT_LT(log_chained, log_independent);
}
