// Spherical pivot transformed distributions (Dupuy, Heitz & Belcour 2017): the transformation, its Jacobian,
// cap invariance, closed-form cap integrals against quadrature, and the samplers through the battery.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <boost/math/quadrature/gauss_kronrod.hpp>

#include "warpcheck/sptd.h"
#include "warpcheck/validation/battery.h"
#include "warpcheck/validation/kernels_sptd.h"

namespace warpcheck {
namespace {

using L = long double;
using validation::Real;
using validation::Vec3L;

Vec3L random_unit(std::mt19937_64& g) {
  std::normal_distribution<double> n;
  Vec3L v(n(g), n(g), n(g));
  return v / v.norm();
}
Cap<L> random_cap(std::mt19937_64& g, L min_omc = 0.01L, L max_omc = 1.99L) {
  std::uniform_real_distribution<double> u(0, 1);
  return Cap<L>{random_unit(g), min_omc + (max_omc - min_omc) * L(u(g))};
}
// The pivots the tests sweep: the centre, moderate, and |r_p| close to 1.
const L kPivotNorms[] = {0, 0.3L, 0.7L, 0.95L, 0.999L};

// Quadrature for the tests (its measured accuracy here: ~1e-8 relative, limited by the outer integral across
// tangencies; hence the 1e-7 tolerances below). The battery's integrate_cap_region copes with jumps by deep bisection, which is
// slow and stalls near 1e-8 for the clamped cosine's kink. These integrands are smooth except across one
// known circle {w : w.m = h} (the kink of the clamped cosine, or a cap's edge), so we integrate over a cap in
// polar coordinates (theta from the cap's axis, phi) and split each meridian where it crosses that circle
// (R cos(theta - delta) = h in closed form): every piece is smooth and Gauss-Kronrod converges fast. Where
// the circle comes from kernel code (a transformed cap), a wrong circle only costs accuracy, so it cannot
// make a wrong closed form agree.
struct Circle {
  Vec3L m = Vec3L(0, 0, 1);
  L h = 2;  // no circle (|h| > 1)
};
Circle boundary_of(const Cap<L>& c) { return Circle{c.axis, 1 - c.one_minus_cos}; }

L integrate_cap_split(const std::function<L(const Vec3L&)>& f, const Cap<L>& cap, const std::vector<Circle>& circles) {
  using GK = boost::math::quadrature::gauss_kronrod<L, 31>;
  const Frame<L> fr = Frame<L>::from_z(cap.axis);
  const L psi = cap_half_angle(cap);
  auto inner = [&](L phi) {
    const Vec3L b = fr.to_world(Vec3L(std::cos(phi), std::sin(phi), 0));
    std::vector<L> cuts = {0, psi};
    for (const Circle& circle : circles) {
      const L p = cap.axis.dot(circle.m), q = b.dot(circle.m), R = std::hypot(p, q);
      if (!(std::abs(circle.h) < R)) continue;
      const L delta = std::atan2(q, p), a = std::acos(circle.h / R);
      for (L th : {delta - a, delta + a, delta - a + kTwoPi<L>, delta + a - kTwoPi<L>, delta + a + kTwoPi<L>})
        if (th > 0 && th < psi) cuts.push_back(th);
    }
    std::sort(cuts.begin(), cuts.end());
    L sum = 0;
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i)
      sum += GK::integrate([&](L th) { return f(Vec3L(std::cos(th) * cap.axis + std::sin(th) * b)) * std::sin(th); },
                           cuts[i], cuts[i + 1], 12, 1e-13L);
    return sum;
  };
  return GK::integrate(inner, L(0), kTwoPi<L>, 14, 1e-12L);
}
// Over the whole sphere in a frame centred on `towards` (put the SPTD's peak, the pivot's direction, there).
L integrate_sphere(const std::function<L(const Vec3L&)>& f, const Vec3L& towards, const std::vector<Circle>& circles = {}) {
  const Vec3L axis = towards.norm() > 0 ? Vec3L(towards / towards.norm()) : Vec3L(0, 0, 1);
  return integrate_cap_split(f, Cap<L>{axis, 2}, circles);
}
// The kink circle of a clamped-cosine SPTD: the boundary of g(hemisphere of n).
Circle kink_of(const Sptd<L>& d) {
  if (d.base == SptdBase::kUniform) return Circle{};
  return boundary_of(pivot_transform_cap(Cap<L>{d.base_axis, 1}, d.pivot));
}

TEST(SptdPivot, SphereFormAgreesWithEq2AndBothAreInvolutions) {
  std::mt19937_64 g(11);
  L worst_eq2 = 0, worst_inv = 0, worst_point_inv = 0;
  for (L r : kPivotNorms) {
    for (int i = 0; i < 200; ++i) {
      const Vec3L rp = random_unit(g) * r, w = random_unit(g);
      const Vec3L gw = pivot_transform(w, rp);
      worst_eq2 = std::max(worst_eq2, (gw - pivot_transform_point(w, rp)).norm());
      worst_inv = std::max(worst_inv, (pivot_transform(gw, rp) - w).norm());  // Eq. 3 on the sphere
      EXPECT_NEAR(gw.norm(), 1, 1e-18L);
      const Vec3L x = random_unit(g) * L(3) * L(i % 7) / 7;  // Eq. 3 for points of R^3 off the sphere
      const Vec3L gx = pivot_transform_point(x, rp);
      worst_point_inv = std::max(worst_point_inv, (pivot_transform_point(gx, rp) - x).norm() / (1 + x.norm()));
    }
  }
  // |r_p| = 0.999 amplifies rounding by up to (1 + |r_p|) / (1 - |r_p|) = 2e3: 1e-18 * 2e3 * margin.
  EXPECT_LT(worst_eq2, 1e-13L);
  EXPECT_LT(worst_inv, 1e-13L);
  EXPECT_LT(worst_point_inv, 1e-13L);
}

TEST(SptdPivot, JacobianEq4MatchesFourthOrderFiniteDifferencesInLongDouble) {
  std::mt19937_64 g(12);
  L worst = 0;
  for (L r : kPivotNorms) {
    for (int i = 0; i < 100; ++i) {
      const Vec3L rp = random_unit(g) * r, w0 = random_unit(g);
      const Frame<L> f = Frame<L>::from_z(w0);
      // w(s, t) = normalize(w0 + s x + t y) has unit area element at (0, 0).
      auto image = [&](L s, L t) { return pivot_transform(Vec3L((w0 + s * f.x + t * f.y).normalized()), rp); };
      // Step relative to the local scale of the map near the pivot direction: |w - r_p|.
      const L h = 1e-4L * (w0 - rp).norm();
      Vec3L ds = (image(-2 * h, 0) - 8 * image(-h, 0) + 8 * image(h, 0) - image(2 * h, 0)) / (12 * h);
      Vec3L dt = (image(0, -2 * h) - 8 * image(0, -h) + 8 * image(0, h) - image(0, 2 * h)) / (12 * h);
      const L fd = ds.cross(dt).norm();
      worst = std::max(worst, std::abs(fd / pivot_jacobian(w0, rp) - 1));
    }
  }
  EXPECT_LT(worst, 1e-9L);
}

TEST(SptdDensity, Eq9NormalisationHoldsByQuadratureForBothBases) {
  for (L r : kPivotNorms) {
    for (SptdBase base : {SptdBase::kUniform, SptdBase::kClampedCosine}) {
      Sptd<L> d;
      d.pivot = Vec3L(0.3L, -0.5L, 0.8L).normalized() * r;
      d.base = base;
      d.base_axis = Vec3L(0.1L, 0.2L, 1).normalized();
      const L integral = integrate_sphere([&](const Vec3L& w) { return sptd_density(d, w); }, d.pivot, {kink_of(d)});
      EXPECT_NEAR(integral, 1, 1e-10L) << "|r_p| = " << double(r) << ", base " << int(base);
    }
  }
}

TEST(SptdDensity, PivotPhaseFunctionEq25IsTheUniformSptd) {
  std::mt19937_64 g(13);
  for (L gp : {-0.9L, -0.3L, 0.0L, 0.5L, 0.99L}) {
    const Vec3L wo = random_unit(g);
    Sptd<L> d;
    d.pivot = gp * wo;
    for (int i = 0; i < 50; ++i) {
      const Vec3L w = random_unit(g);
      EXPECT_NEAR(sptd_density(d, w) / pivot_phase_function(wo.dot(w), gp), 1, 1e-15L);
    }
  }
}

TEST(SptdCaps, BoundaryOfCMapsOntoBoundaryOfGCInLongDouble) {
  std::mt19937_64 g(14);
  L worst = 0;
  int large_images = 0;
  for (L r : kPivotNorms) {
    for (int i = 0; i < 200; ++i) {
      const Vec3L rp = random_unit(g) * r;
      const Cap<L> c = random_cap(g, 1e-4L, 1.999L);
      const Cap<L> gc = pivot_transform_cap(c, rp);
      large_images += gc.one_minus_cos > 1;
      const Frame<L> f = Frame<L>::from_z(c.axis);
      const L cos_a = 1 - c.one_minus_cos, sin_a = std::sqrt(c.one_minus_cos * (2 - c.one_minus_cos));
      for (int k = 0; k < 64; ++k) {
        const L phi = kTwoPi<L> * k / 64;
        const Vec3L b = f.to_world(Vec3L(sin_a * std::cos(phi), sin_a * std::sin(phi), cos_a));
        const L omc = (pivot_transform(b, rp) - gc.axis).squaredNorm() / 2;
        worst = std::max(worst, std::abs(omc / gc.one_minus_cos - 1));
      }
      // Interior maps to interior: the image of the axis and of a point halfway to the boundary.
      EXPECT_TRUE(gc.contains(pivot_transform(c.axis, rp)));
      const L half = cap_half_angle(c) / 2;
      EXPECT_TRUE(gc.contains(pivot_transform(f.to_world(Vec3L(std::sin(half), 0, std::cos(half))), rp)));
    }
  }
  EXPECT_LT(worst, 1e-12L);
  EXPECT_GT(large_images, 50);  // image caps larger than a hemisphere are covered (Eq. 6's failure case)
}

TEST(SptdCaps, ClosedFormCapIntegralsEq10MatchQuadratureOfEq8) {
  std::mt19937_64 g(15);
  int crossing = 0, below_axis = 0;
  for (L r : kPivotNorms) {
    for (int i = 0; i < 2; ++i) {
      for (SptdBase base : {SptdBase::kUniform, SptdBase::kClampedCosine}) {
        Sptd<L> d;
        d.pivot = random_unit(g) * r;
        d.base = base;
        d.base_axis = random_unit(g);
        const Cap<L> c = random_cap(g, 0.02L, 1.98L);
        const L closed = sptd_cap_integral(d, c);
        const L quad = integrate_sphere([&](const Vec3L& w) { return c.contains(w) ? sptd_density(d, w) : L(0); }, d.pivot,
                                         {kink_of(d), boundary_of(c)});
        EXPECT_NEAR(closed, quad, 1e-7L * std::max<L>(quad, 1e-3L)) << "|r_p| " << double(r) << " base " << int(base);
        if (base == SptdBase::kClampedCosine) {
          const auto v = make_cosine_cap_view(pivot_transform_cap(c, d.pivot), d.base_axis);
          crossing += v.valid() && !v.ellipse_only;
          below_axis += v.valid() && v.cos_t < 0;
        }
      }
    }
  }
  EXPECT_GE(crossing, 3);    // the horizon-crossing formula is exercised
  EXPECT_GE(below_axis, 1);   // ... including the crescent (cap axis below the horizon)
}

TEST(SptdCaps, CapIntersectionAppendixBMatchesQuadrature) {
  std::mt19937_64 g(16);
  for (int i = 0; i < 20; ++i) {
    const Cap<L> a = random_cap(g, 0.05L, 1.95L), b = random_cap(g, 0.05L, 1.95L);
    const L closed = cap_intersection_solid_angle(a, b);
    const L quad = integrate_cap_split([&](const Vec3L& w) { return L(b.contains(w)); }, a, {boundary_of(b)});
    EXPECT_NEAR(closed, quad, 1e-7L * quad) << i;
    EXPECT_NEAR(closed, cap_intersection_solid_angle(b, a), 1e-15L);
  }
  // Nested, disjoint and covering configurations.
  const Cap<L> big{Vec3L(0, 0, 1), 1.5L}, small{Vec3L(0, 0.1L, 1).normalized(), 0.1L};
  EXPECT_NEAR(cap_intersection_solid_angle(big, small), small.solid_angle(), 1e-18L);
  EXPECT_EQ(cap_intersection_solid_angle(small, Cap<L>{Vec3L(0, 0, -1), 0.1L}), 0);
  const Cap<L> c1{Vec3L(1, 0, 0), 1.9L}, c2{Vec3L(-1, 0, 0), 1.9L};
  EXPECT_NEAR(cap_intersection_solid_angle(c1, c2), c1.solid_angle() + c2.solid_angle() - 4 * kPi<L>, 1e-15L);
}

TEST(SptdCaps, UniformSptdOverTwoCapsEq19MatchesQuadrature) {
  std::mt19937_64 g(17);
  for (L r : kPivotNorms) {
    for (int i = 0; i < 4; ++i) {
      const Vec3L rp = random_unit(g) * r;
      const Cap<L> c = random_cap(g, 0.05L, 1.5L);
      const Cap<L> h{random_unit(g), 1};  // a hemisphere, as in Eq. 17
      Sptd<L> d;
      d.pivot = rp;
      const L closed = sptd_uniform_two_cap_integral(rp, c, h);
      const L quad = integrate_sphere([&](const Vec3L& w) { return c.contains(w) && h.contains(w) ? sptd_density(d, w) : L(0); },
                                      rp, {boundary_of(c), boundary_of(h)});
      EXPECT_NEAR(closed, quad, 1e-7L * std::max<L>(quad, 1e-2L)) << "|r_p| " << double(r);
    }
  }
}

// Sec. 6.2, Fig. 17: joint pivot-phase-function and sphere-light sampling has the density f_pivot (Eq. 25)
// restricted to the light's cone and normalised there; the normaliser by quadrature of Eq. 25 over the cone.
TEST(SptdSampling, JointPhaseAndSphereLightDensityIsThePhaseFunctionRestrictedToTheCone) {
  SphereLightGeometry<L> light;
  light.shading.position = Vec3L(0.1L, 0, 0);
  light.light = SphereLight<L>{Vec3L(2, 0.5L, 1), 0.6L};
  std::mt19937_64 g(18);
  for (L gp : {hg_to_pivot(0.9L), L(-0.6L), L(0.3L)}) {
    const Vec3L wo = random_unit(g);
    const SptdCapGeometry<L> geo = pivot_phase_sphere_light_geometry(wo, gp, light);
    const Cap<L> cone = geo.cap;
    const L norm = integrate_cap_split([&](const Vec3L& w) { return pivot_phase_function(wo.dot(w), gp); }, cone, {});
    ASSERT_GT(norm, 0);
    for (int i = 0; i < 200; ++i) {
      const Vec3L w = random_unit(g);
      const L expected = cone.contains(w) ? pivot_phase_function(wo.dot(w), gp) / norm : 0;
      if (expected == 0) {
        EXPECT_EQ(pdf_sptd_cap(geo, w), 0);
      } else {
        EXPECT_NEAR(pdf_sptd_cap(geo, w) / expected, 1, 1e-10L);
      }
      // Samples land in the cone, with the restricted, normalised phase function as their density.
      const auto smp = sample_sptd_cap(geo, Vec2<L>(L(i + 0.5L) / 200, L(std::fmod(i * 0.618034L, 1))));
      ASSERT_TRUE(smp.valid());
      EXPECT_TRUE(cone.contains(smp.direction, 1e-15L));
      EXPECT_NEAR(smp.pdf / (pivot_phase_function(wo.dot(smp.direction), gp) / norm), 1, 1e-10L);
    }
  }
}

TEST(SptdSampling, DegenerateInputGivesNoSampleWithAReason) {
  SptdCapGeometry<double> g;
  g.sptd.pivot = Vec3<double>(0, 0, 1);  // on the sphere: not a pivot
  EXPECT_EQ(sample_sptd_cap(g, Vec2<double>(0.3, 0.4)).reason, NoSample::kInvalidGeometry);
  g.sptd.pivot = Vec3<double>(std::nan(""), 0, 0);
  EXPECT_EQ(sample_sptd_cap(g, Vec2<double>(0.3, 0.4)).reason, NoSample::kNonFinite);
  g.sptd.pivot = Vec3<double>(0, 0, 0.5);
  g.cap.one_minus_cos = 0;
  EXPECT_EQ(sample_sptd_cap(g, Vec2<double>(0.3, 0.4)).reason, NoSample::kZeroSize);
  g.cap.one_minus_cos = 0.1;
  g.cap.axis = Vec3<double>(0, 0, -1);
  g.sptd.base = SptdBase::kClampedCosine;
  g.sptd.base_axis = Vec3<double>(0, 0, -1);  // image cap around +z... entirely below the cosine's horizon
  const auto s = sample_sptd_cap(g, Vec2<double>(0.3, 0.4));
  EXPECT_EQ(s.reason, NoSample::kBelowHorizon);
  EXPECT_EQ(pdf_sptd_cap(g, Vec3<double>(0, 0, 1)), 0);
  g.sptd.base_axis = Vec3<double>(0, 0, 0);
  EXPECT_EQ(sample_sptd_cap(g, Vec2<double>(0.3, 0.4)).reason, NoSample::kBadNormal);
}

// The battery (chi-square, KS, pdf integral, pdf/Jacobian consistency) at 200k samples on a few pivots,
// including |r_p| close to 1 and the cosine base in all three shapes of its projected region.
struct BatteryCase {
  const char* name;
  Vec3L pivot;
  SptdBase base;
  Vec3L base_axis;
  Cap<L> cap;
};

TEST(SptdSampling, BatteryPassesOnPivotsIncludingNormCloseToOne) {
  const BatteryCase cases[] = {
      {"uniform-cap", Vec3L(0.2L, 0.1L, 0.5L), SptdBase::kUniform, Vec3L(0, 0, 1), Cap<L>{Vec3L(0.3L, 0, 1).normalized(), 0.3L}},
      {"uniform-cap-0.99", Vec3L(0, 0.6L, 0.8L) * 0.99L, SptdBase::kUniform, Vec3L(0, 0, 1), Cap<L>{Vec3L(0, 0.5L, 1).normalized(), 0.2L}},
      {"phase-0.95", Vec3L(1, 0, 0) * 0.95L, SptdBase::kUniform, Vec3L(0, 0, 1), Cap<L>{Vec3L(0, 0, 1), 2}},
      {"cosine-ellipse", Vec3L(0.1L, 0, 0.4L), SptdBase::kClampedCosine, Vec3L(0, 0, -1), Cap<L>{Vec3L(0.2L, 0, 1).normalized(), 0.2L}},
      {"cosine-crossing", Vec3L(0.5L, 0, 0.3L), SptdBase::kClampedCosine, Vec3L(0, 0, 1), Cap<L>{Vec3L(1, 0, -0.3L).normalized(), 0.6L}},
      {"cosine-crescent", Vec3L(0.2L, 0, 0.3L), SptdBase::kClampedCosine, Vec3L(0, 0, -1), Cap<L>{Vec3L(1, 0, 0.2L).normalized(), 0.3L}},
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
    const auto s = validation::bind_sptd_cap<double>("sptd", bc.name, g);
    const auto results = validation::validate(s, o, 0.01);
    for (const auto& r : results) EXPECT_TRUE(r.passed) << bc.name << " " << r.test << ": " << r.detail;
  }
}

}  // namespace
}  // namespace warpcheck
