// The power figures (power.h) against answers worked out by hand on a uniform grid, their JSON, and the planning
// they answer. The simulation that checks the figures against the battery itself is slow_power.cpp.
#include <gtest/gtest.h>

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/kolmogorov_smirnov.hpp>
#include <boost/math/distributions/non_central_chi_squared.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>

#include "tests/power_fixtures.h"
#include "warpcheck/validation/power.h"

namespace warpcheck::validation {
namespace {

// The uniform density on a 16 x 32 grid: every bin holds 1/512 (a uniform cone's grid).
GridMasses uniform_grid() { return {16, 32, std::vector<double>(512, 1.0 / 512)}; }

double eps_of(const std::vector<TestPower>& t, const std::string& test) {
  for (const TestPower& x : t)
    if (x.test == test) return x.eps;
  ADD_FAILURE() << "no test " << test;
  return 0;
}

// The eps at which chi-square with dof degrees of freedom and non-centrality lambda1 eps^2 has power 0.9.
double chi2_eps_by_hand(double dof, double lambda1, double level) {
  const double critical = boost::math::quantile(boost::math::complement(boost::math::chi_squared(dof), level));
  return std::sqrt(boost::math::non_central_chi_squared::find_non_centrality(dof, critical, 0.1) / lambda1);
}

TEST(Power, TheRegionAlternativeOnAUniformGridHasTheRingNonCentralityWorkedOutByHand) {
  // t10 = 0.1: ring 0 ([0, 1/16)) lies in the region (g = 1), ring 1 ([1/16, 1/8)) by 0.6 (g = 0.6 - 0.4/9 = 5/9),
  // the other 14 rings outside (g = -1/9). Each ring expects n/16, its change n/16 g eps:
  //   lambda1 = n/16 (1 + 25/81 + 14/81) = n/16 * 120/81 = n * 0.0925926 (92.6 at eps = 1% and n = 1e7).
  const double n = 1e7, level = 0.01 / 6;
  const auto t = test_power(uniform_grid(), Alternative::kRegion, std::uint64_t(n), level);
  EXPECT_NEAR(eps_of(t, "chi2-rings"), chi2_eps_by_hand(15, n / 16 * 120 / 81, level), 1e-9);
  // The full grid: the same change spread over 512 bins, 32 to a ring: the same lambda1 with dof 511.
  EXPECT_NEAR(eps_of(t, "chi2"), chi2_eps_by_hand(511, n / 16 * 120 / 81, level), 1e-9);
  EXPECT_GT(eps_of(t, "chi2"), 1.5 * eps_of(t, "chi2-rings"));
  // KS radial: h(t) = t up to t10 = 0.1 where F = 0.1; the nearest sub-row edge is 13/128 (F = 0.1015625,
  // h = 0.1 - 0.0015625 / 9). eps = (d + z sqrt(F (1 - F) / n)) / h, z = 1.2816.
  const double d =
      boost::math::quantile(boost::math::complement(boost::math::kolmogorov_smirnov_distribution<double>(n), level));
  const double F = 13.0 / 128, h = 0.1 - 0.0015625 / 9;
  EXPECT_NEAR(eps_of(t, "ks-radial"), (d + 1.2815515655446004 * std::sqrt(F * (1 - F) / n)) / h, 1e-9);
  // The azimuthal tests cannot see a radial error.
  EXPECT_TRUE(std::isinf(eps_of(t, "chi2-columns")));
  EXPECT_TRUE(std::isinf(eps_of(t, "ks-azimuth")));
}

TEST(Power, TheWedgeIsTheFirstColumnAndItsNonCentralityIsNTimesWOverOneMinusW) {
  // g = 1 on column 0 (mass w = 1/32), -w / (1 - w) = -1/31 elsewhere: lambda1 = n (w + (1 - w) / 31^2) = n w / (1 -
  // w).
  const double n = 1e6, level = 0.01 / 6;
  const auto t = test_power(uniform_grid(), Alternative::kWedge, std::uint64_t(n), level);
  EXPECT_NEAR(eps_of(t, "chi2-columns"), chi2_eps_by_hand(31, n / 31, level), 1e-9);
  EXPECT_TRUE(std::isinf(eps_of(t, "chi2-rings")));
  const auto figures = power_figures(uniform_grid(), std::uint64_t(n), level);
  ASSERT_EQ(figures.size(), 3u);
  EXPECT_EQ(figures[2].alternative, "wedge");
  EXPECT_EQ(figures[2].test, "chi2-columns");
}

TEST(Power, TheTiltOnAUniformGridHasLambdaOfTheRingMidpointsOfTwoTMinusOne) {
  // g = (t - 1/2) / (1/2), each ring's mean g at its midpoint: lambda1 = n/16 sum_r ((2r + 1) / 16 - 1)^2 = n * 85/256.
  const double n = 1e6, level = 0.001;
  const auto t = test_power(uniform_grid(), Alternative::kTilt, std::uint64_t(n), level);
  EXPECT_NEAR(eps_of(t, "chi2-rings"), chi2_eps_by_hand(15, n * 85 / 256, level), 1e-9);
}

TEST(Power, AWedgeWithoutMassIsNotDefinedAndTheFigureSaysSo) {
  GridMasses g = uniform_grid();
  for (int r = 0; r < 16; ++r) g.mass[std::size_t(r * 32)] = 0;  // column 0 empty
  const auto figures = power_figures(g, 1'000'000, 0.001);
  EXPECT_TRUE(std::isnan(figures[2].eps));
  EXPECT_TRUE(figures[2].test.empty());
  EXPECT_FALSE(relative_error(g, Alternative::kWedge));
  EXPECT_TRUE(std::isfinite(figures[0].eps));
}

TEST(Power, TheRelativeErrorHasZeroMeanUnderThePdfAndItsLargestValueIsOne) {
  const GridMasses g = uniform_grid();
  for (Alternative a : kAlternatives) {
    const auto rel = relative_error(g, a);
    ASSERT_TRUE(rel);
    double mean = 0, largest = 0;
    constexpr int kN = 1024;  // midpoints in t and u: exact for the step at t10 = 0.1 and the wedge's at 1/32
    for (int i = 0; i < kN; ++i)
      for (int j = 0; j < 32; ++j) {
        const double v = rel((i + 0.5) / kN, (j + 0.5) / 32);
        mean += v / (kN * 32), largest = std::max(largest, std::abs(v));
      }
    EXPECT_NEAR(mean, 0, 2e-3) << to_string(a);
    EXPECT_NEAR(largest, 1, 2e-3) << to_string(a);
  }
}

TEST(Power, TheFirstStepLevelIsAlphaOverMForHolmAndSidaksThreshold) {
  EXPECT_DOUBLE_EQ(first_step_level(0.01, Correction::kHolm, 4), 0.0025);
  EXPECT_NEAR(first_step_level(0.05, Correction::kSidak, 7), 0.0073008, 1e-7);
}

TEST(Power, SamplesNeededIsTheSmallestCountWhoseBestTestReachesTheError) {
  const GridMasses g = uniform_grid();
  const std::uint64_t n = samples_needed(g, Alternative::kRegion, 1e-3, 0.01, Correction::kHolm, 6);
  ASSERT_GT(n, 0u);
  auto best = [&](std::uint64_t k) {
    double e = INFINITY;
    for (const TestPower& t : test_power(g, Alternative::kRegion, k, 0.01 / 6)) e = std::min(e, t.eps);
    return e;
  };
  EXPECT_LE(best(n), 1e-3);
  EXPECT_GT(best(n - 1), 1e-3);
  // lambda grows as n eps^2: ten times the error needs about a hundredth of the samples.
  const std::uint64_t n10 = samples_needed(g, Alternative::kRegion, 1e-2, 0.01, Correction::kHolm, 6);
  EXPECT_NEAR(double(n) / double(n10), 100, 5);
}

// `warpcheck plan` prints, per case, what samples_needed gives on the case's bin masses from the battery's own
// quadrature (one case, ~5 s).
TEST(Power, ThePlanCommandPrintsTheSamplesNeededForTheCase) {
  namespace fs = std::filesystem;
  const fs::path cli = fs::read_symlink("/proc/self/exe").parent_path().parent_path() / "warpcheck";
  ASSERT_TRUE(fs::exists(cli)) << "build the warpcheck executable";
  const std::string command = cli.string() +
                              " plan --kernel sphere-solid-angle --scalar double --config near --error 0.01"
                              " --alternative region --threads 2";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  char buf[4096];
  for (std::size_t k; (k = std::fread(buf, 1, sizeof buf, pipe)) > 0;) out.append(buf, k);
  ASSERT_EQ(::pclose(pipe), 0) << out;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("near +region +0.01 +(\\d+)  (\\S+)"))) << out;
  BatteryOptions o;
  o.threads = 2;
  const GridMasses g = grid_masses(uniform_cone_case(), o);
  EXPECT_EQ(std::stoull(m[1]), samples_needed(g, Alternative::kRegion, 0.01, 0.01, Correction::kHolm, 6));
  EXPECT_EQ(m[2], "chi2-rings");
}

TEST(Power, ARunsFiguresRoundTripThroughItsJson) {
  BatteryRun run;
  run.samples = 1'000'000;
  TestResult chi2;
  chi2.kernel = "k", chi2.scalar = "double", chi2.config = "c", chi2.test = "chi2", chi2.p_value = 0.5;
  chi2.map_rows = 16, chi2.map_cols = 32;
  chi2.observed.assign(512, 1953), chi2.expected.assign(512, 1e6 / 512);
  run.results.push_back(chi2);
  run.power = run_power(run);
  ASSERT_EQ(run.power.size(), 1u);
  EXPECT_EQ(run.power[0].level, 0.01);  // one statistical test
  run.power[0].figures[2].eps = NAN;    // as for a wedge without mass
  run.power[0].figures[1].eps = INFINITY;
  const BatteryRun back = parse_battery_json(to_json(run));
  ASSERT_EQ(back.power.size(), 1u);
  EXPECT_EQ(back.power[0].kernel, "k");
  EXPECT_EQ(back.power[0].samples, 1'000'000u);
  ASSERT_EQ(back.power[0].figures.size(), 3u);
  EXPECT_EQ(back.power[0].figures[0].eps, run.power[0].figures[0].eps);
  EXPECT_EQ(back.power[0].figures[0].test, run.power[0].figures[0].test);
  EXPECT_TRUE(std::isinf(back.power[0].figures[1].eps));
  EXPECT_TRUE(std::isnan(back.power[0].figures[2].eps));
  EXPECT_TRUE(parse_battery_json(to_json(BatteryRun{})).power.empty());
}

}  // namespace
}  // namespace warpcheck::validation
