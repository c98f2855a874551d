// The battery on LTC sampling of a polygon (Peters 2021 Sec. 4.1) for a random and an ill-conditioned M.
#include <gtest/gtest.h>

#include "ltc_fixtures.h"
#include "warpcheck/validation/battery.h"
#include "warpcheck/validation/kernels_sptd.h"

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
    const auto s = validation::bind_ltc<double>("polygon-ltc", name, LtcPolygonGeometry<L>{pg, m});
    ASSERT_FALSE(s.expect_no_sample) << name;
    for (const auto& res : validation::validate(s, o, 0.01)) EXPECT_TRUE(res.passed) << name << " " << res.test << ": " << res.detail;
  }
}

}  // namespace
}  // namespace warpcheck
