// The battery on SPTD sampling over caps (Dupuy et al. 2017 Sec. 4.2, Fig. 5): 200k samples per case, six cases,
// 105 s wall on the project's loaded 2-core machine (measured when it was in the fast label), mostly the
// quadrature of the chi-square bins and KS marginals; hence the slow label. The fast SptdSampling.* tests check
// the samplers' densities sample by sample.
#include <gtest/gtest.h>

#include "catalogue/sptd_samplers.h"
#include "warpcheck/sptd.h"
#include "warpcheck/validation/battery.h"

namespace warpcheck {
namespace {

using L = long double;
using validation::Vec3L;

// The battery (chi-square, KS, pdf integral, pdf/Jacobian consistency) at 200k samples on a few pivots,
// including |r_p| close to 1 and the cosine base in all three shapes of its projected region.
struct BatteryCase {
  const char* name;
  Vec3L pivot;
  SptdBase base;
  Vec3L base_axis;
  Cap<L> cap;
};

TEST(SptdBattery, PassesOnPivotsIncludingNormCloseToOne) {
  const BatteryCase cases[] = {
      {"uniform-cap", Vec3L(0.2L, 0.1L, 0.5L), SptdBase::kUniform, Vec3L(0, 0, 1),
       Cap<L>{Vec3L(0.3L, 0, 1).normalized(), 0.3L}},
      {"uniform-cap-0.99", Vec3L(0, 0.6L, 0.8L) * 0.99L, SptdBase::kUniform, Vec3L(0, 0, 1),
       Cap<L>{Vec3L(0, 0.5L, 1).normalized(), 0.2L}},
      {"phase-0.95", Vec3L(1, 0, 0) * 0.95L, SptdBase::kUniform, Vec3L(0, 0, 1), Cap<L>{Vec3L(0, 0, 1), 2}},
      {"cosine-ellipse", Vec3L(0.1L, 0, 0.4L), SptdBase::kClampedCosine, Vec3L(0, 0, -1),
       Cap<L>{Vec3L(0.2L, 0, 1).normalized(), 0.2L}},
      {"cosine-crossing", Vec3L(0.5L, 0, 0.3L), SptdBase::kClampedCosine, Vec3L(0, 0, 1),
       Cap<L>{Vec3L(1, 0, -0.3L).normalized(), 0.6L}},
      {"cosine-crescent", Vec3L(0.2L, 0, 0.3L), SptdBase::kClampedCosine, Vec3L(0, 0, -1),
       Cap<L>{Vec3L(1, 0, 0.2L).normalized(), 0.3L}},
  };
  validation::BatteryOptions o;
  o.samples = 200'000;
  o.threads = 1;
  o.seed = 5;
  for (const auto& bc : cases) {
    SptdCapGeometry<L> g;
    g.sptd.pivot = bc.pivot;
    g.sptd.base = bc.base;
    g.sptd.base_axis = bc.base_axis;
    g.cap = bc.cap;
    const auto v = make_sptd_cap_view(g);
    ASSERT_TRUE(v.valid()) << bc.name;
    if (std::string(bc.name) == "cosine-crossing") {
      EXPECT_TRUE(!v.cosine.ellipse_only && v.cosine.cos_t >= 0) << "not crossing";
    }
    if (std::string(bc.name) == "cosine-crescent") {
      EXPECT_LT(v.cosine.cos_t, 0) << "not a crescent";
    }
    if (std::string(bc.name) == "cosine-ellipse") {
      EXPECT_TRUE(v.cosine.ellipse_only);
    }
    const auto s = bc.base == SptdBase::kUniform ? validation::sptd_cap_sampler<SptdUniformCap, double>(bc.name, g)
                                                 : validation::sptd_cap_sampler<SptdCosineCap, double>(bc.name, g);
    const auto results = validation::validate(s, o, 0.01);
    for (const auto& r : results) EXPECT_TRUE(r.passed) << bc.name << " " << r.test << ": " << r.detail;
  }
}

}  // namespace
}  // namespace warpcheck
