// Specifications of the sphere-light kernels that need no statistics: degenerate input, units, support.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "warpcheck/sphere.h"

namespace warpcheck {
namespace {

template <class T> SphereLightGeometry<T> geometry(Vec3<T> x, Vec3<T> n, Vec3<T> c, T r) {
  return SphereLightGeometry<T>{ShadingPoint<T>{x, n}, SphereLight<T>{c, r}};
}

template <class T> class SphereKernels : public ::testing::Test {};
using Scalars = ::testing::Types<float, double, long double>;
TYPED_TEST_SUITE(SphereKernels, Scalars);

TYPED_TEST(SphereKernels, DegenerateGeometryGivesNoSampleWithAReasonNeverNaN) {
  using T = TypeParam;
  const T nan = std::numeric_limits<T>::quiet_NaN(), inf = std::numeric_limits<T>::infinity();
  const Vec3<T> o = Vec3<T>::Zero(), up(0, 0, 1), c(0, 0, 3);
  const struct {
    SphereLightGeometry<T> g;
    NoSample why;
  } cases[] = {
      {geometry<T>(o, up, Vec3<T>(0, 0, 0.5), 1), NoSample::kInsideLight},
      {geometry<T>(o, up, Vec3<T>(0, 0, 1), 1), NoSample::kInsideLight},  // on the sphere
      {geometry<T>(o, up, c, 0), NoSample::kZeroSize},
      {geometry<T>(o, up, c, -1), NoSample::kNegativeSize},
      {geometry<T>(o, Vec3<T>::Zero(), c, 1), NoSample::kBadNormal},
      {geometry<T>(o, Vec3<T>(nan, 0, 1), c, 1), NoSample::kNonFinite},
      {geometry<T>(o, up, Vec3<T>(0, inf, 3), 1), NoSample::kNonFinite},
      {geometry<T>(Vec3<T>(nan, 0, 0), up, c, 1), NoSample::kNonFinite},
      {geometry<T>(o, up, c, nan), NoSample::kNonFinite},
      {geometry<T>(o, up, Vec3<T>(0, 0, -3), 1), NoSample::kBelowHorizon},
  };
  for (const auto& k : cases) {
    const Vec2<T> u(T(0.3), T(0.7));
    for (const DirectionSample<T>& s : {sample_sphere_solid_angle(k.g, u), sample_sphere_visible_area(k.g, u)}) {
      EXPECT_FALSE(s.valid());
      EXPECT_EQ(s.reason, k.why) << to_string(s.reason);
      EXPECT_EQ(s.pdf, T(0));
    }
    EXPECT_EQ(pdf_sphere_solid_angle(k.g, up), T(0));
    EXPECT_EQ(pdf_sphere_visible_area(k.g, up), T(0));
  }
}

// Both kernels on one geometry: 2000 samples are unit directions inside the cone whose pdf matches pdf(direction).
template <class T> void expect_unit_directions_inside_the_cone_with_matching_pdf(const SphereLightGeometry<T>& g) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0, 1);
  const auto view = make_sphere_view(g);
  ASSERT_TRUE(view.valid());
  int valid = 0;
  const T tol = T(64) * std::numeric_limits<T>::epsilon();
  for (int i = 0; i < 2000; ++i) {
    const Vec2<T> u(T(U(rng)), T(U(rng)));
    for (int kernel = 0; kernel < 2; ++kernel) {
      const DirectionSample<T> s =
          kernel == 0 ? sample_sphere_solid_angle(view, u) : sample_sphere_visible_area(view, g.light, u);
      if (!s.valid()) continue;  // only u0 == 1 on the silhouette may fail, and U never gives it
      EXPECT_NEAR(double(s.direction.norm()), 1.0, double(tol));
      EXPECT_TRUE(view.cap().contains(s.direction, tol));
      const T pdf =
          kernel == 0 ? pdf_sphere_solid_angle(view, s.direction) : pdf_sphere_visible_area(view, g.light, s.direction);
      // pdf(direction) re-derives the density from a direction that carries a few ulps of rounding. For the
      // solid-angle kernel the density is constant; for the visible-area kernel its relative sensitivity to an
      // angular perturbation is kappa = (d / r) q / cos_light^2 (differentiate dist^2 / cos_light with
      // q = (d / r) sin(theta), cos_light = sqrt(1 - q^2)), which diverges at the silhouette. The tolerance is
      // 64 ulps times (1 + kappa), not a fitted number.
      T kappa = 0;
      if (kernel == 1) {
        const T d_over_r = view.distance / g.light.radius;
        const Vec3<T> wl = view.frame.to_local(s.direction);
        const T q = d_over_r * std::hypot(wl.x(), wl.y());
        kappa = d_over_r * q / std::max(T(1) - q * q, std::numeric_limits<T>::min());
      }
      EXPECT_LE(std::abs(pdf / s.pdf - T(1)), tol * (T(1) + kappa)) << "kernel " << kernel << " u0 " << double(u[0]);
      ++valid;
    }
  }
  EXPECT_EQ(valid, 4000);
}

TYPED_TEST(SphereKernels, SamplesAreUnitDirectionsInsideTheConeWithMatchingPdf) {
  using T = TypeParam;
  expect_unit_directions_inside_the_cone_with_matching_pdf(
      geometry<T>(Vec3<T>(0.1, -0.2, 0), Vec3<T>(0, 0.3, 1), Vec3<T>(1, 2, 2.5), T(0.7)));
}

// A sphere 0.9 of the largest finite T away (d / r = 3): |p - x| and the density stay finite, and no sample is a
// zero direction (which renormalized would divide by).
TYPED_TEST(SphereKernels, SamplesOfASphereNearTheLargestFiniteDistanceAreUnitDirectionsWithMatchingPdf) {
  using T = TypeParam;
  const T m = std::numeric_limits<T>::max();
  expect_unit_directions_inside_the_cone_with_matching_pdf(
      geometry<T>(Vec3<T>(T(-0.45) * m, 0, 0), Vec3<T>(1, 0, 0), Vec3<T>(T(0.45) * m, 0, 0), T(0.3) * m));
}

}  // namespace
}  // namespace warpcheck

// core.h's hand-rolled cube root (used per sample by the projected-cap quintic) against long double cbrtl, on
// 2e6 logarithmically spread arguments in the iterated range: float within 0.5 ulp (it iterates in double), double
// within 1 ulp (glibc's cbrt, used outside that range, measured 3.4 ulp by the same comparison).
template <class T> double worst_cube_root_ulps() {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> e(-590, 590);  // the iterated range [2^-600, 2^600]
  double worst = 0;
  for (int i = 0; i < 2'000'000; ++i) {
    const T x = T(std::pow(2.0L, (long double)e(rng)));
    if (!(x > T(0)) || !std::isfinite(x)) continue;
    const long double ref = cbrtl((long double)x);
    const long double ulp = std::nextafter(T(ref), std::numeric_limits<T>::infinity()) - T(ref);
    worst = std::max(worst, double(std::abs((long double)warpcheck::cube_root(x) - ref) / ulp));
  }
  return worst;
}

TEST(CubeRoot, IsWithinHalfAnUlpInFloatAndOneUlpInDouble) {
  EXPECT_LE(worst_cube_root_ulps<float>(), 0.5 + 1e-6);
  const double d = worst_cube_root_ulps<double>();
  std::printf("cube_root: worst double error %.3f ulp\n", d);
  EXPECT_LE(d, 1.0);
  EXPECT_EQ(warpcheck::cube_root(0x1p-700), std::cbrt(0x1p-700));  // outside: the library's
  EXPECT_EQ(warpcheck::cube_root(0.0f), 0.0f);
  EXPECT_EQ(warpcheck::cube_root(-8.0), -2.0);
  EXPECT_TRUE(std::isnan(warpcheck::cube_root(std::numeric_limits<double>::quiet_NaN())));
}

// core.h's division-free x^(2/3) for float (the float projected-cap quintic's root) against cbrtl, over every float
// of one period [1, 8): its steps scale exactly with x -> 8 x (checked below across the exponent range where x and
// the result are normal floats), so this covers every such float. Measured: 0.5228 ulp (cube_root(x * x) rounds
// x * x first).
TEST(CubeRootSquaredForFloat, IsWithinAnUlpOverEveryFloatOfOnePeriodAndScalesExactlyByEight) {
  double worst = 0;
  for (float x = 1.0f; x < 8.0f; x = std::nextafter(x, 9.0f)) {
    const long double c = cbrtl((long double)x), ref = c * c;
    const float fr = float(ref);
    const long double ulp = std::nextafter(fr, std::numeric_limits<float>::infinity()) - fr;
    worst = std::max(worst, double(std::abs((long double)warpcheck::cube_root_squared_for_float(x) - ref) / ulp));
  }
  std::printf("cube_root_squared_for_float: worst %.4f ulp over [1, 8)\n", worst);
  EXPECT_LE(worst, 0.53);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> m(1.0f, 8.0f);
  for (int i = 0; i < 20000; ++i) {
    const float x = m(rng);
    const int k = int(rng() % 83) - 41;  // 8^k x and (8^k x)^(2/3) = 4^k x^(2/3) normal floats
    EXPECT_EQ(warpcheck::cube_root_squared_for_float(std::ldexp(x, 3 * k)),
              std::ldexp(warpcheck::cube_root_squared_for_float(x), 2 * k))
        << x << " " << k;
  }
  EXPECT_EQ(warpcheck::cube_root_squared_for_float(0.0f), 0.0f);
  EXPECT_EQ(warpcheck::cube_root_squared_for_float(-8.0f), 4.0f);  // outside: std::cbrt
  EXPECT_TRUE(std::isnan(warpcheck::cube_root_squared_for_float(std::numeric_limits<float>::quiet_NaN())));
}

// core.h's renormalisation factor (3 - n2) / 2 against 1 / sqrt(n2), over every float n2 within 2^-12 of 1, where it
// is used (one Newton step: relative error 3/8 (n2 - 1)^2 <= 2.2e-8 plus its roundings); beyond, 1 / sqrt(n2).
TEST(NearUnitRenormalization, IsWithinAnUlpOfTheInverseSquareRootForEveryFloatWithin2ToTheMinus12OfOne) {
  double worst = 0;
  const float lo = 1.0f - 0x1p-12f, hi = 1.0f + 0x1p-12f;
  for (float n2 = lo; n2 <= hi; n2 = std::nextafter(n2, 2.0f)) {
    const long double ref = 1 / std::sqrt((long double)n2);
    const float fr = float(ref);
    const long double ulp = std::nextafter(fr, 2.0f) - fr;
    worst = std::max(worst, double(std::abs((long double)warpcheck::near_unit_renormalization_factor(n2) - ref) / ulp));
  }
  std::printf("near_unit_renormalization_factor: worst %.4f ulp\n", worst);
  EXPECT_LE(worst, 1.0);
  EXPECT_EQ(warpcheck::near_unit_renormalization_factor(4.0f), 0.5f);  // far from 1: 1 / sqrt
}
