// LTC sampling of polygons and the MIS heuristics of Peters 2021 Section 4. (The battery on LTC sampling, 30+ s
// of one core, is in slow_ltc.cpp.)
#include <gtest/gtest.h>

#include <Eigen/QR>

#include <algorithm>
#include <boost/math/statistics/t_test.hpp>
#include <cfenv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "catalogue/sptd_samplers.h"
#include "ltc_fixtures.h"
#include "warpcheck/mis.h"
#include "warpcheck/validation/battery.h"

namespace warpcheck {
namespace {

TEST(Ltc, IdentityTransformIsProjectedSolidAngleSampling) {
  const auto pg = test_polygon().cast<double>();
  const LtcPolygonGeometry<double> g{pg, Mat3<double>::Identity()};
  std::mt19937_64 r(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 1000; ++i) {
    const Vec2<double> x(u(r), u(r));
    const auto a = sample_ltc_polygon(g, x);
    const auto b = sample_polygon_projected_solid_angle(make_polygon_projected_view(pg), x, kLtcSectorIterations);
    ASSERT_TRUE(a.valid() && b.valid());
    EXPECT_LT((a.direction - b.direction).norm(), 1e-14);
    EXPECT_NEAR(a.pdf / b.pdf, 1, 1e-13);
  }
}

TEST(Ltc, Eq10NormalisationMatchesLambertsFormulaForRandomAndIllConditionedM) {
  std::mt19937_64 r(4);
  const auto pg = test_polygon();
  for (int i = 0; i < 200; ++i) {
    const LtcPolygonGeometry<L> g{pg, i == 0 ? narrow_m() : random_m(r)};
    const auto v = make_ltc_polygon_view(g.cast<double>());
    const L ref = validation::ltc_reference_projected_solid_angle(g);
    if (ref == 0) {
      EXPECT_FALSE(v.valid());
      continue;
    }
    ASSERT_TRUE(v.valid()) << i;
    EXPECT_NEAR(v.integral * kPi<double> / double(ref), 1, 1e-10) << i;
  }
}

TEST(Ltc, SingularOrReflectingTransformsGiveNoSample) {
  const auto pg = test_polygon().cast<double>();
  Mat3<double> m = Mat3<double>::Identity();
  m(2, 2) = 0;
  EXPECT_EQ(sample_ltc_polygon(LtcPolygonGeometry<double>{pg, m}, Vec2<double>(0.5, 0.5)).reason,
            NoSample::kInvalidGeometry);
  m(2, 2) = -1;
  EXPECT_EQ(sample_ltc_polygon(LtcPolygonGeometry<double>{pg, m}, Vec2<double>(0.5, 0.5)).reason,
            NoSample::kInvalidGeometry);
  m(2, 2) = std::nan("");
  EXPECT_EQ(sample_ltc_polygon(LtcPolygonGeometry<double>{pg, m}, Vec2<double>(0.5, 0.5)).reason, NoSample::kNonFinite);
  EXPECT_EQ(pdf_ltc_polygon(LtcPolygonGeometry<double>{pg, m}, Vec3<double>(0.5, 0, 1)), 0);
  // Singular up to rounding: determinant() is 1.4e-17 > 0, but the cofactor expansion that Eigen's inverse()
  // divides by is exactly 0 (its inverse() has -inf entries). No sample, and no division by zero: UBSan's
  // float-divide-by-zero in the sanitizer build, the FE_DIVBYZERO flag in any build (make_ltc_polygon_view
  // inverts with the determinant it tests; Eigen's inverse() raises the flag here with g++ -O3, the view of the
  // identity none).
  Mat3<double> s;
  s << -0.97724830453404243, -0.71395549903980848, 0.31213760910876431, -0.011186738735074364, 0.45739249687330075,
      0.25797111957173724, 0.56127352143764009, -0.45829810002916671, -0.65376533080210242;
  ASSERT_GT(s.determinant(), 0);
  ASSERT_FALSE(Mat3<double>(s.inverse()).allFinite());
  std::feclearexcept(FE_DIVBYZERO);
  const auto singular = make_ltc_polygon_view(LtcPolygonGeometry<double>{pg, s});
  EXPECT_FALSE(std::fetestexcept(FE_DIVBYZERO)) << "make_ltc_polygon_view divided by zero";
  EXPECT_EQ(singular.reason, NoSample::kInvalidGeometry);
  EXPECT_EQ(sample_ltc_polygon(LtcPolygonGeometry<double>{pg, s}, Vec2<double>(0.5, 0.5)).reason,
            NoSample::kInvalidGeometry);
}

// The LTC of s M is that of M for every s > 0, and scaled by a power of two M gives the same samples and pdfs bit for
// bit (the view scales M to unit size exactly, ltc_unit_scale), also where s M alone would leave T's range: with M
// as given, float refused 36 of 100 samples at 2^42 (|M c|^3 times the projected density overflowed) and the view
// at 2^+-43, double the view at 2^+-400 (|s M| = 2^+-1200), and 2^275 put M^-1 P at 1e-82, where Newell's vector's
// squared norm underflows.
template <class T> void expect_power_of_two_scales_sample_as_the_unscaled_transform(std::initializer_list<int> es) {
  const auto pg = test_polygon().cast<T>();
  Mat3<T> m;
  m << 2, 0, 4, 0, 1, 0, 0.25, 0, 1;
  const LtcPolygonView<T> v = make_ltc_polygon_view(LtcPolygonGeometry<T>{pg, m});
  ASSERT_TRUE(v.valid());
  std::mt19937_64 r(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (const int e : es) {  // |s M| = 2^(3 e) |M|, |M| = 1
    const LtcPolygonView<T> s = make_ltc_polygon_view(LtcPolygonGeometry<T>{pg, Mat3<T>(m * std::ldexp(T(1), e))});
    ASSERT_TRUE(s.valid()) << "2^" << e << ": " << to_string(s.reason);
    EXPECT_EQ(s.integral, v.integral) << e;
    for (int i = 0; i < 100; ++i) {
      const Vec2<T> x(T(u(r)), T(u(r)));
      const DirectionSample<T> a = sample_ltc_polygon(v, x), b = sample_ltc_polygon(s, x);
      ASSERT_TRUE(a.valid() && b.valid()) << e;
      EXPECT_EQ(a.direction, b.direction) << e;
      EXPECT_EQ(a.pdf, b.pdf) << e;
      EXPECT_EQ(pdf_ltc_polygon(v, a.direction), pdf_ltc_polygon(s, a.direction)) << e;
    }
  }
}
TEST(Ltc, AnMatrixScaledByAPowerOfTwoSamplesAsTheUnscaledOneBitForBit) {
  expect_power_of_two_scales_sample_as_the_unscaled_transform<float>({-60, -43, -20, 20, 42, 43, 60});
  expect_power_of_two_scales_sample_as_the_unscaled_transform<double>({-400, -300, -200, -100, 100, 200, 275, 400});
}

// Random transforms U diag(sigma) V^T, sigma log-uniform in [10^-x, 10^x]: every sample of every view the kernel
// accepts is a sample, whatever M's scale; 16 samples per accepted view. Without ltc_unit_scale, float at x = 20
// (2000 M, 39 accepted) refused 12 samples and double at x = 110 (20000 M, 160 accepted) 32: |M c|^3 times the
// projected density overflowed.
template <class T> int refused_samples_of_accepted_views(double x, int trials, int* accepted) {
  const auto pg = test_polygon().cast<T>();
  std::mt19937_64 r(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> n;
  auto rotation = [&] {
    Mat3<double> a;
    for (int i = 0; i < 9; ++i) a(i) = n(r);
    return Mat3<double>(Eigen::HouseholderQR<Mat3<double>>(a).householderQ());
  };
  int refused = 0;
  *accepted = 0;
  for (int t = 0; t < trials; ++t) {
    Vec3<double> sigma;
    for (int i = 0; i < 3; ++i) sigma[i] = std::pow(10.0, x * (2 * u(r) - 1));
    Mat3<double> m = rotation() * sigma.asDiagonal() * rotation();
    if (m.determinant() < 0) m.col(0) = -m.col(0);
    const LtcPolygonView<T> v = make_ltc_polygon_view(LtcPolygonGeometry<T>{pg, m.cast<T>()});
    if (!v.valid()) continue;
    ++*accepted;
    for (int i = 0; i < 16; ++i)
      refused += !sample_ltc_polygon(v, Vec2<T>(T((i % 4 + 0.5) / 4), T((i / 4 + 0.5) / 4))).valid();
  }
  return refused;
}
TEST(Ltc, EverySampleOfAnAcceptedViewIsASampleWhateverTheScaleOfM) {
  int accepted = 0;
  EXPECT_EQ(refused_samples_of_accepted_views<float>(4, 2000, &accepted), 0);
  EXPECT_GT(accepted, 1000);
  EXPECT_EQ(refused_samples_of_accepted_views<float>(20, 2000, &accepted), 0);
  EXPECT_GT(accepted, 30);
  EXPECT_EQ(refused_samples_of_accepted_views<double>(8, 2000, &accepted), 0);
  EXPECT_GT(accepted, 1000);
  EXPECT_EQ(refused_samples_of_accepted_views<double>(110, 20000, &accepted), 0);
  EXPECT_GT(accepted, 100);
}

// pdf() at the sampler's own direction gives the sampler's pdf, to the rounding of the density formula (16 eps, the
// fuzz target's allowance), for a near-singular M (sigma_1 / sigma_3 = 1024): Eigen's inverse is off by |E| =
// |M Minv - I| = 8.9e-14, and 1 / |Minv w|^3 with that inverse makes the density 3 (E w).w = -8.3e-14 off.
TEST(Ltc, PdfEqualsTheSamplePdfForANearSingularTransform) {
  LtcPolygonGeometry<double> g;
  g.polygon = PolygonLightGeometry<double>{
      ShadingPoint<double>{{-0.99999999999999989, -6, 1.4786832970547863e-06},
                           {0.86266443124090197, 0.43133202034078566, 0.26412642295034983}},
      PolygonLight<double>{{-1, -6, 0}, {-6.4282032302755097, -9, 0}, {7.428203230275507, -9, 0}}};
  g.m << 0.15393094311796404, 0.22611176580258044, 0.85231093149425219, 0.17081421027716473, 0.25144152677360854,
      -0.51632961880767692, -0.51506759306050398, -0.75331582125345931, 0.083485332827504477;
  const auto v = make_ltc_polygon_view(g);
  ASSERT_TRUE(v.valid());
  const auto s = sample_ltc_polygon(v, Vec2<double>(0, 0));
  ASSERT_TRUE(s.valid());
  EXPECT_NEAR(pdf_ltc_polygon(v, s.direction) / s.pdf, 1, 16 * std::numeric_limits<double>::epsilon());
}

// M^-1 is a two-sided inverse for an ill-conditioned M (cond 6e10): the 3x3 cofactor formula of Eigen's
// inverse() and computeInverseAndDetWithCheck gives |M X - I| = 1.6e-58 but |X M - I| = 2.2 here, and the sample's
// pdf (from M c) and pdf(direction) (from X w) then are 0.83 % apart. With LU
// (ltc_inverse) both residuals are ~eps cond(M) or less, and the two densities agree to what the conditioning
// leaves: w is rounded to eps, which X stretches by |M c| / sigma_3 = 8e7 into 3e-8 rad of c, moving |M c|^3 by up
// to 3 sigma_1 3e-8 / |M c| = 7e-5 relative (measured: 3.2e-6).
TEST(Ltc, TheInverseIsTwoSidedAndPdfMatchesTheSamplePdfForATransformOfCondition6e10) {
  LtcPolygonGeometry<double> g;
  g.polygon = PolygonLightGeometry<double>{
      ShadingPoint<double>{{-1.9899291992187504, 0.031186217543507051, 0.034569129277040013},
                           {-0., 1.4142135623730949, -1.4142135623730951}},
      PolygonLight<double>{{3.9798583984375, 0, 0},
                           {-1.9899291992187491, 0.43301270189221935, 0.43301270189221935},
                           {-1.9899291992187518, -0.43301270189221919, -0.43301270189221919}}};
  g.m << 3.9999999995343387, -2, -7.1515105099495211e-62, 4, -2.0000000004656613, -7.1515105099495211e-62, 4, -2,
      -4.6566128730773926e-10;
  Mat3<double> x;
  double det = 0;
  ASSERT_TRUE(ltc_inverse(g.m, &x, &det));
  using L = long double;
  const Mat3<L> ml = g.m.cast<L>(), xl = x.cast<L>();
  const L bound = 8 * std::numeric_limits<double>::epsilon() * 6e10L;
  EXPECT_LE((ml * xl - Mat3<L>::Identity()).norm(), bound);
  EXPECT_LE((xl * ml - Mat3<L>::Identity()).norm(), bound);
  const auto v = make_ltc_polygon_view(g);
  ASSERT_TRUE(v.valid());
  const auto s = sample_ltc_polygon(v, Vec2<double>(0.0078125, 0.0025777816772490914));
  ASSERT_TRUE(s.valid());
  EXPECT_NEAR(pdf_ltc_polygon(v, s.direction) / s.pdf, 1, 7e-5);
}

// Near both tips of a light straddling the horizon (the battery's polygon-ltc lobe-away), the float sampler's
// density at its samples follows the long double warp's to 64 eps_f, for xi_0 within [1e-4, 1e-3] of either end.
// There the area left to a tip on the horizon grows with the cube of the angle, and two differences lose it to
// cancellation: Eq. 1's two ellipse areas in float (density error 2.9e-4 at xi_0 in [3e-4, 6e-4]) and the sector
// target xi_0 A_Sigma - sum A_k (1.4e-4 at 1 - xi_0 in [3e-4, 6e-4]). polygon_projected.h avoids both
// (EllipseAreaScalar, and the sector selected from the nearer end), leaving 4.6e-6.
TEST(Ltc, FloatSamplesNearTheTipsOfALightStraddlingTheHorizonFollowTheLongDoubleWarp) {
  PolygonLightGeometry<L> pg;
  pg.shading.position = Vec3<L>(0, 0, 0);
  pg.shading.normal = Vec3<L>(0, 0, 1);
  pg.light = PolygonLight<L>{Vec3<L>(1, -0.5L, -0.3L), Vec3<L>(1, 0.5L, -0.3L), Vec3<L>(1, 0.5L, 0.9L),
                             Vec3<L>(1, -0.5L, 0.9L)};
  M3 m;
  m << 0.3L, 0, -0.6L, 0, 0.3L, 0, 0, 0, 1;
  const LtcPolygonGeometry<L> g{pg, m};
  const auto vl = make_ltc_polygon_view(g);
  const auto vf = make_ltc_polygon_view(g.cast<float>());
  ASSERT_TRUE(vl.valid() && vf.valid());
  ASSERT_FALSE(vl.transformed.central);
  std::mt19937_64 r(11);
  std::uniform_real_distribution<double> u(0, 1);
  double worst = 0;
  for (int i = 0; i < 20000; ++i) {
    const double d = 1e-4 * std::pow(10.0, u(r));
    const float u1 = std::min(float(u(r)), 0.99999994f);  // u1 = 1 lands on the horizon: no sample
    for (const float u0 : {float(d), float(1 - d)}) {
      const auto a = sample_ltc_polygon(vf, Vec2<float>(u0, u1));
      const auto b = sample_ltc_polygon(vl, Vec2<L>(u0, u1));
      ASSERT_TRUE(a.valid() && b.valid()) << u0 << " " << u1;
      worst = std::max(worst, double(std::abs(L(a.pdf) / b.pdf - 1)));
    }
  }
  EXPECT_LT(worst, 64 * std::numeric_limits<float>::epsilon());
  std::printf("float against long double density at the samples: %.3g\n", worst);
}

// pdf() is positive at samples well inside the light when two vertices 3e51 apart (at 2e67) lie on the horizon
// up to rounding. Edge planes of the transformed polygon M^-1 P taken from its rounded vertices turn that edge's
// plane into the horizon with a random orientation, and pdf() is 0 at samples 0.09 rad inside.
TEST(Ltc, PdfIsPositiveAtSamplesInsideALightWithAShortEdgeOnTheHorizon) {
  LtcPolygonGeometry<double> g;
  g.polygon = PolygonLightGeometry<double>{
      ShadingPoint<double>{{-4.871296688397204e+67, 1.1610359843866627e+67, -2.435648344198602e+67},
                           {0.59148163293412626, -0.12975569400939727, -0.7958096115112705}},
      PolygonLight<double>{{-2.2716570681338925e+67, -1.8921621456179815e+67, -5.6589321981982735e+64},
                           {-2.3301947293937325e+67, -9.4215158378992969e+66, 7.5404429194839272e+66},
                           {4.6955021667812761e+66, 1.6641069401263595e+67, 1.5688122326536821e+67},
                           {1.3549784773173498e+67, 1.8592051854531317e+67, 1.339998953880259e+67},
                           {1.9288329403068742e+66, -3.4493062043374888e+66, 1.3394595283227462e+66},
                           {-2.2716570681338922e+67, -1.8921621456179815e+67, -5.6589321981983858e+64}}};
  g.m = Mat3<double>::Identity();
  g.m(1, 0) = 7.1054273576010019e-15;
  const auto v = make_ltc_polygon_view(g);
  ASSERT_TRUE(v.valid());
  for (const double u0 : {0.125, 0.32118955207696653, 0.5, 0.50526390524856635, 0.75, 0.875})
    for (const double u1 : {0.25, 0.5, 0.99999618530273438}) {
      const auto s = sample_ltc_polygon(v, Vec2<double>(u0, u1));
      ASSERT_TRUE(s.valid());
      EXPECT_NEAR(pdf_ltc_polygon(v, s.direction) / s.pdf, 1, 1e-6) << u0 << " " << u1;
    }
}

// A light accepted as planar although its vertices leave the plane by far more than the offsets' rounding (here
// 6.4e-8, the rounding of coordinates ~3.2e9), seen from 2.6e-7 off that plane and 24 away: the kernels see the
// flattened light (make_polygon_view), whose projected solid angle Lambert's formula gives in long double. Unflattened,
// the cone of the vertices seen from x is not convex and A_Sigma comes out 1.4e-15 for 1.4e-11.
TEST(Ltc, ANonPlanarLightSeenFromCloseToItsPlaneIsSampledAsItsFlattening) {
  LtcPolygonGeometry<double> g;
  g.polygon =
      PolygonLightGeometry<double>{ShadingPoint<double>{{14.962579331135613, 3221225491.6532202, 11.826609910141354},
                                                        {1, -6.9713964909789094e-18, 2.9531309136255907e-17}},
                                   PolygonLight<double>{{-6, 3221225466, -1},
                                                        {-11.993386006344959, 3221225468.2590613, 0.12953059442379922},
                                                        {-6.6964465405750548, 3221225473.3351254, 2.667562801868943},
                                                        {5.9021149417110728, 3221225477.4058132, 4.7029066037072571},
                                                        {16.31532468053247, 3221225477.4058132, 4.7029066037072571},
                                                        {16.701823351788715, 3221225473.3351254, 2.6675628018689439},
                                                        {6.7705695728877586, 3221225468.2590613, 0.12953059442379988}}};
  g.m = Mat3<double>::Identity();
  // The flattening in long double, onto the plane of the area vector through the centroid, with x at the origin
  // (the offsets V - x are exact; flattened world coordinates ~3.2e9 would round by 3.5e-10, 1e-3 of the height).
  PolygonLightGeometry<L> flat = g.polygon.cast<L>();
  const Vec3<L> x = flat.shading.position;
  flat.shading.position = Vec3<L>::Zero();
  for (int i = 0; i < flat.light.count; ++i) flat.light.vertices[i] -= x;
  Vec3<L> c = Vec3<L>::Zero(), area = Vec3<L>::Zero();
  for (int i = 0; i < flat.light.count; ++i) c += flat.light.vertices[i] / L(flat.light.count);
  for (int i = 1; i + 1 < flat.light.count; ++i)
    area += Vec3<L>(flat.light.vertices[i] - flat.light.vertices[0])
                .cross(Vec3<L>(flat.light.vertices[i + 1] - flat.light.vertices[0]));
  const Vec3<L> nh = area.normalized();
  L off = 0;
  for (int i = 0; i < flat.light.count; ++i) {
    const L d = nh.dot(Vec3<L>(flat.light.vertices[i] - c));
    off = std::max(off, std::abs(d));
    flat.light.vertices[i] -= d * nh;
  }
  ASSERT_GT(off, 5e-8L);  // the light is as non-planar as the finding's
  const L ref = reference_projected_solid_angle(flat);
  const auto v = make_ltc_polygon_view(g);
  ASSERT_TRUE(v.valid());
  // The value's own conditioning: A_Sigma is about proportional to the height 2.6e-7, known to ~eps 24 through the
  // offsets and the normal, 2e-8 relative.
  EXPECT_NEAR(v.integral * kPi<double> / double(ref), 1, 1e-6) << v.integral * kPi<double> << " vs " << double(ref);
  for (const double u0 : {0.125, 0.5, 0.875})
    for (const double u1 : {0.25, 0.5, 0.75}) {
      const auto s = sample_ltc_polygon(v, Vec2<double>(u0, u1));
      ASSERT_TRUE(s.valid());
      EXPECT_NEAR(pdf_ltc_polygon(v, s.direction) / s.pdf, 1, 1e-6) << u0 << " " << u1;
    }
}

// M^-1 P of a convex P is convex, but its computed vertices carry the rounding of the product, up to about eps
// cond(M) of their size; check_polygon is told so (ltc.h) and accepts the transformed polygon. A square with a
// collinear vertex on each edge under M with cond(M) up to 1e8: with only the default rounding (4 eps),
// 2 of these 20000 views are rejected as not convex.
TEST(Ltc, TransformedPolygonsWithCollinearVerticesStayValidForIllConditionedM) {
  const PolygonLight<double> p{{-1, -1, 2}, {0.1, -1, 2}, {1, -1, 2}, {1, 0.3, 2},
                               {1, 1, 2},   {-0.2, 1, 2}, {-1, 1, 2}, {-1, -0.1, 2}};
  std::mt19937_64 r(1);
  std::uniform_real_distribution<double> u(-1, 1);
  int views = 0, valid = 0;
  for (int i = 0; i < 20000; ++i) {
    Mat3<double> m;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) m(a, b) = u(r);
    // Singular values (s0, s1, s0 10^-k), k uniform in [0, 8].
    Eigen::JacobiSVD<Mat3<double>> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Vec3<double> s = svd.singularValues();
    s(2) = s(0) * std::pow(10.0, -8 * std::abs(u(r)));
    m = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
    if (m.determinant() < 0) m.col(0) *= -1;
    const Vec3<double> x(0.5 * u(r), 0.5 * u(r), 0);
    const auto v = make_ltc_polygon_view(LtcPolygonGeometry<double>{{{x, {0, 0, 1}}, p}, m});
    ++views;
    // Below the horizon is legitimate (M^-1 P may lie below z = 0); invalid or zero-size is not.
    EXPECT_NE(v.reason, NoSample::kInvalidGeometry) << i;
    EXPECT_NE(v.reason, NoSample::kZeroSize) << i;
    valid += v.valid();
  }
  EXPECT_GT(valid, views / 2);
}

// ---- MIS ------------------------------------------------------------------------------------------------------

MixedPolygonShading<double> mixed(const M3& m1, double a0, double a1) {
  MixedPolygonShading<double> s;
  s.polygon = test_polygon().cast<double>();
  s.m_specular = m1.cast<double>();
  s.albedo_diffuse = a0, s.albedo_specular = a1, s.emitted = 3;
  return s;
}

// Zero variance in the idealised setting (Sec. 4.2): Lambertian + LTC-exact specular, Lambertian emitter, no
// occlusion. Every estimate, multi-sample or one-sample, equals c_0 + c_1 to 1e-6 relative, for the weighted
// balance heuristic and for clamped optimal MIS with v = 1 (Sec. 4.3: v estimates the light's visibility, which is
// 1 here; w^c = w^w then). With v < 1, clamped optimal MIS blends in the balance heuristic and is not zero-variance
// (by design); there each estimate must equal v (weighted estimate) + (1 - v) (balance estimate) for the same
// random numbers (the weights' blend, Sec. 4.3, carried through the estimator; to rounding, 1e-12).
// Failing counterparts: the balance heuristic, and the weighted heuristic with wrong c (c_1 twice too large in the
// weights and in the one-sample technique choice), must vary by more than 1e-3.
struct ZeroVarianceSpread {
  double weighted = 0, clamped_v1 = 0, blend = 0, balance = 0, wrong_c = 0;
};
ZeroVarianceSpread measure_zero_variance(const MixedPolygonShading<double>& s, std::mt19937_64& r, bool one_sample) {
  std::uniform_real_distribution<double> u(0, 1);
  const auto v = make_mis_view(s);
  MisView<double> wrong = v;
  wrong.c[1] *= 2;
  const double expected = v.sum_c();
  auto f = [&](const Vec3<double>& w) { return idealized_integrand(s, v, w); };
  ZeroVarianceSpread z;
  for (int i = 0; i < 2000; ++i) {
    const std::array<Vec2<double>, 2> uu{Vec2<double>(u(r), u(r)), Vec2<double>(u(r), u(r))};
    const double select = u(r);
    auto estimate = [&](const MisView<double>& view, MisHeuristic h, double vis) {
      return one_sample ? mis_estimate_one(view, h, vis, select, uu[0], f) : mis_estimate_multi(view, h, vis, uu, f);
    };
    auto dev = [&](double e) { return std::abs(e / expected - 1); };
    const double weighted = estimate(v, MisHeuristic::kWeightedBalance, 0.0);
    const double balance = estimate(v, MisHeuristic::kBalance, 0.0);
    const double half = estimate(v, MisHeuristic::kClampedOptimal, 0.5);
    z.weighted = std::max(z.weighted, dev(weighted));
    z.clamped_v1 = std::max(z.clamped_v1, dev(estimate(v, MisHeuristic::kClampedOptimal, 1.0)));
    z.blend = std::max(z.blend, std::abs(half - (0.5 * weighted + 0.5 * balance)) / expected);
    z.balance = std::max(z.balance, dev(balance));
    z.wrong_c = std::max(z.wrong_c, dev(estimate(wrong, MisHeuristic::kWeightedBalance, 0.0)));
  }
  return z;
}

void expect_zero_variance(bool one_sample) {
  std::mt19937_64 r(one_sample ? 9 : 7);
  std::uniform_real_distribution<double> u(0, 1);
  ZeroVarianceSpread worst, least{1, 1, 1, 1, 1};  // worst of the zero-variance ones, least of the counterparts
  for (int k = 0; k < 20; ++k) {
    const auto s = mixed(k == 0 ? narrow_m() : random_m(r), 0.01 + u(r), 0.01 + u(r));
    const auto v = make_mis_view(s);
    ASSERT_TRUE(v.technique[0].valid() && v.technique[1].valid()) << k;
    const ZeroVarianceSpread z = measure_zero_variance(s, r, one_sample);
    EXPECT_LT(z.weighted, 1e-6) << k;
    EXPECT_LT(z.clamped_v1, 1e-6) << k;
    EXPECT_LT(z.blend, 1e-12) << k;
    EXPECT_GT(z.balance, 1e-3) << k;
    EXPECT_GT(z.wrong_c, 1e-3) << k;
    worst.weighted = std::max(worst.weighted, z.weighted), worst.clamped_v1 = std::max(worst.clamped_v1, z.clamped_v1);
    worst.blend = std::max(worst.blend, z.blend);
    least.balance = std::min(least.balance, z.balance), least.wrong_c = std::min(least.wrong_c, z.wrong_c);
  }
  std::printf(
      "[ measured ] %s: max |estimate / sum c - 1| weighted %.1e, clamped v = 1 %.1e; blend identity %.1e; "
      "least spread of the counterparts: balance %.1e, wrong c %.1e\n",
      one_sample ? "one-sample" : "multi-sample", worst.weighted, worst.clamped_v1, worst.blend, least.balance,
      least.wrong_c);
}

TEST(Mis, MultiSampleWeightedBalanceAndClampedOptimalHaveZeroVarianceInTheIdealisedSetting) {
  expect_zero_variance(false);
}
TEST(Mis, OneSampleWeightedBalanceAndClampedOptimalHaveZeroVarianceInTheIdealisedSetting) {
  expect_zero_variance(true);
}

// ---- Unbiasedness with an occluder -------------------------------------------------------------------------------

// The occluder blocks every direction with w.o > 0 (a wall whose edge passes through the shading point). The
// visible part of the light is the polygon clipped by that plane through x (Sutherland-Hodgman here, in long
// double), and the exact integral of the idealised integrand over it is sum_j L_e a_j A_Sigma(M_j^-1 P') / pi
// by Lambert's formula (polygon.h's reference), independent of the kernels.
PolygonLightGeometry<L> visible_part(const PolygonLightGeometry<L>& g, const Vec3L& o) {
  PolygonLightGeometry<L> out = g;
  out.light.count = 0;
  const int m = g.light.count;
  for (int i = 0; i < m; ++i) {
    const Vec3L a = g.light.vertices[i] - g.shading.position, b = g.light.vertices[(i + 1) % m] - g.shading.position;
    const L da = a.dot(o), db = b.dot(o);
    if (da <= 0) out.light.vertices[out.light.count++] = g.shading.position + a;
    if ((da < 0 && db > 0) || (da > 0 && db < 0))
      out.light.vertices[out.light.count++] = g.shading.position + a + da / (da - db) * (b - a);
  }
  return out;
}

TEST(Mis, AllEstimatorsAreUnbiasedWithAnOccluderByAStudentTTest) {
  M3 m1b;  // a moderately glossy lobe tilted towards the light
  m1b << 0.3L, 0, 0.4L, 0, 0.25L, -0.1L, 0, 0, 1;
  const auto s = mixed(m1b, 0.4, 0.7);
  const auto v = make_mis_view(s);
  ASSERT_TRUE(v.technique[0].valid() && v.technique[1].valid());
  // Cuts the light, leaving 89% of the unshadowed shading visible. (An earlier occluder left only 8% visible:
  // the estimators' relative standard deviations rose to 0.3-2.9 and the t-test lost its power.)
  const Vec3L o = Vec3L(1, 0.3L, -0.8L).normalized();
  const auto pl = visible_part(test_polygon(), o);
  ASSERT_GE(pl.light.count, 3);
  const L exact =
      s.emitted *
      (s.albedo_diffuse * validation::ltc_reference_projected_solid_angle(LtcPolygonGeometry<L>{pl, M3::Identity()}) +
       s.albedo_specular * validation::ltc_reference_projected_solid_angle(LtcPolygonGeometry<L>{pl, m1b})) /
      kPi<L>;
  ASSERT_GT(exact, 0);
  ASSERT_LT(exact, 0.95L * v.sum_c());  // the occluder matters
  auto f = [&](const Vec3<double>& w) { return w.cast<L>().dot(o) > 0 ? 0.0 : idealized_integrand(s, v, w); };
  // Six estimators tested at family-wise alpha = 0.01 (Sidak), plus a deliberately biased control that must be
  // rejected at the same per-test level: the noisiest estimator (one-sample balance heuristic; relative standard
  // deviation 1.47, measured with 2e5 samples) scaled by 1.02. At n = 1e5 a 2% bias is then
  // ~4.3 standard errors, so the t-test has power against it; every other estimator here is less noisy.
  const int n = 100000;
  const double alpha_each = 1 - std::pow(1 - 0.01, 1.0 / 6);
  std::mt19937_64 r(8);
  std::uniform_real_distribution<double> u(0, 1);
  auto t_test = [&](auto&& estimate) {
    std::vector<double> x(n);
    for (int i = 0; i < n; ++i) x[i] = estimate();
    double mean = 0, var = 0;
    for (double e : x) mean += e;
    mean /= n;
    for (double e : x) var += (e - mean) * (e - mean);
    var /= n - 1;
    return boost::math::statistics::one_sample_t_test(mean, var, double(n), double(exact)).second;
  };
  for (MisHeuristic h : {MisHeuristic::kBalance, MisHeuristic::kWeightedBalance, MisHeuristic::kClampedOptimal}) {
    const double p_multi = t_test([&] {
      const std::array<Vec2<double>, 2> uu{Vec2<double>(u(r), u(r)), Vec2<double>(u(r), u(r))};
      return mis_estimate_multi(v, h, 0.5, uu, f);
    });
    const double p_one = t_test([&] { return mis_estimate_one(v, h, 0.5, u(r), Vec2<double>(u(r), u(r)), f); });
    EXPECT_GT(p_multi, alpha_each) << "multi-sample, heuristic " << int(h);
    EXPECT_GT(p_one, alpha_each) << "one-sample, heuristic " << int(h);
    std::printf("[ measured ] heuristic %d: t-test p multi-sample %.3g, one-sample %.3g\n", int(h), p_multi, p_one);
  }
  const double p_biased = t_test(
      [&] { return 1.02 * mis_estimate_one(v, MisHeuristic::kBalance, 0.5, u(r), Vec2<double>(u(r), u(r)), f); });
  EXPECT_LT(p_biased, alpha_each) << "the t-test cannot detect a 2% bias";
  std::printf("[ measured ] control 1.02 x one-sample balance: p %.3g (must be < %.3g)\n", p_biased, alpha_each);
  // A biased technique: the specular technique's normaliser A_Sigma(M_1^-1 P) 1% too large, so that its returned
  // pdf (sample and pdf_ltc_polygon alike) is 1% below its samples' true density; the weights still sum to one,
  // and the estimator's mean is off by 0.01 int f w_1. Rejected for the multi-sample weighted balance heuristic
  // and clamped optimal MIS (measured below as p-values; the specular technique carries most of the estimate).
  MisView<double> biased = v;
  biased.technique[1].transformed.projected_solid_angle *= 1.01;
  for (MisHeuristic h : {MisHeuristic::kWeightedBalance, MisHeuristic::kClampedOptimal}) {
    const double p = t_test([&] {
      const std::array<Vec2<double>, 2> uu{Vec2<double>(u(r), u(r)), Vec2<double>(u(r), u(r))};
      return mis_estimate_multi(biased, h, 0.5, uu, f);
    });
    EXPECT_LT(p, alpha_each) << "a technique whose pdf is 1% off is not detected, heuristic " << int(h);
    std::printf("[ measured ] control biased specular technique, heuristic %d: p %.3g\n", int(h), p);
  }
}

}  // namespace
}  // namespace warpcheck
