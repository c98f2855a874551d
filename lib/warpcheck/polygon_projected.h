// warpcheck/polygon_projected.h: projected-solid-angle sampling of convex polygons, Peters 2021 Section 3,
// and its biased variant (Section 6.4).
//
// pdf(w) = cos(theta) / A_Sigma inside the clipped polygon, A_Sigma the sum of the sector areas (Eq. 1). Edge normals
// n_j = v_j x v_{j+1} (Kahan, Sec. 3.7) with n_{j,z} > 0 on outer and < 0 on inner edges; a sector is chosen by area,
// its azimuth found in closed form (central, Sec. 3.2) or by tangent-line iteration (decentral, Sec. 3.3-3.4).
//
// Our departures (docs/derivations/polygon-projected.md): ellipses in homogeneous form, Ct_j = n_{j,z}^2 C_j, finite
// where C_j is not; vertices sorted by merging the outer and inner chains; Eq. 6's root taken around the current
// iterate; and near a sector's tip, residuals and areas counted from the nearer end.
#pragma once

#include <type_traits>

#include "warpcheck/polygon.h"

namespace warpcheck {

// ---- arctangents ----

// The biased variant's atan2 (Sec. 6.4 asks for forward error <= 1.2e-5 rad): atan on [0, 1] by octant symmetry, by
// the odd degree-9 polynomial of Abramowitz & Stegun 4.4.47 (Hastings; bound 1e-5, measured by test_polygon).
template <class T> T atan2_approx(T y, T x) {
  const T ax = std::abs(x), ay = std::abs(y);
  const T hi = std::max(ax, ay), lo = std::min(ax, ay);
  if (!(hi > T(0))) return T(0);
  const T t = lo / hi, t2 = t * t;
  T r = t * (T(0.9998660L) + t2 * (T(-0.3302995L) + t2 * (T(0.1801410L) + t2 * (T(-0.0851330L) + t2 * T(0.0208351L)))));
  if (ay > ax) r = kPi<T> / 2 - r;
  if (x < T(0)) r = kPi<T> - r;
  return std::signbit(y) ? -r : r;
}

// Eq. 1's arctangent in scalar A for a kernel of scalar T: the biased variant's approximation, else the kernels'.
template <class A, bool kBiased, class T = A> A polygon_atan2(A y, A x) {
  if constexpr (kBiased)
    return atan2_approx(y, x);
  else
    return kernel_atan2<A, T>(y, x);
}

// ---- Ellipses in homogeneous form ----

template <class T> struct EdgeEllipse {
  Vec2<T> nxy = Vec2<T>::Zero();  // xy part of the unit edge normal
  T nz = 0;                       // z part; 0 in the zenith case

  T c() const { return nz * nz; }
  // a^T Ct b with Ct = nz^2 I + nxy nxy^T.
  T form(const Vec2<T>& a, const Vec2<T>& b) const { return nz * nz * a.dot(b) + nxy.dot(a) * nxy.dot(b); }
  Vec2<T> times(const Vec2<T>& a) const { return nz * nz * a + nxy * nxy.dot(a); }  // Ct a
  // 1 / (w^T C w): the ray through w meets the ellipse at w / sqrt(w^T C w) (Eq. 3).
  T inverse_quadratic(const Vec2<T>& w) const {
    const T f = form(w, w);
    return f > T(0) ? nz * nz / f : T(0);
  }
  // 1 - |p|^2 (z^2, Eq. 2) of the ellipse point p = w / sqrt(w^T C w), as (nxy.w)^2 / w^T Ct w: no cancellation.
  T one_minus_radius2(const Vec2<T>& w) const {
    const T f = form(w, w);
    if (!(f > T(0))) return T(1);
    const T d = nxy.dot(w);
    return std::min(T(1), d * d / f);
  }
};

// The boundary point at azimuth w on an edge, as (|p|^2, z^2): where the ray meets the segment a b, which is Eq. 3's
// point but well conditioned where the ellipse is a needle; without endpoints (a = b = 0), Eq. 3.
template <class T>
void edge_boundary_point(const EdgeEllipse<T>& e, const Vec3<T>& a, const Vec3<T>& b, const Vec2<T>& w, T* r2, T* z2) {
  const T ca = kahan_cross2(w, Vec2<T>(a.x(), a.y())), cb = kahan_cross2(w, Vec2<T>(b.x(), b.y()));
  const T den = ca - cb;
  if (a != b && std::isfinite(den)) {
    // den = 0: a radial edge (n_z = 0), all of whose points have azimuth w: its midpoint.
    const T t = den != T(0) ? std::clamp(ca / den, T(0), T(1)) : T(0.5);
    Vec3<T> p = a + t * (b - a);
    // Behind the ray beyond rounding (t is noise for an edge along the ray's line): the endpoint ahead along w.
    const Vec2<T> axy(a.x(), a.y()), bxy(b.x(), b.y()), pxy(p.x(), p.y());
    const T behind = T(8) * std::numeric_limits<T>::epsilon() * (axy.norm() + bxy.norm()) * w.norm();
    if (pxy.dot(w) < -behind) p = axy.dot(w) >= bxy.dot(w) ? a : b;
    const T m = max_abs(p);
    if (m > T(0) && std::isfinite(m)) {
      const Vec3<T> q = p / m;
      const T n2 = q.squaredNorm();
      *r2 = std::min(T(1), (q.x() * q.x() + q.y() * q.y()) / n2);
      *z2 = std::min(T(1), q.z() * q.z() / n2);
      return;
    }
  }
  *r2 = std::min(T(1), e.inverse_quadratic(w) * w.squaredNorm());
  *z2 = e.one_minus_radius2(w);
}

template <class T> EdgeEllipse<T> edge_ellipse(const Vec3<T>& n_unit) {
  return EdgeEllipse<T>{Vec2<T>(n_unit.x(), n_unit.y()), n_unit.z()};
}

// Eq. 1 (homogeneous form): the ellipse's area in the sector from s0 to s1, given cross = s0 x s1.
template <class T, bool kBiased = false, class Kernel = T>
T ellipse_sector_area(const EdgeEllipse<T>& e, const Vec2<T>& s0, const Vec2<T>& s1, T cross) {
  const T a = std::abs(e.nz);
  return a / T(2) * polygon_atan2<T, kBiased, Kernel>(a * cross, e.form(s0, s1));
}

// ---- Sectors ----

template <class T> struct ProjectedSector {
  Vec2<T> s0 = Vec2<T>::Zero(), s1 = Vec2<T>::Zero();            // boundaries, counterclockwise, at most 180 degrees
  EdgeEllipse<T> outer, inner;                                   // inner only in the decentral case
  Vec3<T> outer_a = Vec3<T>::Zero(), outer_b = Vec3<T>::Zero();  // the edges' clipped endpoints (local frame)
  Vec3<T> inner_a = Vec3<T>::Zero(), inner_b = Vec3<T>::Zero();
  bool decentral = false;
  T area = 0;
};

// The root of Eq. 6 around a nearby direction: w = base + tau R base, w^T T w = a0 + a1 tau + a2 tau^2, Blinn's root
// (where it increases) tau = -2 a0 / (a1 + sqrt(D)) = (sqrt(D) - a1) / (2 a2), each form where it does not cancel.
// Returns w up to sign; 0 when all coefficients vanish.
template <class T> Vec2<T> increasing_root_around(const Vec2<T>& base, T a0, T a1, T a2) {
  const T sq = std::sqrt(std::max(T(0), kahan_det(a1, T(4) * a0, a2, a1)));
  const bool up = a1 >= T(0);
  const T num = up ? -T(2) * a0 : sq - a1, den = up ? a1 + sq : T(2) * a2;  // tau = num / den
  return den * base + num * Vec2<T>(-base.y(), base.x());
}

// Approximate L1 normalisation (Sec. 3.7): guards against under- and overflow; the length is irrelevant.
template <class T> Vec2<T> l1_normalized(const Vec2<T>& w) {
  const T s = std::abs(w.x()) + std::abs(w.y());
  return s > T(0) && std::isfinite(s) ? Vec2<T>(w / s) : w;
}

// The scalar of Eq. 1's difference of two ellipse areas: double for float (near a sector's tip the terms can be ~4000
// times the difference), except in the biased variant, whose atan2 error dominates.
template <class T, bool kBiased> using EllipseAreaScalar =
    std::conditional_t<std::is_same_v<T, float> && !kBiased, double, T>;

template <class A, class T> EdgeEllipse<A> ellipse_cast(const EdgeEllipse<T>& e) {
  return EdgeEllipse<A>{e.nxy.template cast<A>(), A(e.nz)};
}

// Eq. 1 for both ellipses of a decentral sector: the area between them from a to b, given cross = a x b.
template <class T, bool kBiased = false>
T area_between_ellipses(const ProjectedSector<T>& s, const Vec2<T>& a, const Vec2<T>& b, T cross) {
  using A = EllipseAreaScalar<T, kBiased>;
  const Vec2<A> aa = a.template cast<A>(), ba = b.template cast<A>();
  const A c = std::is_same_v<A, T> || cross == T(0) ? A(cross) : kahan_cross2(aa, ba);
  return T(ellipse_sector_area<A, kBiased, T>(ellipse_cast<A>(s.outer), aa, ba, c) -
           ellipse_sector_area<A, kBiased, T>(ellipse_cast<A>(s.inner), aa, ba, c));
}

// The area between the ellipses in the sector from s0 to w (the subtracted terms of Eq. 7).
template <class T, bool kBiased = false> T decentral_area_to(const ProjectedSector<T>& s, const Vec2<T>& w) {
  return area_between_ellipses<T, kBiased>(s, s.s0, w, kahan_cross2(s.s0, w));
}

// The area between the ellipses in the sector from w to s1.
template <class T, bool kBiased = false> T decentral_area_from(const ProjectedSector<T>& s, const Vec2<T>& w) {
  return area_between_ellipses<T, kBiased>(s, w, s.s1, kahan_cross2(w, s.s1));
}

// Eq. 7's residual A_delta(w) = A - area(s0 -> w), from the sector's nearer end: beyond half the sector as
// area(w -> s1) - rest, rest = A_j - A (known to the caller more accurately than the difference).
template <class T, bool kBiased = false>
T decentral_residual(const ProjectedSector<T>& s, T target, T rest, const Vec2<T>& w) {
  if (target <= rest) return target - decentral_area_to<T, kBiased>(s, w);
  return decentral_area_from<T, kBiased>(s, w) - rest;
}
template <class T, bool kBiased = false> T decentral_residual(const ProjectedSector<T>& s, T target, const Vec2<T>& w) {
  return decentral_residual<T, kBiased>(s, target, s.area - target, w);
}

// Section 3.4: the two-quad initialisation, w^T Q w = 0 with
//   Q = lambda_{o,k} D_o R s_k r_i^T - (lambda_{i,k} D_i R s_k + 2 A_q r_i) r_o^T
// (docs/derivations/polygon-projected.md); r_l scaled to stay finite as n_{l,z} -> 0. Quad 1's area is negative.
template <class T, bool kBiased = false> Vec2<T> decentral_initialization(const ProjectedSector<T>& s, T target) {
  const Vec2<T> s0 = s.s0 / s.s0.norm(), s1 = s.s1 / s.s1.norm();
  const Vec2<T> sh = s0 + s1;  // Eq. 8
  auto lambda = [](const EdgeEllipse<T>& e, const Vec2<T>& v) {
    const T f = e.form(v, v);
    return f > T(0) ? std::abs(e.nz) / std::sqrt(f) : T(0);
  };
  const T li0 = lambda(s.inner, s0), lih = lambda(s.inner, sh), li1 = lambda(s.inner, s1);
  const T lo0 = lambda(s.outer, s0), loh = lambda(s.outer, sh), lo1 = lambda(s.outer, s1);
  // Quad areas by the shoelace formula of the diagonals.
  auto quad_area = [](const Vec2<T>& a, const Vec2<T>& b, const Vec2<T>& c, const Vec2<T>& d) {
    return std::abs(kahan_cross2<T>(c - a, d - b)) / T(2);
  };
  const T q0 = quad_area(li0 * s0, lih * sh, loh * sh, lo0 * s0);
  const T q1 = quad_area(li1 * s1, lih * sh, loh * sh, lo1 * s1);
  const T scaled = s.area > T(0) ? target * (q0 + q1) / s.area : T(0);
  const bool first = scaled <= q0;
  const Vec2<T>& sk = first ? s0 : s1;
  const T lik = first ? li0 : li1, lok = first ? lo0 : lo1;
  const T aq = first ? scaled : scaled - (q0 + q1);
  // r_l scaled by 1 / |n_{l,z}|: C_l lambda = Ct_l / n_z^2 * |n_z| mu = Ct_l mu / |n_z|, mu = 1 / sqrt(v^T Ct v).
  auto mu = [](const EdgeEllipse<T>& e, const Vec2<T>& v) {
    const T f = e.form(v, v);
    return f > T(0) ? T(1) / std::sqrt(f) : T(0);
  };
  const Vec2<T> ri = s.inner.times(Vec2<T>(mu(s.inner, sh) * sh + mu(s.inner, sk) * sk));
  const Vec2<T> ro = s.outer.times(Vec2<T>(mu(s.outer, sh) * sh + mu(s.outer, sk) * sk));
  const T di = lih * ri.dot(sh), do_ = loh * ro.dot(sh);
  // w^T Q w as a quadratic in tau, w = s_k + tau R s_k.
  const Vec2<T> rsk(-sk.y(), sk.x());  // R s_k
  const T ri_s = ri.dot(sk), ri_p = ri.dot(rsk), ro_s = ro.dot(sk), ro_p = ro.dot(rsk), s2 = sk.squaredNorm();
  const T a0 = -T(2) * aq * ri_s * ro_s;
  const T a1 = s2 * (lok * do_ * ri_s - lik * di * ro_s) - T(2) * aq * (ri_s * ro_p + ri_p * ro_s);
  const T a2 = s2 * (lok * do_ * ri_p - lik * di * ro_p) - T(2) * aq * ri_p * ro_p;
  Vec2<T> w = increasing_root_around(sk, a0, a1, a2);
  if (w.dot(sh) < T(0)) w = -w;
  if (!(std::abs(w.x()) + std::abs(w.y()) > T(0)) || !all_finite(Vec3<T>(w.x(), w.y(), T(0)))) w = sh;
  return l1_normalized(w);
}

// Section 3.3: one step of the tangent-line iteration (Eq. 5 in homogeneous form, Eq. 6, Eq. 7).
template <class T, bool kBiased = false>
Vec2<T> decentral_iteration(const ProjectedSector<T>& s, T target, T rest, const Vec2<T>& wn) {
  const T a_delta = decentral_residual<T, kBiased>(s, target, rest, wn);
  // w^T T w as a quadratic in tau, w = w_n + tau R w_n, from T's factors; x . w_n as a difference of squares.
  const Vec2<T> rw(-wn.y(), wn.x());  // R w_n
  const T n2 = wn.squaredNorm();
  const T di = s.inner.nxy.dot(wn), d_o = s.outer.nxy.dot(wn);
  const T fi = s.inner.c() * n2 + di * di, fo = s.outer.c() * n2 + d_o * d_o;
  const T gi = di * s.inner.nxy.dot(rw), go = d_o * s.outer.nxy.dot(rw);
  const T p = s.outer.nz * di, q = s.inner.nz * d_o;
  const T x_w = (p - q) * (p + q), x_rw = s.outer.c() * gi - s.inner.c() * go;
  const T a0 = -T(2) * a_delta * fi * fo;
  const T a1 = n2 * x_w - T(2) * a_delta * (fi * go + gi * fo);
  const T a2 = n2 * x_rw - T(2) * a_delta * gi * go;
  Vec2<T> w = increasing_root_around(wn, a0, a1, a2);
  // "The sign on the resulting direction may be wrong, so we check the dot product with the half-vector."
  const Vec2<T> sh = s.s0 / s.s0.norm() + s.s1 / s.s1.norm();
  if (w.dot(sh) < T(0)) w = -w;
  // All coefficients vanish where the ellipses meet at the horizon (Sec. 3.5): keep the current direction.
  if (!(std::abs(w.x()) + std::abs(w.y()) > T(0)) || !std::isfinite(w.x()) || !std::isfinite(w.y())) return wn;
  return l1_normalized(w);
}

// Puts w back on the sector's nearer boundary (where the ellipses coincide, Eq. 5's root can leave the sector).
template <class T> Vec2<T> clamp_to_sector(const ProjectedSector<T>& s, const Vec2<T>& w) {
  if (cross2_sign(s.s0, w) < 0) return l1_normalized(s.s0);
  if (cross2_sign(w, s.s1) < 0) return l1_normalized(s.s1);
  return w;
}

// The decentral inversion: initialisation plus `iterations` steps, each kept inside the sector. `target` is the
// area from s0, `rest` the area to s1 (decentral_residual). The sector's ends are exact: there Eq. 6's constant
// term vanishes, tau = 0 is a root, and where the ellipses meet at that end its linear term's sign is rounding,
// which can make the increasing root the other one, anywhere in the sector.
template <class T, bool kBiased = false>
Vec2<T> invert_decentral_sector(const ProjectedSector<T>& s, T target, T rest, int iterations) {
  if (!(target > T(0))) return l1_normalized(s.s0);
  if (!(rest > T(0))) return l1_normalized(s.s1);
  Vec2<T> w = clamp_to_sector(s, decentral_initialization<T, kBiased>(s, target));
  for (int k = 0; k < iterations; ++k) w = clamp_to_sector(s, decentral_iteration<T, kBiased>(s, target, rest, w));
  return w;
}
template <class T, bool kBiased = false>
Vec2<T> invert_decentral_sector(const ProjectedSector<T>& s, T target, int iterations) {
  return invert_decentral_sector<T, kBiased>(s, target, s.area - target, iterations);
}

// Section 3.2: the central case in closed form, phi = 2 A / |n_z| in the Cholesky-transformed circle and the 2x2
// system (-s0^T R w, |n_z| s0^T Ct w) ~ (sin phi, cos phi) by Cramer's rule, times -det > 0 instead of divided.
template <class T> Vec2<T> invert_central_sector(const ProjectedSector<T>& s, T target) {
  const T a = std::abs(s.outer.nz);
  const T phi = a > T(0) ? std::min(T(2) * target / a, kPi<T>) : T(0);
  T b1, cos_phi;
  sine_cosine(phi, b1, cos_phi);
  const T b2 = a * cos_phi;
  const Vec2<T> r1(-s.s0.y(), s.s0.x());
  const Vec2<T> r2 = s.outer.times(s.s0);
  return l1_normalized(Vec2<T>(r1.y() * b2 - r2.y() * b1, r2.x() * b1 - r1.x() * b2));
}

// ---- The per-light precomputation ----

template <class T> struct PolygonProjectedView {
  NoSample reason = NoSample::kNone;
  Frame<T> frame = Frame<T>::from_z(Vec3<T>(T(0), T(0), T(1)));
  bool flip_y = false;      // y flipped so that the vertex order winds positively (Sec. 3.1)
  LocalPolygon<T> clipped;  // in the (flipped) shading frame, clipped to z >= 0
  std::array<Vec3<T>, kMaxClippedVertices> edge_normals{};  // n_j = v_j x v_{j+1} (Kahan), not normalised
  // The density's cone test: the light's own edge planes (polygon_inward_planes) and the horizon.
  std::array<Vec3<T>, kMaxPolygonVertices + 1> inward{};
  int planes = 0;
  bool central = true;
  int sector_count = 0;
  std::array<ProjectedSector<T>, kMaxClippedVertices> sectors{};
  T projected_solid_angle = 0;  // A_Sigma, the sum of the sector areas

  bool valid() const { return reason == NoSample::kNone; }
  Vec3<T> to_local(const Vec3<T>& w) const {
    Vec3<T> l = frame.to_local(w);
    if (flip_y) l.y() = -l.y();
    return l;
  }
  Vec3<T> to_world(Vec3<T> l) const {
    if (flip_y) l.y() = -l.y();
    return frame.to_world(l);
  }
};

namespace polygon_projected_detail {

// The sum of the clipped polygon's azimuth increments: 2 pi times its winding number about the zenith, up to
// rounding far below pi (each increment is atan2 of kahan_cross2's exact sign).
template <class T> T azimuth_increments(const LocalPolygon<T>& p) {
  T sum = 0;
  for (int j = 0; j < p.count; ++j) {
    const Vec3<T>& next = p.v[wrap_index(j + 1, p.count)];
    const Vec2<T> a(p.v[j].x(), p.v[j].y()), b(next.x(), next.y());
    sum += kernel_atan2(kahan_cross2(a, b), a.dot(b));
  }
  return sum;
}

// 2^e, exactly, at compile time (e within T's normal range).
template <class T> constexpr T exact_power_of_two(int e) {
  T p = 1;
  for (; e > 0; --e) p *= 2;
  for (; e < 0; ++e) p /= 2;
  return p;
}

// Whether x y and x y + z w, for coordinates like c, neither under- nor overflow: c is 0 or within
// [2^(e_min/2 + p), 2^(e_max/2 - 1)] (p: T's digits), so products, their exact errors and kahan_det's result are
// multiples of 2^(e_min - 1) below T's largest value.
template <class T> bool products_stay_normal(T c) {
  using limits = std::numeric_limits<T>;
  constexpr T lo = exact_power_of_two<T>(limits::min_exponent / 2 + limits::digits);
  constexpr T hi = exact_power_of_two<T>(limits::max_exponent / 2 - 1);
  return c == T(0) || (std::abs(c) >= lo && std::abs(c) <= hi);
}

// Whether the clipped polygon winds around the zenith (its azimuth increments sum to 2 pi): robust where the signs
// of the n_z are noise. Where no product under- or overflows, each increment atan2(a x b, a . b) has kahan_cross2's
// exact sign and an error of a few ulps, so the sum is 2 pi times the winding number up to far less than pi; that
// number is then counted exactly, as signed crossings of the ray y = 0, x > 0 (Sunday 2001). Elsewhere, and where an
// edge has a x b = 0 and a . b <= 0 (an increment of +-pi by the sign of a zero), the sum decides.
template <class T> bool winds_around_zenith(const LocalPolygon<T>& p) {
  int winding = 0;
  for (int j = 0; j < p.count; ++j) {
    const Vec3<T>&a = p.v[j], &b = p.v[wrap_index(j + 1, p.count)];
    const int side = det_sign(a.x(), a.y(), b.x(), b.y());
    if (!products_stay_normal(a.x()) || !products_stay_normal(a.y()) ||
        (side == 0 && !(a.x() * b.x() + a.y() * b.y() > T(0))))
      return azimuth_increments(p) > kPi<T>;
    if (a.y() <= T(0) && b.y() > T(0) && side > 0) ++winding;
    if (b.y() <= T(0) && a.y() > T(0) && side < 0) --winding;
  }
  return winding > 0;
}

// The image-width test of resolved_by_coordinates: D (h / d) > 64 eps scale. Its left side only falls as d rises (each
// rounding is monotone).
template <class T> bool image_wider_than_rounding(T diameter, T h, T d, T scale) {
  return diameter * (h / d) > T(64) * std::numeric_limits<T>::epsilon() * scale;
}

// Whether the light is resolved by its local coordinates: not below 64 eps of the coordinates' scale, in extent or
// in its image's width D h / d, h = |plane_distance|, d = max(h, nearest vertex's distance - D). The light's extents
// are its preparation's where it has one.
template <class T> bool resolved_by_coordinates(const PolygonLightGeometry<T>& g, const PolygonView<T>& pv) {
  T extent, scale, diameter;
  if (pv.prepared)
    extent = pv.prepared->extent, scale = pv.prepared->magnitude, diameter = pv.prepared->diameter;
  else
    polygon_extents(g.light, extent, scale, diameter);
  scale += max_abs(g.shading.position);
  if (!(extent > T(64) * std::numeric_limits<T>::epsilon() * scale)) return false;
  const T h = std::abs(pv.plane_distance);
  // The verdict at d's bound max(h, 2 |V_0 - x|_inf) first, without the vertices' norms: where it passes, it passes
  // at d (the computed stable_norm of V_0 - x is below sqrt(3) |V_0 - x|_inf (1 + 4 eps) for a normal maximum).
  const T m0 = max_abs(Vec3<T>(g.light.vertices[0] - g.shading.position));
  if (m0 >= std::numeric_limits<T>::min() && image_wider_than_rounding(diameter, h, std::max(h, T(2) * m0), scale))
    return true;
  T nearest = std::numeric_limits<T>::infinity();
  for (int i = 0; i < g.light.count; ++i)
    nearest = std::min(nearest, stable_norm(Vec3<T>(g.light.vertices[i] - g.shading.position)));
  return image_wider_than_rounding(diameter, h, std::max(h, nearest - diameter), scale);
}

// Each clipped edge's normal n_j (Kahan), its sign of n_{j,z} (outer +, inner -, radial 0) and its ellipse.
template <class T> struct ClippedEdges {
  std::array<int, kMaxClippedVertices> sign{};
  std::array<EdgeEllipse<T>, kMaxClippedVertices> ell{};
  bool any_negative = false, any_positive = false;
};
template <class T> ClippedEdges<T> classify_edges(PolygonProjectedView<T>& v) {
  ClippedEdges<T> c;
  const int m = v.clipped.count;
  for (int j = 0; j < m; ++j) {
    v.edge_normals[j] = kahan_cross(v.clipped.v[j], v.clipped.v[wrap_index(j + 1, m)]);
    const T nz = v.edge_normals[j].z();  // = kahan_cross2 of the xy parts: the sorting comparison
    c.sign[j] = nz > T(0) ? 1 : (nz < T(0) ? -1 : 0);
    c.any_negative = c.any_negative || c.sign[j] < 0;
    c.any_positive = c.any_positive || c.sign[j] > 0;
    c.ell[j] = edge_ellipse(safe_normalized(v.edge_normals[j]));
  }
  return c;
}

// The xy part of clipped vertex i (modulo the count).
template <class T> Vec2<T> clipped_xy(const PolygonProjectedView<T>& v, int i) {
  const Vec3<T>& p = v.clipped.v[wrap_index(i, v.clipped.count)];
  return Vec2<T>(p.x(), p.y());
}

// Sec. 3.1, Fig. 3a: one sector per edge. Its sine s0 x s1 is n_{j,z} >= 0 by construction.
template <class T, bool kBiased> void central_sectors(PolygonProjectedView<T>& v, const ClippedEdges<T>& edges) {
  const int m = v.clipped.count;
  for (int j = 0; j < m; ++j) {
    ProjectedSector<T>& s = v.sectors[v.sector_count++];
    s.s0 = clipped_xy(v, j), s.s1 = clipped_xy(v, j + 1), s.outer = edges.ell[j];
    s.outer_a = v.clipped.v[j], s.outer_b = v.clipped.v[wrap_index(j + 1, m)];
    s.area = std::max(T(0), ellipse_sector_area<T, kBiased>(s.outer, s.s0, s.s1, v.edge_normals[j].z()));
  }
}

// Fig. 3b: the clockwise end c and the counterclockwise end e of the outer chain, where the signs change between runs
// of outer (+) and inner (-) edges, skipping edges of sign 0; the outermost where rounding leaves several runs.
// False when there is no such pair.
template <class T>
bool outer_chain_ends(const PolygonProjectedView<T>& v, const ClippedEdges<T>& edges, int& c, int& e) {
  const int m = v.clipped.count;
  auto nonzero_sign = [&](int j, int step) {
    for (int k = 1; k < m; ++k)
      if (const int sg = edges.sign[wrap_index(j + step * k, m)]; sg != 0) return sg;
    return 0;
  };
  c = -1, e = -1;
  for (int j = 0; j < m; ++j) {
    if (edges.sign[j] <= 0) continue;
    if (nonzero_sign(j, -1) < 0 && (c < 0 || kahan_cross2(clipped_xy(v, c), clipped_xy(v, j)) < T(0))) c = j;
    if (nonzero_sign(j, 1) < 0 && (e < 0 || kahan_cross2(clipped_xy(v, e), clipped_xy(v, j + 1)) > T(0)))
      e = wrap_index(j + 1, m);
  }
  return !(c < 0 || e < 0 || c == e);
}

// Sec. 3.7, Fig. 3b: the decentral sectors, by merging the outer chain (forward from c to e) with the inner one
// (backward from c to e) like the merge step of merge sort. False when the chains do not exist.
template <class T, bool kBiased> bool decentral_sectors(PolygonProjectedView<T>& v, const ClippedEdges<T>& edges) {
  const int m = v.clipped.count;
  int c, e;
  if (!outer_chain_ends(v, edges, c, e)) return false;
  std::array<int, kMaxClippedVertices + 1> ov{}, oe{}, iv{}, ie{};
  const int no = wrap_index(e - c, m), ni = m - no;
  ov[0] = c, iv[0] = c;
  for (int k = 0; k < no; ++k) oe[k] = wrap_index(c + k, m), ov[k + 1] = wrap_index(c + k + 1, m);
  for (int k = 0; k < ni; ++k) ie[k] = wrap_index(c - k - 1, m), iv[k + 1] = ie[k];
  int a = 0, bi = 0;
  Vec2<T> cur = clipped_xy(v, ov[0]);
  while (a < no && bi < ni && v.sector_count < kMaxClippedVertices) {
    const Vec2<T> next_o = clipped_xy(v, ov[a + 1]), next_i = clipped_xy(v, iv[bi + 1]);
    const T order = kahan_cross2(next_o, next_i);
    ProjectedSector<T>& s = v.sectors[v.sector_count++];
    s.decentral = true;
    s.outer = edges.ell[oe[a]], s.inner = edges.ell[ie[bi]];
    s.outer_a = v.clipped.v[oe[a]], s.outer_b = v.clipped.v[wrap_index(oe[a] + 1, m)];
    s.inner_a = v.clipped.v[ie[bi]], s.inner_b = v.clipped.v[wrap_index(ie[bi] + 1, m)];
    s.s0 = cur;
    if (order > T(0))
      s.s1 = next_o, ++a;
    else if (order < T(0))
      s.s1 = next_i, ++bi;
    else
      s.s1 = next_o, ++a, ++bi;
    cur = s.s1;
    const T cross = kahan_cross2(s.s0, s.s1);
    const T sine = cross > T(0) ? cross : T(0);  // a sector is at most 180 degrees: clamp rounding
    s.area = std::max(T(0), area_between_ellipses<T, kBiased>(s, s.s0, s.s1, sine));
  }
  return true;
}

}  // namespace polygon_projected_detail

// The per-light precomputation: the clipped polygon in the (flipped) shading frame (Sec. 3.1), its sectors (Fig. 3)
// and A_Sigma. vertex_rounding: as for check_polygon (polygon.h).
template <class T, bool kBiased>
NoSample fill_polygon_projected_view(const PolygonLightGeometry<T>& g, T vertex_rounding, PolygonProjectedView<T>& v) {
  using namespace polygon_projected_detail;
  PolygonView<T> pv = make_polygon_view(g, vertex_rounding);  // its local polygon flipped in place below
  if (!pv.valid()) return pv.reason;
  if (!resolved_by_coordinates(g, pv)) return NoSample::kTooSmall;
  v.frame = pv.frame;
  v.flip_y = pv.plane_distance < T(0);
  const int n = polygon_inward_planes(g, pv, v.inward.data());
  v.inward[n] = pv.normal;
  v.planes = n + 1;
  if (v.flip_y)
    for (int i = 0; i < pv.local.count; ++i) pv.local.v[i].y() = -pv.local.v[i].y();
  clip_to_upper_hemisphere(pv.local, v.clipped);  // in place: no copy
  const int m = v.clipped.count;
  bool above = false;
  for (int i = 0; i < m; ++i) above = above || v.clipped.v[i].z() > T(0);
  if (m < 3 || !above) return NoSample::kBelowHorizon;
  const ClippedEdges<T> edges = classify_edges(v);
  if (!edges.any_positive) return NoSample::kTooSmall;  // no projected area representable
  // A vertex at the zenith: the central decomposition is exact, and an n_z < 0 elsewhere is noise.
  bool zenith_vertex = false;
  for (int i = 0; i < m; ++i)
    zenith_vertex = zenith_vertex || (v.clipped.v[i].x() == T(0) && v.clipped.v[i].y() == T(0));
  v.central = !edges.any_negative || zenith_vertex || winds_around_zenith(v.clipped);
  if (v.central)
    central_sectors<T, kBiased>(v, edges);
  else if (!decentral_sectors<T, kBiased>(v, edges))
    return NoSample::kTooSmall;
  T total = 0;
  for (int k = 0; k < v.sector_count; ++k) total += v.sectors[k].area;
  // The density cos / A_Sigma must be representable too.
  if (!(total > T(0)) || !std::isfinite(total) || !has_finite_reciprocal(total)) return NoSample::kTooSmall;
  v.projected_solid_angle = total;
  return NoSample::kNone;
}

template <class T, bool kBiased = false>
PolygonProjectedView<T> make_polygon_projected_view(const PolygonLightGeometry<T>& g,
                                                    T vertex_rounding = kPolygonVertexRounding<T>) {
  PolygonProjectedView<T> v;  // filled in place: no copy of the view on return
  v.reason = fill_polygon_projected_view<T, kBiased>(g, vertex_rounding, v);
  return v;
}

// ---- Sampling and density ----

template <class T> T pdf_polygon_projected_solid_angle(const PolygonProjectedView<T>& v, const Vec3<T>& w) {
  if (!v.valid() || !all_finite(w)) return T(0);
  const Vec3<T> l = v.to_local(w);
  if (!(l.z() > T(0))) return T(0);
  for (int j = 0; j < v.planes; ++j)
    if (v.inward[j].dot(w) < T(0)) return T(0);
  const T len = w.norm();
  return len > T(0) ? l.z() / len / v.projected_solid_angle : T(0);
}

// `iterations`: tangent-line iterations in the decentral case (the paper's default, 2).
template <class T, bool kBiased = false>
DirectionSample<T> sample_polygon_projected_solid_angle(const PolygonProjectedView<T>& v, const Vec2<T>& u,
                                                        int iterations = 2) {
  if (!v.valid()) return DirectionSample<T>::none(v.reason);
  // Sector selection by xi_0 (Sec. 3.2), for xi_0 > 1/2 from the far end by 1 - xi_0 (exact): the area left to the
  // last sector's tip then carries its own relative rounding, not eps A_Sigma.
  const bool from_end = u[0] > T(0.5);
  T left = from_end ? (T(1) - u[0]) * v.projected_solid_angle : u[0] * v.projected_solid_angle;
  int k = -1;
  for (int n = 0; n < v.sector_count; ++n) {
    const int i = from_end ? v.sector_count - 1 - n : n;
    if (!(v.sectors[i].area > T(0))) continue;
    k = i;
    if (left < v.sectors[i].area) break;
    left -= v.sectors[i].area;
  }
  if (k < 0) return DirectionSample<T>::none(NoSample::kTooSmall);
  const ProjectedSector<T>& s = v.sectors[k];
  left = std::clamp(left, T(0), s.area);
  const T target = from_end ? s.area - left : left, rest = from_end ? left : s.area - left;
  // Sec. 3.2-3.3: r^2 = (1 - xi_1) r_i^2 + xi_1 r_o^2 between the boundaries, and z^2 likewise (no cancellation).
  Vec2<T> w;
  T ri2 = 0, zi2 = 1, ro2, zo2;
  if (!s.decentral) {
    // Kept in the sector: the biased variant's closed-form angle can overshoot s1 by atan2_approx's error.
    w = clamp_to_sector(s, invert_central_sector(s, target));
  } else {
    w = invert_decentral_sector<T, kBiased>(s, target, rest, iterations);
    edge_boundary_point(s.inner, s.inner_a, s.inner_b, w, &ri2, &zi2);
  }
  edge_boundary_point(s.outer, s.outer_a, s.outer_b, w, &ro2, &zo2);
  const T r2 = (T(1) - u[1]) * ri2 + u[1] * ro2, z2 = (T(1) - u[1]) * zi2 + u[1] * zo2;
  // Eq. 2: project up to the hemisphere.
  const T wn = w.norm();
  const T rho = wn > T(0) ? std::sqrt(r2) / wn : T(0);
  const Vec3<T> local(rho * w.x(), rho * w.y(), std::sqrt(std::max(T(0), z2)));
  DirectionSample<T> out;
  out.direction = safe_normalized(v.to_world(local));
  if (out.direction.isZero()) return DirectionSample<T>::none(NoSample::kTooSmall);
  out.pdf = v.to_local(out.direction).z() / v.projected_solid_angle;
  if (!(out.pdf > T(0)) || !std::isfinite(out.pdf)) return DirectionSample<T>::none(NoSample::kOnSilhouette);
  return out;
}

template <class T> DirectionSample<T> sample_polygon_projected_solid_angle(const PolygonLightGeometry<T>& g,
                                                                           const Vec2<T>& u, int iterations = 2) {
  return sample_polygon_projected_solid_angle<T, false>(make_polygon_projected_view<T, false>(g), u, iterations);
}
template <class T> T pdf_polygon_projected_solid_angle(const PolygonLightGeometry<T>& g, const Vec3<T>& w) {
  return pdf_polygon_projected_solid_angle(make_polygon_projected_view<T, false>(g), w);
}

// The inverse warp of the unbiased sampler: the u that sample_polygon_projected_solid_angle maps to w with an exact
// inversion; false outside the support. u0 is the area from the first sector's start to w's azimuth over A_Sigma
// (Eq. 1 for the central sector, Eq. 7's area between the ellipses for a decentral one), u1 inverts the radial
// interpolation r^2 = (1 - u1) r_i^2 + u1 r_o^2 at that azimuth. The sampler's tangent-line iterations approximate
// the first; an inversion stopped early shows as inverse(sample(u)) != u.
template <class T>
bool invert_polygon_projected_solid_angle(const PolygonProjectedView<T>& v, const Vec3<T>& w, Vec2<T>& u) {
  if (!(pdf_polygon_projected_solid_angle(v, w) > T(0))) return false;
  const Vec3<T> l = v.to_local(w / w.norm());
  const Vec2<T> wxy(l.x(), l.y());
  T before = 0;
  for (int k = 0; k < v.sector_count; ++k) {
    const ProjectedSector<T>& s = v.sectors[k];
    if (!(s.area > T(0))) continue;
    const bool last = k == v.sector_count - 1;
    if (cross2_sign(s.s0, wxy) < 0 || (!last && cross2_sign(wxy, s.s1) < 0)) {
      before += s.area;
      continue;
    }
    T ri2 = 0, zi2 = 1, ro2, zo2;
    const T to_w =
        s.decentral ? decentral_area_to(s, wxy) : ellipse_sector_area(s.outer, s.s0, wxy, kahan_cross2(s.s0, wxy));
    if (s.decentral) edge_boundary_point(s.inner, s.inner_a, s.inner_b, wxy, &ri2, &zi2);
    edge_boundary_point(s.outer, s.outer_a, s.outer_b, wxy, &ro2, &zo2);
    const T r2 = wxy.squaredNorm();
    u[0] = std::clamp((before + std::clamp(to_w, T(0), s.area)) / v.projected_solid_angle, T(0), T(1));
    u[1] = ro2 > ri2 ? std::clamp((r2 - ri2) / (ro2 - ri2), T(0), T(1)) : T(0.5);
    return true;
  }
  return false;
}

// Section 6.4, the biased variant: no iteration, the approximate atan2. Its pdf is a renderer's, cos / A_Sigma with
// the approximate A_Sigma; the samples' true density differs by the initialisation's error (the bias).
template <class T>
DirectionSample<T> sample_polygon_projected_solid_angle_biased(const PolygonLightGeometry<T>& g, const Vec2<T>& u) {
  return sample_polygon_projected_solid_angle<T, true>(make_polygon_projected_view<T, true>(g), u, 0);
}
template <class T> T pdf_polygon_projected_solid_angle_biased(const PolygonLightGeometry<T>& g, const Vec3<T>& w) {
  return pdf_polygon_projected_solid_angle(make_polygon_projected_view<T, true>(g), w);
}

// ---- Catalogue traits (warpcheck/catalogue.h) ----------------------------------------------------------------

// kBiased: Sec. 6.4's variant (no iteration, approximate arctangent), biased by design.
template <class T, bool kBiased> struct PolygonProjectedSolidAngleKernel {
  static constexpr const char* name =
      kBiased ? "polygon-projected-solid-angle-biased" : "polygon-projected-solid-angle";
  static constexpr const char* description = kBiased ? "projected solid angle, Peters 2021 Sec. 6.4, biased"
                                                     : "projected solid angle, Peters 2021 Sec. 3 with 2 iterations";
  using Scalar = T;
  using Geometry = PolygonLightGeometry<T>;
  using View = PolygonProjectedView<T>;
  static View view(const Geometry& g) { return make_polygon_projected_view<T, kBiased>(g); }
  static DirectionSample<T> sample(const View& v, const Vec2<T>& u) {
    return sample_polygon_projected_solid_angle<T, kBiased>(v, u, kBiased ? 0 : 2);
  }
  static T pdf(const View& v, const Vec3<T>& w) { return pdf_polygon_projected_solid_angle(v, w); }
  // The unbiased sampler's inverse warp (the biased one's initialisation is not an inversion).
  static bool invert(const View& v, const Vec3<T>& w, Vec2<T>& u) requires(!kBiased) {
    return invert_polygon_projected_solid_angle(v, w, u);
  }
  // The clipped polygon's vertices.
  static Cap<T> bounding_cap(const Geometry& g) {
    const View v = view(g);
    if (!v.valid()) return polygon_bounding_cap(g);
    std::array<Vec3<T>, kMaxClippedVertices> w;
    for (int i = 0; i < v.clipped.count; ++i) w[i] = v.to_world(v.clipped.v[i]);
    return bounding_cap_of_directions(w.data(), v.clipped.count);
  }
  static T normaliser(const View& v) { return v.projected_solid_angle; }
  // The sectors' cumulative area fractions (the sector is picked by u0, Sec. 3.2).
  static std::vector<T> kinks_u0(const Geometry& g) {
    const View v = view(g);
    std::vector<T> a;
    for (int k = 0; k < v.sector_count; ++k) a.push_back(v.sectors[k].area);
    return cumulative_area_fractions<T>(a.begin(), a.end());
  }
  static std::vector<Vec3<T>> boundary_planes(const Geometry& g) { return polygon_boundary_planes(g); }
};
template <class T> using PolygonProjectedSolidAngle = PolygonProjectedSolidAngleKernel<T, false>;
template <class T> using PolygonProjectedSolidAngleBiased = PolygonProjectedSolidAngleKernel<T, true>;

}  // namespace warpcheck
