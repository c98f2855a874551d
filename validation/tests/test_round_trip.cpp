// The battery's test "round-trip": inverse(sample(u)) == u and sample(inverse(w)) == w, for a sampler with an
// inverse warp; the kernels that invert a CDF by iteration provide theirs through bind_kernel. Each property comes
// with the error it must catch: an inversion stopped early, an approximate inversion against the exact inverse, an
// inverse with a constant rounded to five digits.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "battery/tests.h"
#include "warpcheck/catalogue.h"
#include "warpcheck/validation/battery.h"

namespace warpcheck::validation {
namespace {

// Uniform in a cone of half-angle 0.3 rad around +z, with its closed-form inverse; `pi` is the inverse's constant.
SamplerUnderTest cone(Real pi = kPi<Real>) {
  const Real cos_max = std::cos(Real(0.3)), density = 1 / (kTwoPi<Real> * (1 - cos_max));
  SamplerUnderTest s;
  s.kernel = "test-cone", s.scalar = "long double", s.config = "0.3 rad";
  s.sample = [=](double u0, double u1) {
    const Real c = 1 - u0 * (1 - cos_max), r = std::sqrt(1 - c * c), phi = kTwoPi<Real> * u1;
    return Sample{Vec3L(r * std::cos(phi), r * std::sin(phi), c), density, true};
  };
  s.pdf = [=](const Vec3L& w) { return w.z() >= cos_max ? density : 0; };
  s.bounding_cap = Cap<Real>{Vec3L(0, 0, 1), 1 - cos_max};
  s.inverse = [=](const Vec3L& w) -> std::optional<std::array<Real, 2>> {
    if (!(w.z() >= cos_max)) return std::nullopt;
    const Real phi = std::atan2(w.y(), w.x());
    return std::array<Real, 2>{(1 - w.z()) / (1 - cos_max), (phi < 0 ? phi + 2 * pi : phi) / (2 * pi)};
  };
  return s;
}

// The decentral case of the projected-solid-angle polygon sampler (Peters 2021 Sec. 3.3) on the registry's
// "triangle" (reversed winding), sampled with `iterations` tangent-line steps, against the kernel's exact inverse.
// Measured: max u-error 1.5e-2 after 0 steps, 1.4e-5 after 1, 2.2e-13 after 2 (the kernel's count).
SamplerUnderTest polygon_projected(int iterations) {
  using K = PolygonProjectedSolidAngle<double>;
  const PolygonLightGeometry<double> g{
      ShadingPoint<double>{Vec3<double>::Zero(), Vec3<double>(0, 0, 1)},
      PolygonLight<double>{Vec3<double>(0.8, 0.9, 0.8), Vec3<double>(1.3, -0.4, 0.5), Vec3<double>(0.3, 0.1, 1)}};
  SamplerUnderTest s = bind_kernel<K>("triangle", g);
  s.sample = [v = K::view(g), iterations](double u0, double u1) {
    return to_sample(sample_polygon_projected_solid_angle(v, Vec2<double>(u0, u1), iterations));
  };
  return s;
}

SphereLightGeometry<double> sphere_light() {  // the registry's case2: centre 14 deg up, half-angle 27 deg
  return SphereLightGeometry<double>{ShadingPoint<double>{Vec3<double>::Zero(), Vec3<double>(0, 0, 1)},
                                     SphereLight<double>{Vec3<double>(2, 0, 0.5), 1}};
}

std::string detail(const TestResult& r) { return r.detail; }

// A bent fan about +z, in gnomonic coordinates (x, y) = (w_x / w_z, w_y / w_z) relative to its tip p: x = X sqrt(u0),
// y = k x u1 + x^2, the region between two curves that meet at the tip, as a polygon's first sector near its start
// (w moves as sqrt(u0); the u1 column vanishes at the tip; the lines of constant u1 are bent). The tip is placed
// so that a cell centre of the direction grid lies at u = (1.2e-6, 1/2). The inverse is exact except within 1e-4
// of the tip, where its u0 is `error` too large (u0 above the grid's first primary row: only the direction grid
// sees it).
SamplerUnderTest bent_fan(Real error) {
  constexpr Real X = 0.2L, k = 0.5L;
  const Cap<Real> cap{Vec3L(0, 0, 1), 0.1L};
  const Vec3L g = cap_direction(cap, Real(10.5L) / 32, kTwoPi<Real> * Real(5.5L) / 32);  // a grid direction
  const Real xg = X * std::sqrt(Real(1.2e-6L));
  const Real px = g.x() / g.z() - xg, py = g.y() / g.z() - (k * xg / 2 + xg * xg);
  auto local = [=](const Vec3L& w) -> std::optional<std::array<Real, 2>> {
    if (!(w.z() > 0)) return std::nullopt;
    const Real x = w.x() / w.z() - px, y = w.y() / w.z() - py;
    if (!(x > 0 && x <= X)) return std::nullopt;
    const Real u1 = (y - x * x) / (k * x);
    if (!(u1 >= 0 && u1 <= 1)) return std::nullopt;
    return std::array<Real, 2>{x * x / (X * X), u1};
  };
  SamplerUnderTest s;
  s.kernel = "test-bent-fan", s.scalar = "long double", s.config = "tip";
  s.sample = [=](double u0, double u1) {
    const Real x = X * std::sqrt(Real(u0)), y = k * x * u1 + x * x;
    return Sample{Vec3L(px + x, py + y, 1).normalized(), 1, true};
  };
  s.pdf = [=](const Vec3L& w) { return local(w) ? Real(1) : Real(0); };
  s.bounding_cap = cap;
  s.inverse = [=](const Vec3L& w) {
    auto u = local(w);
    if (u && (*u)[0] < 1e-4L) (*u)[0] += error;
    return u;
  };
  return s;
}

// The registry's random geometry random-s1-7 of the clamped-cosine SPTD: a cap over the whole sphere whose axis is
// -n to within 1.1e-16 rad (n the base's axis), pivot 0.54 n.
SptdCapGeometry<Real> cosine_sptd_on_minus_n() {
  SptdCapGeometry<Real> g;
  g.sptd.base = SptdBase::kClampedCosine;
  g.sptd.base_axis = Vec3L(0.303495504249298886368L, 0.933282919095442697888L, -0.192024664627108543336L);
  g.sptd.pivot = Vec3L(0.16456031504667265053L, 0.506041536179951956242L, -0.104118970018784520737L);
  g.cap = Cap<Real>{Vec3L(-0.303495504249298775346L, -0.933282919095442697888L, 0.192024664627108571091L), 2};
  return g;
}

TEST(RoundTrip, AnExactInversePasses) {
  const TestResult r = battery::round_trip(cone());
  EXPECT_TRUE(r.passed) << detail(r);
  EXPECT_LT(r.statistic, 1e-12);
}

TEST(RoundTrip, AnInverseWithPiRoundedToFiveDigitsFails) {
  // u1 = phi / 2 pi' for phi in [0, pi), (phi + 2 pi') / 2 pi' below: off by (pi / pi' - 1) min(u1, 1 - u1), 1.13e-6
  // at the grid's u1 = 31/64 and 33/64.
  const TestResult r = battery::round_trip(cone(3.1416L));
  EXPECT_FALSE(r.passed) << detail(r);
  EXPECT_NEAR(r.statistic, 1.13e-6, 0.01e-6);
}

TEST(RoundTrip, AnInverseWithoutAPreimageInsideTheSupportFails) {
  SamplerUnderTest s = cone();
  const auto inverse = s.inverse;
  s.inverse = [inverse](const Vec3L& w) { return w.x() > 0.2L ? std::nullopt : inverse(w); };
  EXPECT_FALSE(battery::round_trip(s).passed);
}

// A clamp on the wrong side of a piece acts only within a few epsilons of the piece's end: the cell centres never
// reach it, the points beside a declared kink do.
TEST(RoundTrip, AnInverseWrongOnlyAtTheEndOfAPieceFailsWhereTheKinkIsDeclared) {
  SamplerUnderTest s = cone();
  const auto inverse = s.inverse;
  s.inverse = [inverse](const Vec3L& w) {
    auto u = inverse(w);
    if (u && std::abs((*u)[0] - 0.4L) < 1e-12L) (*u)[0] = 0.1L;
    return u;
  };
  EXPECT_TRUE(battery::round_trip(s).passed) << "no kink declared: the grid does not reach u0 = 0.4";
  s.kinks_u0 = {0.4L};
  const TestResult r = battery::round_trip(s);
  EXPECT_FALSE(r.passed) << detail(r);
  EXPECT_NEAR(r.statistic, 0.3, 1e-9);
}

TEST(RoundTrip, ThePolygonSamplersTwoTangentLineIterationsPassAndFewerFail) {
  for (int iterations : {2, 3}) {
    const TestResult r = battery::round_trip(polygon_projected(iterations));
    EXPECT_TRUE(r.passed) << iterations << " iterations: " << detail(r);
  }
  for (int iterations : {0, 1}) {
    const TestResult r = battery::round_trip(polygon_projected(iterations));
    EXPECT_FALSE(r.passed) << iterations << " iterations: " << detail(r);
  }
}

TEST(RoundTrip, TheQuinticApproximationFailsAgainstTheExactInverse) {
  const SphereLightGeometry<double> g = sphere_light();
  const SamplerUnderTest quintic = bind_kernel<SphereProjectedCap<double>>("case2", g);
  SamplerUnderTest mixed = bind_kernel<SphereProjectedCapExact<double>>("case2", g);
  EXPECT_TRUE(battery::round_trip(quintic).passed) << detail(battery::round_trip(quintic));
  EXPECT_TRUE(battery::round_trip(mixed).passed) << detail(battery::round_trip(mixed));
  mixed.sample = quintic.sample;  // the quintic's warp, the exact warp's inverse
  const TestResult r = battery::round_trip(mixed);
  EXPECT_FALSE(r.passed) << detail(r);
}

TEST(RoundTrip, NextToAFansTipTheDirectionGridMeasuresTheDistanceToTheTruePreimage) {
  // w moves as sqrt(u0) there, so the first-order u-error J^+ (sample(u') - w) with J taken 2e-4 away, or even at u'
  // (the bent fan's second-order term goes into u1), is many times the true one.
  const TestResult close = battery::round_trip(bent_fan(5e-7L));
  EXPECT_TRUE(close.passed) << detail(close);
  EXPECT_NEAR(close.statistic, 5e-7, 0.05e-6) << detail(close);
  const TestResult off = battery::round_trip(bent_fan(2e-6L));
  EXPECT_FALSE(off.passed) << detail(off);
  EXPECT_NEAR(off.statistic, 2e-6, 0.1e-6) << detail(off);
  EXPECT_LT(battery::round_trip(bent_fan(0)).statistic, 1e-12);
}

TEST(RoundTrip, TheCosineSptdRoundTripsWhenItsCapsAxisIsMinusTheBaseAxisToRounding) {
  // The sampler's frame (e_x, e_y, n) must be orthonormal: with e_x from the axis' part orthogonal to n, which is
  // rounding noise here, a tilt of e_x towards n moved every sample (double: u-error 0.34, long double 7.6e-5).
  const SptdCapGeometry<Real> g = cosine_sptd_on_minus_n();
  const TestResult d = battery::round_trip(bind_kernel<SptdCosineCap<double>>("c", g.cast<double>()));
  EXPECT_TRUE(d.passed) << detail(d);
  const TestResult l = battery::round_trip(bind_kernel<SptdCosineCap<Real>>("c", g));
  EXPECT_TRUE(l.passed) << detail(l);
  // Axes 1e-16 to 1e-6 rad from -n and from n: the frame stays orthonormal to rounding.
  for (const Real sign : {-1.0L, 1.0L})
    for (const Real angle : {1e-16L, 1e-14L, 1e-12L, 1e-9L, 1e-6L}) {
      const Vec3<double> n = g.sptd.base_axis.cast<double>();
      const Vec3<double> t = Frame<double>::from_z(n).x;
      const Cap<double> cap{(sign * std::cos(double(angle)) * n + std::sin(double(angle)) * t).normalized(), 0.5};
      const CosineCapView<double> v = make_cosine_cap_view(cap, n);
      SCOPED_TRACE(testing::Message() << "axis " << angle << " rad from " << sign << " n");
      EXPECT_LE(std::abs(v.ex.dot(n)), 4 * std::numeric_limits<double>::epsilon());
      EXPECT_NEAR(v.ey.norm(), 1, 4 * std::numeric_limits<double>::epsilon());
    }
}

TEST(RoundTrip, KernelsThatInvertACdfBindTheirInverse) {
  const SphereLightGeometry<double> light = sphere_light();
  EXPECT_TRUE(bind_kernel<SphereProjectedCap<double>>("c", light).inverse);
  EXPECT_TRUE(bind_kernel<SphereProjectedCapExact<double>>("c", light).inverse);
  EXPECT_TRUE(polygon_projected(2).inverse);
  SptdCapGeometry<double> sptd;
  sptd.sptd.pivot = Vec3<double>(0.5, 0, 0.3);
  sptd.cap = Cap<double>{Vec3<double>(1, 0, -0.3).normalized(), 0.6};
  EXPECT_TRUE(bind_kernel<SptdUniformCap<double>>("c", sptd).inverse);
  EXPECT_TRUE(bind_kernel<SptdCosineCap<double>>("c", sptd).inverse);
  // Closed-form warps without an inverse of their own: no round-trip.
  EXPECT_FALSE(bind_kernel<SphereSolidAngle<double>>("c", light).inverse);
}

TEST(RoundTrip, IsNotRunWithoutAnInverseAndNeedsTwoUniforms) {
  SamplerUnderTest s = cone();
  s.inverse = nullptr;
  BatteryOptions o;
  o.samples = 20'000, o.radial_bins = 4, o.azimuth_bins = 4, o.ks_cdf_nodes = 64, o.consistency_points = 64;
  for (const TestResult& r : run_battery(s, o)) EXPECT_NE(r.test, "round-trip");
  s = cone();
  bool ran = false;
  for (const TestResult& r : run_battery(s, o)) ran = ran || (r.test == "round-trip" && r.passed);
  EXPECT_TRUE(ran);
  s.uniforms = 3;
  s.sample_u = [sample = s.sample](std::span<const double> u) { return sample(u[0], u[1]); };
  EXPECT_THROW(run_battery(s, o), std::invalid_argument);
}

}  // namespace
}  // namespace warpcheck::validation
