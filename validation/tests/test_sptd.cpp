// Spherical pivot transformed distributions (Dupuy, Heitz & Belcour 2017): the transformation, its Jacobian,
// cap invariance, closed-form cap integrals against quadrature, and the samplers through the battery.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <numbers>
#include <random>

#include <boost/math/quadrature/gauss_kronrod.hpp>

#include "autodiff_eigen.h"
#include "catalogue/sptd_samplers.h"
#include "warpcheck/sptd.h"
#include "warpcheck/validation/battery.h"

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
// tangencies; hence the 1e-7 tolerances below). The battery's integrate_cap_region copes with jumps by deep bisection,
// which is slow and stalls near 1e-8 for the clamped cosine's kink. These integrands are smooth except across one known
// circle {w : w.m = h} (the kink of the clamped cosine, or a cap's edge), so we integrate over a cap in polar
// coordinates (theta from the cap's axis, phi) and split each meridian where it crosses that circle (R cos(theta -
// delta) = h in closed form): every piece is smooth and Gauss-Kronrod converges fast. Where the circle comes from
// kernel code (a transformed cap), a wrong circle only costs accuracy, so it cannot make a wrong closed form agree.
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
L integrate_sphere(const std::function<L(const Vec3L&)>& f, const Vec3L& towards,
                   const std::vector<Circle>& circles = {}) {
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

// A pivot within an ulp of the sphere, r = 1 - eps/2, and w on its direction p: g(w) = -p and Eq. 4 gives
// ((1 + r) / (1 - r))^2, whatever w's length (1 +- a few eps, as any rounded unit vector). The plain difference
// r_p - w is of the order of that length error there: it gives g = +p, Jacobian Inf for |w| = r, and for the
// vectors below g = 0 (0 / 0, UBSan float-divide-by-zero).
template <class T> void expect_on_pivot_direction_maps_to_antipode() {
  const T eps = std::numeric_limits<T>::epsilon();
  const Vec3<T> rp(T(0), T(0), T(1) - eps / T(2));
  ASSERT_TRUE(valid_pivot(rp));
  const L r = L(rp.z());
  const L expected_jacobian = std::pow((1 + r) / (1 - r), 2);  // k / (1 - r)^2 = (1 + r) / (1 - r), squared
  for (const T len : {T(1) - eps / T(2), T(1), T(1) + eps, T(1) + T(2) * eps}) {
    const Vec3<T> w(T(0), T(0), len);
    const Vec3<T> g = pivot_transform(w, rp);
    EXPECT_TRUE(all_finite(g)) << "|w| - 1 = " << L(len) - 1;
    EXPECT_LE((g - Vec3<T>(T(0), T(0), T(-1))).norm(), T(4) * eps) << "|w| - 1 = " << L(len) - 1;
    // k and 1 - r both carry r's rounding (exact here), the squares and the quotient a few eps.
    EXPECT_NEAR(L(pivot_jacobian(w, rp)) / expected_jacobian, 1, 16 * L(eps)) << "|w| - 1 = " << L(len) - 1;
  }
}

TEST(SptdPivot, SphereFormMapsThePivotsDirectionToItsAntipodeForAPivotWithinAnUlpOfTheSphere) {
  expect_on_pivot_direction_maps_to_antipode<float>();
  expect_on_pivot_direction_maps_to_antipode<double>();
  // r_p with 1 - |r_p| = 1.1e-16 and the uniform SPTD over the whole sphere, whose image is the whole sphere
  // around C's axis w = (-1.49e-8, 0, -1) (|w| = 1 + 1.1e-16), sampled at u = 0. w is 2e-24 rad off p (with
  // rounding, |w x p| < 1e-23), and g stretches by (1 + r) / (1 - r) = 1.8e16 at p: g(w) lies within 1e-6 rad of -p.
  const Vec3<double> rp(-1.4901161193847653e-08, -0.0, -0.99999999999999978), w(-1.4901161193847656e-08, 0.0, -1.0);
  const Vec3<double> p = rp / rp.norm();
  const Vec3<double> g = pivot_transform(w, rp);
  ASSERT_TRUE(all_finite(g));
  EXPECT_NEAR(g.norm(), 1, 4e-16);
  EXPECT_LT((g + p).norm(), 1e-6);
  SptdCapGeometry<double> geo;
  geo.sptd.pivot = rp;
  geo.cap = Cap<double>{w, 2};
  const DirectionSample<double> s = sample_sptd_cap(geo, Vec2<double>(0, 0));
  ASSERT_TRUE(s.valid());
  EXPECT_LT((s.direction + p).norm(), 1e-6);
  EXPECT_GT(s.pdf, 0);
  EXPECT_EQ(s.pdf, pdf_sptd_cap(geo, s.direction));
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

// ---- Eq. 4 against Boost's autodiff of the kernel's own transformation ----------------------------------------
//
// pivot_transform (and pivot_transform_point, Eq. 2 verbatim) are instantiated on AD = a first-order fvar
// (autodiff_eigen.h makes it an Eigen scalar): the kernel's code itself is differentiated, not a copy of it.
// Along w(s) = normalize(w0 + s e) for the tangent e = x or y of a frame at w0 (unit speed at s = 0, the two
// directions orthonormal), the derivatives dg/ds give the area element |dg/ds_x x dg/ds_y| of g at w0, which
// Eq. 4 states in closed form. Returns the worst relative disagreement with `jacobian` (Eq. 4 as the kernel
// computes it, or a deliberately wrong formula for the failing counterpart) over the pivots and directions.
using AD = boost::math::differentiation::autodiff_fvar<L, 1>;

template <class Transform, class Jacobian> L worst_autodiff_jacobian_error(Transform&& transform, Jacobian&& jacobian) {
  std::mt19937_64 g(19);
  L worst = 0;
  for (L r : kPivotNorms) {
    for (int i = 0; i < 100; ++i) {
      const Vec3L rp = random_unit(g) * r, w0 = random_unit(g);
      const Frame<L> f = Frame<L>::from_z(w0);
      Vec3L d[2];
      for (int k = 0; k < 2; ++k) {
        const AD s = boost::math::differentiation::make_fvar<L, 1>(0);
        const Vec3<AD> e = (k == 0 ? f.x : f.y).cast<AD>();
        const Vec3<AD> w = Vec3<AD>(w0.cast<AD>() + s * e).normalized();
        const Vec3<AD> gw = transform(w, Vec3<AD>(rp.cast<AD>()));
        d[k] = Vec3L(gw.x().derivative(1), gw.y().derivative(1), gw.z().derivative(1));
      }
      worst = std::max(worst, std::abs(d[0].cross(d[1]).norm() / jacobian(w0, rp) - 1));
    }
  }
  return worst;
}

TEST(SptdPivot, JacobianEq4MatchesAutodiffOfTheKernelsTransformInLongDouble) {
  auto eq4 = [](const Vec3L& w, const Vec3L& rp) { return pivot_jacobian(w, rp); };
  // The kernel's sphere form and Eq. 2 verbatim, both differentiated by autodiff (measured worst: 8.7e-19 and
  // 2.3e-16; the verbatim form cancels in its denominator near |r_p| = 1).
  const L sphere_form =
      worst_autodiff_jacobian_error([](const Vec3<AD>& w, const Vec3<AD>& rp) { return pivot_transform(w, rp); }, eq4);
  const L eq2_form = worst_autodiff_jacobian_error(
      [](const Vec3<AD>& w, const Vec3<AD>& rp) { return pivot_transform_point(w, rp); }, eq4);
  EXPECT_LT(sphere_form, 1e-14L);
  EXPECT_LT(eq2_form, 1e-14L);
  // Failing counterparts: the check rejects plausible wrong Jacobians. Eq. 34 alone (the ratio of the disks'
  // radii, r2 / r1, not its square, Eq. 29), and Eq. 4 with the pivot's sign flipped (|w + r_p|).
  const L radius_ratio = worst_autodiff_jacobian_error(
      [](const Vec3<AD>& w, const Vec3<AD>& rp) { return pivot_transform(w, rp); },
      [](const Vec3L& w, const Vec3L& rp) { return (1 - rp.squaredNorm()) / (w - rp).squaredNorm(); });
  const L flipped =
      worst_autodiff_jacobian_error([](const Vec3<AD>& w, const Vec3<AD>& rp) { return pivot_transform(w, rp); },
                                    [](const Vec3L& w, const Vec3L& rp) { return pivot_jacobian(w, Vec3L(-rp)); });
  EXPECT_GT(radius_ratio, 0.1L);
  EXPECT_GT(flipped, 0.1L);
  std::printf("[ measured ] Eq. 4 vs autodiff: sphere form %.1Le, Eq. 2 form %.1Le; counterparts %.2Lg, %.2Lg\n",
              sphere_form, eq2_form, radius_ratio, flipped);
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

// The cap-invariance claim (Sec. 3.3) as a measurement of a cap transform: the worst relative error of
// 1 - cos(angle to the image axis) of g(b), over 64 points b on the boundary of C, against the image cap's own
// 1 - cos, for random caps and pivots; and how many interior points (C's axis, a point halfway to the boundary)
// the image cap misses. Large image caps (more than a hemisphere, where Eq. 6 as printed points the wrong way)
// are counted.
struct CapInvariance {
  L worst_boundary = 0;
  int interior_missed = 0, large_images = 0;
};
template <class CapTransform> CapInvariance measure_cap_invariance(CapTransform&& transform) {
  std::mt19937_64 g(14);
  CapInvariance m;
  for (L r : kPivotNorms) {
    for (int i = 0; i < 200; ++i) {
      const Vec3L rp = random_unit(g) * r;
      const Cap<L> c = random_cap(g, 1e-4L, 1.999L);
      const Cap<L> gc = transform(c, rp);
      m.large_images += gc.one_minus_cos > 1;
      const Frame<L> f = Frame<L>::from_z(c.axis);
      const L cos_a = 1 - c.one_minus_cos, sin_a = std::sqrt(c.one_minus_cos * (2 - c.one_minus_cos));
      for (int k = 0; k < 64; ++k) {
        const L phi = kTwoPi<L> * k / 64;
        const Vec3L b = f.to_world(Vec3L(sin_a * std::cos(phi), sin_a * std::sin(phi), cos_a));
        const L omc = (pivot_transform(b, rp) - gc.axis).squaredNorm() / 2;
        const L e = std::abs(omc / gc.one_minus_cos - 1);
        m.worst_boundary = std::max(m.worst_boundary, std::isnan(e) ? std::numeric_limits<L>::infinity() : e);
      }
      const L half = cap_half_angle(c) / 2;
      m.interior_missed += !gc.contains(pivot_transform(c.axis, rp));
      m.interior_missed += !gc.contains(pivot_transform(f.to_world(Vec3L(std::sin(half), 0, std::cos(half))), rp));
    }
  }
  return m;
}

TEST(SptdCaps, BoundaryOfCMapsOntoBoundaryOfGCInLongDouble) {
  const CapInvariance m =
      measure_cap_invariance([](const Cap<L>& c, const Vec3L& rp) { return pivot_transform_cap(c, rp); });
  EXPECT_LT(m.worst_boundary, 1e-12L);
  EXPECT_EQ(m.interior_missed, 0);
  EXPECT_GT(m.large_images, 50);  // image caps larger than a hemisphere are covered (Eq. 6's failure case)
}

// Failing counterparts of the claim's check: Eqs. 6-7 as printed (the normalised mean of g(w_1), g(w_2) as the
// axis) give the complement's axis for image caps larger than a hemisphere; and the kernel's cap with its
// 1 - cos off by 1e-10 relative (a rounding-level error, 100 times the check's bound).
TEST(SptdCaps, CapInvarianceCheckRejectsEq6AsPrintedAndASlightlyWrongAperture) {
  auto as_printed = [](const Cap<L>& c, const Vec3L& rp) {
    Vec3L t = rp - rp.dot(c.axis) * c.axis;
    t = t.norm() > 1e-15L ? Vec3L(t.normalized()) : Frame<L>::from_z(c.axis).x;
    const L cos_a = 1 - c.one_minus_cos, sin_a = std::sqrt(c.one_minus_cos * (2 - c.one_minus_cos));
    const Vec3L g1 = pivot_transform(Vec3L(cos_a * c.axis + sin_a * t), rp);
    const Vec3L g2 = pivot_transform(Vec3L(cos_a * c.axis - sin_a * t), rp);
    const Vec3L axis = (g1 + g2).normalized();  // Eq. 6
    return Cap<L>{axis, 1 - axis.dot(g1)};      // Eq. 7
  };
  const CapInvariance printed = measure_cap_invariance(as_printed);
  EXPECT_GT(printed.worst_boundary, 1e-12L);
  EXPECT_GT(printed.interior_missed, 0);
  const CapInvariance off = measure_cap_invariance([](const Cap<L>& c, const Vec3L& rp) {
    Cap<L> gc = pivot_transform_cap(c, rp);
    gc.one_minus_cos *= 1 + 1e-10L;
    return gc;
  });
  EXPECT_GT(off.worst_boundary, 1e-12L);
}

// Eq. 10's closed forms against quadrature of Eq. 8 over C, on random pivots, bases and caps. The quadrature
// values are computed once (they are the expensive part) and shared with the test's failing counterparts.
struct CapIntegralCase {
  Sptd<L> d;
  Cap<L> c;
  L quad;
};
const std::vector<CapIntegralCase>& cap_integral_cases() {
  static const std::vector<CapIntegralCase> cases = [] {
    std::vector<CapIntegralCase> out;
    std::mt19937_64 g(15);
    for (L r : kPivotNorms) {
      for (int i = 0; i < 2; ++i) {
        for (SptdBase base : {SptdBase::kUniform, SptdBase::kClampedCosine}) {
          Sptd<L> d;
          d.pivot = random_unit(g) * r;
          d.base = base;
          d.base_axis = random_unit(g);
          const Cap<L> c = random_cap(g, 0.02L, 1.98L);
          const L quad = integrate_sphere([&](const Vec3L& w) { return c.contains(w) ? sptd_density(d, w) : L(0); },
                                          d.pivot, {kink_of(d), boundary_of(c)});
          out.push_back({d, c, quad});
        }
      }
    }
    return out;
  }();
  return cases;
}
// Worst |closed - quadrature| / max(quadrature, 1e-3) (the quadrature's accuracy is ~1e-8 relative; see above).
template <class ClosedForm> L worst_cap_integral_error(ClosedForm&& closed_form) {
  L worst = 0;
  for (const auto& k : cap_integral_cases()) {
    const L e = std::abs(closed_form(k.d, k.c) - k.quad) / std::max<L>(k.quad, 1e-3L);
    worst = std::max(worst, std::isnan(e) ? std::numeric_limits<L>::infinity() : e);
  }
  return worst;
}

TEST(SptdCaps, ClosedFormCapIntegralsEq10MatchQuadratureOfEq8) {
  int crossing = 0, below_axis = 0, large_images = 0;
  for (const auto& k : cap_integral_cases()) {
    const Cap<L> image = pivot_transform_cap(k.c, k.d.pivot);
    large_images += image.one_minus_cos > 1;
    if (k.d.base == SptdBase::kClampedCosine) {
      const auto v = make_cosine_cap_view(image, k.d.base_axis);
      crossing += v.valid() && !v.ellipse_only;
      below_axis += v.valid() && v.cos_t < 0;
    }
  }
  EXPECT_LT(worst_cap_integral_error([](const Sptd<L>& d, const Cap<L>& c) { return sptd_cap_integral(d, c); }), 1e-7L);
  EXPECT_GE(crossing, 3);      // the horizon-crossing formula is exercised
  EXPECT_GE(below_axis, 1);    // ... including the crescent (cap axis below the horizon)
  EXPECT_GE(large_images, 1);  // ... and an image cap larger than a hemisphere
  // Failing counterparts (here, not in a test of their own, so that the quadrature runs once per process): the
  // comparison rejects a closed form 1e-6 off (10 times its bound) and the clamped cosine's projected area
  // without the horizon (the whole ellipse E, which is wrong whenever g(C) crosses it).
  EXPECT_GT(
      worst_cap_integral_error([](const Sptd<L>& d, const Cap<L>& c) { return sptd_cap_integral(d, c) * (1 + 1e-6L); }),
      1e-7L);
  EXPECT_GT(worst_cap_integral_error([](const Sptd<L>& d, const Cap<L>& c) {
              if (d.base == SptdBase::kUniform) return sptd_cap_integral(d, c);
              const auto v = make_cosine_cap_view(pivot_transform_cap(c, d.pivot), d.base_axis);
              return v.valid() ? v.sin_a * v.A : L(0);  // area of E / pi
            }),
            1e-7L);
}

// The clamped cosine's normaliser, the area of the projected region R (the image cap's projected solid angle),
// in double where it is small: caps of 1e-2 .. 1e-4 rad straddling the cosine's horizon, against the kernel in
// long double on the same (exactly widened) cap. R's area moves by at most its height 2 sin(alpha) per unit of
// abscissa and the abscissae x_c, x0 carry a few eps absolute: tolerance 8 eps 2 sin(alpha) / area + 16 eps.
// The segment form (CosineCapView::seg0) keeps the disk part from being a difference of two areas ~pi, off by
// ~eps pi absolute: 1.0e-6 relative at alpha = 1.4e-3 (tolerance 1.4e-8), 2.1e-4 at 1e-4. And caps whose axis lies
// on the horizon up to rounding (cos t = 1e-300 and cos(pi/2) in double): R is the disk right of x0 = cos(alpha),
// area alpha - sin(alpha) cos(alpha); the test x0 >= x_c + A for R = E holds there up to rounding and must not
// give the area of the degenerate ellipse, 5e-301 and 3e-17.
TEST(SptdCaps, CosineCapAreaIsAccurateInDoubleForSmallCapsAcrossAndOnTheHorizon) {
  const double e = std::numeric_limits<double>::epsilon();
  for (double alpha : {1e-2, 1.4e-3, 1e-4})
    for (double f : {-0.5, 0.5}) {
      const double t = std::numbers::pi / 2 + f * alpha;
      const Cap<double> c{Vec3<double>(std::sin(t), 0, std::cos(t)), 2 * std::pow(std::sin(alpha / 2), 2)};
      const auto v = make_cosine_cap_view(c, Vec3<double>(0, 0, 1));
      const auto vl = make_cosine_cap_view(Cap<L>{c.axis.cast<L>(), L(c.one_minus_cos)}, Vec3L(0, 0, 1));
      ASSERT_TRUE(v.valid() && vl.valid() && !v.ellipse_only) << alpha << " " << f;
      const L tol = 8 * e * 2 * std::sin(L(alpha)) / vl.area + 16 * e;
      EXPECT_LE(std::abs(v.area / vl.area - 1), tol) << "alpha " << alpha << " t - pi/2 " << f * alpha;
    }
  for (double alpha : {24 * std::numbers::pi / 180, 0.3})
    for (double cos_t : {1e-300, std::cos(std::numbers::pi / 2)}) {
      const Cap<double> c{Vec3<double>(1, 0, cos_t), 2 * std::pow(std::sin(alpha / 2), 2)};
      const auto v = make_cosine_cap_view(c, Vec3<double>(0, 0, 1));
      const L a = std::acos(1 - L(c.one_minus_cos));
      ASSERT_TRUE(v.valid());
      EXPECT_NEAR(v.area / double(a - std::sin(a) * std::cos(a)), 1, 1e-12) << "alpha " << alpha << " cos t " << cos_t;
    }
}

// A crescent whose tip is within rounding of the unit circle's leftmost point (1 + x0 = 1.1e-16: g(C)'s boundary
// tangent to the horizon at E's vertex). Computed independently, c0 = sqrt(1 - x0^2) and E's half-height there are
// each the square root of a difference within rounding of 0 (1.49e-8 against 1.38e-8), the crescent's terms do not
// cancel, and the integral is 4.7e-11 off relatively. The kernel's is within a few eps of long double's; the image
// g(C) itself carries a few eps of the pivot transform, to which an area of ~3 is not sensitive beyond O(1): 64 eps.
TEST(SptdCaps, ClampedCosineIntegralIsAccurateWhenTheCrescentTipTouchesTheHorizonAtEsVertex) {
  SptdCapGeometry<double> g;
  g.sptd.pivot = Vec3<double>(0, 0.5, 0);
  g.sptd.base = SptdBase::kClampedCosine;
  g.sptd.base_axis = Vec3<double>(2, 0, 0);
  g.cap = Cap<double>{Vec3<double>(0.088301988714510074, -0.99609375, 1.0005567036034595e-16), 1.99609375};
  const auto v = make_sptd_cap_view(g);
  const auto vl = make_sptd_cap_view(g.cast<L>());
  ASSERT_TRUE(v.valid() && vl.valid());
  ASSERT_TRUE(v.cosine.tip);
  EXPECT_LE(std::abs(v.base_integral / vl.base_integral - 1), 64 * std::numeric_limits<double>::epsilon())
      << v.base_integral << " vs " << double(vl.base_integral);
}

// The same crescent's tip near E's top instead (x0 - x_c within rounding of 0: g(C) a near-hemisphere, 1 - cos =
// 1 - d). Taking n0 = c0 / sin(alpha) there makes tau0 = sqrt(1 - n0^2) the square root of a difference within
// rounding of 0 (areas 2.1e-8 and 4.1e-10 off relatively).
// Reference: the projected solid angle of a hemisphere at angle t from n is (pi / 2)(1 + cos t) (Lambert's formula
// for the lune), and dP/dalpha = sin(alpha) times the cosine integral over the boundary circle = 2 sin t there, so
// P = (pi / 2)(1 + cos t) - 2 sin t asin(d) + O(d^2) (cos alpha = d; O(d^2) < 1e-19 for d <= 1e-10). Tolerance as
// in CosineCapAreaIsAccurateInDoubleForSmallCapsAcrossAndOnTheHorizon: the abscissae carry a few eps, R's area
// moves by its height 2 sin(alpha) per unit of abscissa. Measured: within 18 eps (t = 2.9, d = 8.2e-14); with
// n0 = c0 / sin(alpha), up to 2.9e9 eps.
TEST(SptdCaps, ClampedCosineIntegralIsAccurateWhenTheCrescentTipIsNearEsTop) {
  const double e = std::numeric_limits<double>::epsilon();
  for (double t : {2.1331, 1.6162, 2.9})
    for (double d : {8.2e-14, 1e-10}) {
      const Vec3<double> axis(std::sin(t), 0, std::cos(t));
      const double omc = 1 - d, exact_d = 1 - omc;  // 1 - omc is exact (Sterbenz)
      const auto v = make_cosine_cap_view(Cap<double>{axis, omc}, Vec3<double>(0, 0, 1));
      ASSERT_TRUE(v.valid() && v.tip) << t << " " << d;
      const L n = axis.cast<L>().norm(), cos_t = L(axis.z()) / n, sin_t = L(axis.x()) / n;
      const L ref = std::numbers::pi_v<L> / 2 * (1 + cos_t) - 2 * sin_t * std::asin(L(exact_d));
      const L tol = 8 * e * 2 / ref + 16 * e;
      EXPECT_LE(std::abs(v.area / ref - 1), tol) << "t " << t << " d " << d << ": " << v.area << " vs " << double(ref);
    }
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
      const L quad =
          integrate_sphere([&](const Vec3L& w) { return c.contains(w) && h.contains(w) ? sptd_density(d, w) : L(0); },
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

// Every sample lies in C, and its returned pdf is Eq. 8's density restricted to C and divided by Eq. 10's
// integral (the kernel's own normaliser, checked against quadrature above), on pivots up to |r_p| = 0.999 and
// the clamped cosine in its three shapes. (The statistical battery on the same samplers runs in slow_sptd.cpp and
// on the registry's configurations through `warpcheck validate --kernel 'sptd-*'`.)
TEST(SptdSampling, SamplesLieInTheCapWithTheRestrictedNormalisedEq8Density) {
  struct C {
    Vec3L pivot;
    SptdBase base;
    Vec3L base_axis;
    Cap<L> cap;
  };
  const Vec3L diag = Vec3L(0.3L, -0.5L, 0.8L).normalized();
  const C cases[] = {
      {Vec3L(0.2L, 0.1L, 0.5L), SptdBase::kUniform, Vec3L(0, 0, 1), Cap<L>{Vec3L(0.3L, 0, 1).normalized(), 0.3L}},
      {diag * 0.999L, SptdBase::kUniform, Vec3L(0, 0, 1), Cap<L>{Vec3L(diag + Vec3L(0.1L, 0, 0)).normalized(), 0.1L}},
      {diag * 0.999L, SptdBase::kUniform, Vec3L(0, 0, 1), Cap<L>{Vec3L(-diag + Vec3L(0, 0.2L, 0)).normalized(), 0.5L}},
      {Vec3L(0.1L, 0, 0.4L), SptdBase::kClampedCosine, Vec3L(0, 0, -1), Cap<L>{Vec3L(0.2L, 0, 1).normalized(), 0.2L}},
      {Vec3L(0.5L, 0, 0.3L), SptdBase::kClampedCosine, Vec3L(0, 0, 1), Cap<L>{Vec3L(1, 0, -0.3L).normalized(), 0.6L}},
      {Vec3L(0.2L, 0, 0.3L), SptdBase::kClampedCosine, Vec3L(0, 0, -1), Cap<L>{Vec3L(1, 0, 0.2L).normalized(), 0.3L}},
  };
  std::mt19937_64 g(20);
  std::uniform_real_distribution<double> u(0, 1);
  for (const C& c : cases) {
    SptdCapGeometry<L> geo;
    geo.sptd.pivot = c.pivot, geo.sptd.base = c.base, geo.sptd.base_axis = c.base_axis, geo.cap = c.cap;
    const auto v = make_sptd_cap_view(geo);
    ASSERT_TRUE(v.valid());
    for (int i = 0; i < 2000; ++i) {
      const auto smp = sample_sptd_cap(v, Vec2<L>(L(u(g)), L(u(g))));
      ASSERT_TRUE(smp.valid());
      EXPECT_TRUE(c.cap.contains(smp.direction, 1e-15L));
      EXPECT_NEAR(smp.pdf / (sptd_density(v.sptd, smp.direction) / v.base_integral), 1, 1e-12L);
      EXPECT_NEAR(pdf_sptd_cap(v, smp.direction) / smp.pdf, 1, 1e-15L);
    }
  }
}

// A pivot near the sphere shrinks a cap on its far side into an image next to r_p's direction (registry case
// pivot-0.999-away: |r_p| = 0.999, image radius 5.8e-4 rad). Unit vectors there are rounded by float's eps, which
// g stretches by k / |w - r_p|^2 ~ 1700 on the way back; samples and densities formed from offsets to r_p
// (pivot_transform_cap's axis_minus_pivot) do not see that. Measured by this test: worst 4.1e-7 rad; formed from
// unit vectors in the image instead, 1.8e-4, and 9 of the 1e5 float samples declined.
TEST(SptdSampling, FloatSamplesOfAUniformSptdWithItsPivotAt0999FarFromTheCapMatchLongDoubleToAFewUlps) {
  const Vec3L diag = Vec3L(0.3L, -0.5L, 0.8L).normalized();
  SptdCapGeometry<L> g;
  g.sptd.pivot = diag * 0.999L;
  g.sptd.base = SptdBase::kUniform;
  g.cap = Cap<L>{(-diag + Vec3L(0, 0.2L, 0)).normalized(), 0.5L};
  const auto vf = make_sptd_cap_view(g.cast<float>());
  const auto vl = make_sptd_cap_view(g.cast<float>().cast<L>());  // the same (float) geometry, exactly
  ASSERT_TRUE(vf.valid() && vl.valid());
  std::mt19937_64 r(11);
  std::uniform_real_distribution<float> u(0, 1);
  L worst = 0;
  for (int i = 0; i < 100000; ++i) {
    const Vec2<float> x(u(r), u(r));
    const auto sf = sample_sptd_cap(vf, x);
    const auto sl = sample_sptd_cap(vl, Vec2<L>(x.x(), x.y()));
    ASSERT_TRUE(sf.valid() && sl.valid()) << i;
    worst = std::max(worst, (sf.direction.cast<L>() - sl.direction).norm());
  }
  std::printf("[ float ] worst |w_float - w_LD| %.3Lg rad over 1e5 samples\n", worst);
  EXPECT_LT(worst, 2e-6L);  // 16 ulps of float's directions; the unit-vector image gave 1.9e-4
}

// The clamped cosine's crescent (registry case sptd-cosine-cap/crescent: image cap's axis below n's horizon) in
// float near its tip x0 (u0 -> 0) and near the disk's rim (u0 -> 1), against the long double sampler on the same
// (float) geometry, exactly widened. Near x0 the crescent's mass grows like (x - x0)^3 while the difference form
// disk(x0..x) - (E(x) - E(x0)) subtracts two terms ~2 c0 (x - x0), and near x = 1 the area right of x is a rounded
// x's 1 - x; both leave float's x(u) wrong by far more than its rounding. Measured by this test: worst 3.1e-7 rad
// near the tip and 1.8e-7 near the rim, none declined; the difference form with x solved to x's relative
// precision: 5.7e-3 and 6.2e-4 rad, and 1699 of the 14700 samples declined (x = x0 exactly, z = 0). (1 - d rounds
// to 1 in float for d < 6e-8: those u0 are left out.)
TEST(SptdSampling, FloatCosineCapCrescentSamplesMatchLongDoubleToAFewUlpsNearTheTipAndTheRim) {
  SptdCapGeometry<L> g;
  g.sptd.pivot = Vec3L(0.2L, 0, 0.3L);
  g.sptd.base = SptdBase::kClampedCosine;
  g.sptd.base_axis = Vec3L(0, 0, -1);
  g.cap = Cap<L>{Vec3L(1, 0, 0.2L).normalized(), 0.3L};
  const auto vf = make_sptd_cap_view(g.cast<float>());
  const auto vl = make_sptd_cap_view(g.cast<float>().cast<L>());  // the same (float) geometry, exactly
  ASSERT_TRUE(vf.valid() && vl.valid());
  ASSERT_TRUE(vf.cosine.cos_t < 0 && vf.cosine.x0 > -1 && vf.cosine.x0 < 1) << "not a crescent with a tip";
  std::mt19937_64 r(5);
  std::uniform_real_distribution<float> u(0, 1);
  L worst_tip = 0, worst_rim = 0;
  int declined = 0;
  for (int e = 0; e <= 80; ++e) {
    const float d = std::pow(10.0f, -1 - 0.1f * float(e));  // 1e-1 .. 1e-9
    for (int j = 0; j < 100; ++j) {
      const float u1 = u(r);
      for (const float u0 : {d, 1 - d}) {
        if (!(u0 < 1)) continue;
        const auto sf = sample_sptd_cap(vf, Vec2<float>(u0, u1));
        const auto sl = sample_sptd_cap(vl, Vec2<L>(u0, u1));
        if (!sf.valid() || !sl.valid()) {
          ++declined;
          continue;
        }
        L& worst = u0 < 0.5f ? worst_tip : worst_rim;
        worst = std::max(worst, (sf.direction.cast<L>() - sl.direction).norm());
      }
    }
  }
  std::printf("[ float ] crescent: worst |w_float - w_LD| %.3Lg rad near the tip, %.3Lg near the rim, %d declined\n",
              worst_tip, worst_rim, declined);
  EXPECT_EQ(declined, 0);
  EXPECT_LT(worst_tip, 2e-6L);  // 16 ulps of float's directions
  EXPECT_LT(worst_rim, 2e-6L);
}

}  // namespace
}  // namespace warpcheck
