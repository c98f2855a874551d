// The battery's own statistics against known answers: chi-square, Kolmogorov-Smirnov, the Holm and Sidak
// corrections and the deterministic tests, each on inputs small enough to work out by hand (the working is in the
// comments) or checked against Boost.Math called directly, never against a value the battery produced; then a fast
// calibration (uniform p-values on correct samplers). Each group names the slips in the battery's arithmetic it
// catches; the negative controls fail by margins too large to see them, and the 100-seed calibration is slow.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/kolmogorov_smirnov.hpp>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

#include "battery/drawing.h"
#include "battery/tests.h"
#include "tests/quadrature_fixtures.h"
#include "warpcheck/validation/battery.h"
#include "warpcheck/validation/registry.h"
#include "warpcheck/validation/results.h"

namespace warpcheck::validation {
namespace {

// ---- Chi-square ------------------------------------------------------------------------------------------------
// Slips caught: the outside-the-cap cell left out, or counting only the samples outside and not the declined and
// non-finite ones; dof = cells instead of cells - 1, or the bins before pooling instead of after; bins expecting
// exactly min_expected pooled (<= for <); no pooling; the partial pool kept as its own cell, dropped, or folded into
// the largest bin instead of the smallest; the p-value from the CDF instead of its complement; a sample where the
// pdf puts no mass not failing the test.

// chi_square on a hand-made histogram of n samples: the bins' masses (1 - their sum lies outside the cap), the
// counts in them, and the samples outside the cap, declined and non-finite.
TestResult chi_square_of(std::uint64_t n, const std::vector<Real>& mass, const std::vector<std::uint64_t>& counts,
                         std::uint64_t outside, std::uint64_t declined = 0, std::uint64_t non_finite = 0) {
  SamplerUnderTest s;
  s.kernel = "hand-made";
  BatteryOptions o;
  o.samples = n;
  battery::Draws d;
  d.n = n, d.counts = counts, d.outside = outside, d.declined = declined, d.non_finite = non_finite;
  battery::Expected e;
  e.mass = mass;
  e.quadrature = "hand";
  return battery::chi_square(s, o, d, e);
}

// Expected counts e out of n = 1024 as masses e / 1024 (exact in binary).
std::vector<Real> masses_of_1024(const std::vector<int>& expected) {
  std::vector<Real> m;
  for (int e : expected) m.push_back(Real(e) / 1024);
  return m;
}

// Survival functions of chi-square with 2 and 4 degrees of freedom in closed form: e^(-x/2) and e^(-x/2) (1 + x/2).
double chi2_survival_dof2(double x) { return std::exp(-x / 2); }
double chi2_survival_dof4(double x) { return std::exp(-x / 2) * (1 + x / 2); }

TEST(ChiSquareKnownAnswers, TheOutsideCellHoldsTheOutsideDeclinedAndNonFiniteSamplesAndCountsAsOneMoreDegree) {
  // n = 1000; four bins of masses 1/8, 1/4, 3/8, 1/8 expect 125, 250, 375, 125; the cell outside the cap expects
  // 1000 (1 - 7/8) = 125 and holds 120 outside + 15 declined + 5 non-finite = 140 samples.
  //   chi2 = 15^2/125 + 20^2/250 + 5^2/375 + 15^2/125 + 15^2/125 = 1.8 + 1.6 + 1/15 + 1.8 + 1.8 = 106/15,
  //   dof = 5 cells - 1 = 4.
  const TestResult r = chi_square_of(1000, {0.125L, 0.25L, 0.375L, 0.125L}, {140, 230, 380, 110}, 120, 15, 5);
  const double chi2 = 106.0 / 15;
  EXPECT_NEAR(r.statistic, chi2, 1e-12);
  ASSERT_TRUE(r.p_value);
  EXPECT_NEAR(*r.p_value, chi2_survival_dof4(chi2), 1e-12) << r.detail;  // 0.1324...
  EXPECT_NE(r.detail.find("dof 4,"), std::string::npos) << r.detail;
  EXPECT_NE(r.detail.find(" 0 pooled"), std::string::npos) << r.detail;
}

TEST(ChiSquareKnownAnswers, BinsExpectingFewerThanFiveArePooledIntoOneCellWhateverTheirPlaceInTheGrid) {
  // n = 1024, expected counts (grid order) 300, 2, 5, 400, 1, 314, 2; nothing outside the cap (its empty cell
  // expects 0 and joins the pool). Pooled: 2 + 1 + 2 = 5 expected, 4 + 3 + 0 = 7 observed, a cell of its own since
  // 5 >= min_expected. The bin expecting exactly 5 is not pooled. Cells (expected, observed): (5, 7), (5, 9),
  // (300, 290), (314, 308), (400, 410):
  //   chi2 = 4/5 + 16/5 + 100/300 + 36/314 + 100/400 = 4 + 1/3 + 18/157 + 1/4, dof = 5 - 1 = 4.
  const TestResult r = chi_square_of(1024, masses_of_1024({300, 2, 5, 400, 1, 314, 2}), {290, 4, 9, 410, 3, 308, 0}, 0);
  const double chi2 = 4 + 1.0 / 3 + 18.0 / 157 + 0.25;
  EXPECT_NEAR(r.statistic, chi2, 1e-12);
  ASSERT_TRUE(r.p_value);
  EXPECT_NEAR(*r.p_value, chi2_survival_dof4(chi2), 1e-12) << r.detail;  // 0.3197...
  EXPECT_NE(r.detail.find("dof 4,"), std::string::npos) << r.detail;
  EXPECT_NE(r.detail.find(" 4 pooled"), std::string::npos) << r.detail;  // three bins and the empty outside cell
}

TEST(ChiSquareKnownAnswers, APoolStillExpectingFewerThanFiveIsFoldedIntoTheSmallestRegularBin) {
  // n = 1024, expected 60, 1, 921, 40, 2 (grid order); the pool expects 1 + 2 (+ 0 outside) = 3 < 5 and holds
  // 2 + 3 = 5: it joins the smallest regular bin, 40 (observed 35). Cells: (43, 40), (60, 70), (921, 914):
  //   chi2 = 9/43 + 100/60 + 49/921, dof = 3 - 1 = 2.
  const TestResult r = chi_square_of(1024, masses_of_1024({60, 1, 921, 40, 2}), {70, 2, 914, 35, 3}, 0);
  const double chi2 = 9.0 / 43 + 100.0 / 60 + 49.0 / 921;
  EXPECT_NEAR(r.statistic, chi2, 1e-12);
  ASSERT_TRUE(r.p_value);
  EXPECT_NEAR(*r.p_value, chi2_survival_dof2(chi2), 1e-12) << r.detail;  // 0.3811...
  EXPECT_NE(r.detail.find("dof 2,"), std::string::npos) << r.detail;
}

TEST(ChiSquareKnownAnswers, AnOutsideCellExpectingFewerThanFiveIsPooledAndThePValueIsBoostsChiSquaredSurvival) {
  // n = 1024, bins expecting 200, 300, 521 and 1.5 (mass 3/2048); outside the cap 1024 - 1022.5 = 1.5 expected,
  // 4 observed (3 outside, 1 declined). Pool: 1.5 + 1.5 = 3 < 5, observed 0 + 4 = 4, folded into the 200 bin
  // (observed 190). Cells (203, 194), (300, 310), (521, 520):
  //   chi2 = 81/203 + 100/300 + 1/521, dof 2; the p-value against boost::math::chi_squared(2) directly.
  const TestResult r = chi_square_of(1024, {Real(200) / 1024, Real(300) / 1024, Real(521) / 1024, Real(3) / 2048},
                                     {190, 310, 520, 0}, 3, 1);
  const double chi2 = 81.0 / 203 + 100.0 / 300 + 1.0 / 521;
  EXPECT_NEAR(r.statistic, chi2, 1e-12);
  ASSERT_TRUE(r.p_value);
  const boost::math::chi_squared dist(2);
  EXPECT_NEAR(*r.p_value, boost::math::cdf(boost::math::complement(dist, chi2)), 1e-12) << r.detail;
}

TEST(ChiSquareKnownAnswers, ASampleWhereThePdfPutsNoMassGivesPZero) {
  // Every mass inside the cap (1/4 + 3/4): one declined sample is impossible under the null hypothesis...
  const TestResult declined = chi_square_of(1024, {0.25L, 0.75L}, {256, 767}, 0, 1);
  ASSERT_TRUE(declined.p_value);
  EXPECT_EQ(*declined.p_value, 0.0) << declined.detail;
  EXPECT_TRUE(std::isinf(declined.statistic));
  // ... and so is a sample in a bin of zero mass.
  const TestResult empty_bin = chi_square_of(1024, {0.25L, 0.75L, 0}, {256, 767, 1}, 0);
  ASSERT_TRUE(empty_bin.p_value);
  EXPECT_EQ(*empty_bin.p_value, 0.0) << empty_bin.detail;
}

// The grid aggregates on a hand-made 2 x 2 grid of n = 1000 samples: masses 1/8, 1/8 (ring 0), 1/4, 1/4 (ring 1),
// 1/4 outside the cap; counts 140, 140, 230, 240, 250 outside. Slips caught: a bin joining the wrong ring or column,
// the outside cell left out, dof from the grid instead of the cells.
std::vector<TestResult> aggregates_of_2x2() {
  SamplerUnderTest s;
  s.kernel = "hand-made";
  BatteryOptions o;
  o.samples = 1000, o.radial_bins = 2, o.azimuth_bins = 2;
  battery::Draws d;
  d.n = 1000, d.counts = {140, 140, 230, 240}, d.outside = 250;
  battery::Expected e;
  e.mass = {0.125L, 0.125L, 0.25L, 0.25L};
  std::vector<TestResult> out;
  battery::aggregate_chi_squares(s, o, d, e, out);
  return out;
}

TEST(ChiSquareKnownAnswers, TheRingAggregateSumsEachRingAndSeesACoherentExcessWithFewerDegreesOfFreedom) {
  // Rings (expected, observed): (250, 280), (500, 470), outside (250, 250): chi2 = 900/250 + 900/500 = 5.4, dof 2,
  // p = e^-2.7 = 0.067; the full grid's chi2 of the same counts is 5.6 with dof 4 (p = 0.23).
  const std::vector<TestResult> r = aggregates_of_2x2();
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0].test, "chi2-rings");
  EXPECT_NEAR(r[0].statistic, 5.4, 1e-12);
  EXPECT_NEAR(*r[0].p_value, chi2_survival_dof2(5.4), 1e-12) << r[0].detail;
  const TestResult full = chi_square_of(1000, {0.125L, 0.125L, 0.25L, 0.25L}, {140, 140, 230, 240}, 250);
  EXPECT_NEAR(full.statistic, 5.6, 1e-12);
  EXPECT_LT(*r[0].p_value, *full.p_value / 3);
}

TEST(ChiSquareKnownAnswers, TheColumnAggregateSumsEachColumnAndTheCoarseGridKeepsAGridSmallerThanItself) {
  // Columns: (375, 370), (375, 380), outside (250, 250): chi2 = 25/375 + 25/375 = 2/15, dof 2. The coarse grid
  // (at most 4 x 8) of a 2 x 2 grid is the grid itself: chi2 = 225/125 + 225/125 + 400/250 + 100/250 = 5.6, dof 4.
  const std::vector<TestResult> r = aggregates_of_2x2();
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[1].test, "chi2-columns");
  EXPECT_NEAR(r[1].statistic, 2.0 / 15, 1e-12);
  EXPECT_NEAR(*r[1].p_value, chi2_survival_dof2(2.0 / 15), 1e-12) << r[1].detail;
  EXPECT_EQ(r[2].test, "chi2-coarse");
  EXPECT_NEAR(r[2].statistic, 5.6, 1e-12);
  EXPECT_NEAR(*r[2].p_value, chi2_survival_dof4(5.6), 1e-12) << r[2].detail;
}

// ---- Kolmogorov-Smirnov ---------------------------------------------------------------------------------------
// Slips caught: a one-sided D (F - i/n or i/n - F without the absolute value); the count at a node taken before
// adding its slab (the empirical CDF's left limit); n taken as the samples in the slabs instead of every sample
// drawn (one outside the cap leaves the empirical CDF at 0.8 at the last node); the p-value from the CDF instead of
// its complement, or for another n than the samples'.

// Survival function of the limiting Kolmogorov distribution of sqrt(n) D, which Boost's
// kolmogorov_smirnov_distribution(n) implements: P(sqrt(n) D > lambda) = 2 sum_k>=1 (-1)^(k-1) exp(-2 k^2 lambda^2),
// whose terms beyond k = 20 are below e^-220 for lambda >= 0.5; below 0.5 by the dual series (Jacobi's theta
// transformation) 1 - sqrt(2 pi) / lambda sum_k>=1 exp(-(2k-1)^2 pi^2 / (8 lambda^2)), whose third term is below
// e^-123 there.
double kolmogorov_survival(double lambda) {
  if (!(lambda > 0)) return 1;
  double sum = 0;
  if (lambda < 0.5) {
    for (int k = 1; k <= 5; ++k)
      sum += std::exp(-(2 * k - 1) * (2 * k - 1) * kPi<double> * kPi<double> / (8 * lambda * lambda));
    return 1 - std::sqrt(kTwoPi<double>) / lambda * sum;
  }
  for (int k = 1; k <= 40; ++k) sum += (k % 2 ? 2 : -2) * std::exp(-2.0 * k * k * lambda * lambda);
  return sum;
}

// The reference itself: its two series meet at lambda = 0.5, and both agree with Boost's distribution for n = 1;
// at lambda = 1.358 the survival is the classical 5% point.
TEST(KsKnownAnswers, TheKolmogorovSurvivalUsedAsReferenceAgreesWithBoostAndItsTwoSeriesMeet) {
  EXPECT_NEAR(kolmogorov_survival(0.5 - 1e-12), kolmogorov_survival(0.5), 1e-11);
  const boost::math::kolmogorov_smirnov_distribution<double> one(1);
  for (double lambda : {0.2, 0.3, 0.45, 0.5, 0.8, 1.0, 1.358, 2.0})
    EXPECT_NEAR(kolmogorov_survival(lambda), boost::math::cdf(boost::math::complement(one, lambda)), 1e-13) << lambda;
  EXPECT_NEAR(kolmogorov_survival(1.358), 0.05, 1e-4);
}

// ks-radial of n samples, slabs[k] of them in (x[k-1], x[k]], against the CDF F = x (uniform on [0, 1]).
TestResult ks_uniform(std::uint64_t n, const std::vector<Real>& x, const std::vector<std::uint64_t>& slabs) {
  SamplerUnderTest s;
  s.kernel = "hand-made";
  const battery::KsCdfs c{x, x, x, x};
  battery::Draws d;
  d.n = n, d.radial_slabs = slabs, d.azimuth_slabs = slabs;
  std::vector<TestResult> out;
  battery::ks_tests(s, c, d, out);
  EXPECT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].statistic, out[1].statistic);  // the same slabs and CDF on both marginals
  return out[0];
}

TEST(KsKnownAnswers, DIsTheLargerOfDPlusAndDMinusAndIsFoundJustBeforeAJumpWhenANodeIsThere) {
  // Values 0.4, 0.6, 0.85, 0.9 of U(0, 1), n = 4. D+ = max(i/n - x_i) = max(-0.15, -0.1, -0.1, 0.1) = 0.1;
  // D- = max(x_i - (i-1)/n) = max(0.4, 0.35, 0.35, 0.15) = 0.4, just before the jump at 0.4. Exact D = 0.4.
  // With a node 1e-9 before each value, D at the nodes is 0.4 - 1e-9.
  const Real e = 1e-9L;
  const TestResult before = ks_uniform(4, {0, 0.4L - e, 0.4L, 0.6L - e, 0.6L, 0.85L - e, 0.85L, 0.9L - e, 0.9L, 1},
                                       {0, 0, 1, 0, 1, 0, 1, 0, 1, 0});
  EXPECT_NEAR(before.statistic, 0.4 - 1e-9, 1e-15);
  // With nodes at the values only, D is read on the right limits: |x_i - i/n| = 0.15, 0.1, 0.1, 0.1, so D at the
  // nodes is 0.15 <= the exact 0.4 (the conservative direction).
  const TestResult at_values = ks_uniform(4, {0, 0.4L, 0.6L, 0.85L, 0.9L, 1}, {0, 1, 1, 1, 1, 0});
  EXPECT_NEAR(at_values.statistic, 0.15, 1e-15);
  // Values 0.05, 0.1, 0.8, 0.9: D+ = max(0.2, 0.4, -0.05, 0.1) = 0.4 at 0.1, D- = max(0.05, -0.15, 0.3, 0.15) =
  // 0.3: the exact D = 0.4 is read at the node 0.1.
  const TestResult plus = ks_uniform(4, {0, 0.05L, 0.1L, 0.8L, 0.9L, 1}, {0, 1, 1, 1, 1, 0});
  EXPECT_NEAR(plus.statistic, 0.4, 1e-15);
}

TEST(KsKnownAnswers, ASampleBeyondTheLastNodeLeavesTheEmpiricalCdfBelowOne) {
  // n = 5 with values 0.1, 0.3, 0.5, 0.7 and one sample outside: the empirical CDF at the nodes is 0.2, 0.4, 0.6,
  // 0.8 and 0.8 at x = 1: |F - i/n| = 0.1, 0.1, 0.1, 0.1, 0.2, so D = 0.2 (n = 4 would give 0.3 at 0.7).
  const TestResult r = ks_uniform(5, {0, 0.1L, 0.3L, 0.5L, 0.7L, 1}, {0, 1, 1, 1, 1, 0});
  EXPECT_NEAR(r.statistic, 0.2, 1e-15);
  ASSERT_TRUE(r.p_value);
  EXPECT_NEAR(*r.p_value, kolmogorov_survival(0.2 * std::sqrt(5.0)), 1e-12);  // 0.9639...
}

TEST(KsKnownAnswers, ThePValueIsTheKolmogorovSurvivalOfSqrtNTimesD) {
  // n = 1000: 530 values in (0, 0.5], 470 in (0.5, 1]; D = |0.5 - 0.53| = 0.03 at the node 0.5,
  // lambda = 0.03 sqrt(1000) = 0.9487, p = 0.3296...
  const TestResult r = ks_uniform(1000, {0, 0.5L, 1}, {0, 530, 470});
  EXPECT_NEAR(r.statistic, 0.03, 1e-15);
  ASSERT_TRUE(r.p_value);
  EXPECT_NEAR(*r.p_value, kolmogorov_survival(0.03 * std::sqrt(1000.0)), 1e-12);
  // And for the values of the first test (n = 4, D = 0.4 - 1e-9): lambda = 0.8, p = 0.5441...
  const TestResult small = ks_uniform(4, {0, 0.4L - 1e-9L, 0.4L, 0.6L, 0.85L, 0.9L, 1}, {0, 0, 1, 1, 1, 1, 0});
  ASSERT_TRUE(small.p_value);
  EXPECT_NEAR(*small.p_value, kolmogorov_survival((0.4 - 1e-9) * 2), 1e-12);
}

// ---- Holm and Sidak -------------------------------------------------------------------------------------------
// Slips caught: single-step Bonferroni (alpha / m for every p) instead of Holm's step-down alpha / (m - i); Holm
// not stopping at its first acceptance; < for <= at a threshold; the p-values sorted descending; Bonferroni's
// alpha / m or 1 - (1 - alpha)^m for Sidak's 1 - (1 - alpha)^(1/m); every result counted in m, by apply_correction
// or by the count the CLI and the JSON report (BatteryRun::statistical_tests).

// Which of the p-values apply_correction rejects (in their order), after checking that m is their number.
std::vector<bool> rejected(const std::vector<double>& p, double alpha, Correction c) {
  std::vector<TestResult> r;
  for (double x : p) {
    r.emplace_back().p_value = x;
    r.emplace_back().passed = true;  // a deterministic result between each: judged by nothing, counted nowhere
  }
  EXPECT_EQ(apply_correction(r, alpha, c), p.size());
  std::vector<bool> out;
  for (std::size_t k = 0; k < r.size(); k += 2) {
    out.push_back(!r[k].passed);
    EXPECT_TRUE(r[k + 1].passed);
  }
  return out;
}

using Rejections = std::vector<bool>;

TEST(CorrectionKnownAnswers, HolmStepsDownWhereBonferroniWouldStop) {
  // alpha 0.05, m = 3: Holm's thresholds for the sorted p-values 0.05/3 = 0.0167, 0.025, 0.05. 0.01 <= 0.0167,
  // 0.02 <= 0.025, 0.04 <= 0.05: all three rejected; Bonferroni (0.0167 for all) rejects only 0.01.
  EXPECT_EQ(rejected({0.04, 0.01, 0.02}, 0.05, Correction::kHolm), (Rejections{true, true, true}));
  // 0.001 <= 0.0167 rejected; 0.03 > 0.025 accepted, and Holm stops: 0.032 <= 0.05 is accepted too.
  EXPECT_EQ(rejected({0.032, 0.03, 0.001}, 0.05, Correction::kHolm), (Rejections{false, false, true}));
}

TEST(CorrectionKnownAnswers, HolmRejectsAtItsThresholdsAndJudgesTiesAlike) {
  // alpha 0.5, m = 2: thresholds 0.25 and 0.5 exactly; p equal to them is rejected (p <= threshold).
  EXPECT_EQ(rejected({0.5, 0.25}, 0.5, Correction::kHolm), (Rejections{true, true}));
  // Ties: alpha 0.05, m = 3. 0.01, 0.01 <= 0.0167, 0.025 rejected, 0.2 accepted; three 0.02 > 0.0167: none.
  EXPECT_EQ(rejected({0.01, 0.2, 0.01}, 0.05, Correction::kHolm), (Rejections{true, false, true}));
  EXPECT_EQ(rejected({0.02, 0.02, 0.02}, 0.05, Correction::kHolm), (Rejections{false, false, false}));
}

TEST(CorrectionKnownAnswers, WithOneTestHolmAndSidakRejectExactlyAtAlpha) {
  EXPECT_EQ(rejected({0.01}, 0.01, Correction::kHolm), (Rejections{true}));
  EXPECT_EQ(rejected({0.01 * (1 + 1e-12)}, 0.01, Correction::kHolm), (Rejections{false}));
  EXPECT_EQ(rejected({0.01 * (1 - 1e-12)}, 0.01, Correction::kSidak), (Rejections{true}));
  EXPECT_EQ(rejected({0.01 * (1 + 1e-12)}, 0.01, Correction::kSidak), (Rejections{false}));
}

TEST(CorrectionKnownAnswers, SidakRejectsBelowOneMinusOneMinusAlphaToTheOneOverM) {
  // alpha 0.05, m = 7: threshold 1 - 0.95^(1/7) = 0.0073008 (std::pow in long double); Bonferroni's would be
  // 0.05 / 7 = 0.0071429. Each p sits 1e-9 relative on either side of the threshold, or between the two levels.
  const double t = double(1 - std::pow(0.95L, 1.0L / 7));
  EXPECT_NEAR(t, 0.0073008, 1e-7);
  const std::vector<double> p = {t * (1 - 1e-9), t * (1 + 1e-9), 0.0072, 0.5, 0.9, 0.0001, 0.99};
  EXPECT_EQ(rejected(p, 0.05, Correction::kSidak), (Rejections{true, false, true, false, false, true, false}));
}

TEST(CorrectionKnownAnswers, TheReportedStatisticalTestCountIsTheNumberOfPValuesCorrected) {
  // Two battery runs' worth of results: 3 p-values each and 3 deterministic results each.
  BatteryRun run;
  for (int k = 0; k < 2; ++k)
    for (const char* test : {"chi2", "ks-radial", "ks-azimuth", "pdf-integral", "pdf-consistency", "normalization"}) {
      TestResult& r = run.results.emplace_back();
      r.test = test;
      if (std::string(test).rfind("pdf", 0) != 0 && std::string(test) != "normalization") r.p_value = 0.5;
    }
  EXPECT_EQ(apply_correction(run.results, 0.01, Correction::kHolm), 6u);
  EXPECT_EQ(run.statistical_tests(), 6u);
}

// The same count as the CLI reports it: `warpcheck validate` prints "... correction over M statistical tests", M the
// p-values in its JSON file, six per case (chi2, ks-radial, ks-azimuth, chi2-rings, chi2-columns, chi2-coarse); four
// cases of 2000 samples (~1 s).
TEST(CorrectionKnownAnswers, TheCliSummaryCountsEveryPValueOfTheRunInItsCorrection) {
  namespace fs = std::filesystem;
  // The CLI is built into the build root, the test executable into build/validation/.
  const fs::path cli = fs::read_symlink("/proc/self/exe").parent_path().parent_path() / "warpcheck";
  ASSERT_TRUE(fs::exists(cli)) << "build the warpcheck executable";
  const fs::path json = fs::temp_directory_path() / ("warpcheck-count-" + std::to_string(::getpid()) + ".json");
  const std::string command = cli.string() +
                              " validate --kernel 'sphere-*' --scalar double --config near --config far --samples 2000"
                              " --threads 1 --quiet --correction sidak --json " +
                              json.string();
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  char buf[4096];
  for (std::size_t k; (k = std::fread(buf, 1, sizeof buf, pipe)) > 0;) out.append(buf, k);
  ::pclose(pipe);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("on (\\d+) cases in .* sidak correction over (\\d+) statistical")))
      << out;
  std::ifstream f(json);
  const BatteryRun run = parse_battery_json(std::string(std::istreambuf_iterator<char>(f), {}));
  fs::remove(json);
  std::size_t p_values = 0;
  for (const TestResult& r : run.results) p_values += r.p_value.has_value();
  EXPECT_EQ(std::stoul(m[1]), 4u);
  EXPECT_EQ(p_values, 6 * 4u);
  EXPECT_EQ(std::stoul(m[2]), p_values);
}

// ---- Deterministic tests --------------------------------------------------------------------------------------
// Slips caught: pdf-integral without the integral outside the bounding cap (0.85 for a uniform density on the
// sphere over kBounding), or the inside alone compared with 1; pdf-consistency reporting only the area-element
// error or only the pdf(direction) error, or its relative error as |area element / pdf - 1| (1/1.02 - 1 = -0.0196
// instead of 0.02).

// The uniform cone on kBounding (axis z, 1 - cos theta_max = 0.3), density 1 / (2 pi 0.3), sampled by t = u0,
// phi = 2 pi u1, with its pdf(direction) scaled by pdf_factor and its returned pdf by sample_factor on the inner half
// of the cap by solid angle: t < 1/2, i.e. u0 < 1/2 and z > 1 - 0.15.
SamplerUnderTest scaled_cone(Real pdf_factor, Real sample_factor) {
  SamplerUnderTest s;
  s.kernel = "scaled-cone", s.scalar = "long double", s.config = "inner half";
  s.bounding_cap = kBounding;
  const Real density = 1 / (kTwoPi<Real> * Real(0.3));
  s.sample = [=](double u0, double u1) {
    return Sample{cap_direction(kBounding, Real(u0), kTwoPi<Real> * Real(u1)), density * (u0 < 0.5 ? sample_factor : 1),
                  true};
  };
  s.pdf = [=](const Vec3L& w) {
    if (!kBounding.contains(w, 1e-15L)) return Real(0);
    return density * (w.z() > Real(0.85) ? pdf_factor : 1);
  };
  return s;
}

BatteryOptions few_samples() {
  BatteryOptions o;
  o.samples = 1000;  // the deterministic tests do not depend on it
  return o;
}

// The result named test of a battery run on s.
TestResult battery_result(const SamplerUnderTest& s, const std::string& test) {
  for (TestResult& r : run_battery(s, few_samples()))
    if (r.test == test) return r;
  throw std::runtime_error("no result " + test);
}

TEST(DeterministicKnownAnswers, ThePdfIntegralOfAConeWithHalfItsMassScaledByOneAndAHalfIsOffByAQuarter) {
  // integral = 1.5 * 1/2 + 1/2 = 1.25: the statistic |integral - 1| = 0.25, to the quadrature's 1e-8.
  const TestResult r = battery_result(scaled_cone(1.5L, 1.5L), "pdf-integral");
  EXPECT_NEAR(r.statistic, 0.25, 1e-8) << r.detail;
  EXPECT_FALSE(r.passed);
}

TEST(DeterministicKnownAnswers, ThePdfIntegralCountsTheMassOutsideTheBoundingCap) {
  // The uniform density 1 / (4 pi) on the sphere over the cap kBounding: inside 2 pi 0.3 / (4 pi) = 0.15, outside
  // 0.85, in all 1 (statistic 0).
  SamplerUnderTest s;
  s.kernel = "uniform-sphere", s.scalar = "long double", s.config = "small cap";
  s.bounding_cap = kBounding;
  const Real density = 1 / (2 * kTwoPi<Real>);
  s.sample = [=](double u0, double u1) {
    const Real z = 1 - 2 * Real(u0), rho = std::sqrt(std::max<Real>(0, 1 - z * z)), phi = kTwoPi<Real> * Real(u1);
    return Sample{Vec3L(rho * std::cos(phi), rho * std::sin(phi), z), density, true};
  };
  s.pdf = [=](const Vec3L&) { return density; };
  EXPECT_NEAR(double(battery::outside_integral(s, few_samples())), 0.85, 1e-9);
  const TestResult r = battery_result(s, "pdf-integral");
  EXPECT_NEAR(r.statistic, 0, 1e-8) << r.detail;
  EXPECT_TRUE(r.passed) << r.detail;
}

TEST(DeterministicKnownAnswers, PdfConsistencyReportsTheFactorBetweenTheReturnedPdfAndTheAreaElement) {
  // Returned pdf and pdf(direction) both 1.02 times the density on the inner half: pdf(direction) agrees with the
  // returned pdf, and the returned pdf times the area element is 1.02 there.
  const TestResult r = battery_result(scaled_cone(1.02L, 1.02L), "pdf-consistency");
  EXPECT_NEAR(r.statistic, 0.02, 1e-6) << r.detail;
  EXPECT_FALSE(r.passed);
}

TEST(DeterministicKnownAnswers, PdfConsistencyReportsTheFactorBetweenPdfOfTheDirectionAndTheReturnedPdf) {
  // The returned pdf is right; pdf(direction) is 1.03 times it on the inner half: |pdf(dir) / pdf - 1| = 0.03.
  const TestResult r = battery_result(scaled_cone(1.03L, 1), "pdf-consistency");
  EXPECT_NEAR(r.statistic, 0.03, 1e-6) << r.detail;
  EXPECT_FALSE(r.passed);
}

// ---- Calibration, fast ----------------------------------------------------------------------------------------
// Correct samplers at fixed seeds: the p-values of each statistical test are uniform on [0, 1], by a KS test of
// uniformity computed here (kolmogorov_survival above), not by the battery. Slips caught: a one-sided KS D, D read
// on the empirical CDF's left limits, the KS p-value for another sample count than the draws' (the nodes'). A
// chi-square dof off by one moves the chi2 uniformity p-value only from 0.75 to 0.72: the known-answer tests above
// pin those. The 100-seed calibration with its failure-rate check is slow_calibration.cpp.

// The KS p-value of the hypothesis that p is a sample of U(0, 1): D = max over the sorted p_(i) of
// max(i/N - p_(i), p_(i) - (i-1)/N).
double uniformity_p_value(std::vector<double> p) {
  std::sort(p.begin(), p.end());
  const double n = double(p.size());
  double d = 0;
  for (std::size_t i = 0; i < p.size(); ++i) d = std::max({d, double(i + 1) / n - p[i], p[i] - double(i) / n});
  return kolmogorov_survival(d * std::sqrt(n));
}

TEST(CalibrationKnownAnswers, CorrectSamplersGiveUniformPValuesAtFixedSeeds) {
  constexpr int kSeeds = 40;
  const Registry reg = default_registry();
  std::vector<SamplerUnderTest> samplers = {scaled_cone(1, 1)};  // the exact uniform cone
  for (const Case* c : reg.select({"sphere-solid-angle", "sphere-visible-area"}, {"near", "grazing"}))
    if (c->scalar == "double") samplers.push_back(c->make());
  ASSERT_EQ(samplers.size(), 5u);
  BatteryOptions o;
  o.samples = 100'000;
  std::vector<std::uint64_t> seeds;
  for (int k = 1; k <= kSeeds; ++k) seeds.push_back(std::uint64_t(1000 + k));
  std::map<std::string, std::vector<double>> p_by_test;
  for (const SamplerUnderTest& s : samplers)
    for (const std::vector<TestResult>& run : run_battery_seeds(s, o, seeds))
      for (const TestResult& r : run)
        if (r.p_value) p_by_test[r.test].push_back(*r.p_value);
  ASSERT_EQ(p_by_test.size(), 6u);
  // Six tests of 200 p-values, each at 1e-3: a correct battery fails this check for some seed set with
  // probability at most 6e-3 (and, the seeds being fixed, then always; this one passes).
  for (const auto& [test, p] : p_by_test) {
    EXPECT_EQ(p.size(), samplers.size() * kSeeds);
    EXPECT_GT(uniformity_p_value(p), 1e-3) << test;
  }
}

}  // namespace
}  // namespace warpcheck::validation
