// The battery on LTC sampling of a polygon (Peters 2021 Sec. 4.1) for a random and an ill-conditioned M.
#include <gtest/gtest.h>

#include "catalogue/sptd_samplers.h"
#include "ltc_fixtures.h"
#include "warpcheck/validation/battery.h"
#include "warpcheck/validation/registry.h"

namespace warpcheck {
namespace {

TEST(Ltc, BatteryPassesForRandomAndIllConditionedM) {
  std::mt19937_64 r(5);
  validation::BatteryOptions o;
  o.samples = 200'000;
  o.threads = 1;
  o.seed = 6;
  const auto pg = test_polygon();
  const std::pair<const char*, M3> cases[] = {{"random", random_m(r)}, {"ill-conditioned", narrow_m()}};
  for (const auto& [name, m] : cases) {
    const auto s = validation::ltc_sampler<double>(name, LtcPolygonGeometry<L>{pg, m});
    ASSERT_FALSE(s.expect_no_sample) << name;
    for (const auto& res : validation::validate(s, o, 0.01))
      EXPECT_TRUE(res.passed) << name << " " << res.test << ": " << res.detail;
  }
}

// Regression: the registry's near-singular LTC (|M| = 1e-8, a lobe 1e-4 rad wide) at the CLI's default 1e7 samples,
// double. Before ks_cdfs started each azimuth slab's radial lines with one panel per chi-square ring, the
// quadrature of the azimuth marginal lost 0.23% of the mass and ks-azimuth failed with p = 5e-47
// (`warpcheck validate --kernel polygon-ltc --config near-singular --scalar double`). About 2 minutes of one core.
TEST(Ltc, NearSingularRegistryCasePassesTheBatteryAtTheDefaultSampleCount) {
  const validation::Registry reg = validation::default_registry();
  int found = 0;
  for (const validation::Case& c : reg.cases()) {
    if (c.kernel != "polygon-ltc" || c.scalar != "double" || c.config != "near-singular") continue;
    ++found;
    validation::BatteryOptions o;
    o.threads = 1;
    for (const auto& r : validation::validate(c.make(), o, 0.01))
      EXPECT_TRUE(r.passed) << r.test << ": " << r.statistic << " " << r.detail;
  }
  EXPECT_EQ(found, 1);
}

}  // namespace
}  // namespace warpcheck
