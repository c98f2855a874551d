// Specifications of the batch API (lib/warpcheck/batch.h): the vectorised sphere solid-angle batch gives the
// scalar kernel's samples to a few ulps, declines like the scalar kernel, never outputs NaN, and passes the
// battery (validate(), 200k samples, fixed seed, Holm at alpha = 0.01) when the battery draws through it.
#include <gtest/gtest.h>

#include <array>
#include <random>
#include <vector>

#include "warpcheck/batch.h"
#include "warpcheck/validation/battery.h"

namespace warpcheck {
namespace {

template <class T> SphereLightGeometry<T> geometry(Vec3<T> x, Vec3<T> n, Vec3<T> c, T r) {
  return SphereLightGeometry<T>{ShadingPoint<T>{x, n}, SphereLight<T>{c, r}};
}

template <class T> class Batch : public ::testing::Test {};
using Scalars = ::testing::Types<float, double, long double>;
TYPED_TEST_SUITE(Batch, Scalars);

TYPED_TEST(Batch, SphereSolidAngleBatchMatchesTheScalarKernelToAFewUlps) {
  using T = TypeParam;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(0, 1);
  const SphereLightGeometry<T> lights[] = {
      geometry<T>(Vec3<T>(0.1, -0.2, 0), Vec3<T>(0, 0.3, 1), Vec3<T>(1, 2, 2.5), T(0.7)),
      geometry<T>(Vec3<T>(0, 0, 0), Vec3<T>(0, 0, 1), Vec3<T>(3, 0, -0.9), T(1)),      // qz = -0.9, partly below
      geometry<T>(Vec3<T>(0, 0, 0), Vec3<T>(0, 0, 1), Vec3<T>(0, 0, 1e4), T(1)),       // tiny cone
      geometry<T>(Vec3<T>(0, 0, 0), Vec3<T>(0, 0, 1), Vec3<T>(0, -1.001, 0.1), T(1)),  // huge cone
  };
  // 1003 samples: not a multiple of the block size or any vector width; u includes the ends 0 and 1.
  const std::size_t n = 1003;
  std::vector<T> u0(n), u1(n), x(n), y(n), z(n), pdf(n);
  for (std::size_t i = 0; i < n; ++i) u0[i] = T(U(rng)), u1[i] = T(U(rng));
  u0[0] = 0, u1[0] = 0, u0[1] = 1, u1[1] = 1, u1[2] = T(0.25), u1[3] = T(0.5), u1[4] = T(0.75), u1[5] = T(0.125);
  // Measured bound: the polynomial sincos and the scalar std::sin/std::cos each round to within an ulp or
  // so; through the frame and the renormalisation the direction differs by a few ulps of 1.
  const T tol = T(16) * std::numeric_limits<T>::epsilon();
  for (const auto& g : lights) {
    const SphereView<T> v = make_sphere_view(g);
    ASSERT_TRUE(v.valid());
    ASSERT_EQ(sample_sphere_solid_angle_batch(v, u0.data(), u1.data(), n,
                                              DirectionBatch<T>{x.data(), y.data(), z.data(), pdf.data()}),
              NoSample::kNone);
    T worst = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const DirectionSample<T> s = sample_sphere_solid_angle(v, Vec2<T>(u0[i], u1[i]));
      ASSERT_TRUE(s.valid());
      EXPECT_EQ(pdf[i], s.pdf);  // the same expression: bit-identical
      worst = std::max(worst, (Vec3<T>(x[i], y[i], z[i]) - s.direction).template lpNorm<Eigen::Infinity>());
    }
    EXPECT_LE(worst, tol) << "worst |batch - scalar| component";
  }
}

TYPED_TEST(Batch, SphereSolidAngleBatchDeclinesLikeTheScalarKernelAndNeverOutputsNaN) {
  using T = TypeParam;
  const T nan = std::numeric_limits<T>::quiet_NaN();
  std::vector<T> u0 = {T(0.5), nan, T(-1), T(2)}, u1 = {nan, T(0.5), T(3), T(-0.5)};
  std::vector<T> x(4, T(7)), y(4, T(7)), z(4, T(7)), pdf(4, T(7));
  const DirectionBatch<T> out{x.data(), y.data(), z.data(), pdf.data()};
  // A light entirely below the horizon: every output zero, the view's reason returned.
  const auto below = make_sphere_view(geometry<T>(Vec3<T>::Zero(), Vec3<T>(0, 0, 1), Vec3<T>(0, 1, -3), T(1)));
  EXPECT_EQ(sample_sphere_solid_angle_batch(below, u0.data(), u1.data(), 4, out), NoSample::kBelowHorizon);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(x[i] == 0 && y[i] == 0 && z[i] == 0 && pdf[i] == 0);
  // NaN and out-of-range primary samples are clamped into [0, 1]: unit directions, never NaN.
  const auto ok = make_sphere_view(geometry<T>(Vec3<T>::Zero(), Vec3<T>(0, 0, 1), Vec3<T>(0, 1, 3), T(1)));
  EXPECT_EQ(sample_sphere_solid_angle_batch(ok, u0.data(), u1.data(), 4, out), NoSample::kNone);
  for (int i = 0; i < 4; ++i) {
    const Vec3<T> w(x[i], y[i], z[i]);
    EXPECT_TRUE(all_finite(w)) << i;
    EXPECT_NEAR(double(w.norm()), 1.0, 1e-6) << i;
    EXPECT_TRUE(ok.cap().contains(w, T(1e-5))) << i;
  }
}

// The battery, drawing every sample through the batch: each primary sample fills a whole block of 128 lanes
// (batch.h's kBlock), so that the vectorised loops compute it, not the scalar remainder a block of one would take,
// and every lane must agree with lane 0 bit for bit. Default tolerance (1e-6) in float too, as the registry uses
// for the scalar float sphere kernels.
template <class T> validation::SamplerUnderTest batch_sampler(const SphereLightGeometry<validation::Real>& g) {
  using validation::Real;
  SphereLightGeometry<T> gt{ShadingPoint<T>{g.shading.position.template cast<T>(), g.shading.normal.template cast<T>()},
                            SphereLight<T>{g.light.center.template cast<T>(), T(g.light.radius)}};
  const SphereView<T> v = make_sphere_view(gt);
  validation::SamplerUnderTest s;
  s.kernel = "sphere-solid-angle-batch";
  s.scalar = validation::scalar_name<T>();
  s.config = "batch";
  s.sample = [v](double u0, double u1) {
    constexpr std::size_t kLanes = 128;
    std::array<T, kLanes> a, b, x, y, z, pdf;
    a.fill(validation::to_unit<T>(u0)), b.fill(validation::to_unit<T>(u1));
    const NoSample r = sample_sphere_solid_angle_batch(v, a.data(), b.data(), kLanes,
                                                       DirectionBatch<T>{x.data(), y.data(), z.data(), pdf.data()});
    bool lanes_agree = true;
    for (std::size_t i = 1; i < kLanes; ++i)
      lanes_agree = lanes_agree && x[i] == x[0] && y[i] == y[0] && z[i] == z[0] && pdf[i] == pdf[0];
    // A lane that disagrees is reported as a declined sample: the battery's chi2 counts even one as a sample where
    // the pdf puts no mass (p = 0; declined, outside and non-finite samples share that count, which negative control
    // outside-now-and-then exercises).
    return validation::Sample{validation::Vec3L(x[0], y[0], z[0]), Real(pdf[0]), r == NoSample::kNone && lanes_agree};
  };
  s.reference_sample = [g](Real u0, Real u1) {
    const SphereView<Real> vr = make_sphere_view(g);
    Real x, y, z, pdf;
    const NoSample r = sample_sphere_solid_angle_batch(vr, &u0, &u1, 1, DirectionBatch<Real>{&x, &y, &z, &pdf});
    return validation::Sample{validation::Vec3L(x, y, z), pdf, r == NoSample::kNone};
  };
  s.pdf = [gt](const validation::Vec3L& w) { return Real(pdf_sphere_solid_angle(gt, Vec3<T>(w.template cast<T>()))); };
  const Cap<Real> cap = make_sphere_view(g).cap();
  s.bounding_cap = cap;
  return s;
}

TEST(BatchBattery, SphereSolidAngleBatchPassesTheBatteryInFloatAndDouble) {
  const SphereLightGeometry<validation::Real> g{
      ShadingPoint<validation::Real>{validation::Vec3L(0.1L, -0.2L, 0), validation::Vec3L(0, 0.3L, 1)},
      SphereLight<validation::Real>{validation::Vec3L(1, 2, 2.5L), 0.7L}};
  validation::BatteryOptions o;
  o.samples = 200'000;
  o.seed = 9;
  o.threads = 1;
  for (const auto& s : {batch_sampler<float>(g), batch_sampler<double>(g)}) {
    const auto results = validation::validate(s, o);
    EXPECT_TRUE(validation::all_passed(results)) << validation::format_table(results);
  }
}

}  // namespace
}  // namespace warpcheck
