// Claims of Peters & Dachsbacher 2019 that need large counts, quadratures or the battery (ctest label "slow");
// the fast ones are in test_projected_cap.cpp.
#include <gtest/gtest.h>

#include <boost/math/distributions/kolmogorov_smirnov.hpp>
#include <boost/math/tools/roots.hpp>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "warpcheck/validation/projected_cap_claims.h"

namespace warpcheck::validation {
namespace {

using namespace projected_cap_test;

TEST(ProjectedCapCase3, DensityRatioNeverExceedsPapersBoundOn1e5RandomConfigurations) {
  // Long double: in double the density's rounding near Case 4 (d/r ~ 760, depth 0.99993) lifted the ratio to
  // 1 + 2.8e-8 times the bound (projected_cap_claims, double run). (1e4 in the fast suite.)
  const Case3RatioStats s = case3_ratio_search<long double>(100'000, 8, 20260501);
  EXPECT_EQ(s.configurations, 100'000);
  // The bound is attained (at the corners of the cut disk), so ratio / bound - 1 is rounding noise of either sign;
  // it must stay below the rounding error estimated by comparing with double (see Case3RatioStats).
  EXPECT_LE(s.worst_excess_over_rounding, 0.0) << "max ratio/bound " << s.worst_ratio_over_bound << " at d/r = "
                                                << s.worst_d_over_r << ", depth " << s.worst_depth;
  EXPECT_GT(s.worst_ratio_over_bound, 1 - 1e-9);  // the grid reaches the extremes: the bound is sharp
  EXPECT_LE(s.worst_ratio_d_ge_1_094, 2.0);
  EXPECT_LE(s.worst_ratio_d_ge_2, std::sqrt(2.0));
  EXPECT_GT(s.worst_ratio_d_ge_2, 1.3);  // configurations near the limit were drawn
}

TEST(ProjectedCapLambertian, EstimateIsUnbiasedInCase3ForBothInverses) {
  // E[cos/pdf] over primary sample space by tanh-sinh quadrature equals the independent projected solid angle.
  for (const char* name : {"case3", "case3-fig9"}) {
    const ProjectedCapConfig c = config(name);
    const Real phi = reference_projected_solid_angle(c.g);
    const LambertianMoments q = projected_cap_lambertian_moments<double, CutDiskInverse::kQuintic>(c.g, 1e-9L);
    const LambertianMoments e = projected_cap_lambertian_moments<double, CutDiskInverse::kExact>(c.g, 1e-9L);
    EXPECT_LT(std::abs(q.m1_in / phi - 1), 1e-7L) << name;
    EXPECT_LT(std::abs(e.m1_in / phi - 1), 1e-7L) << name;
    EXPECT_GT(e.m2 / (e.m1 * e.m1) - 1, 1e-4L) << name;  // Case 3 is not zero-variance (bounded deviation)
  }
}

TEST(ProjectedCapBattery, PassesAt200kSamplesOnOneConfigurationPerCase) {
  const Registry r = default_registry();
  BatteryOptions o;
  o.samples = 200'000;
  o.threads = 1;
  for (const char* cfg : {"case1", "case2", "case3", "case4"}) {
    const auto cases = r.select({"sphere-projected-cap"}, {cfg});
    for (const Case* c : cases) {
      if (c->scalar != "double") continue;
      const std::vector<TestResult> res = validate(c->make(), o);
      for (const TestResult& t : res) EXPECT_TRUE(t.passed) << cfg << " " << t.test << ": " << t.detail;
    }
  }
}

}  // namespace
}  // namespace warpcheck::validation
