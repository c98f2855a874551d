// The battery's test "round-trip": inverse(sample(u)) == u and sample(inverse(w)) == w, for a sampler with an
// inverse warp; the kernels that invert a CDF by iteration provide theirs through bind_kernel. Each property comes
// with the error it must catch: an inversion stopped early, an approximate inversion against the exact inverse, an
// inverse with a constant rounded to five digits.
#include <gtest/gtest.h>

#include <cmath>
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
