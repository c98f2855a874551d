// warpcheck/sptd.h: spherical pivot transformed distributions (SPTDs), Dupuy, Heitz & Belcour 2017,
// "A Spherical Cap Preserving Parameterization for Spherical Distributions".
//
// Contents (equation numbers are the paper's):
//   pivot_transform_point   Eq. 2, the pivot transformation of any point of R^3 (an involution, Eq. 3)
//   pivot_transform         Eq. 2 restricted to the unit sphere, in the form g(w) = r_p + k (r_p - w) / |r_p - w|^2
//                           (r_p - w by pivot_offset, for the unit vector in w's direction)
//   pivot_jacobian          Eq. 4, d g(w) / d w = (k / |w - r_p|^2)^2, k = 1 - |r_p|^2
//   pivot_transform_cap     Eqs. 6-7, the image g(C) of a spherical cap
//   sptd_density            Eq. 8, D(w) = D_std(g(w)) dg/dw for the uniform and the clamped-cosine D_std
//   sptd_cap_integral       Eq. 10, the integral of D over a cap C = integral of D_std over g(C)
//   cap_intersection_solid_angle        Eqs. 35-36 (Appendix B, exact), and Eq. 37 (the approximation)
//   sptd_uniform_two_cap_integral       Eqs. 17-19, a uniform SPTD over the intersection of two caps
//   sample_sptd_cap / pdf_sptd_cap      Sec. 4.2: sample D_std over g(C), pivot back (Fig. 5)
//   pivot_phase_function    Eq. 25; henyey_greenstein Eq. 26; hg_to_pivot Eqs. 27-28
//   sample_pivot_phase_sphere_light     Sec. 6.2, joint pivot-phase-function and sphere-light sampling
//
// Derivations that the paper leaves out (its supplement is not available to us):
//  * On the sphere, Eq. 2 equals the "anti-inversion" g(w) = r_p + k (r_p - w) / |r_p - w|^2 (the second
//    intersection of the line from w through r_p with the sphere: |g(w) - r_p| |w - r_p| = k is Eq. 33, and
//    g(w) - r_p points away from w - r_p). test_sptd checks the two forms agree. We use the second form on
//    the sphere: it has no cancellation in its denominator, and it is exactly what the Jacobian (Eq. 4) refers to.
//    It holds for unit w only; w - r_p is taken for the unit vector in w's direction (pivot_offset), as a rounded
//    "unit" vector's length error is amplified by k / |w - r_p|^2 there.
//  * Eq. 6 takes the normalised mean of the two transformed boundary points as the axis of g(C). That is
//    right only when g(C) is at most a hemisphere; for a larger image cap the mean points to the centre of the
//    complement, and for a hemisphere it is zero. We take the axis as +-the in-plane bisector of g(w_1),
//    g(w_2) and pick the sign for which g(w_c) (which lies in g(C), as w_c lies in C) is inside.
//  * The clamped-cosine D_std = max(0, w.n) / pi over a cap: its integral is the projected solid angle of
//    the cap above the horizon of n (Snyder 1996 gives it for caps up to a hemisphere). We derive it and the
//    sampler from the orthographic projection onto the disk of n (Malley's method, so cosine-weighted =
//    uniform in the projection): with n = z and the cap axis a = (sin t, 0, cos t), half-angle alpha, the
//    cap's boundary circle projects to the ellipse E centred at x_c = sin t cos(alpha) with semi-axes
//    A = sin(alpha) |cos t| (along x) and sin(alpha) (along y); points with x >= x_0 = cos(alpha) / sin(t)
//    lie on the cap's side of its plane everywhere in the upper hemisphere. The projected region R is
//      cos t >= 0:  (E with x < x_0)  union  (disk with x >= x_0)          (convex)
//      cos t < 0:   (disk with x >= x_0) minus E                         (a crescent)
//    which holds for any alpha in (0, pi]. R's area (the projected solid angle) is a sum of elliptic and
//    circular segment areas, in closed form. Sampling: when R = E (cap entirely above the horizon) an affine
//    image of the uniform disk, in closed form; otherwise x by inverting the closed-form area-CDF with
//    Boost's TOMS 748 root finder, then y uniform on R's chord at x. (The projected spherical cap sampler of
//    Peters & Dachsbacher 2019 would serve here too; lib/warpcheck/projected_cap.h did not exist when this
//    was written, so this is our own exact method; its cost is one 1D root find per sample near the horizon.)
//  * The crescent's tip (cos t < 0, x0 in (-1, 1); issue 5). E touches the unit circle at P0 = (x0, +-c0),
//    c0 = sqrt(1 - x0^2): with c = sqrt(1 - x^2) and E's half-height m at x, multiplying c^2 - m^2 =
//    cos^2(alpha) - x^2 + (x - x_c)^2 / cos^2(t) by cos^2(t) gives (x sin t - cos(alpha))^2, so
//    c^2 - m^2 = tan^2(t) (x - x0)^2 (a double root at x0: the tangency). R's half-chord is then
//    c - m = tan^2(t) (x - x0)^2 / (c + m), without cancellation; tan(t) (x - x0) = sin(t) sin(alpha) (x - x0) / A.
//    The mass of R between x0 and x ~ (2/3) tan^2(t) (x - x0)^3 / c0 was the difference of disk(x0..x) and
//    E(x0..x), each ~2 c0 (x - x0): in float x(u0) was all cancellation for small u0 (pdf(dir) and the warp's
//    area element 2.4e-4 apart at u0 = 1.5e-4 against a tolerance of 1.6e-5, and 2 of 1e7 samples declined with
//    x = x0). We take it in closed form from areas that do not cancel (derived here, not in the paper): for the
//    upper half, between x0 and x <= x_c + A, (circular segment on the chord P0 -> (x, c)) - (E's segment on the
//    chord P0 -> (x, m)) + (the triangle between the two chords, (x - x0)(c - m) / 2), each segment from its
//    half-angle by the series of projected_cap.h's cut_disk_area_from_angle (E's after the affine map onto the unit
//    disk, times its area factor sin(alpha) A). Right of E's end the same with E's whole segment from P0 and the
//    trapezoid under the disk's chord. For small x - x0 all three terms are cubic in x - x0 like the mass: with D
//    the upper half's mass, the triangle is 3 D / 2, E's segment exceeds the circle's (~(x - x0)^3 / (12 c0^3)) by
//    D / 2, so the terms' magnitudes add up to (2 + 1 / (tan^2(t) c0^2)) D (2.02 D in the registry's crescent),
//    independently of x - x0. It is one formula on [x0, x_c + A] (no switch, hence no new kink), and C1 at
//    x_c + A, already a kink of the warp. Measured in float on the registry's crescent: the CDF within 2.5 eps of
//    the long double kernel's on the same float geometry for x - x0 from 1e-5 to 1 - x0 (the difference form:
//    2.4e3 relative at 1e-4, 8e-3 at 1e-2).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include <boost/math/tools/roots.hpp>

#include "warpcheck/core.h"
#include "warpcheck/projected_cap.h"  // cut_disk_area_from_angle
#include "warpcheck/sphere.h"

namespace warpcheck {

// ---- The pivot transformation (Sec. 3.2) -------------------------------------------------------------------

// A pivot r_p must lie strictly inside the unit sphere.
template <class T> bool valid_pivot(const Vec3<T>& rp) { return all_finite(rp) && rp.squaredNorm() < T(1); }

// k = 1 - |r_p|^2 as (1 - |r_p|)(1 + |r_p|).
template <class T> T pivot_k(const Vec3<T>& rp) {
  const T r = rp.norm();
  return (T(1) - r) * (T(1) + r);
}

// Eq. 2, verbatim, for any point r of R^3 (not only the sphere). Eq. 3: g(g(r)) = r.
template <class T> Vec3<T> pivot_transform_point(const Vec3<T>& r, const Vec3<T>& rp) {
  const T a = r.dot(rp) - T(1);
  const Vec3<T> d = r - rp;
  const Vec3<T> c = r.cross(rp);
  return (a * d - d.cross(c)) / (a * a + c.squaredNorm());
}

// r_p - w for the unit vector in w's direction (w != 0), from quantities exact for it: with p = r_p / |r_p| and
// theta = angle(w, p), r_p - w = ((1 - cos theta) - (1 - |r_p|)) p - (w's part orthogonal to p), 1 - cos theta as
// sin^2 / (1 + cos) near p. The plain difference r_p - w carries w's length error (1 +- eps for any rounded unit
// vector), which the anti-inversion divides by |r_p - w|^2 ~ (1 - |r_p|)^2 near p: for |r_p| = 1 - eps/2 and w on p
// with |w| = 1 + eps it gave g = 0 (UBSan division by zero in the normalisation, found by fuzz_sptd_double, issue 7).
// Here the component along p is -(1 - |r_p|) to rounding for w near p, with the same 1 - |r_p| as pivot_k, so
// |r_p - w|^2 >= (1 - |r_p|)^2 > 0. A pivot shorter than eps / 8 moves g(w) from -w by at most 2 |r_p| < eps / 4
// (Eq. 2): taken as 0.
template <class T> Vec3<T> pivot_offset(const Vec3<T>& w, const Vec3<T>& rp) {
  const T wn = w.norm();
  const T r = rp.norm();  // as in pivot_k
  if (!(r > std::numeric_limits<T>::epsilon() / T(8))) return -w / wn;
  const Vec3<T> p = rp / r;
  const Vec3<T> x = w.cross(p) / wn;  // |x| = sin theta; w's part orthogonal to p is |w| p x x
  const T c = w.dot(p) / wn;
  const T one_minus_c = c > T(0) ? x.squaredNorm() / (T(1) + c) : T(1) - c;
  return (one_minus_c - (T(1) - r)) * p - p.cross(x);
}

// Eq. 2 on the unit sphere, in the anti-inversion form derived in the header comment, for the unit vector in w's
// direction (pivot_offset); renormalised.
template <class T> Vec3<T> pivot_transform(const Vec3<T>& w, const Vec3<T>& rp, T k) {
  const Vec3<T> d = pivot_offset(w, rp);
  const T d2 = d.squaredNorm();
  if (!(d2 > T(0))) return -w / w.norm();  // only where |r_p| rounds to 1 (k = 0, no pivot): g(p) = -p
  const Vec3<T> g = rp + (k / d2) * d;
  return g / g.norm();
}
template <class T> Vec3<T> pivot_transform(const Vec3<T>& w, const Vec3<T>& rp) {
  return pivot_transform(w, rp, pivot_k(rp));
}

// Eq. 4: the Jacobian dg(w)/dw = (k / |w - r_p|^2)^2 of the transformation on the sphere.
template <class T> T pivot_jacobian(const Vec3<T>& w, const Vec3<T>& rp, T k) {
  const T j = k / pivot_offset(w, rp).squaredNorm();
  return j * j;
}
template <class T> T pivot_jacobian(const Vec3<T>& w, const Vec3<T>& rp) { return pivot_jacobian(w, rp, pivot_k(rp)); }

// Eqs. 6-7 (with the orientation fix described in the header): the cap g(C).
// axis_minus_pivot: if given, set to the image axis minus r_p, accurate to rounding of its own size, when the image
// is a small cap (below 30 degrees; else left unset and false returned in *relative). Such an image lies near r_p's
// direction when |r_p| is near 1, and a unit vector there is rounded by eps, which g stretches by k / |w - r_p|^2
// on the way back (Eq. 4; 1700 for |r_p| = 0.999, registry case pivot-0.999-away). Derived here: g1 - r_p =
// k o1 / |o1|^2 with o1 = pivot_offset(p1) = r_p - p1 (the anti-inversion form); the image circle's centre is the
// midpoint m = r_p + h of g1 and g2 (the ends of a diameter), h = (q1 + q2) / 2 with q_i = g_i - r_p; the axis is
// m / |m|, so axis - r_p = h + m (1 - |m|) / |m|, and as |r_p + q_i| = 1, 1 - |m|^2 = |q1 - q2|^2 / 4 exactly.
template <class T> Cap<T> pivot_transform_cap(const Cap<T>& c, const Vec3<T>& rp, T k,
                                              Vec3<T>* axis_minus_pivot = nullptr, bool* relative = nullptr) {
  if (relative) *relative = false;
  if (c.one_minus_cos >= T(2)) return Cap<T>{c.axis, T(2)};  // the whole sphere maps onto itself
  const Vec3<T>& wc = c.axis;
  // The plane through the origin, w_c and r_p (Fig. 3 (1)); any plane through w_c when r_p is parallel to it.
  // Two Gram-Schmidt passes: with r_p nearly parallel to w_c one pass leaves a component along w_c of ~eps |r_p|,
  // so t.w_c / |t| is rounding noise and the boundary points below lie off the sphere, where the anti-inversion
  // form of g does not apply (found by fuzz_sptd_double: |t| = 2.1e-14, t.w_c / |t| = -6.1e-3, boundary points
  // 1.1e-6 off the unit sphere, the image's 1 - cos off by 3.8e-5, issue 7). After the second pass t is orthogonal
  // to w_c up to rounding; below the threshold it is noise, and every plane through w_c is one of symmetry.
  // For a tiny pivot the squares of t's entries underflow (found by fuzz_sptd_double with |r_p| = 8e-153: t / |t|
  // off unit length, the image's 1 - cos off by 2.4e-4, issue 7): stableNorm, and below min_T / eps_T (subnormal
  // products lose their precision; |r_p| = 2e-308: 1 - cos off by 6e-9) any plane, as the pivot is negligible.
  Vec3<T> t = rp - rp.dot(wc) * wc;
  t -= t.dot(wc) * wc;
  const T tn = t.stableNorm();
  constexpr T e = std::numeric_limits<T>::epsilon();
  t = tn > T(64) * e * rp.stableNorm() && tn > std::numeric_limits<T>::min() / e ? Vec3<T>(t / tn)
                                                                                 : Frame<T>::from_z(wc).x;
  const T omc = c.one_minus_cos;
  const T cos_a = T(1) - omc, sin_a = std::sqrt(std::max(T(0), omc * (T(2) - omc)));
  // Fig. 3 (2)-(3): the boundary points in that plane and their images.
  const Vec3<T> p1 = cos_a * wc + sin_a * t, p2 = cos_a * wc - sin_a * t;
  const Vec3<T> g1 = pivot_transform(p1, rp, k);
  const Vec3<T> g2 = pivot_transform(p2, rp, k);
  const Vec3<T> gc = pivot_transform(wc, rp, k);
  // Eq. 6 (in-plane bisector), robust for image caps of any size.
  const Vec3<T> sum = g1 + g2, diff = g1 - g2;
  Vec3<T> axis;
  if (sum.squaredNorm() >= diff.squaredNorm())
    axis = sum / sum.norm();
  else {
    const Vec3<T> m = wc.cross(t).cross(diff);  // in the plane, orthogonal to g1 - g2
    axis = m / m.norm();
  }
  // g(w_c) lies inside g(C). That test compares distances of the order of the image's size, which are noise for an
  // image below the resolution of T's directions (found by fuzz_sptd_double: an image of 5e-18 rad oriented as the
  // whole sphere, density 4e-21 instead of 1.8e14, issue 7). But g stretches lengths on C by at most k / d_min^2
  // (Eq. 4; d_min the distance from r_p to C: 1 - |r_p| if C contains r_p's direction, else that to the nearer
  // boundary point, p1 or p2), so g(C) has diameter <= 2 alpha k / d_min^2; below pi/2 it cannot be the complement
  // of the cap around the bisector (diameter >= pi): no flip there.
  const T rn = rp.norm();
  const bool contains_pivot = rn > T(0) && (rp / rn - wc).squaredNorm() <= T(2) * omc;
  const Vec3<T> o1 = pivot_offset(p1, rp), o2 = pivot_offset(p2, rp);  // r_p - p_i for unit p_i
  const T d1 = o1.norm(), d2 = o2.norm();
  const T d_min = contains_pivot ? T(1) - rn : std::min(d1, d2);
  const T alpha = T(2) * std::asin(std::min(T(1), std::sqrt(omc / T(2))));
  const bool surely_small = T(2) * alpha * k < kPi<T> / T(2) * d_min * d_min;
  if (!surely_small && (gc - axis).squaredNorm() > (g1 - axis).squaredNorm()) axis = -axis;
  // Eq. 7, as a chord length (1 - cos = |g_i - axis|^2 / 2) averaged over both boundary points. Where the image
  // circle is small (the image cap or its complement within 30 degrees) that chord is a difference of nearly equal
  // unit vectors and loses eps / psi' relatively (found by fuzz_sptd_double: psi' = 2.5e-12, 1 - cos off by
  // 3.3e-5, issue 7). There we use the distance formula of the inversion instead (derived here, not in the paper):
  // g is the inversion about r_p of power k followed by the point reflection through r_p, so |g(p) - g(q)| =
  // k |p - q| / (|p - r_p| |q - r_p|), and g1, g2 are the ends of a diameter of the image circle (which is
  // symmetric about the plane); hence sin(psi'') = k sin(alpha) / (|p1 - r_p| |p2 - r_p|) for the smaller of the
  // two caps the circle bounds, and 1 - cos(psi'') = s^2 / (1 + sqrt(1 - s^2)) without cancellation.
  // (The plain differences p_i - r_p vanished for a boundary point on r_p's direction when |r_p| is within an ulp
  // of 1, found by fuzz_sptd_double under UBSan's float-divide-by-zero, issue 7; pivot_offset's distances are at
  // least 1 - |r_p| > 0, the guard stays for k = 0.)
  const T chord_denominator = d1 * d2;
  const T s = chord_denominator > T(0) ? k * sin_a / chord_denominator : T(1);
  T image_omc;
  if (s < T(0.5)) {
    const T small = s * s / (T(1) + std::sqrt((T(1) - s) * (T(1) + s)));
    image_omc = axis.dot(g1) >= T(0) ? small : T(2) - small;
    if (axis_minus_pivot && image_omc == small && sum.squaredNorm() >= diff.squaredNorm() && d1 > T(0) && d2 > T(0)) {
      const Vec3<T> q1 = (k / (d1 * d1)) * o1, q2 = (k / (d2 * d2)) * o2;
      const Vec3<T> h = (q1 + q2) / T(2), m = rp + h;
      const T mn = m.norm();
      const Vec3<T> off = h + m * ((q1 - q2).squaredNorm() / T(4) / (T(1) + mn) / mn);
      const Vec3<T> a = rp + off;
      if (all_finite(off) && a.norm() > T(0)) {
        *axis_minus_pivot = off;
        axis = a / a.norm();
        if (relative) *relative = true;
      }
    }
  } else {
    image_omc = std::min(T(2), ((g1 - axis).squaredNorm() + (g2 - axis).squaredNorm()) / T(4));
  }
  return Cap<T>{axis, image_omc};
}
template <class T> Cap<T> pivot_transform_cap(const Cap<T>& c, const Vec3<T>& rp) {
  return pivot_transform_cap(c, rp, pivot_k(rp));
}

// ---- The original distributions D_std and their cap integrals ------------------------------------------------

enum class SptdBase : std::uint8_t { kUniform, kClampedCosine };

template <class T> struct Sptd {
  Vec3<T> pivot = Vec3<T>::Zero();
  SptdBase base = SptdBase::kUniform;
  Vec3<T> base_axis = Vec3<T>(T(0), T(0), T(1));  // n of the clamped cosine max(0, w.n) / pi
};

template <class T> T sptd_base_density(const Sptd<T>& d, const Vec3<T>& w) {
  if (d.base == SptdBase::kUniform) return T(1) / (T(4) * kPi<T>);
  return std::max(T(0), w.dot(d.base_axis)) / kPi<T>;
}

// Eq. 8: D(w) = D_std(g(w)) (k / |w - r_p|^2)^2.
template <class T> T sptd_density(const Sptd<T>& d, const Vec3<T>& w) {
  const T k = pivot_k(d.pivot);
  return sptd_base_density(d, pivot_transform(w, d.pivot, k)) * pivot_jacobian(w, d.pivot, k);
}

// The clamped cosine restricted to a cap, in the projected-disk form derived in the header.
template <class T> struct CosineCapView {
  NoSample reason = NoSample::kNone;
  Cap<T> cap;
  Vec3<T> ex = Vec3<T>::Zero(), ey = Vec3<T>::Zero(), ez = Vec3<T>::Zero();  // ez = n; ex towards the cap axis
  T cos_a = 0, sin_a = 0;                                                    // cap half-angle alpha
  T cos_t = 0, sin_t = 0;                                                    // angle t between the cap axis and n
  T xc = 0, A = 0, x0 = 0;    // ellipse centre and x semi-axis; x >= x0: full chord side
  T seg0 = 0;                 // area of the unit disk right of x0, without cancellation (make_cosine_cap_view)
  bool ellipse_only = false;  // R = E (cap entirely above the horizon)
  // The crescent with its tip at x0 in (-1, 1) (cos t < 0), where E touches the unit circle at (x0, +-c0):
  // E's normalised abscissa tau0 = (x0 - x_c) / A there and its normalised half-height n0 = sqrt(1 - tau0^2)
  // (both computed from c0, make_cosine_cap_view).
  bool tip = false;
  T c0 = 0, tau0 = 0, n0 = 0;
  T area = 0;  // projected solid angle of (cap, upper hemisphere) = area of R

  bool valid() const { return reason == NoSample::kNone; }

  // Area of the ellipse E with abscissa < x, and of the unit disk with abscissa < x.
  T ellipse_cdf(T x) const {
    if (!(A > T(0))) return T(0);
    const T t = std::clamp((x - xc) / A, T(-1), T(1));
    return sin_a * A * (t * std::sqrt((T(1) - t) * (T(1) + t)) + std::asin(t) + kPi<T> / T(2));
  }
  // Area of the unit disk right of x = cos(theta), theta in [0, pi]: C(theta) = theta - sin(theta) cos(theta) by
  // projected_cap.h's cut_disk_area_from_angle (a series where that difference cancels) up to pi/2, pi - C(pi -
  // theta) beyond. The area of the disk between x0 and x was the difference of two areas left of them, ~pi each,
  // which leaves an absolute error of ~eps pi: relatively ~eps pi / area for a small cap straddling the horizon
  // (found by fuzz_sptd_double: image cap of 1.4e-3 rad on the horizon, area 1.76e-9 off by 4e-7, issue 7).
  static T disk_right_of_angle(T theta) {
    return theta <= kPi<T> / T(2) ? cut_disk_area_from_angle(theta) : kPi<T> - cut_disk_area_from_angle(kPi<T> - theta);
  }
  static T disk_right_of(T x) { return disk_right_of_angle(std::acos(std::clamp(x, T(-1), T(1)))); }
  // Area of R with abscissa < x; the disk part between x0 and x as seg0 - (disk right of x). The crescent with a
  // tip (cos t < 0, x0 in (-1, 1)) by crescent_cdf, as a function of s = x - x0.
  T cdf(T x) const {
    if (tip) return x > x0 ? crescent_cdf(x - x0) : T(0);
    const T disk = x > x0 ? std::max(T(0), seg0 - disk_right_of(x)) : T(0);
    if (cos_t >= T(0)) return ellipse_cdf(std::min(x, x0)) + disk;
    return x > x0 ? std::max(T(0), disk - (ellipse_cdf(x) - ellipse_cdf(x0))) : T(0);
  }
  // The crescent's chord at x = x0 + s, s >= 0: the disk's half-height c, E's half-height m (0 right of E), and
  // R's half-chord w = c - m as (c^2 - m^2) / (c + m) = (sin t sin(alpha) s / A)^2 / (c + m) (header comment;
  // s / A, not tan(t) s, which overflows for cos t -> 0). All from s, not from a rounded x = x0 + s.
  struct CrescentChord {
    T c, m, w;
  };
  CrescentChord crescent_chord(T s) const {
    const T one_minus_x = (T(1) - x0) - s, one_plus_x = (T(1) + x0) + s;
    const T c = std::sqrt(std::max(T(0), one_minus_x * one_plus_x));
    if (!(A > T(0))) return {c, T(0), c};
    const T v = s / A, one_minus_tau = (T(1) - tau0) - v;
    if (!(one_minus_tau > T(0))) return {c, T(0), c};
    const T m = sin_a * std::sqrt(one_minus_tau * (T(1) + tau0 + v));
    const T ks = sin_t * sin_a * v;
    const T w = c + m > T(0) ? std::min(c, ks * ks / (c + m)) : T(0);
    return {c, m, w};
  }
  // Area of the crescent between x0 and x0 + s, without the cancellation of the difference form above (header
  // comment): twice (upper half) the circular segment on the chord from the tip P0 = (x0, c0) to (x, c), minus E's
  // segment on the chord from P0 to (x, m) (E's right end (x_c + A, 0) once x is past it), plus the polygon
  // between the two chords and the vertical at x. Each segment as cut_disk_area_from_angle of its half-angle,
  // atan2(|chord| / 2, distance of the chord's midpoint from the centre), E's in its normalised coordinates
  // (tau, y / sin(alpha)) times the area factor sin(alpha) A; the chord's rise as a product, c0 - c =
  // s (x0 + x) / (c0 + c).
  T crescent_cdf(T s) const {
    if (!(s > T(0))) return T(0);
    const CrescentChord ch = crescent_chord(s);
    const T c = ch.c;
    const T sum_x = T(2) * x0 + s, sum_c = c0 + c;
    const T rise_c = sum_c > T(0) ? s * sum_x / sum_c : T(0);
    const T circle = cut_disk_area_from_angle(std::atan2(std::hypot(s, rise_c), std::hypot(sum_x, sum_c)));
    T ellipse = T(0), polygon;
    const T v_end = T(1) - tau0;  // E's right end at s = A (1 - tau0)
    const T v = A > T(0) ? std::min(s / A, v_end) : T(0);
    if (v > T(0)) {
      const T tau = tau0 + v, n = std::sqrt(std::max(T(0), (v_end - v) * (T(1) + tau)));
      const T sum_tau = tau0 + tau, sum_n = n0 + n;
      const T rise_n = sum_n > T(0) ? v * sum_tau / sum_n : T(0);
      ellipse = sin_a * A * cut_disk_area_from_angle(std::atan2(std::hypot(v, rise_n), std::hypot(sum_tau, sum_n)));
    }
    if (A > T(0) && s / A < v_end)
      polygon = s * ch.w / T(2);
    else
      polygon = (c0 * (s - A * v_end) + c * s) / T(2);
    return T(2) * std::max(T(0), circle - ellipse + polygon);
  }
  // Half-height of E at abscissa x (0 outside it).
  T ellipse_half_height(T x) const {
    if (!(A > T(0))) return T(0);
    const T t = std::clamp((x - xc) / A, T(-1), T(1));
    return sin_a * std::sqrt((T(1) - t) * (T(1) + t));
  }
};

template <class T> CosineCapView<T> make_cosine_cap_view(const Cap<T>& cap, const Vec3<T>& n) {
  CosineCapView<T> v;
  v.cap = cap;
  if (!all_finite(cap.axis) || !all_finite(n) || !std::isfinite(cap.one_minus_cos))
    return v.reason = NoSample::kNonFinite, v;
  if (!(cap.one_minus_cos > T(0))) return v.reason = NoSample::kZeroSize, v;
  const T omc = std::min(T(2), cap.one_minus_cos);
  v.cos_a = T(1) - omc;
  v.sin_a = std::sqrt(std::max(T(0), omc * (T(2) - omc)));
  v.ez = n;
  v.cos_t = std::clamp(cap.axis.dot(n), T(-1), T(1));
  const Vec3<T> tangential = cap.axis - v.cos_t * n;
  v.sin_t = cap.axis.cross(n).norm();
  if (v.sin_t > T(0) && tangential.norm() > T(0))
    v.ex = tangential / tangential.norm();
  else
    v.ex = Frame<T>::from_z(n).x, v.sin_t = T(0);
  v.ey = v.ez.cross(v.ex);
  v.xc = v.sin_t * v.cos_a;
  v.A = v.sin_a * std::abs(v.cos_t);
  // x >= x0 <=> cos(alpha) - x sin(t) <= 0; clamped to +-2 (only comparisons with x in [-1, 1] matter).
  if (v.sin_t > T(0))
    v.x0 = std::clamp(v.cos_a / v.sin_t, T(-2), T(2));
  else
    v.x0 = v.cos_a > T(0) ? T(2) : T(-2);
  // The disk's area right of x0 as a segment area (cdf): x0 itself is known to an absolute eps either way.
  v.seg0 = v.x0 >= T(1) ? T(0) : v.x0 <= T(-1) ? kPi<T> : CosineCapView<T>::disk_right_of(v.x0);
  // R = E exactly when the cap lies entirely above the horizon, alpha + t <= pi/2, i.e. cos(alpha) >= sin(t) (both
  // angles in [0, pi/2] there). The test x0 >= x_c + A (= sin(t + alpha)) is equivalent only for cos(t) > 0: at
  // cos(t) = 0 it reads x0 >= x_c, which holds up to rounding for any alpha (found by fuzz_sptd_double: a cap of
  // half-angle 24 deg with its axis on the horizon, cos(t) = 5e-39, got the area of its degenerate ellipse, 2.5e-39,
  // and a density of 3e40 instead of 1455, issue 7).
  v.ellipse_only = v.cos_t >= T(0) && v.cos_a >= v.sin_t;
  v.tip = v.cos_t < T(0) && v.x0 > T(-1) && v.x0 < T(1);
  if (v.tip) {
    // P0 must lie on both curves to rounding, or crescent_cdf's three terms (each ~c0 near a tip at x0 -> +-1)
    // no longer cancel to the tip's cubic mass. Of E's normalised coordinates there, tau0 = (x0 - x_c) / A and
    // n0 = sqrt(1 - tau0^2), whichever is the smaller is taken directly and the other from it (the square root of
    // a difference is well conditioned only for the smaller one):
    //  * near E's vertex (|tau0| > 1/sqrt 2), n0 = c0 / sin(alpha) (E's half-height m0 = c0 at the tangency,
    //    c^2 - m^2 = 0 there, header comment), c0 = sqrt(1 - x0^2), and tau0 = +-sqrt(1 - n0^2) on x0's side of
    //    x_c. From x0 - x_c instead, n0 was the square root of a difference within rounding of 0 (found by
    //    fuzz_sptd_double 4d8f70f9: a tip at 1 + x0 = 1.1e-16, the cap's boundary tangent to the horizon at E's
    //    vertex, c0 = 1.49e-8 against sin(alpha) n0 = 1.38e-8, the area 4.7e-11 off relatively, issue 7);
    //  * elsewhere tau0 = (x0 - x_c) / A and n0 from it. From c0 / sin(alpha) instead, tau0 was the square root of
    //    1 - n0^2 with n0 within rounding of 1 (found by fuzz_sptd_double bd9360f1 and 9219e2fc: a near-hemisphere
    //    image cap with x0 - x_c = 2.8e-14 resp. 1.5e-10, tau0 off by up to sqrt(eps); the area 2.1e-8 resp.
    //    4.1e-10 off relatively; both passed before the first branch was applied everywhere, issue 7).
    // The area is insensitive to where along the circle P0 then sits: moving it by d changes the mass between it
    // and the true tip by O(d^3).
    v.c0 = std::sqrt((T(1) - v.x0) * (T(1) + v.x0));
    const T tau_x = v.A > T(0) ? std::clamp((v.x0 - v.xc) / v.A, T(-1), T(1)) : T(1);
    if (std::abs(tau_x) <= std::numbers::sqrt2_v<T> / T(2)) {
      v.tau0 = tau_x;
      v.n0 = std::sqrt((T(1) - v.tau0) * (T(1) + v.tau0));
    } else {
      v.n0 = v.A > T(0) && v.sin_a > T(0) ? std::min(T(1), v.c0 / v.sin_a) : T(0);
      v.tau0 = std::copysign(std::sqrt((T(1) - v.n0) * (T(1) + v.n0)), tau_x);
    }
  }
  v.area = v.ellipse_only ? kPi<T> * v.sin_a * v.A : v.cdf(T(1));
  if (!(v.area > T(0)) || !std::isfinite(v.area)) return v.reason = NoSample::kBelowHorizon, v;
  return v;
}

// Integral of D_std over a cap: the uniform one is omc / 2 (solid angle / 4 pi); the clamped cosine one
// is the projected solid angle / pi.
template <class T> T base_cap_integral(const Sptd<T>& d, const Cap<T>& c) {
  if (d.base == SptdBase::kUniform) return std::min(T(2), c.one_minus_cos) / T(2);
  const CosineCapView<T> v = make_cosine_cap_view(c, d.base_axis);
  return v.valid() ? v.area / kPi<T> : T(0);
}

// Eq. 10: the integral of the SPTD over the cap C.
template <class T> T sptd_cap_integral(const Sptd<T>& d, const Cap<T>& c) {
  return base_cap_integral(d, pivot_transform_cap(c, d.pivot));
}

// ---- Intersection of two caps (Appendix B) ---------------------------------------------------------------------

// Angles from chord lengths (accurate for tiny caps): psi = 2 asin(sqrt(omc / 2)).
template <class T> T cap_half_angle(const Cap<T>& c) {
  return T(2) * std::asin(std::sqrt(std::clamp(c.one_minus_cos / T(2), T(0), T(1))));
}
template <class T> T angle_between_unit(const Vec3<T>& a, const Vec3<T>& b) {
  return T(2) * std::asin(std::min(T(1), (a - b).norm() / T(2)));
}

// Eqs. 35-36 (Oat & Sander 2007; Tovchigrechko & Vakser 2001). One case the paper's Eq. 35 omits: when the
// two caps together cover the sphere (psi_1 + psi_2 + psi_d >= 2 pi) the intersection is A_1 + A_2 - 4 pi.
template <class T> T cap_intersection_solid_angle(const Cap<T>& c1, const Cap<T>& c2) {
  T p1 = cap_half_angle(c1), p2 = cap_half_angle(c2);
  T a1 = c1.solid_angle(), a2 = c2.solid_angle();
  if (p1 > p2) std::swap(p1, p2), std::swap(a1, a2);
  const T pd = angle_between_unit(c1.axis, c2.axis);
  if (p2 - p1 >= pd) return a1;                                                   // the smaller cap inside the larger
  if (p1 + p2 <= pd) return T(0);                                                 // disjoint
  if (p1 + p2 + pd >= kTwoPi<T>) return std::max(T(0), a1 + a2 - T(4) * kPi<T>);  // union covers the sphere
  const T c1c = std::cos(p1), c2c = std::cos(p2), cd = std::cos(pd);
  const T s1 = std::sin(p1), s2 = std::sin(p2), sd = std::sin(pd);
  auto acos_c = [](T x) { return std::acos(std::clamp(x, T(-1), T(1))); };
  const T b = kTwoPi<T> - kTwoPi<T> * c1c - kTwoPi<T> * c2c - T(2) * acos_c((cd - c1c * c2c) / (s1 * s2)) +
              T(2) * c1c * acos_c((c1c * cd - c2c) / (s1 * sd)) + T(2) * c2c * acos_c((c2c * cd - c1c) / (s2 * sd));
  return std::clamp(b, T(0), std::min(a1, a2));
}

// Eqs. 37-38: the approximation of Oat & Sander 2007 used by the paper's real-time implementation (only for
// the "otherwise" case of Eq. 35; the other cases are exact as above).
template <class T> T cap_intersection_solid_angle_approx(const Cap<T>& c1, const Cap<T>& c2) {
  T p1 = cap_half_angle(c1), p2 = cap_half_angle(c2);
  T a1 = c1.solid_angle();
  if (p1 > p2) std::swap(p1, p2), a1 = c2.solid_angle();
  const T pd = angle_between_unit(c1.axis, c2.axis);
  if (p2 - p1 >= pd) return a1;
  if (p1 + p2 <= pd) return T(0);
  const T x = std::clamp((p1 + p2 - pd) / (T(2) * p1), T(0), T(1));
  return a1 * (T(3) * x * x - T(2) * x * x * x);
}

// Eqs. 17-19: a uniform SPTD integrated over the intersection D = C n H of two caps is
// (1 / 4 pi) |g(C) n g(H)|.
template <class T> T sptd_uniform_two_cap_integral(const Vec3<T>& rp, const Cap<T>& c, const Cap<T>& h) {
  const T k = pivot_k(rp);
  return cap_intersection_solid_angle(pivot_transform_cap(c, rp, k), pivot_transform_cap(h, rp, k)) / (T(4) * kPi<T>);
}

// ---- Sampling D_std over a cap -----------------------------------------------------------------------------

// Uniform over a cap (Shirley 1996 cone sampling, as in sphere.h): 1 - cos = u0 (1 - cos(psi)).
// The sample minus the cap's axis, in the axis' frame: (sin cos phi, sin sin phi, -(1 - cos)).
template <class T> Vec3<T> uniform_cap_offset_local(T cap_one_minus_cos, const Vec2<T>& u) {
  const T omc = u[0] * std::min(T(2), cap_one_minus_cos);
  const T sin_t = std::sqrt(std::max(T(0), omc * (T(2) - omc)));
  const T phi = kTwoPi<T> * u[1];
  return Vec3<T>(sin_t * std::cos(phi), sin_t * std::sin(phi), -omc);
}
template <class T> Vec3<T> sample_uniform_cap_direction(const Cap<T>& c, const Vec2<T>& u) {
  const Vec3<T> w =
      Frame<T>::from_z(c.axis).to_world(Vec3<T>(uniform_cap_offset_local(c.one_minus_cos, u) + Vec3<T>(0, 0, 1)));
  return w / w.norm();
}

// Clamped cosine over a cap: a point of R (header comment) lifted to the hemisphere of n.
template <class T> Vec3<T> sample_cosine_cap_direction(const CosineCapView<T>& v, const Vec2<T>& u) {
  T x, y, z;
  if (v.ellipse_only) {
    // Uniform in E: the uniform disk (polar map) under the affine map onto E.
    const T r = std::sqrt(u[0]), phi = kTwoPi<T> * u[1];
    x = v.xc + v.A * r * std::cos(phi);
    y = v.sin_a * r * std::sin(phi);
    z = std::sqrt(std::max(T(0), (T(1) - x) * (T(1) + x) - y * y));
  } else {
    // x from the area-CDF of R (TOMS 748 on a bracket: the CDF is monotone and continuous), then y uniform on
    // R's chord at x. Hand-rolled inversion because the CDF is ours; the root finder is Boost's.
    const T target = u[0] * v.area;
    T lo = T(-1), hi = T(1);
    if (v.cos_t >= T(0))
      lo = std::max(lo, v.xc - v.A);
    else
      lo = std::max(lo, std::min(v.x0, T(1)));
    // Right of x_full (x0 for cos t >= 0, E's right end x_c + A for the crescent) R is the full disk chord, and the
    // area right of x is disk_right_of(x): there x is found from that upper tail, (1 - u0) area, which keeps its
    // relative precision as u0 -> 1 where the CDF's u0 area - cdf(x) cancels (float: pdf(dir) and the warp's area
    // element 3.4e-5 apart at u0 = 0.9996 in the crossing configuration, and up to 5e-2 for u0 > 0.9999 in the
    // crescent, measured against the long double sampler; issue 5). The switch is at x_full, a kink of the warp
    // anyway (registered in kernels_sptd.h).
    const T upper = (T(1) - u[0]) * v.area;
    const T x_full = v.cos_t >= T(0) ? v.x0 : v.xc + v.A;
    const T seg_full = v.cos_t >= T(0) ? v.seg0 : CosineCapView<T>::disk_right_of(x_full);
    // The upper tail is solved for the angle theta, x = cos(theta): near x = 1 a rounded x carries 1 - x, hence c
    // and the direction, only to ulp(1) / (1 - x) (float: directions 7.7e-6 rad off the long double sampler's and
    // pdf(dir) 1.7e-3 off at u0 = 1 - 6e-7 in the crescent); c = sin(theta) keeps its relative precision.
    const bool upper_tail = x_full < T(1) && upper <= seg_full;
    if (upper_tail) lo = T(0), hi = std::acos(std::max(T(-1), x_full));
    // The crescent with a tip, left of x_full: solved for s = x - x0 on [0, x_full - x0] by crescent_cdf, to s's own
    // relative precision (a relative tolerance on x ~ 0.4 leaves s = 1e-2 off by up to 1e-5 relative, and
    // z ~ tan(t) s with it); the chord from s too (crescent_chord).
    const bool by_s = v.tip && !upper_tail;
    if (by_s) lo = T(0), hi = std::max(T(0), std::min(x_full, T(1)) - v.x0);
    // The unknown q is theta in the upper tail, s = x - x0 in the crescent with a tip, and x otherwise.
    auto f = [&](T q) {
      return upper_tail ? CosineCapView<T>::disk_right_of_angle(q) - upper
             : by_s     ? v.crescent_cdf(q) - target
                        : v.cdf(q) - target;
    };
    T q;
    const T flo = f(lo), fhi = f(hi);
    if (flo >= T(0))
      q = lo;
    else if (fhi <= T(0))
      q = hi;
    else {
      std::uintmax_t iters = 200;
      const auto tol = boost::math::tools::eps_tolerance<T>(std::numeric_limits<T>::digits - 2);
      const auto r = boost::math::tools::toms748_solve(f, lo, hi, flo, fhi, tol, iters);
      q = (r.first + r.second) / T(2);
    }
    T c, m, w;  // the disk's and E's half-heights at x, and w = c - m (R's half-chord in the crescent)
    if (upper_tail) {
      x = std::cos(q), c = std::sin(q), m = T(0), w = c;  // right of x_full: R's chord is the disk's
    } else if (by_s) {
      const auto ch = v.crescent_chord(q);
      x = v.x0 + q, c = ch.c, m = ch.m, w = ch.w;
    } else {
      x = q;
      c = std::sqrt(std::max(T(0), (T(1) - x) * (T(1) + x)));
      m = std::min(c, v.ellipse_half_height(x));
      w = c - m;
    }
    const T s = T(2) * u[1] - T(1);  // in [-1, 1)
    // 1 - |s| from u1 itself (exact), and c - |y| from it in each branch: the lift z = sqrt(c^2 - y^2) =
    // sqrt((c - |y|)(c + |y|)) of a point near the chord's end would otherwise be the difference of two nearly
    // equal squares (float: pdf(dir) and the warp's area element 7.4e-5 apart at u1 = 0.99985 in the crossing
    // configuration, and 3 in 1e7 samples declined with z rounded to 0 in the crescent; issue 5). The branch by
    // the inversion's piece, not by comparing a rounded cos(theta) with x0.
    const T one_minus_abs_s = T(2) * std::min(u[1], T(1) - u[1]);
    T c_minus_abs_y;
    if (upper_tail || (v.cos_t >= T(0) && x >= v.x0))
      y = s * c, c_minus_abs_y = c * one_minus_abs_s;
    else if (v.cos_t >= T(0))
      y = s * m, c_minus_abs_y = w + m * one_minus_abs_s;
    else {
      y = std::copysign(m + w * std::abs(s), s);  // the crescent: jumps across E at u1 = 1/2
      c_minus_abs_y = w * one_minus_abs_s;
    }
    z = std::sqrt(std::max(T(0), c_minus_abs_y * (c + std::abs(y))));
  }
  const Vec3<T> w = x * v.ex + y * v.ey + z * v.ez;
  return w / w.norm();
}

// ---- SPTDs over a cap (Sec. 4.2, Fig. 5) -----------------------------------------------------------------------

template <class T> struct SptdCapGeometry {
  Sptd<T> sptd;
  Cap<T> cap = Cap<T>{Vec3<T>(T(0), T(0), T(1)), T(2)};  // default: the whole sphere

  template <class U> SptdCapGeometry<U> cast() const {
    SptdCapGeometry<U> g;
    g.sptd.pivot = sptd.pivot.template cast<U>();
    g.sptd.base = sptd.base;
    g.sptd.base_axis = sptd.base_axis.template cast<U>();
    g.cap = Cap<U>{cap.axis.template cast<U>(), U(cap.one_minus_cos)};
    return g;
  }
};

template <class T> struct SptdCapView {
  NoSample reason = NoSample::kNone;
  Sptd<T> sptd;
  T k = 0;
  Cap<T> cap, image;  // C and g(C)
  // Uniform base with a small image: g(C)'s axis minus r_p (pivot_transform_cap); samples and densities are then
  // formed from offsets to r_p, never from unit vectors near it.
  bool image_relative = false;
  Vec3<T> image_offset = Vec3<T>::Zero();
  CosineCapView<T> cosine;  // for the clamped-cosine base
  T base_integral = 0;      // integral of D_std over g(C) = integral of D over C (Eq. 10)
  bool valid() const { return reason == NoSample::kNone; }
};

template <class T> SptdCapView<T> make_sptd_cap_view(const SptdCapGeometry<T>& g) {
  SptdCapView<T> v;
  v.sptd = g.sptd;
  v.cap = g.cap;
  if (!all_finite(g.sptd.pivot) || !all_finite(g.sptd.base_axis) || !all_finite(g.cap.axis) ||
      !std::isfinite(g.cap.one_minus_cos))
    return v.reason = NoSample::kNonFinite, v;
  if (!valid_pivot(g.sptd.pivot)) return v.reason = NoSample::kInvalidGeometry, v;
  if (g.cap.one_minus_cos < T(0)) return v.reason = NoSample::kNegativeSize, v;
  if (!(g.cap.one_minus_cos > T(0))) return v.reason = NoSample::kZeroSize, v;
  if (!normalize_normal(g.cap.axis, v.cap.axis)) return v.reason = NoSample::kInvalidGeometry, v;
  if (g.sptd.base == SptdBase::kClampedCosine && !normalize_normal(g.sptd.base_axis, v.sptd.base_axis))
    return v.reason = NoSample::kBadNormal, v;
  v.k = pivot_k(v.sptd.pivot);
  if (!(v.k > T(0))) return v.reason = NoSample::kInvalidGeometry, v;
  v.image = v.sptd.base == SptdBase::kUniform
                ? pivot_transform_cap(v.cap, v.sptd.pivot, v.k, &v.image_offset, &v.image_relative)
                : pivot_transform_cap(v.cap, v.sptd.pivot, v.k);
  if (!(v.image.one_minus_cos > T(0)) || !all_finite(v.image.axis)) return v.reason = NoSample::kTooSmall, v;
  if (v.sptd.base == SptdBase::kUniform) {
    v.base_integral = v.image.one_minus_cos / T(2);
  } else {
    v.cosine = make_cosine_cap_view(v.image, v.sptd.base_axis);
    if (!v.cosine.valid()) return v.reason = v.cosine.reason, v;
    v.base_integral = v.cosine.area / kPi<T>;
  }
  // The normalised base density 1 / |g(C)| resp. 1 / area must be representable (as for sphere lights, sphere.h).
  const T norm = v.sptd.base == SptdBase::kUniform ? v.image.solid_angle() : v.cosine.area;
  if (!std::isfinite(T(1) / norm)) return v.reason = NoSample::kTooSmall, v;
  return v;
}

// Density of the original distribution restricted to g(C), normalised, at w_i.
// Membership in g(C) by the squared chord from its axis, with a relative slack of 8 eps: a sample generated inside
// g(C) must test inside after the pivot round trip (two roundings).
template <class T> bool within_image(const SptdCapView<T>& v, T chord2_to_axis) {
  const T slack = T(8) * std::numeric_limits<T>::epsilon();
  return chord2_to_axis <= T(2) * v.image.one_minus_cos * (T(1) + slack);
}

template <class T> T base_cap_pdf(const SptdCapView<T>& v, const Vec3<T>& wi) {
  if (!within_image(v, (wi - v.image.axis).squaredNorm())) return T(0);
  if (v.sptd.base == SptdBase::kUniform) return T(1) / v.image.solid_angle();
  const T c = wi.dot(v.sptd.base_axis);
  return c > T(0) ? c / v.cosine.area : T(0);
}

template <class T> T pdf_sptd_cap(const SptdCapView<T>& v, const Vec3<T>& w) {
  if (!v.valid() || !all_finite(w)) return T(0);
  const T len = w.norm();
  if (!(len > T(0))) return T(0);
  const Vec3<T> wu = w / len;
  // 0 outside C, tested on C itself, not only through the image: in T the image cap can swallow C's complement,
  // where its 1 - cos is within rounding of 2 (found by fuzz_sptd_double: |r_p| = 1 - 9e-13, a C of 120 deg whose
  // image is the sphere minus a cap of ~1e-12 rad, stored as 1 - cos = 2: pdf > 0 at 0.45 rad outside C, issue 7).
  // By the chord to the axis for C up to a hemisphere, to the antipode for larger C (whose complement's chord,
  // 2 - (1 - cos), is then exact), each with a relative slack of 8 eps plus a chord of 4 eps for the rounding of
  // unit directions; a relative slack on the chord to the axis would be ~1e-3 rad near the antipode in float.
  const T e = std::numeric_limits<T>::epsilon(), omc = v.cap.one_minus_cos;
  const bool in_c = omc <= T(1)
                        ? (wu - v.cap.axis).squaredNorm() <= T(2) * omc * (T(1) + T(8) * e) + T(16) * e * e
                        : (wu + v.cap.axis).squaredNorm() >= T(2) * (T(2) - omc) * (T(1) - T(8) * e) - T(16) * e * e;
  if (!in_c) return T(0);
  T p;
  if (v.image_relative) {
    // g(w) - r_p = k o / |o|^2, o = pivot_offset(w) (the anti-inversion form); g(w) - axis = that - image_offset.
    const Vec3<T> o = pivot_offset(wu, v.sptd.pivot);
    const T o2 = o.squaredNorm();
    p = o2 > T(0) && within_image(v, Vec3<T>((v.k / o2) * o - v.image_offset).squaredNorm())
            ? T(1) / v.image.solid_angle()
            : T(0);
  } else {
    p = base_cap_pdf(v, pivot_transform(wu, v.sptd.pivot, v.k));
  }
  // The product overflows for densities beyond T's range (a pivot within ~eps of the sphere, a tiny cap): no
  // density rather than Inf (found by fuzz_sptd_float, issue 7).
  const T pdf = p > T(0) ? p * pivot_jacobian(wu, v.sptd.pivot, v.k) : T(0);
  return std::isfinite(pdf) ? pdf : T(0);
}

template <class T> DirectionSample<T> sample_sptd_cap(const SptdCapView<T>& v, const Vec2<T>& u) {
  if (!v.valid()) return DirectionSample<T>::none(v.reason);
  DirectionSample<T> s;
  if (v.image_relative) {
    // w_i - r_p = (axis - r_p) - axis (1 - cos) + sin (cos phi e_x + sin phi e_y) (Shirley's cone sampling as in
    // sample_uniform_cap_direction), and w = g(w_i) = r_p - k q / |q|^2 for q = w_i - r_p (anti-inversion form).
    const Vec3<T> q =
        v.image_offset + Frame<T>::from_z(v.image.axis).to_world(uniform_cap_offset_local(v.image.one_minus_cos, u));
    const T q2 = q.squaredNorm();
    if (!(q2 > T(0))) return DirectionSample<T>::none(NoSample::kOnSilhouette);
    const Vec3<T> w = v.sptd.pivot - (v.k / q2) * q;
    s.direction = w / w.norm();
  } else {
    const Vec3<T> wi = v.sptd.base == SptdBase::kUniform ? sample_uniform_cap_direction(v.image, u)
                                                         : sample_cosine_cap_direction(v.cosine, u);
    s.direction = pivot_transform(wi, v.sptd.pivot, v.k);  // Fig. 5 (4): w = g(w_i)
  }
  s.pdf = pdf_sptd_cap(v, s.direction);
  if (!(s.pdf > T(0)) || !std::isfinite(s.pdf) || !all_finite(s.direction))
    return DirectionSample<T>::none(NoSample::kOnSilhouette);
  return s;
}

template <class T> DirectionSample<T> sample_sptd_cap(const SptdCapGeometry<T>& g, const Vec2<T>& u) {
  return sample_sptd_cap(make_sptd_cap_view(g), u);
}
template <class T> T pdf_sptd_cap(const SptdCapGeometry<T>& g, const Vec3<T>& w) {
  return pdf_sptd_cap(make_sptd_cap_view(g), w);
}

// ---- Phase functions (Sec. 6.2) ----------------------------------------------------------------------------

// Eq. 25: the uniform SPTD with pivot g_p w_o, as a function of mu = w_o . w.
template <class T> T pivot_phase_function(T mu, T gp) {
  const T r = (T(1) - gp * gp) / (T(1) + gp * gp - T(2) * gp * mu);
  return r * r / (T(4) * kPi<T>);
}
// Eq. 26.
template <class T> T henyey_greenstein(T mu, T g) {
  const T d = T(1) + g * g - T(2) * g * mu;
  return (T(1) - g * g) / (T(4) * kPi<T> * d * std::sqrt(d));
}
// Eqs. 27-28: the paper's rational fit g_p(g).
template <class T> T hg_to_pivot(T g) {
  const T u = std::abs(g);
  const T q = (T(0.7489L) * u - T(0.6121L) * u * u) / (T(1) - T(0.8409L) * u + T(0.0223L) * u * u);
  return std::copysign(q, g);
}

// The pivot phase function as an SPTD geometry: pivot g_p w_o, uniform base, over a cap (the whole sphere
// by default).
template <class T>
SptdCapGeometry<T> pivot_phase_geometry(const Vec3<T>& wo, T gp,
                                        const Cap<T>& cap = Cap<T>{Vec3<T>(T(0), T(0), T(1)), T(2)}) {
  SptdCapGeometry<T> g;
  g.sptd.pivot = gp * wo;
  g.sptd.base = SptdBase::kUniform;
  g.cap = cap;
  return g;
}

// Sec. 6.2, Fig. 17 (right): the pivot phase function sampled jointly with a sphere light, i.e. restricted
// to the cone the light subtends. The density is normalised over that cone.
template <class T>
SptdCapGeometry<T> pivot_phase_sphere_light_geometry(const Vec3<T>& wo, T gp, const SphereLightGeometry<T>& light) {
  // A medium has no horizon: aim the shading normal at the light so that only the light's own validity counts.
  SphereLightGeometry<T> g = light;
  g.shading.normal = light.light.center - light.shading.position;
  const SphereView<T> sv = make_sphere_view(g);
  Cap<T> cap = sv.cap();
  if (!sv.valid()) cap.one_minus_cos = T(0);  // gives "zero size": no sample
  return pivot_phase_geometry(wo, gp, cap);
}

// ---- Catalogue traits (warpcheck/catalogue.h) ----------------------------------------------------------------

// An SPTD over a cap with base distribution B (Sec. 4.2); the geometry's base is set to B. The pivot phase
// function (pivot_phase_geometry) and its joint sampling with a sphere light (pivot_phase_sphere_light_geometry)
// are the uniform kernel on particular geometry.
template <class T, SptdBase B> struct SptdCapKernel {
  static constexpr bool kUniform = B == SptdBase::kUniform;
  static constexpr const char* name = kUniform ? "sptd-uniform-cap" : "sptd-cosine-cap";
  static constexpr const char* description =
      kUniform ? "uniform SPTD over a cap, Dupuy et al. 2017" : "clamped-cosine SPTD over a cap, Dupuy et al. 2017";
  using Scalar = T;
  using Geometry = SptdCapGeometry<T>;
  using View = SptdCapView<T>;
  static View view(const Geometry& g) {
    Geometry with_base = g;
    with_base.sptd.base = B;
    return make_sptd_cap_view(with_base);
  }
  static DirectionSample<T> sample(const View& v, const Vec2<T>& u) { return sample_sptd_cap(v, u); }
  static T pdf(const View& v, const Vec3<T>& w) { return pdf_sptd_cap(v, w); }
  // The support lies in C.
  static Cap<T> bounding_cap(const Geometry& g) {
    Cap<T> c = g.cap;
    if (!normalize_normal(g.cap.axis, c.axis)) c.axis = Vec3<T>(T(0), T(0), T(1));
    return c;
  }
  static T normaliser(const View& v) { return v.base_integral; }  // the integral of D over C (Eq. 10)
  // The cosine base near the horizon: x(u0) inverts an area-CDF whose chord length has square-root corners where x
  // passes the ends of the ellipse E and the horizon abscissa x0; y jumps across E at u1 = 1/2 in the crescent.
  static std::vector<T> kinks_u0(const Geometry& g) {
    std::vector<T> kinks;
    if constexpr (!kUniform) {
      const View v = view(g);
      if (v.valid() && !v.cosine.ellipse_only) {
        const auto& c = v.cosine;
        for (T x : {c.xc - c.A, c.xc + c.A, c.x0})
          if (x > T(-1) && x < T(1)) kinks.push_back(c.cdf(x) / c.area);
      }
    }
    return kinks;
  }
  static std::vector<T> kinks_u1(const Geometry& g) {
    if constexpr (!kUniform) {
      const View v = view(g);
      if (v.valid() && !v.cosine.ellipse_only) return {T(0.5L)};
    }
    return {};
  }
};
template <class T> using SptdUniformCap = SptdCapKernel<T, SptdBase::kUniform>;
template <class T> using SptdCosineCap = SptdCapKernel<T, SptdBase::kClampedCosine>;

}  // namespace warpcheck
