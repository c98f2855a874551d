// Claims of Peters & Dachsbacher 2019, "Sampling Projected Spherical Caps in Real Time", as fast tests of
// lib/warpcheck/projected_cap.h (a few seconds in all). Large counts and quadratures live in slow_projected_cap.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/math/distributions/kolmogorov_smirnov.hpp>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <random>
#include <string>
#include <typeinfo>
#include <vector>

#include "projected_cap_fixtures.h"

namespace warpcheck::validation {
namespace {

using namespace projected_cap_test;

// ---- Sec. 3.6: the quintic ---------------------------------------------------------------------------------

TEST(ProjectedCapQuintic, MaxErrorAgainstExactInverseOfAReproducesPapers4_6e5) {
  const QuinticError e = quintic_max_error(20000);
  // The paper (Sec. 3.6) gives 4.6e-5 to two digits: the measured maximum must round to it.
  EXPECT_GE(e.max_error, 4.55e-5L) << "at A = " << double(e.at);
  EXPECT_LT(e.max_error, 4.65e-5L) << "at A = " << double(e.at);
}

TEST(ProjectedCapQuintic, PublishedFitJumpsAtTheCentreAndTheRescaledHalvesMeetThere) {
  // As published, d_x(A -> 0-) = -d_x(A -> 0+) = 1 - g(0) (pi/2)^(2/3) = +4.63e-5: a jump of the warp.
  const Real half = kPi<Real> / 2, tiny = 1e-15L;
  const Real jump = paper_quintic_x<Real>(half - tiny) - paper_quintic_x<Real>(half + tiny);
  EXPECT_NEAR(jump, 2 * 4.632e-5L, 1e-8L);
  // kQuinticE0 solves g(pi/2 - e) e^(2/3) = 1 (recomputed here by Boost's Newton in long double) ...
  std::uintmax_t it = 60;
  const Real e0 = boost::math::tools::newton_raphson_iterate(
      [half](Real e) {
        const Real s = half - e, c = std::cbrt(e * e);
        return std::make_pair(quintic_g(s) * c - 1, -quintic_g_prime(s) * c + quintic_g(s) * 2 / (3 * std::cbrt(e)));
      },
      half, Real(1.5), half, 62, it);
  EXPECT_NEAR(kQuinticE0<Real>, e0, 1e-18L);
  // ... so the sampler's rescaled halves meet at d_x = 0, continuously, in every precision.
  auto x = [](auto a) { return sample_cut_unit_disk_x<decltype(a), CutDiskInverse::kQuintic>(a).x; };
  EXPECT_LT(std::abs(x(half - tiny)), 1e-14L);
  EXPECT_LT(std::abs(x(half + tiny)), 1e-14L);
  EXPECT_LT(std::abs(x(double(half) - 1e-12)), 1e-11);
  EXPECT_LT(std::abs(x(float(half) + 1e-6f)), 1e-5f);
  EXPECT_LE(x(half - tiny), x(half + tiny));
}

TEST(ProjectedCapQuintic, RescaledFitErrorAgainstTheExactInverseIsAtMostTwiceThePapers) {
  // The rescaling moves the fit by up to (1 - kappa) pi/2 in area near the centre; measured: 9.0e-5 (at A = 0.106;
  // the published fit's maximum 4.63e-5 is at A = 0.108 and has the same sign as the shift). The sampler reports
  // the exact density of this fit, so its error costs uniformity, not correctness.
  const QuinticError e = quintic_max_error(20000, rescaled_quintic_inverse_of_A);
  EXPECT_GT(e.max_error, 8.9e-5L) << "at A = " << double(e.at);
  EXPECT_LT(e.max_error, 9.1e-5L) << "at A = " << double(e.at);
}

TEST(ProjectedCapQuintic, ExactInverseOfTheKernelAgreesWithBoostToms748InverseOfA) {
  // The kernel's exact mode (Newton on the cut-disk angle) against an independent Boost TOMS 748 solve of A(X).
  Real worst = 0;
  for (int i = 0; i <= 2000; ++i) {
    const Real a = kPi<Real> / 2 * Real(i) / 2000;
    const Real x = sample_cut_unit_disk_x<Real, CutDiskInverse::kExact>(kPi<Real> / 2 + a).x;
    worst = std::max(worst, std::abs(x - exact_inverse_of_A(a)));
  }
  EXPECT_LT(worst, 1e-15L);
}

// ---- Sec. 3.5: the Case-3 density ratio bound ---------------------------------------------------------------

TEST(ProjectedCapCase3, DensityRatioNeverExceedsPapersBoundOn1e4RandomConfigurations) {
  expect_case3_ratio_within_bound(10'000);
}

TEST(ProjectedCapCase3, RatioTestCatchesADensityTwoPercentAboveTheBound) {
  // Negative control: the same comparison against the bound scaled by 0.98 must report an excess.
  const ProjectedCapView<long double> p = make_projected_cap_view(unit_geometry<long double>(-0.2L, 0.4L));
  const long double excess = case3_density_ratio(p, 8) / (0.98L * case3_bound(p)) - 1;
  EXPECT_GT(double(excess), case3_rounding_allowance(p));
}

TEST(ProjectedCapCase3, RatioOnAFineGridEqualsTheRatioOnTheCoarseGrid) {
  // The max/min of the density are at the cut disk's corners: refining the grid 64x changes nothing.
  for (const auto& [h, ry] :
       std::vector<std::pair<double, double>>{{-0.2, 0.4}, {-0.39, 0.4}, {-0.5, 0.9}, {-0.9, 0.999}}) {
    const auto v = make_projected_cap_view(unit_geometry<double>(h, ry));
    ASSERT_EQ(v.which_case, 3);
    EXPECT_NEAR(case3_density_ratio(v, 8), case3_density_ratio(v, 512), 1e-12) << h << " " << ry;
  }
}

// ---- Continuity across cases (Sec. 3.4, Fig. 4) ----------------------------------------------------------------

template <CutDiskInverse M> void expect_lipschitz_across(double h_boundary, double ry) {
  // For fixed (u0, u1) the direction moves by at most K eps when the centre's height crosses the boundary by eps,
  // with the same K for eps = 1e-4 and 1e-8 (continuity with a Lipschitz bound, not just a jump that shrinks).
  // (The constant is not uniform in u: at eps = 1e-4 across h = 0 some u near the lune's top moved by 0.09, K = 444,
  // while K -> 0.89 as eps -> 0; so the check uses eps = 1e-7 and 1e-9.)
  double k_large = 0, k_small = 0;
  for (double eps : {1e-7, 1e-9}) {
    std::mt19937_64 g(5);
    std::uniform_real_distribution<double> U(0, 1);
    double worst = 0;
    for (int i = 0; i < 4000; ++i) {
      const Vec2<double> u(U(g), U(g));
      const auto a = sample_projected_spherical_cap<double, M>(unit_geometry<double>(h_boundary - eps, ry), u);
      const auto b = sample_projected_spherical_cap<double, M>(unit_geometry<double>(h_boundary + eps, ry), u);
      ASSERT_TRUE(a.valid() && b.valid());
      worst = std::max(worst, (a.direction - b.direction).norm() / (2 * eps));
    }
    (eps > 1e-8 ? k_large : k_small) = worst;
  }
  EXPECT_LT(k_small, 5.0);
  EXPECT_NEAR(k_small, k_large, 0.01 * k_large);
}

TEST(ProjectedCapContinuity, DirectionIsLipschitzInTheHeightAcrossTheTangentBoundaryCase1To2) {
  expect_lipschitz_across<CutDiskInverse::kQuintic>(0.4, 0.4);
  expect_lipschitz_across<CutDiskInverse::kExact>(0.4, 0.4);
}

TEST(ProjectedCapContinuity, DirectionIsLipschitzInTheHeightAcrossTheCentreOnHorizonBoundaryCase2To3) {
  expect_lipschitz_across<CutDiskInverse::kQuintic>(0.0, 0.4);
  expect_lipschitz_across<CutDiskInverse::kExact>(0.0, 0.4);
}

// ---- The Lambertian estimator (Sec. 3.1) ---------------------------------------------------------------------

TEST(ProjectedCapLambertian, EstimateIsTheSameForEverySampleInCases1And2AndEqualsIndependentProjectedSolidAngle) {
  // With the exact inverse of A(X), cos / pdf = A_E + A_D for every sample (the paper's zero-variance claim).
  for (const char* name :
       {"case1", "case1-grazing", "tangent-horizon", "case2", "centre-on-horizon", "huge", "near-touching"}) {
    const ProjectedCapConfig c = config(name);
    const Real phi = reference_projected_solid_angle(c.g);
    const auto v = make_projected_cap_view(c.g);
    ASSERT_LE(v.which_case, 2) << name;
    std::mt19937_64 g(11);
    std::uniform_real_distribution<double> U(0, 1);
    Real lo = 1e300L, hi = 0;
    for (int i = 0; i < 4000; ++i) {
      const auto s = sample_projected_spherical_cap<Real, CutDiskInverse::kExact>(v, Vec2<Real>(U(g), U(g)));
      ASSERT_TRUE(s.valid());
      const Real x = std::max<Real>(0, s.direction.dot(v.z)) / s.pdf;
      lo = std::min(lo, x), hi = std::max(hi, x);
    }
    EXPECT_LT(hi / lo - 1, 1e-12L) << name;
    EXPECT_LT(std::abs(hi / phi - 1), 1e-9L) << name << ": estimate " << double(hi) << " vs " << double(phi);
  }
}

TEST(ProjectedCapQuintic, DensityFactorMatchesFiniteDifferencesOfTheQuinticWarp) {
  // The paper claims only that the quintic approximates X(A) to 4.6e-5 (Sec. 3.6); it claims nothing about the
  // density, and the density of the quintic's warp is not uniform. The kernel reports it in closed form
  // (quintic_density); check that against central differences of the warp itself: per unit left-area, the cut
  // disk's strip at x has area 2 sqrt(1 - x^2) |dx/da|, so the density is 1 / (2 sqrt(1 - x^2) |dx/da|).
  Real worst = 0;
  for (int i = 1; i < 400; ++i) {
    // At a = pi/2 the sampler's rescaled halves meet with equal slopes but opposite curvature, so a central
    // difference across that point carries an O(step) error (2.9e-8 measured), not a density error.
    if (i == 200) continue;
    const Real a = kPi<Real> * Real(i) / 400, step = 1e-6L;
    const auto x = [](Real t) { return sample_cut_unit_disk_x<Real, CutDiskInverse::kQuintic>(t); };
    const Real dxda = (x(a + step).x - x(a - step).x) / (2 * step);
    const CutDiskX<Real> c = x(a);
    const Real fd = 1 / (2 * c.half_height * std::abs(dxda));
    worst = std::max(worst, std::abs(fd / c.density() - 1));
  }
  EXPECT_LT(worst, 1e-8L);  // central differences at step 1e-6 in long double: truncation ~1e-12, rounding ~1e-13
}

TEST(ProjectedCapQuintic, DensityFactorDeviatesFromUniformByAboutHalfAPercent) {
  // A documented property of the paper's method (not a claim of the paper): the quintic's warp has density
  // factor f(a) in [f_lo, f_hi] per unit left-area instead of 1. On a 20000-point grid of a in (0, pi) the
  // measured f_hi / f_lo - 1 is 5.9e-3 (the colleague's first version of this test assumed < 2e-4, which was
  // wrong). So with the quintic the Lambertian estimate cos/pdf of Cases 1-2 is Phi / f: not zero-variance.
  // A linear grid plus a logarithmic one towards the ends of the area range (e -> 0, where the samples of the
  // disk's edge lie: the linear grid alone missed the minimum there, and a sample's estimate exceeded phi / lo).
  Real lo = 1e300L, hi = 0;
  auto visit = [&](Real e) {
    const Real f = quintic_density(kPi<Real> / 2 - e, e);
    lo = std::min(lo, f), hi = std::max(hi, f);
  };
  // The sampler evaluates the quintic at e in (0, e0] (its rescaled argument, projected_cap.h).
  for (int i = 1; i <= 20000; ++i) visit(kQuinticE0<Real> * Real(i) / 20000);
  for (int i = 0; i <= 2000; ++i) visit(std::pow(10.0L, -15 + 11 * Real(i) / 2000));
  EXPECT_GT(hi / lo - 1, 5e-3L) << double(lo) << " " << double(hi);
  EXPECT_LT(hi / lo - 1, 7e-3L) << double(lo) << " " << double(hi);
  // Away from the Case-2 threshold the kernel's samples show exactly that spread.
  const ProjectedCapConfig c = config("case2");
  const auto v = make_projected_cap_view(c.g);
  const auto bands = projected_cap_bands<CutDiskInverse::kQuintic>(c.g);
  const Real phi = reference_projected_solid_angle(c.g);
  std::mt19937_64 g(12);
  std::uniform_real_distribution<double> U(0, 1);
  Real elo = 1e300L, ehi = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec2<Real> u(U(g), U(g));
    bool in_band = false;
    for (const auto& [a, b] : bands) in_band = in_band || (u[0] >= a - 1e-9L && u[0] <= b + 1e-9L);
    if (in_band) continue;
    const auto s = sample_projected_spherical_cap<Real>(v, u);
    ASSERT_TRUE(s.valid());
    const Real x = std::max<Real>(0, s.direction.dot(v.z)) / s.pdf;
    elo = std::min(elo, x), ehi = std::max(ehi, x);
  }
  // A sample's estimate is Phi kappa (L* / L) / f: kappa from the rescaled argument (f is per unit of it), L* / L
  // per piece the quintic's left-area range over the exact one (the ranges end where the quintic reaches the cuts,
  // projected_cap.h).
  const Real r_e = kQuinticKappa<Real> * v.quintic_area_e_unit / v.area_e_unit;
  const Real r_d = kQuinticKappa<Real> * v.quintic_area_d / v.area_d;
  EXPECT_GE(elo, phi * std::min(r_e, r_d) / hi * (1 - 1e-9L));
  EXPECT_LE(ehi, phi * std::max(r_e, r_d) / lo * (1 + 1e-9L));
  EXPECT_LT(std::abs(r_e - 1) + std::abs(r_d - 1), 1e-3L);
  EXPECT_GT(ehi / elo - 1, 2e-3L);  // the samples do spread (not constant)
}

// The geometry of the worst case that the search pdf-warp-sphere-projected-cap found with the published quintic
// (pdf x area element 2.006 at d/r = 102.3, centre 0.068 deg up, u = (0.254194, 0.889313)): there the published
// fit's two Case-2 pieces overlapped at the seam w_x = t_x (the mirrored disk reached 1.4e-7 beyond it). With the
// ranges matched to the cuts they meet exactly: the warp is continuous across u0 = tau and one piece reaches
// each direction, so pdf x area element = 1.
TEST(ProjectedCapQuintic, Case2PiecesMeetExactlyAtTheSeam) {
  const long double d = std::pow(10.0L, 2.00985L), e = 0.0684289L * kPi<Real> / 180;
  const SphereLightGeometry<Real> g{ShadingPoint<Real>{Vec3L::Zero(), Vec3L(0, 0, 1)},
                                    SphereLight<Real>{Vec3L(d * std::cos(e), 0, d * std::sin(e)), 1}};
  const auto v = make_projected_cap_view(g);
  ASSERT_EQ(v.which_case, 2);
  auto w = [&](Real a, Real b) { return sample_projected_spherical_cap<Real>(v, Vec2<Real>(a, b)).direction; };
  // Continuity at the threshold: the ellipse piece ends where the mirrored disk begins.
  for (Real u1 : {0.1L, 0.5L, 0.889313L}) {
    const Vec3L before = v.to_local(w(v.tau * (1 - 1e-15L), u1)), after = v.to_local(w(v.tau, u1));
    EXPECT_NEAR(before.x(), v.t_x, 1e-12L) << u1;
    EXPECT_NEAR(after.x(), v.t_x, 1e-12L) << u1;
    EXPECT_LT((before - after).norm(), 1e-12L) << u1;
  }
  // At the search's worst case: one piece, pdf x area element = 1.
  const Vec2<Real> u(0.254194L, 0.889313L);
  const auto s = sample_projected_spherical_cap<Real>(v, u);
  ASSERT_TRUE(s.valid());
  EXPECT_GE(v.to_local(s.direction).x(), v.t_x);  // the mirrored disk stays on its side of the seam
  const Real step = 1e-7L;
  const Vec3L du0 = (w(u[0] + step, u[1]) - w(u[0] - step, u[1])) / (2 * step);
  const Vec3L du1 = (w(u[0], u[1] + step) - w(u[0], u[1] - step)) / (2 * step);
  EXPECT_LT(std::abs(s.pdf * du0.cross(du1).norm() - 1), 1e-6L);
  Vec2<Real> back;
  ASSERT_TRUE(invert_projected_spherical_cap<Real>(v, s.direction, back));
  EXPECT_LT((back - u).cwiseAbs().maxCoeff(), 1e-12L);
}

// A sample within a few epsilons of Case 2's seam (u0 near tau) has a positive pdf(direction) and a preimage: the
// pieces' left-areas round, and such a direction can miss both pieces' ranges by an ulp of pi.
template <class T, CutDiskInverse M> int seam_samples_without_pdf(const SphereLightGeometry<Real>& gl) {
  const SphereLightGeometry<T> g{
      ShadingPoint<T>{gl.shading.position.template cast<T>(), gl.shading.normal.template cast<T>()},
      SphereLight<T>{gl.light.center.template cast<T>(), T(gl.light.radius)}};
  const auto v = make_projected_cap_view(g);
  EXPECT_EQ(v.which_case, 2);
  const T eps = std::numeric_limits<T>::epsilon();
  int without = 0;
  for (int m = -4; m <= 4; ++m)
    for (int j = 0; j < 64; ++j) {
      const Vec2<T> u(v.tau * (T(1) + T(m) * eps), (T(j) + T(0.5)) / T(64));
      const auto s = sample_projected_spherical_cap<T, M>(v, u);
      if (!s.valid()) continue;
      Vec2<T> back;
      if (!(pdf_projected_spherical_cap<T, M>(v, s.direction) > T(0)) ||
          !invert_projected_spherical_cap<T, M>(v, s.direction, back))
        ++without;
    }
  return without;
}
TEST(ProjectedCapPieces, SamplesOnTheSeamHaveTheirPdfAndAPreimageInEveryScalarType) {
  const Vec3L up(0, 0, 1);
  for (const auto& [center, radius] : {std::pair{Vec3L(2, 0, 0.5L), 1.0L}, std::pair{Vec3L(5, 0, 0.004L), 1e-2L},
                                       std::pair{Vec3L(0, 50, 60), 75.0L}}) {
    const SphereLightGeometry<Real> g{ShadingPoint<Real>{Vec3L::Zero(), up}, SphereLight<Real>{center, radius}};
    EXPECT_EQ((seam_samples_without_pdf<float, CutDiskInverse::kQuintic>(g)), 0) << radius;
    EXPECT_EQ((seam_samples_without_pdf<float, CutDiskInverse::kExact>(g)), 0) << radius;
    EXPECT_EQ((seam_samples_without_pdf<double, CutDiskInverse::kQuintic>(g)), 0) << radius;
    EXPECT_EQ((seam_samples_without_pdf<double, CutDiskInverse::kExact>(g)), 0) << radius;
    EXPECT_EQ((seam_samples_without_pdf<long double, CutDiskInverse::kQuintic>(g)), 0) << radius;
    EXPECT_EQ((seam_samples_without_pdf<long double, CutDiskInverse::kExact>(g)), 0) << radius;
  }
}

// A sample on an edge of its chord (u1 = 0 or 1) lies on the light's boundary, where its own piece can refuse it by
// rounding. Its pdf and preimage are then its own or none, never another piece's: the disk piece's left-area of a
// direction beyond the seam is its mirror image's, whose preimage maps to a direction up to a light's width away.
template <class T, CutDiskInverse M> Real edge_round_trip_over_tolerance(const SphereLightGeometry<Real>& gl) {
  const SphereLightGeometry<T> g{
      ShadingPoint<T>{gl.shading.position.template cast<T>(), gl.shading.normal.template cast<T>()},
      SphereLight<T>{gl.light.center.template cast<T>(), T(gl.light.radius)}};
  const auto v = make_projected_cap_view(g);
  Real worst = 0;
  if (!v.valid()) return worst;
  for (int j = 0; j < 64; ++j)
    for (T u1 : {T(0), T(1)}) {
      const auto s = sample_projected_spherical_cap<T, M>(v, Vec2<T>((T(j) + T(0.5)) / T(64), u1));
      Vec2<T> back;
      if (!s.valid() || !invert_projected_spherical_cap<T, M>(v, s.direction, back)) continue;
      const auto again = sample_projected_spherical_cap<T, M>(v, back);
      if (!again.valid()) return std::numeric_limits<Real>::infinity();
      worst = std::max(worst, (to_long(again.direction) - to_long(s.direction)).norm());
    }
  // Against a thousandth of the light's angular radius plus T's rounding: a preimage of the direction itself maps
  // back within rounding.
  const Real d = (gl.light.center - gl.shading.position).norm();
  return worst /
         (1e-3L * std::asin(std::min<Real>(1, gl.light.radius / d)) + 64 * Real(std::numeric_limits<T>::epsilon()));
}
// Double and long double: in float the inverse of a tiny light is itself only good to a few percent of its size
// (tiny-straddling: 1.5e-4 rad of 2e-3, with or without the mirror), as large as the mirror's error there.
TEST(ProjectedCapPieces, ASampleOnAnEdgeOfItsChordHasItsOwnPreimageOrNone) {
  for (const ProjectedCapConfig& c : projected_cap_configs()) {
    EXPECT_LE((edge_round_trip_over_tolerance<double, CutDiskInverse::kQuintic>(c.g)), 1) << c.name;
    EXPECT_LE((edge_round_trip_over_tolerance<double, CutDiskInverse::kExact>(c.g)), 1) << c.name;
    EXPECT_LE((edge_round_trip_over_tolerance<long double, CutDiskInverse::kQuintic>(c.g)), 1) << c.name;
    EXPECT_LE((edge_round_trip_over_tolerance<long double, CutDiskInverse::kExact>(c.g)), 1) << c.name;
  }
}

// u0 = 0 reaches the cut, i.e. the top of the Case-3 lune, which lies on the light's boundary, in every precision,
// and u0 -> 1 reaches the left end of the disk. With the published ranges the quintic's abscissa at left-area A_D
// misses -t_x and the lune's top is never sampled (E[cos/pdf; hit] 1.1e-4 low in case3).
template <class T> void expect_case3_lune_top_reached(const char* name) {
  const ProjectedCapConfig c = config(name);
  const SphereLightGeometry<T> g{
      ShadingPoint<T>{c.g.shading.position.template cast<T>(), c.g.shading.normal.template cast<T>()},
      SphereLight<T>{c.g.light.center.template cast<T>(), T(c.g.light.radius)}};
  const auto v = make_projected_cap_view(g);
  ASSERT_EQ(v.which_case, 3) << name;
  const auto s = sample_projected_spherical_cap<T>(v, Vec2<T>(T(0), T(0.5)));
  ASSERT_TRUE(s.valid()) << name;
  const SphereView<Real> sv = make_sphere_view(c.g);
  const Vec3L w = to_long(s.direction).normalized();
  // The angle from the light's axis equals theta_max (on the boundary), to the precision of T.
  const Real angle = std::atan2(w.cross(sv.frame.z).norm(), w.dot(sv.frame.z));
  const Real theta_max = std::asin(std::sqrt(sv.sin2_theta_max));
  EXPECT_NEAR(angle / theta_max, 1, 64 * Real(std::numeric_limits<T>::epsilon()) / (1 - std::cos(theta_max)))
      << name << " " << typeid(T).name();
  // And it is the highest point of the lune: local z = c_z + r_z.
  EXPECT_NEAR(Real(v.to_local(s.direction).z()), Real(v.top), 64 * Real(std::numeric_limits<T>::epsilon())) << name;
}
TEST(ProjectedCapQuintic, Case3SamplesReachTheTopOfTheLuneExactly) {
  for (const char* name : {"case3", "case3-fig9", "case3-sliver", "near-touching-case3"}) {
    expect_case3_lune_top_reached<float>(name);
    expect_case3_lune_top_reached<double>(name);
    expect_case3_lune_top_reached<long double>(name);
  }
}

TEST(ProjectedCapFrame, OverheadLightGivesTheSameSamplesInDoubleAndLongDouble) {
  // The worst case of precision-sphere-projected-cap-double-angle (0.65 rad): a light at elevation 90 deg, whose
  // long double frame axis x came out (-0.225, 0, 0.974), not horizontal. The frame must be horizontal and the
  // samples must agree between double and long double on the same (rounded) input.
  for (long double log_d : {0.216119L, 1.0L, 3.0L}) {
    const long double d = std::pow(10.0L, log_d), e = 90 * kPi<Real> / 180;
    const Vec3L c(d * std::cos(e), 0, d * std::sin(e));
    const SphereLightGeometry<double> gd{ShadingPoint<double>{Vec3<double>::Zero(), Vec3<double>(0, 0, 1)},
                                         SphereLight<double>{c.cast<double>(), 1}};
    const SphereLightGeometry<Real> gl{ShadingPoint<Real>{Vec3L::Zero(), Vec3L(0, 0, 1)},
                                       SphereLight<Real>{gd.light.center.cast<Real>(), 1}};  // same rounded input
    const auto vl = make_projected_cap_view(gl);
    const auto vd = make_projected_cap_view(gd);
    EXPECT_EQ(vl.x.z(), 0.0L) << double(vl.x.x()) << " " << double(vl.x.z());
    EXPECT_EQ(vd.x.z(), 0.0);
    for (double u0 : {1e-6, 0.3, 0.999999})
      for (double u1 : {1e-6, 0.7}) {
        const auto a = sample_projected_spherical_cap<double>(vd, Vec2<double>(u0, u1));
        const auto b = sample_projected_spherical_cap<Real>(vl, Vec2<Real>(u0, u1));
        ASSERT_TRUE(a.valid() && b.valid());
        EXPECT_LT(double((to_long(a.direction) - b.direction).norm()), 1e-12)
            << double(log_d) << " " << u0 << " " << u1;
      }
  }
}

// ---- float accuracy of the sampling path --------------------------------------------------------------------

// Largest |pdf_float / pdf_long_double - 1| of the samples at the same (float) primary samples, and the same with
// w_z recomputed naively as sqrt(1 - w_x^2 - w_y^2) from the float sample's own local w_x, w_y (the lift that
// disk_to_local's sum-of-squares heights avoid).
struct FloatPdfError {
  double kernel = 0, naive = 0, u0 = 0, u1 = 0, wz = 0;
};
FloatPdfError float_sample_pdf_error(const ProjectedCapConfig& c, int n) {
  const SphereLightGeometry<float> gf{
      ShadingPoint<float>{c.g.shading.position.cast<float>(), c.g.shading.normal.cast<float>()},
      SphereLight<float>{c.g.light.center.cast<float>(), float(c.g.light.radius)}};
  const SphereLightGeometry<Real> gl{
      ShadingPoint<Real>{gf.shading.position.cast<Real>(), gf.shading.normal.cast<Real>()},
      SphereLight<Real>{gf.light.center.cast<Real>(), Real(gf.light.radius)}};  // the same rounded input
  const auto vf = make_projected_cap_view(gf);
  const auto vl = make_projected_cap_view(gl);
  FloatPdfError e;
  if (!vf.valid() || !vl.valid()) return e;
  std::mt19937_64 g(7);
  std::uniform_real_distribution<float> U(0, 1);
  for (int i = 0; i < n; ++i) {
    const Vec2<float> u(U(g), U(g));
    const auto a = sample_projected_spherical_cap<float>(vf, u);
    const auto b = sample_projected_spherical_cap<Real>(vl, Vec2<Real>(u[0], u[1]));
    if (!a.valid() || !b.valid()) continue;
    if (double(std::abs(Real(a.pdf) / b.pdf - 1)) > e.kernel) {
      e.u0 = u[0];
      e.u1 = u[1];
      const Vec3<float> wl = vf.to_local(a.direction);
      e.wz = wl.z();
    }
    e.kernel = std::max(e.kernel, double(std::abs(Real(a.pdf) / b.pdf - 1)));
    const Vec3<float> w = vf.to_local(a.direction);
    const float naive_z = std::sqrt(std::max(0.0f, 1 - (w.x() * w.x() + w.y() * w.y())));
    e.naive = std::max(e.naive, double(std::abs(Real(a.pdf) / Real(w.z()) * Real(naive_z) / b.pdf - 1)));
  }
  return e;
}

TEST(ProjectedCapFloat, SamplePdfsNearTheHorizonKeepTheirDigits) {
  // A float sample's pdf against the long double sample's at the same primary sample. Even an exact float warp
  // differs by the float sample's position error (a few eps in the left-area) times the log-derivative of the
  // density, which is large near the horizon (w_z -> 0): for "huge" ~3e-6 at w_z = 0.044 (estimated from the
  // intermediate values; measured 5.3e-6). Measured (20000 samples per configuration): at most 1.75e-5
  // (near-touching-case3) and 1.05e-5 = 176 eps_float (near-touching) in the others. Bound: 256 eps_float =
  // 3.1e-5, in every configuration. With only the heights of disk_to_local written without cancellation (not the
  // left-areas, right-areas and r_y^2 - h^2) it is 1.7e-4 (tangent-horizon), 2.9e-4 (case2), 3.2e-4 (huge); the
  // naive lift of the same samples gives up to 1 (case3-fig9) and 3.4 (tiny-straddling: w_x ~ 1 - 1e-6 leaves w_z
  // no digit).
  // near-touching-case3 (a Case-3 cap of 87 deg): 1.75e-5 with w_x^2 = d_x^2 + (1 - s_y^2) d_y^2 + (1 - k^2) d_z^2
  // (projected_cap.h header), 4.0e-5 with Case 3's w_x = sqrt(1 - w_y^2 - w_z^2). near-touching (d = 1.001 r):
  // 1.05e-5, cos(theta_max) = sqrt(1 - (r/d)^2) itself is that far off; inherent for general positions, where d is
  // only known to eps d (writing it sqrt((d - r)(d + r)) / d fixes this axis-aligned configuration but makes the
  // recorded worst case precision-sphere-solid-angle-float-angle 8% worse, so sphere.h keeps 1 - (r/d)^2).
  const double eps = std::numeric_limits<float>::epsilon();
  double worst_naive = 0;
  for (const ProjectedCapConfig& c : projected_cap_configs()) {
    const FloatPdfError e = float_sample_pdf_error(c, 20000);
    std::printf("%-22s float pdf error %.3g (naive lift %.3g) at u = (%.9g, %.9g), w_z %.3g\n", c.name, e.kernel,
                e.naive, e.u0, e.u1, e.wz);
    worst_naive = std::max(worst_naive, e.naive);
    EXPECT_LE(e.kernel, 256 * eps) << c.name;
  }
  EXPECT_GT(worst_naive, 1e4 * eps);  // the check sees the naive lift's error
}

// Float on "tiny": on a light of 2e-3 rad, float's directions are 3e-5 of its radius apart, so its edge is rounded
// that coarsely and a few samples land where the float pdf is 0 (27 and 30 in 1e6, quintic and exact inverse),
// balanced by a band just beyond the edge where it is positive (the rim the battery integrates:
// docs/derivations/battery-quadrature.md). In double none does.
template <class T> SphereLightGeometry<T> rounded_to(const SphereLightGeometry<Real>& g) {
  return {ShadingPoint<T>{g.shading.position.cast<T>(), g.shading.normal.cast<T>()},
          SphereLight<T>{g.light.center.cast<T>(), T(g.light.radius)}};
}
template <template <class> class K> void count_samples_where_the_pdf_is_zero(int* in_float, int* in_double) {
  const SphereLightGeometry<Real>* g = nullptr;
  const std::vector<ProjectedCapConfig> configs = projected_cap_configs();
  for (const ProjectedCapConfig& c : configs)
    if (std::string(c.name) == "tiny") g = &c.g;
  ASSERT_TRUE(g);
  const auto vf = K<float>::view(rounded_to<float>(*g));
  const auto vd = K<double>::view(rounded_to<double>(*g));
  std::mt19937_64 r(1);
  std::uniform_real_distribution<double> u(0, 1);
  *in_float = *in_double = 0;
  for (int i = 0; i < 1000000; ++i) {
    const double u0 = u(r), u1 = u(r);
    const DirectionSample<float> a = K<float>::sample(vf, Vec2<float>(float(u0), float(u1)));
    const DirectionSample<double> b = K<double>::sample(vd, Vec2<double>(u0, u1));
    *in_float += a.valid() && K<float>::pdf(vf, a.direction) == 0;
    *in_double += b.valid() && K<double>::pdf(vd, b.direction) == 0;
  }
}

TEST(ProjectedCapFloat, OnATwoMilliradianLightAFewSamplesLandWhereTheFloatPdfIsZero) {
  int f = 0, d = 0;
  count_samples_where_the_pdf_is_zero<SphereProjectedCap>(&f, &d);
  EXPECT_GT(f, 5);
  EXPECT_LT(f, 100);
  EXPECT_EQ(d, 0);
  count_samples_where_the_pdf_is_zero<SphereProjectedCapExact>(&f, &d);
  EXPECT_GT(f, 5);
  EXPECT_LT(f, 100);
  EXPECT_EQ(d, 0);
}

TEST(ProjectedCapFrame, FrameIsHorizontalForALightOverheadUpToRoundingWithATiltedNormal) {
  // Normal and direction to the centre agree to rounding (d = r (1 + 2e-16), a cap of 90 deg), the normal not
  // axis-aligned. Two Gram-Schmidt passes leave x parallel to n (x.z = 1, y = 0) and a sample at n.w = -1;
  // x = n x (w_d x n) is horizontal to rounding.
  const SphereLightGeometry<double> g{
      ShadingPoint<double>{Vec3<double>(-1.2669652949151753, 3.4659473398571494, 1.1334826474575876),
                           Vec3<double>(0.26696529491517529, 0.53393058983035058, -0.13348264745758764)},
      SphereLight<double>{Vec3<double>(-1, 3.9998779296875, 1), 0.6116943359375}};
  const auto v = make_projected_cap_view(g);
  ASSERT_TRUE(v.valid());
  const double e = std::numeric_limits<double>::epsilon();
  EXPECT_LE(std::abs(v.x.dot(v.z)), 4 * e);
  EXPECT_NEAR(v.y.norm(), 1, 4 * e);
  int valid = 0;
  for (double u0 : {0.0, 1e-6, 0.3, 0.7, 1.0})
    for (double u1 : {0.0, 0.25, 0.5, 0.999}) {
      const auto s = sample_projected_spherical_cap<double>(v, Vec2<double>(u0, u1));
      if (!s.valid()) continue;
      ++valid;
      EXPECT_GE(s.direction.dot(v.z), -4 * e) << u0 << " " << u1;
    }
  EXPECT_GE(valid, 16);
}

// ---- Scale and the Case-3 lift ------------------------------------------------------------------------------

TEST(ProjectedCapScale, SubnormalAndHugeLightsSampleExactlyLikeTheSameLightAtUnitScale) {
  // The sampler depends on the light only through w_d and r / |c - x|, both unchanged when c - x and r are
  // multiplied by a power of two. A light at 2^-1074 (c - x = (1, 3, -1) denorm_min, where |c - x| computed at that
  // scale rounds to 3 denorm_min, |w_d| = 1.106, A_E + A_D 40 % off and all 15 samples of each normal below differ)
  // and one at 2^900 (where |c - x|^2 would overflow) must give bit-identical views, samples and densities to the
  // unit-scale light: every coordinate below is an integer times the scale, so c - x is exact at each scale, and the
  // view is built from (c - x) 2^-e, r 2^-e (unit_scale_geometry) in all three.
  const Vec3<double> c0(0, 3, 3), x0(-1, 0, 4);
  const Vec3<double> wd = (c0 - x0).normalized(), side = Vec3<double>(1, 0, 1).normalized();  // side . wd = 0
  int cases_seen[4] = {0, 0, 0, 0};
  for (double h : {0.9, 0.3, 0.0, -0.2, -0.55}) {  // r_y = 2 / sqrt(11) = 0.603: Cases 1, 2, 2, 3, 3
    const Vec3<double> n = wd * h + side * std::sqrt(1 - h * h);
    const SphereLightGeometry<double> unit{ShadingPoint<double>{x0, n}, SphereLight<double>{c0, 2}};
    const ProjectedCapView<double> vu = make_projected_cap_view(unit);
    ASSERT_TRUE(vu.valid()) << h;
    ++cases_seen[vu.which_case];
    for (int exponent : {-1074, -1000, 900}) {
      const double k = std::ldexp(1.0, exponent);
      const SphereLightGeometry<double> g{ShadingPoint<double>{x0 * k, n}, SphereLight<double>{c0 * k, 2 * k}};
      const ProjectedCapView<double> v = make_projected_cap_view(g);
      ASSERT_TRUE(v.valid()) << h << " " << exponent;
      EXPECT_EQ(v.which_case, vu.which_case);
      EXPECT_EQ(v.sphere.frame.z, vu.sphere.frame.z) << h << " " << exponent;
      EXPECT_EQ(v.total, vu.total) << h << " " << exponent;
      for (double u0 : {0.0, 1e-9, 0.3, 0.7, 1 - 1e-9})
        for (double u1 : {1e-6, 0.5, 0.9}) {
          const auto a = sample_projected_spherical_cap<double>(v, Vec2<double>(u0, u1));
          const auto b = sample_projected_spherical_cap<double>(vu, Vec2<double>(u0, u1));
          ASSERT_EQ(a.valid(), b.valid());
          if (!a.valid()) continue;
          EXPECT_EQ(a.direction, b.direction) << h << " " << exponent << " " << u0 << " " << u1;
          EXPECT_EQ(a.pdf, b.pdf) << h << " " << exponent << " " << u0 << " " << u1;
          EXPECT_EQ(pdf_projected_spherical_cap<double>(v, a.direction),
                    pdf_projected_spherical_cap<double>(vu, a.direction));
        }
    }
  }
  EXPECT_GT(cases_seen[1] * cases_seen[2] * cases_seen[3], 0);
}

// A light overhead to far below rounding, the horizontal parts of w_d and n subnormal. x taken as the subnormal
// horizontal part over its rounded norm is (1, 1, 0), of length sqrt 2, and puts every sample off the axis 0.11 rad
// outside the cap (0.41 rad from the axis against theta_max 0.298).
TEST(ProjectedCapScale, ALightOverheadToASubnormalHorizontalPartIsSampledInsideItsCap) {
  const double e = std::numeric_limits<double>::epsilon();
  SphereLightGeometry<double> g;
  g.light.center = Vec3<double>(1.0000000031710769e-30, 1.0000000031710769e-30, 0.5);
  g.light.radius = 3.0454106285624994e+287;
  g.shading.position = Vec3<double>(2.0000000063421537e-30, 2.0000000063421537e-30, -1.0373429953541013e+288);
  g.shading.normal = Vec3<double>(-1.0000000063421537e-60, -1.0000000063421537e-60, 1.0373429986435956e+258);
  const ProjectedCapView<double> v = make_projected_cap_view(g);
  ASSERT_TRUE(v.valid());
  EXPECT_NEAR(v.x.norm(), 1, 4 * e);
  const long double theta_max = std::asin(3.0454106285624994e+287L / 1.0373429953541013e+288L);
  for (double u0 : {0.0, 0.3, 0.7, 1.0})
    for (double u1 : {0.0, 0.25, 0.5, 0.999}) {
      const auto s = sample_projected_spherical_cap<double>(v, Vec2<double>(u0, u1));
      ASSERT_TRUE(s.valid()) << u0 << " " << u1;
      // the cap's axis is +z to 1e-318
      const long double angle =
          std::acos(std::min(1.0L, (long double)s.direction.z() / s.direction.cast<long double>().norm()));
      // samples at u0 = 0, 1 lie on the rim: a few eps of the kernel's rounding, times 1 / sin(theta_max) = 3.4 in acos
      EXPECT_LE(angle, theta_max + 1e-12L) << u0 << " " << u1;
    }
}

TEST(ProjectedCapCase3, SamplePdfsKeepTheirDigitsNearTheLunesFlatSide) {
  // A cap of 90 deg - 0.02 deg (r / d = 1 - 2^-24, v = 3.45e-4; r^2 is exact in double, so the double and long
  // double views agree to rounding) with its centre just below the horizon. Samples near u0 = 0 lie next to the
  // lune's flat side, w_x ~ v, where the lift 1 - w_y^2 - w_z^2 loses eps / w_x^2 = 1.9e-9 of the density (max over
  // the grid below: 9.2e-10 exact, 1.9e-9 quintic; the harness allows 16 eps). With the lift as a sum of
  // squares (projected_cap.h, header) every factor of the density is a product or quotient of quantities known to
  // a few eps, without amplification: a few tens of eps at most, bound kTolUlps = 64 eps (measured: at most
  // 9.3 eps), for the sample's pdf against long double at the same u and against pdf() of its own direction (the
  // density is smooth there: its log-gradient times the direction's few-eps rounding is below an eps).
  const double eps = std::numeric_limits<double>::epsilon();
  for (double h : {-1e-200, -1e-17, -1e-9}) {
    const SphereLightGeometry<double> g{ShadingPoint<double>{Vec3<double>::Zero(), Vec3<double>(0, 0, 1)},
                                        SphereLight<double>{Vec3<double>(1, 0, h), 1 - std::ldexp(1.0, -24)}};
    const SphereLightGeometry<Real> gl{ShadingPoint<Real>{Vec3L::Zero(), Vec3L(0, 0, 1)},
                                       SphereLight<Real>{g.light.center.cast<Real>(), Real(g.light.radius)}};
    const auto v = make_projected_cap_view(g);
    const auto vl = make_projected_cap_view(gl);
    ASSERT_EQ(v.which_case, 3);
    auto check = [&]<CutDiskInverse M>() {
      for (double u0 : {1e-14, 1e-12, 5.8207660913467407e-11, 1e-9, 1e-7, 1e-5, 1e-3, 0.1, 0.5, 0.9})
        for (double u1 : {1e-9, 0.01, 0.27, 0.5, 0.999999}) {
          const auto a = sample_projected_spherical_cap<double, M>(v, Vec2<double>(u0, u1));
          const auto b = sample_projected_spherical_cap<Real, M>(vl, Vec2<Real>(u0, u1));
          ASSERT_TRUE(a.valid() && b.valid()) << h << " " << u0 << " " << u1;
          EXPECT_LE(double(std::abs(Real(a.pdf) / b.pdf - 1)), 64 * eps) << h << " " << u0 << " " << u1;
          EXPECT_LE(std::abs(pdf_projected_spherical_cap<double, M>(v, a.direction) / a.pdf - 1), 64 * eps)
              << h << " " << u0 << " " << u1;
        }
    };
    check.template operator()<CutDiskInverse::kExact>();
    check.template operator()<CutDiskInverse::kQuintic>();
  }
}

TEST(ProjectedCapInverse, PdfGivesACase2DiskPieceBelowALeftAreaUlpItsOwnDensity) {
  // An overhead light touching x (h = r_y = 1 - 5.7e-14 up to 1e-16), Case 2 with a disk piece of area
  // A_D = 6.4e-16 (half-cap of 9.9e-6 rad around the local x axis), less than two ulps of pi in left-area, and
  // tau = 1 - 2^-53 (the quintic's disk piece then has 0.55 x the ellipse's density: its u0 share is quantised).
  // pdf() compares right-areas here: comparing the ellipse piece's left-areas near pi gives the ellipse's density
  // to 29 of the 50 directions below (theta in [0.5, 1) of the piece's radius, the outer part). Every one must get
  // the disk piece's density, the sampler's.
  const SphereLightGeometry<double> g{
      ShadingPoint<double>{Vec3<double>(-8.9672072669915119e+26, 8.7416627936820459e+26, -1.4445920849195454e+26),
                           Vec3<double>(-3.1900322795701238e-07, -0.70833782255786737, -0.70587359288606144)},
      SphereLight<double>{Vec3<double>(-8.9672072669915119e+26, 7.5697645773807265e+26, -2.6124131383234877e+26),
                          1.6544338736085515e+26}};
  const auto v = make_projected_cap_view(g);
  ASSERT_EQ(v.which_case, 2);
  ASSERT_LT(v.area_d, 2 * (kPi<double> - std::nextafter(kPi<double>, 0.0)));
  const auto s = sample_projected_spherical_cap<double>(v, Vec2<double>(std::nextafter(1.0, 0.0), 0.5));  // disk piece
  ASSERT_TRUE(s.valid());
  const double disk = s.pdf / v.to_local(s.direction).z();  // per projected solid angle, constant on the piece
  const double theta_t = std::acos(v.t_x);
  for (int i = 0; i < 50; ++i) {
    const double th = (0.5 + 0.01 * i) * theta_t, y = std::sin(th) / std::sqrt(2.0);
    const Vec3<double> w = v.to_world(Vec3<double>(std::cos(th), y, y));
    const double p = pdf_projected_spherical_cap<double>(v, w) / v.to_local(w.normalized()).z();
    // The quintic's density factor varies by ~g' e <= 1e-15 over a piece of left-areas e <= 6.4e-16, the
    // ellipse's density is 1.8 x the disk piece's: 1e-6 separates them with room for the direction's rounding.
    EXPECT_NEAR(p / disk, 1, 1e-6) << i;
  }
}

TEST(ProjectedCapReference, RingQuadratureMatchesClosedFormsInCase1) {
  // Entirely above the horizon the projected solid angle of a cap is pi sin^2(theta_max) cos(angle to the
  // normal) (the ellipse's area pi r_x r_y): an exact check of the independent ring quadrature.
  for (const char* name : {"case1", "case1-grazing", "near-touching", "tiny"}) {
    const ProjectedCapConfig c = config(name);
    const SphereView<Real> s = make_sphere_view(c.g);
    const Real expected = kPi<Real> * s.sin2_theta_max * s.normal.dot(s.frame.z);
    EXPECT_LT(std::abs(reference_projected_solid_angle(c.g) / expected - 1), 1e-13L) << name;
  }
  // Overhead light, half-angle 90 deg in the limit: the whole hemisphere projects to the unit disk, area pi.
  const SphereLightGeometry<Real> big{ShadingPoint<Real>{Vec3L::Zero(), Vec3L(0, 0, 1)},
                                      SphereLight<Real>{Vec3L(0, 0, 1e6L), 1e6L - 1e-3L}};
  EXPECT_NEAR(double(reference_projected_solid_angle(big)), std::numbers::pi, 1e-6);
}

// ---- Round trip and inverse -------------------------------------------------------------------------------------

TEST(ProjectedCapInverse, RoundTripRecoversUTo1e9InDoubleAwayFromKinks) {
  for (const char* name : {"case1", "case1-grazing", "tangent-horizon", "case2", "centre-on-horizon", "case3",
                           "case3-fig9", "case3-sliver", "near-touching", "huge"}) {
    const ProjectedCapConfig c = config(name);
    const RoundTrip q = round_trip<CutDiskInverse::kQuintic>(c.g, 20000, 3);
    const RoundTrip e = round_trip<CutDiskInverse::kExact>(c.g, 20000, 3);
    EXPECT_LT(q.worst, 1e-9) << name << " quintic at u = (" << q.at[0] << ", " << q.at[1] << ")";
    EXPECT_LT(e.worst, 1e-9) << name << " exact at u = (" << e.at[0] << ", " << e.at[1] << ")";
    EXPECT_EQ(q.failures + e.failures, 0) << name;
    EXPECT_GT(q.checked, 15000) << name;
  }
}

TEST(ProjectedCapInverse, KsOnRoundTrippedU0ByExactInverseDoesNotResolveTheQuinticAt1e5Samples) {
  // u0' = exact inverse of the quintic's sample. Its CDF differs from uniform by D_true (computed on a grid);
  // KS needs about n* = (1.63 / D_true)^2 samples to reject at 1%. Below n* it must not reject (false-positive
  // control at a fixed seed); slow_projected_cap.cpp checks that it does reject well above n*.
  const ProjectedCapConfig c = config("case3");
  const Real d_true = round_trip_u0_deviation(c.g, 100000);
  EXPECT_GT(d_true, 4e-4L);  // measured 4.47e-4: n* = 1.3e7
  EXPECT_LT(d_true, 5e-4L);
  const KsResult k = ks_round_trip_u0(c.g, 100000, 21);
  EXPECT_GT(k.p_value, 0.01) << "D = " << k.d;
}

// ---- Degenerate input ------------------------------------------------------------------------------------------

template <class T> void expect_no_sample(const SphereLightGeometry<T>& g, NoSample why) {
  const auto s = sample_projected_spherical_cap<T>(g, Vec2<T>(T(0.3), T(0.6)));
  EXPECT_FALSE(s.valid());
  EXPECT_EQ(s.reason, why) << to_string(s.reason);
  EXPECT_EQ(s.pdf, T(0));
  EXPECT_TRUE(all_finite(s.direction));
  const T p = pdf_projected_spherical_cap<T>(g, Vec3<T>(T(0.6), T(0), T(0.8)));
  EXPECT_EQ(p, T(0));
}

template <class T> void degenerate_suite() {
  const T nan = std::numeric_limits<T>::quiet_NaN(), inf = std::numeric_limits<T>::infinity();
  using G = SphereLightGeometry<T>;
  using S = ShadingPoint<T>;
  using L = SphereLight<T>;
  const Vec3<T> o = Vec3<T>::Zero(), up(0, 0, 1);
  expect_no_sample(G{S{o, up}, L{Vec3<T>(0, 1, -3), T(1)}}, NoSample::kBelowHorizon);  // Case 4
  expect_no_sample(G{S{o, up}, L{Vec3<T>(nan, 0, 3), T(1)}}, NoSample::kNonFinite);
  expect_no_sample(G{S{o, up}, L{Vec3<T>(0, 0, 3), inf}}, NoSample::kNonFinite);
  expect_no_sample(G{S{o, Vec3<T>::Zero()}, L{Vec3<T>(0, 0, 3), T(1)}}, NoSample::kBadNormal);
  expect_no_sample(G{S{o, up}, L{Vec3<T>(0, 0, 3), T(0)}}, NoSample::kZeroSize);
  expect_no_sample(G{S{o, up}, L{Vec3<T>(0, 0, 3), T(-1)}}, NoSample::kNegativeSize);
  expect_no_sample(G{S{o, up}, L{Vec3<T>(0, 0, 0.5), T(1)}}, NoSample::kInsideLight);
  // Non-finite random numbers.
  const auto s = sample_projected_spherical_cap<T>(G{S{o, up}, L{Vec3<T>(0, 0, 3), T(1)}}, Vec2<T>(nan, T(0.5)));
  EXPECT_EQ(s.reason, NoSample::kNonFinite);
  // Extreme but valid input gives a finite sample or a reason, never NaN: sweep scales and the u corners.
  for (T scale : {T(1e-30), T(1e-6), T(1), T(1e6), T(1e30)})
    for (T h : {T(-0.999), T(-0.3), T(0), T(1e-7), T(0.3), T(1)})
      for (T u0 : {T(0), T(0.5), T(1)})
        for (T u1 : {T(0), T(1)}) {
          const T d = T(1.5) * scale;
          const Vec3<T> c = d * Vec3<T>(std::sqrt((1 - h) * (1 + h)), 0, h);
          const auto x = sample_projected_spherical_cap<T>(G{S{o, up}, L{c, scale}}, Vec2<T>(u0, u1));
          if (x.valid()) {
            EXPECT_TRUE(all_finite(x.direction) && std::isfinite(x.pdf) && x.pdf > 0) << scale << " " << h;
            EXPECT_NEAR(double(x.direction.norm()), 1.0, 1e-5);
          } else {
            EXPECT_EQ(x.pdf, T(0));
          }
        }
}

TEST(ProjectedCapDegenerate, NoSampleWithAReasonAndNeverNaNInFloat) { degenerate_suite<float>(); }
TEST(ProjectedCapDegenerate, NoSampleWithAReasonAndNeverNaNInDouble) { degenerate_suite<double>(); }
TEST(ProjectedCapDegenerate, NoSampleWithAReasonAndNeverNaNInLongDouble) { degenerate_suite<long double>(); }

// Random sphere lights seen from the origin with normal +z: every case, as the projected-cap views classify them.
template <class T> std::vector<ProjectedCapView<T>> polar_test_views(int per_case) {
  std::mt19937_64 g(17);
  std::uniform_real_distribution<double> unit(-1, 1), radius(0.05, 0.95);
  std::vector<ProjectedCapView<T>> out;
  std::array<int, 5> count{};
  while (*std::min_element(count.begin() + 1, count.begin() + 4) < per_case) {
    const Vec3<T> c = Vec3<T>(T(unit(g)), T(unit(g)), T(unit(g))).normalized() * T(2);
    const SphereLightGeometry<T> geo{ShadingPoint<T>{Vec3<T>::Zero(), Vec3<T>(0, 0, 1)},
                                     SphereLight<T>{c, T(2 * radius(g))}};
    const ProjectedCapView<T> v = make_projected_cap_view(geo);
    if (!v.valid() || count[v.which_case] >= per_case) continue;
    ++count[v.which_case];
    out.push_back(v);
  }
  return out;
}

template <class T> void polar_outside_case1_is_the_quintic() {
  std::mt19937_64 g(5);
  std::uniform_real_distribution<double> unit(0, 1);
  for (const ProjectedCapView<T>& v : polar_test_views<T>(20)) {
    if (v.which_case == 1) continue;
    for (int k = 0; k < 200; ++k) {
      const Vec2<T> u(T(unit(g)), T(unit(g)));
      const DirectionSample<T> a = sample_projected_spherical_cap_polar(v, u),
                               b = sample_projected_spherical_cap<T>(v, u);
      ASSERT_EQ(a.valid(), b.valid());
      if (!a.valid()) continue;
      EXPECT_EQ(a.direction, b.direction);
      EXPECT_EQ(a.pdf, b.pdf);
      EXPECT_EQ(pdf_projected_spherical_cap_polar(v, a.direction), pdf_projected_spherical_cap<T>(v, a.direction));
    }
  }
}
TEST(ProjectedCapPolar, OutsideCase1SamplesAsTheQuinticBitForBit) {
  polar_outside_case1_is_the_quintic<float>();
  polar_outside_case1_is_the_quintic<double>();
}

// Case 1: uniform on the ellipse per projected solid angle, so pdf = cos / A_E at every sample, and pdf(direction)
// agrees; the inverse returns the u that drew the sample.
template <class T> void polar_case1_is_uniform_on_the_ellipse(double tol) {
  std::mt19937_64 g(9);
  std::uniform_real_distribution<double> unit(0, 1);
  int checked = 0;
  for (const ProjectedCapView<T>& v : polar_test_views<T>(20)) {
    if (v.which_case != 1) continue;
    for (int k = 0; k < 200; ++k) {
      const Vec2<T> u(T(unit(g)), T(unit(g)));
      const DirectionSample<T> s = sample_projected_spherical_cap_polar(v, u);
      ASSERT_TRUE(s.valid());
      const double cos_n = double(s.direction.dot(v.z)), expected = cos_n / double(v.area_e);
      EXPECT_NEAR(double(s.pdf) / expected, 1, tol);
      EXPECT_NEAR(double(pdf_projected_spherical_cap_polar(v, s.direction)) / double(s.pdf), 1, tol);
      Vec2<T> back(T(0), T(0));
      ASSERT_TRUE(SphereProjectedCapPolar<T>::invert(v, s.direction, back));
      EXPECT_NEAR(double(back[0]), double(u[0]), 1e3 * tol);
      EXPECT_NEAR(std::remainder(double(back[1] - u[1]), 1.0), 0, 1e3 * tol);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 20 * 200);
}
TEST(ProjectedCapPolar, Case1DensityIsUniformOnTheEllipseAndInverts) {
  polar_case1_is_uniform_on_the_ellipse<float>(1e-4);
  polar_case1_is_uniform_on_the_ellipse<double>(1e-12);
}

}  // namespace
}  // namespace warpcheck::validation
