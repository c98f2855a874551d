// warpcheck/sptd.h: spherical pivot transformed distributions (SPTDs), Dupuy, Heitz & Belcour 2017,
// "A Spherical Cap Preserving Parameterization for Spherical Distributions".
//
// Equation numbers are the paper's: the pivot transformation g (Eqs. 2-4), the image of a cap (Eqs. 6-7), SPTD
// densities and cap integrals (Eqs. 8, 10, 17-19, 35-37), sampling over a cap (Sec. 4.2), phase functions (Sec. 6.2).
//
// Beyond the paper (derivations: docs/derivations/sptd.md): on the sphere g is the anti-inversion
// r_p + k (r_p - w) / |r_p - w|^2; Eq. 6's axis is the oriented in-plane bisector (the mean fails beyond a
// hemisphere); and the clamped cosine over a cap is sampled exactly through its orthographic projection R onto the
// disk of n (Malley's method): the cap's boundary projects to an ellipse E, R is E cut by the cap's plane (cos t >= 0)
// or the disk beyond the plane minus E (a crescent), R's area-CDF in x is closed-form and inverted by TOMS 748, and y
// is uniform on R's chord. This sampler is not projected_cap.h's; it shares only cut_disk_area_from_angle.
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

// ---- The pivot transformation (Sec. 3.2) ----

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

// r_p - w for the unit vector in w's direction: ((1 - cos theta) - (1 - |r_p|)) p - (w's part orthogonal to p),
// p = r_p / |r_p|. No length error of a rounded w, and |r_p - w| >= 1 - |r_p| > 0. A pivot below eps / 8 is 0.
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

// Eq. 2 on the unit sphere, in the anti-inversion form, for the unit vector in w's direction; renormalised.
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

namespace sptd_detail {

// Fig. 3 (1): the unit t orthogonal to w_c in the plane of w_c and r_p, by two Gram-Schmidt passes; any such t where
// it is rounding noise (every plane through w_c is then one of symmetry).
template <class T> Vec3<T> boundary_plane_direction(const Vec3<T>& wc, const Vec3<T>& rp) {
  Vec3<T> t = rp - rp.dot(wc) * wc;
  t -= t.dot(wc) * wc;
  const T tn = stable_norm(t);
  constexpr T e = std::numeric_limits<T>::epsilon();
  return tn > T(64) * e * stable_norm(rp) && tn > std::numeric_limits<T>::min() / e ? Vec3<T>(t / tn)
                                                                                    : Frame<T>::from_z(wc).x;
}

// The image axis minus r_p from o_i = r_p - p_i: q_i = k o_i / d_i^2, h = (q1 + q2) / 2, m = r_p + h, axis - r_p =
// h + m (1 - |m|) / |m|, 1 - |m|^2 = |q1 - q2|^2 / 4 (docs/derivations/sptd.md). False if not representable.
template <class T>
bool image_axis_offset(const Vec3<T>& rp, T k, const Vec3<T>& o1, const Vec3<T>& o2, T d1, T d2, Vec3<T>& off) {
  const Vec3<T> q1 = (k / (d1 * d1)) * o1, q2 = (k / (d2 * d2)) * o2;
  const Vec3<T> h = (q1 + q2) / T(2), m = rp + h;
  const T mn = m.norm();
  off = h + m * ((q1 - q2).squaredNorm() / T(4) / (T(1) + mn) / mn);
  return all_finite(off) && Vec3<T>(rp + off).norm() > T(0);
}

}  // namespace sptd_detail

// Eqs. 6-7, the axis as the oriented in-plane bisector: the cap g(C). axis_minus_pivot: if given, the image axis
// minus r_p to its own rounding, for a small image (below 30 degrees; *relative says whether it was set), whose
// unit vectors near r_p g would stretch by k / |w - r_p|^2 (docs/derivations/sptd.md).
template <class T> Cap<T> pivot_transform_cap(const Cap<T>& c, const Vec3<T>& rp, T k,
                                              Vec3<T>* axis_minus_pivot = nullptr, bool* relative = nullptr) {
  if (relative) *relative = false;
  if (c.one_minus_cos >= T(2)) return Cap<T>{c.axis, T(2)};  // the whole sphere maps onto itself
  const Vec3<T>& wc = c.axis;
  const Vec3<T> t = sptd_detail::boundary_plane_direction(wc, rp);
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
  // Orientation: g(w_c) lies inside g(C). Not tested where g(C)'s diameter, at most 2 alpha k / d_min^2 (Eq. 4),
  // is below pi/2: no complement is that small, and the test is noise for tiny images.
  const T rn = rp.norm();
  const bool contains_pivot = rn > T(0) && (rp / rn - wc).squaredNorm() <= T(2) * omc;
  const Vec3<T> o1 = pivot_offset(p1, rp), o2 = pivot_offset(p2, rp);  // r_p - p_i for unit p_i
  const T d1 = o1.norm(), d2 = o2.norm();
  const T d_min = contains_pivot ? T(1) - rn : std::min(d1, d2);
  const T alpha = T(2) * std::asin(std::min(T(1), std::sqrt(omc / T(2))));
  const bool surely_small = T(2) * alpha * k < kPi<T> / T(2) * d_min * d_min;
  if (!surely_small && (gc - axis).squaredNorm() > (g1 - axis).squaredNorm()) axis = -axis;
  // Eq. 7 as a chord, 1 - cos = |g_i - axis|^2 / 2; for a small image circle (within 30 degrees) by the inversion's
  // distance formula instead, sin(psi'') = k sin(alpha) / (|p1 - r_p| |p2 - r_p|), without cancellation.
  const T chord_denominator = d1 * d2;
  const T s = chord_denominator > T(0) ? k * sin_a / chord_denominator : T(1);
  if (!(s < T(0.5)))
    return Cap<T>{axis, std::min(T(2), ((g1 - axis).squaredNorm() + (g2 - axis).squaredNorm()) / T(4))};
  const T small = s * s / (T(1) + std::sqrt((T(1) - s) * (T(1) + s)));
  const T image_omc = axis.dot(g1) >= T(0) ? small : T(2) - small;
  Vec3<T> off = Vec3<T>::Zero();
  if (axis_minus_pivot && image_omc == small && sum.squaredNorm() >= diff.squaredNorm() && d1 > T(0) && d2 > T(0) &&
      sptd_detail::image_axis_offset(rp, k, o1, o2, d1, d2, off)) {
    *axis_minus_pivot = off;
    const Vec3<T> a = rp + off;
    axis = a / a.norm();
    if (relative) *relative = true;
  }
  return Cap<T>{axis, image_omc};
}
template <class T> Cap<T> pivot_transform_cap(const Cap<T>& c, const Vec3<T>& rp) {
  return pivot_transform_cap(c, rp, pivot_k(rp));
}

// ---- The original distributions D_std and their cap integrals ----

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

// The clamped cosine restricted to a cap, in the projected-disk form (header comment).
template <class T> struct CosineCapView {
  NoSample reason = NoSample::kNone;
  Cap<T> cap;
  Vec3<T> ex = Vec3<T>::Zero(), ey = Vec3<T>::Zero(), ez = Vec3<T>::Zero();  // ez = n; ex towards the cap axis
  T cos_a = 0, sin_a = 0;                                                    // cap half-angle alpha
  T cos_t = 0, sin_t = 0;                                                    // angle t between the cap axis and n
  T xc = 0, A = 0, x0 = 0;    // ellipse centre and x semi-axis; x >= x0: full chord side
  T seg0 = 0;                 // area of the unit disk right of x0, without cancellation (make_cosine_cap_view)
  bool ellipse_only = false;  // R = E (cap entirely above the horizon)
  // The crescent's tip (x0, +-c0), x0 in (-1, 1), and E's normalised coordinates there, tau0 and n0.
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
  // Area of the unit disk right of x = cos(theta), theta in [0, pi], without cancellation.
  static T disk_right_of_angle(T theta) {
    return theta <= kPi<T> / T(2) ? cut_disk_area_from_angle(theta) : kPi<T> - cut_disk_area_from_angle(kPi<T> - theta);
  }
  static T disk_right_of(T x) { return disk_right_of_angle(std::acos(std::clamp(x, T(-1), T(1)))); }
  // Area of R with abscissa < x; the disk part between x0 and x as seg0 - (disk right of x), not a difference of
  // two areas ~pi; the crescent with a tip by crescent_cdf.
  T cdf(T x) const {
    if (tip) return x > x0 ? crescent_cdf(x - x0) : T(0);
    const T disk = x > x0 ? std::max(T(0), seg0 - disk_right_of(x)) : T(0);
    if (cos_t >= T(0)) return ellipse_cdf(std::min(x, x0)) + disk;
    return x > x0 ? std::max(T(0), disk - (ellipse_cdf(x) - ellipse_cdf(x0))) : T(0);
  }
  // The crescent's chord at x = x0 + s from s: the disk's and E's half-heights c, m and R's half-chord
  // w = c - m = (sin t sin(alpha) s / A)^2 / (c + m) (c^2 - m^2 has a double root at the tip).
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
  // Area of the crescent between x0 and x0 + s without cancellation: twice (the circle's segment on the chord from
  // the tip P0 to (x, c) - E's segment on the chord from P0 to (x, m) + the polygon between the chords), segments
  // by cut_disk_area_from_angle of their half-angles (docs/derivations/sptd.md).
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

template <class T> NoSample fill_cosine_cap_view(const Cap<T>& cap, const Vec3<T>& n, CosineCapView<T>& v) {
  v.cap = cap;
  if (!all_finite(cap.axis) || !all_finite(n) || !std::isfinite(cap.one_minus_cos)) return NoSample::kNonFinite;
  if (!(cap.one_minus_cos > T(0))) return NoSample::kZeroSize;
  const T omc = std::min(T(2), cap.one_minus_cos);
  v.cos_a = T(1) - omc;
  v.sin_a = std::sqrt(std::max(T(0), omc * (T(2) - omc)));
  v.ez = n;
  v.cos_t = std::clamp(cap.axis.dot(n), T(-1), T(1));
  // e_x: the axis' part orthogonal to n, a difference known to an absolute ~eps, so that one pass leaves e_x . n ~
  // eps / sin t. The frame must be orthonormal to rounding: x e_x + y e_y + z n is the sample at abscissa x only then
  // (a tilt d = e_x . n shifts every sample by ~d, so the warp is not the density's). A second pass where |d| exceeds
  // 4 eps; below sin t = 64 eps the axis is +-n to rounding (|d| could reach 1) and any frame about n serves.
  const Vec3<T> tangential = cap.axis - v.cos_t * n;
  v.sin_t = cap.axis.cross(n).norm();
  constexpr T eps = std::numeric_limits<T>::epsilon();
  if (v.sin_t > T(64) * eps && tangential.norm() > T(0)) {
    v.ex = tangential / tangential.norm();
    if (const T d = v.ex.dot(n); std::abs(d) > T(4) * eps) {
      const Vec3<T> again = v.ex - d * n;
      v.ex = again / again.norm();
    }
  } else {
    v.ex = Frame<T>::from_z(n).x, v.sin_t = T(0);
  }
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
  // R = E exactly when alpha + t <= pi/2, i.e. cos(alpha) >= sin(t) (x0 >= x_c + A fails at cos t = 0).
  v.ellipse_only = v.cos_t >= T(0) && v.cos_a >= v.sin_t;
  v.tip = v.cos_t < T(0) && v.x0 > T(-1) && v.x0 < T(1);
  if (v.tip) {
    // P0 on both curves to rounding: of tau0 and n0 the smaller is taken directly, n0 = c0 / sin(alpha) near E's
    // vertex, else tau0, and the other from it.
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
  if (!(v.area > T(0)) || !std::isfinite(v.area)) return NoSample::kBelowHorizon;
  return NoSample::kNone;
}

template <class T> CosineCapView<T> make_cosine_cap_view(const Cap<T>& cap, const Vec3<T>& n) {
  CosineCapView<T> v;  // filled in place: no copy of the view on return
  v.reason = fill_cosine_cap_view(cap, n, v);
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

// ---- Intersection of two caps (Appendix B) ----

// Angles from chord lengths (accurate for tiny caps): psi = 2 asin(sqrt(omc / 2)).
template <class T> T cap_half_angle(const Cap<T>& c) {
  return T(2) * std::asin(std::sqrt(std::clamp(c.one_minus_cos / T(2), T(0), T(1))));
}
template <class T> T angle_between_unit(const Vec3<T>& a, const Vec3<T>& b) {
  return T(2) * std::asin(std::min(T(1), (a - b).norm() / T(2)));
}

// Eqs. 35-36 (Oat & Sander 2007; Tovchigrechko & Vakser 2001), and the case Eq. 35 omits: caps covering the sphere
// together (psi_1 + psi_2 + psi_d >= 2 pi) intersect in A_1 + A_2 - 4 pi.
template <class T> T cap_intersection_solid_angle(const Cap<T>& c1, const Cap<T>& c2) {
  T p1 = cap_half_angle(c1), p2 = cap_half_angle(c2);
  T a1 = c1.solid_angle(), a2 = c2.solid_angle();
  if (p1 > p2) std::swap(p1, p2), std::swap(a1, a2);
  const T pd = angle_between_unit(c1.axis, c2.axis);
  if (p2 - p1 >= pd) return a1;                                                   // the smaller cap inside the larger
  if (p1 + p2 <= pd) return T(0);                                                 // disjoint
  if (p1 + p2 + pd >= kTwoPi<T>) return std::max(T(0), a1 + a2 - T(4) * kPi<T>);  // union covers the sphere
  T c1c, c2c, cd, s1, s2, sd;
  sine_cosine(p1, s1, c1c);
  sine_cosine(p2, s2, c2c);
  sine_cosine(pd, sd, cd);
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

// ---- Sampling D_std over a cap ----

// Uniform over a cap (Shirley 1996 cone sampling, as in sphere.h): 1 - cos = u0 (1 - cos(psi)).
// The sample minus the cap's axis, in the axis' frame: (sin cos phi, sin sin phi, -(1 - cos)).
template <class T> Vec3<T> uniform_cap_offset_local(T cap_one_minus_cos, const Vec2<T>& u) {
  const T omc = u[0] * std::min(T(2), cap_one_minus_cos);
  const T sin_t = std::sqrt(std::max(T(0), omc * (T(2) - omc)));
  const T phi = kTwoPi<T> * u[1];
  T sin_phi, cos_phi;
  sine_cosine(phi, sin_phi, cos_phi);
  return Vec3<T>(sin_t * cos_phi, sin_t * sin_phi, -omc);
}
template <class T> Vec3<T> sample_uniform_cap_direction(const Cap<T>& c, const Vec2<T>& u) {
  const Vec3<T> w =
      Frame<T>::from_z(c.axis).to_world(Vec3<T>(uniform_cap_offset_local(c.one_minus_cos, u) + Vec3<T>(0, 0, 1)));
  return w / w.norm();
}

namespace sptd_detail {

// R's chord at x: the disk's and E's half-heights c, m, and w = c - m; upper_tail: right of x_full (the disk's chord).
template <class T> struct CosineCapChord {
  T x, c, m, w;
  bool upper_tail;
};

// x from R's area-CDF (TOMS 748). Right of x_full (a kink) from the upper tail (1 - u0) area, solved for
// theta = acos(x) so that c = sin(theta) keeps its precision; in the crescent with a tip for s = x - x0.
template <class T> CosineCapChord<T> invert_cosine_cap_cdf(const CosineCapView<T>& v, T u0) {
  const T target = u0 * v.area;
  T lo = T(-1), hi = T(1);
  if (v.cos_t >= T(0))
    lo = std::max(lo, v.xc - v.A);
  else
    lo = std::max(lo, std::min(v.x0, T(1)));
  const T upper = (T(1) - u0) * v.area;
  const T x_full = v.cos_t >= T(0) ? v.x0 : v.xc + v.A;
  const T seg_full = v.cos_t >= T(0) ? v.seg0 : CosineCapView<T>::disk_right_of(x_full);
  const bool upper_tail = x_full < T(1) && upper <= seg_full;
  if (upper_tail) lo = T(0), hi = std::acos(std::max(T(-1), x_full));
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
  if (upper_tail) {
    T sin_q, cos_q;
    sine_cosine(q, sin_q, cos_q);
    return {cos_q, sin_q, T(0), sin_q, true};
  }
  if (by_s) {
    const auto ch = v.crescent_chord(q);
    return {v.x0 + q, ch.c, ch.m, ch.w, false};
  }
  const T c = std::sqrt(std::max(T(0), (T(1) - q) * (T(1) + q)));
  const T m = std::min(c, v.ellipse_half_height(q));
  return {q, c, m, c - m, false};
}

}  // namespace sptd_detail

// Clamped cosine over a cap: a point of R (header comment) lifted to the hemisphere of n. Where R = E, the uniform
// disk (polar map) under the affine map onto E; otherwise x from R's area-CDF and y uniform on R's chord at x.
template <class T> Vec3<T> sample_cosine_cap_direction(const CosineCapView<T>& v, const Vec2<T>& u) {
  T x, y, z;
  if (v.ellipse_only) {
    const T r = std::sqrt(u[0]), phi = kTwoPi<T> * u[1];
    T sin_phi, cos_phi;
    sine_cosine(phi, sin_phi, cos_phi);
    x = v.xc + v.A * r * cos_phi;
    y = v.sin_a * r * sin_phi;
    z = std::sqrt(std::max(T(0), (T(1) - x) * (T(1) + x) - y * y));
  } else {
    const sptd_detail::CosineCapChord<T> ch = sptd_detail::invert_cosine_cap_cdf(v, u[0]);
    const T c = ch.c, m = ch.m, w = ch.w;
    x = ch.x;
    const T s = T(2) * u[1] - T(1);  // in [-1, 1)
    // The lift z = sqrt((c - |y|)(c + |y|)) with c - |y| from 1 - |s| (exact from u1), branching by the inversion's
    // piece: no difference of nearly equal squares.
    const T one_minus_abs_s = T(2) * std::min(u[1], T(1) - u[1]);
    T c_minus_abs_y;
    if (ch.upper_tail || (v.cos_t >= T(0) && x >= v.x0))
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

// ---- SPTDs over a cap (Sec. 4.2, Fig. 5) ----

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
  // Uniform base with a small image: g(C)'s axis minus r_p; samples and densities then from offsets to r_p.
  bool image_relative = false;
  Vec3<T> image_offset = Vec3<T>::Zero();
  CosineCapView<T> cosine;  // for the clamped-cosine base
  T base_integral = 0;      // integral of D_std over g(C) = integral of D over C (Eq. 10)
  bool valid() const { return reason == NoSample::kNone; }
};

template <class T> NoSample fill_sptd_cap_view(const SptdCapGeometry<T>& g, SptdCapView<T>& v) {
  v.sptd = g.sptd;
  v.cap = g.cap;
  if (!all_finite(g.sptd.pivot) || !all_finite(g.sptd.base_axis) || !all_finite(g.cap.axis) ||
      !std::isfinite(g.cap.one_minus_cos))
    return NoSample::kNonFinite;
  if (!valid_pivot(g.sptd.pivot)) return NoSample::kInvalidGeometry;
  if (g.cap.one_minus_cos < T(0)) return NoSample::kNegativeSize;
  if (!(g.cap.one_minus_cos > T(0))) return NoSample::kZeroSize;
  if (!normalize_normal(g.cap.axis, v.cap.axis)) return NoSample::kInvalidGeometry;
  if (g.sptd.base == SptdBase::kClampedCosine && !normalize_normal(g.sptd.base_axis, v.sptd.base_axis))
    return NoSample::kBadNormal;
  v.k = pivot_k(v.sptd.pivot);
  if (!(v.k > T(0))) return NoSample::kInvalidGeometry;
  v.image = v.sptd.base == SptdBase::kUniform
                ? pivot_transform_cap(v.cap, v.sptd.pivot, v.k, &v.image_offset, &v.image_relative)
                : pivot_transform_cap(v.cap, v.sptd.pivot, v.k);
  if (!(v.image.one_minus_cos > T(0)) || !all_finite(v.image.axis)) return NoSample::kTooSmall;
  if (v.sptd.base == SptdBase::kUniform) {
    v.base_integral = v.image.one_minus_cos / T(2);
  } else {
    v.cosine.reason = fill_cosine_cap_view(v.image, v.sptd.base_axis, v.cosine);  // in place, not copied
    if (!v.cosine.valid()) return v.cosine.reason;
    v.base_integral = v.cosine.area / kPi<T>;
  }
  // The normalised base density 1 / |g(C)| resp. 1 / area must be representable (as for sphere lights, sphere.h);
  // norm >= 0 here (the image's 1 - cos and a valid cosine view's area are positive).
  const T norm = v.sptd.base == SptdBase::kUniform ? v.image.solid_angle() : v.cosine.area;
  if (!has_finite_reciprocal(norm)) return NoSample::kTooSmall;
  return NoSample::kNone;
}

template <class T> SptdCapView<T> make_sptd_cap_view(const SptdCapGeometry<T>& g) {
  SptdCapView<T> v;  // filled in place: no copy of the view on return
  v.reason = fill_sptd_cap_view(g, v);
  return v;
}

// Membership in g(C) by the squared chord from its axis, with a relative slack of 8 eps: a sample generated inside
// g(C) must test inside after the pivot round trip (two roundings).
template <class T> bool within_image(const SptdCapView<T>& v, T chord2_to_axis) {
  const T slack = T(8) * std::numeric_limits<T>::epsilon();
  return chord2_to_axis <= T(2) * v.image.one_minus_cos * (T(1) + slack);
}

// Density of the original distribution restricted to g(C), normalised, at w_i.
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
  // 0 outside C, tested on C itself (in T the image can swallow C's complement): by the chord to the axis, or to the
  // antipode beyond a hemisphere, with slack for two roundings and for unit directions.
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
  // The product overflows for densities beyond T's range (a pivot within ~eps of the sphere, a tiny cap): 0.
  const T pdf = p > T(0) ? p * pivot_jacobian(wu, v.sptd.pivot, v.k) : T(0);
  return std::isfinite(pdf) ? pdf : T(0);
}

template <class T> DirectionSample<T> sample_sptd_cap(const SptdCapView<T>& v, const Vec2<T>& u) {
  if (!v.valid()) return DirectionSample<T>::none(v.reason);
  DirectionSample<T> s;
  if (v.image_relative) {
    // q = w_i - r_p = (axis - r_p) - axis (1 - cos) + sin (cos phi e_x + sin phi e_y), w = g(w_i) = r_p - k q / |q|^2.
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

namespace sptd_detail {

// The azimuth of (x, y) as a fraction of a turn, in [0, 1].
template <class T> T azimuth_fraction(T y, T x) {
  const T phi = std::atan2(y, x);
  return (phi < T(0) ? phi + kTwoPi<T> : phi) / kTwoPi<T>;
}

// The inverse of uniform_cap_offset_local: u from the offset d = w_i - axis in the axis' frame (|d|^2 = 2 (1 - cos)).
template <class T> Vec2<T> uniform_cap_offset_inverse(T cap_one_minus_cos, const Vec3<T>& d) {
  return Vec2<T>(d.squaredNorm() / (T(2) * std::min(T(2), cap_one_minus_cos)), azimuth_fraction(d.y(), d.x()));
}

// The inverse of sample_cosine_cap_direction at the unit w_i: u0 from R's area-CDF at x (from the upper tail's
// area right of x where the sampler took it), u1 from y's place on R's chord at x, in the sampler's three forms.
template <class T> Vec2<T> cosine_cap_inverse(const CosineCapView<T>& v, const Vec3<T>& wi) {
  const T x = wi.dot(v.ex), y = wi.dot(v.ey);
  if (v.ellipse_only) {
    const T px = v.A > T(0) ? (x - v.xc) / v.A : T(0), py = v.sin_a > T(0) ? y / v.sin_a : T(0);
    return Vec2<T>(px * px + py * py, azimuth_fraction(py, px));
  }
  const T x_full = v.cos_t >= T(0) ? v.x0 : v.xc + v.A;
  const T u0 = x >= x_full ? T(1) - CosineCapView<T>::disk_right_of(x) / v.area : v.cdf(x) / v.area;
  const T c = std::sqrt(std::max(T(0), (T(1) - x) * (T(1) + x)));
  T s;
  if (x >= x_full || (v.cos_t >= T(0) && x >= v.x0)) {
    s = c > T(0) ? y / c : T(0);
  } else {
    const T m = v.tip ? v.crescent_chord(x - v.x0).m : std::min(c, v.ellipse_half_height(x));
    if (v.cos_t >= T(0))
      s = m > T(0) ? y / m : T(0);
    else
      s = c > m ? std::copysign((std::abs(y) - m) / (c - m), y) : T(0);
  }
  return Vec2<T>(std::clamp(u0, T(0), T(1)), std::clamp((s + T(1)) / T(2), T(0), T(1)));
}

}  // namespace sptd_detail

// The inverse warp of sample_sptd_cap: w_i = g(w) (g is an involution, Eq. 3), then the base sampler's inverse;
// false outside the support. The cosine base's u0 is R's closed-form area-CDF, which the sampler inverts by TOMS 748:
// an inversion that stops early shows as inverse(sample(u)) != u.
template <class T> bool invert_sptd_cap(const SptdCapView<T>& v, const Vec3<T>& w, Vec2<T>& u) {
  if (!(pdf_sptd_cap(v, w) > T(0))) return false;
  const Vec3<T> wu = w / w.norm();
  const Frame<T> f = Frame<T>::from_z(v.image.axis);
  if (v.image_relative) {
    // As pdf_sptd_cap: w_i - axis = k o / |o|^2 - image_offset, o = pivot_offset(w).
    const Vec3<T> o = pivot_offset(wu, v.sptd.pivot);
    u = sptd_detail::uniform_cap_offset_inverse(v.image.one_minus_cos,
                                                f.to_local(Vec3<T>((v.k / o.squaredNorm()) * o - v.image_offset)));
  } else {
    const Vec3<T> wi = pivot_transform(wu, v.sptd.pivot, v.k);
    u = v.sptd.base == SptdBase::kUniform
            ? sptd_detail::uniform_cap_offset_inverse(v.image.one_minus_cos, f.to_local(Vec3<T>(wi - v.image.axis)))
            : sptd_detail::cosine_cap_inverse(v.cosine, wi);
  }
  u = Vec2<T>(std::clamp(u[0], T(0), T(1)), std::clamp(u[1], T(0), T(1)));
  return true;
}

template <class T> DirectionSample<T> sample_sptd_cap(const SptdCapGeometry<T>& g, const Vec2<T>& u) {
  return sample_sptd_cap(make_sptd_cap_view(g), u);
}
template <class T> T pdf_sptd_cap(const SptdCapGeometry<T>& g, const Vec3<T>& w) {
  return pdf_sptd_cap(make_sptd_cap_view(g), w);
}

// ---- Phase functions (Sec. 6.2) ----

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
  static constexpr SptdBase base = B;
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
  static bool invert(const View& v, const Vec3<T>& w, Vec2<T>& u) { return invert_sptd_cap(v, w, u); }
  // The support lies in C.
  static Cap<T> bounding_cap(const Geometry& g) {
    Cap<T> c = g.cap;
    if (!normalize_normal(g.cap.axis, c.axis)) c.axis = Vec3<T>(T(0), T(0), T(1));
    return c;
  }
  static T normaliser(const View& v) { return v.base_integral; }  // the integral of D over C (Eq. 10)
  // The cosine base vanishes beyond its horizon: D (Eq. 8) kinks on the edge of g(H), H the base's hemisphere.
  static std::vector<Cap<T>> boundary_caps(const Geometry& g) {
    Vec3<T> n;
    if (kUniform || !valid_pivot(g.sptd.pivot) || !normalize_normal(g.sptd.base_axis, n)) return {};
    return {pivot_transform_cap(Cap<T>{n, T(1)}, g.sptd.pivot)};
  }
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
