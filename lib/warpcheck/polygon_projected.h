// warpcheck/polygon_projected.h: projected-solid-angle sampling of convex polygons, Peters 2021 Section 3,
// and its biased variant (Section 6.4).
//
// Density: pdf(w) = cos(theta) / A_Sigma inside the polygon (clipped to the upper hemisphere), where A_Sigma
// is the polygon's projected solid angle, computed by the kernel as the sum of its sector areas (Eq. 1).
//
// Outline (Sec. 3.1-3.4). The polygon is expressed in the shading frame, its y coordinates flipped if its
// vertex order winds negatively as seen from the shading point (Sec. 3.1), and clipped to z >= 0. Edge j has
// the great-circle normal n_j = v_j x v_{j+1} (Kahan's determinants, Sec. 3.7); with this winding all n_j
// point into the polygon and the xy-projection of the polygon runs counterclockwise, so n_{j,z} > 0 marks an
// outer edge and n_{j,z} < 0 an inner one (Sec. 3.7). Rays through the vertices cut the unit disk into
// sectors (Fig. 3). A sector is chosen in proportion to its area, then the azimuth inside it is found in
// closed form (central case, Sec. 3.2) or by the tangent-line iteration (decentral case, Sec. 3.3, Eq. 5-7)
// from the two-quad initialisation (Sec. 3.4), and the radius in closed form.
//
// Homogeneous ellipses (our derivation; Supplement A.2 is not available to us). The paper stores
// u_j = n_{j,xy} / n_{j,z} and C_j = I + u_j u_j^T, which is infinite in the zenith case n_{j,z} = 0. We store
// the unit normal n_j instead and work with the scaled matrix Ct_j := n_{j,z}^2 C_j = n_{j,z}^2 I +
// n_{j,xy} n_{j,xy}^T, which is finite (|Ct_j| = n_{j,z}^2 for unit n_j). Every formula is rewritten with it:
//   Eq. 1:    area = |n_z| / 2 * atan2(|n_z| s0 x s1, s0^T Ct s1)      (since sqrt|C| = 1 / |n_z|)
//   Eq. 3:    1 / (w^T C w) = n_z^2 / (w^T Ct w)
//   Eq. 5:    multiplied by n_{i,z}^2 n_{o,z}^2 > 0, which leaves its roots unchanged:
//             T = R w_n (n_{o,z}^2 w_n^T Ct_i - n_{i,z}^2 w_n^T Ct_o) - 2 A_delta Ct_i w_n w_n^T Ct_o
// A zenith edge then simply has area 0 in every sector and radius 0, which is what its degenerate ellipse (a
// segment through the origin) encloses; no branch is needed.
//
// Vertex sorting (Sec. 3.7). The GPU code sorts with bitonic sorting networks to avoid register spilling.
// On the CPU there is no such concern, so we use the structure directly: the polygon is convex and, in the
// decentral case, does not surround the zenith, so its vertices' azimuths rise along the outer chain (edges
// with n_z > 0) and fall along the inner chain (n_z < 0). Starting at the clockwise end, we merge the two
// monotonic chains like the merge step of merge sort. That is a correct sort (a merge of two sorted lists)
// in O(m), and it pairs every sector with its inner and outer edge as a by-product. The comparisons are
// Kahan cross products, the same computation as n_{j,z}, so sorting and edge classification agree (Sec. 3.7).
#pragma once

#include <type_traits>

#include "warpcheck/polygon.h"

namespace warpcheck {

// ---- arctangents -------------------------------------------------------------------------------------------

// The biased variant's atan2 (Sec. 6.4 asks for a piecewise polynomial with forward error <= 1.2e-5 rad).
// We reduce to atan on [0, 1] by octant symmetry and use the odd degree-9 polynomial of Abramowitz & Stegun
// 4.4.47 (Hastings), whose error bound there is 1e-5; test_polygon measures the actual maximum.
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

template <class T, bool kBiased> T polygon_atan2(T y, T x) {
  if constexpr (kBiased)
    return atan2_approx(y, x);
  else
    return std::atan2(y, x);
}

// ---- Ellipses in homogeneous form ------------------------------------------------------------------------

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
  // 1 - |p|^2 for the ellipse point p = w / sqrt(w^T C w), i.e. its z^2 on the hemisphere (Eq. 2), from the
  // identity w^T Ct w - nz^2 |w|^2 = (nxy.w)^2: no cancellation near the horizon, where 1 - |p|^2 computed
  // as a difference loses half the digits (found by fuzz_polygon_projected_double: samples 3.5e-9 rad below
  // a clipped polygon's horizon vertex in double). A degenerate ellipse (f = 0) has p = 0.
  T one_minus_radius2(const Vec2<T>& w) const {
    const T f = form(w, w);
    if (!(f > T(0))) return T(1);
    const T d = nxy.dot(w);
    return std::min(T(1), d * d / f);
  }
};

// The boundary point of a sector at azimuth w on one edge, as (|p|^2, z^2) of the unit direction p (their sum
// is 1). From the edge's own endpoints a, b (clipped, local frame) when known: the ray at azimuth w meets the
// segment at a + t (b - a), t = (w x a) / ((w x a) - (w x b)) clamped to [0, 1] (w x a and w x b have opposite
// signs inside the sector, so the denominator does not cancel). Mathematically this is the point of Eq. 3
// (the ellipse is the edge's great circle projected), but it is well conditioned where the ellipse is a
// needle: an edge whose great circle passes within rounding of the zenith has |n_z| ~ eps |n_xy|, and there
// an azimuth error of eps moves Eq. 3's point along the needle by eps / |n_z|, past the edge's end (found by
// fuzz_polygon_projected_double: the light's plane containing the normal, samples 0.23 rad outside; our
// remedy, issue 7). Without endpoints (a = b = 0), Eq. 3.
template <class T>
void edge_boundary_point(const EdgeEllipse<T>& e, const Vec3<T>& a, const Vec3<T>& b, const Vec2<T>& w, T* r2, T* z2) {
  const T ca = kahan_cross2(w, Vec2<T>(a.x(), a.y())), cb = kahan_cross2(w, Vec2<T>(b.x(), b.y()));
  const T den = ca - cb;
  if (a != b && std::isfinite(den)) {
    // den = 0: the segment's xy projection is parallel to w up to rounding. Inside a sector that means a radial
    // edge (its great circle through the zenith, n_z = 0): all its points have azimuth w and each one is a
    // boundary point, while Eq. 3's radius along the degenerate ellipse's diameter is 0 / 0 rounding noise
    // (found by fuzz_polygon_projected_double: u_0 = 0 picked a zero-width sector of area 8e-21 next to such an
    // edge, sample 0.75 rad outside an ordinary triangle, issue 7). We take its midpoint.
    const T t = den != T(0) ? std::clamp(ca / den, T(0), T(1)) : T(0.5);
    Vec3<T> p = a + t * (b - a);
    // The point must lie on the ray, not behind it. An edge whose great circle passes near the zenith and whose
    // ends lie at nearly opposite azimuths is nearly collinear with the ray's line; at w on one end's azimuth
    // (u_0 = 0 gives w = s0 exactly) ca and cb are both rounding noise, and t could pick the far end behind the
    // ray: r^2 of a horizon vertex instead of the near vertex's (found by fuzz_polygon_projected_double
    // 07bc462c...: sample 0.74 rad outside a triangle, issue 7). The endpoint ahead along w is then the point.
    // Behind by more than rounding only: an edge through the zenith meets every ray at p ~ 0, where the sign of
    // p . w is noise (44e37d33...: the endpoint put a sample 0.36 rad outside).
    const Vec2<T> axy(a.x(), a.y()), bxy(b.x(), b.y()), pxy(p.x(), p.y());
    const T behind = T(8) * std::numeric_limits<T>::epsilon() * (axy.norm() + bxy.norm()) * w.norm();
    if (pxy.dot(w) < -behind) p = axy.dot(w) >= bxy.dot(w) ? a : b;
    const T m = p.cwiseAbs().maxCoeff();
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

// Eq. 1 (homogeneous form): the area of the ellipse inside the sector from s0 counterclockwise to s1, given
// cross = s0 x s1 (passed in so that callers decide on its computation and clamping).
template <class T, bool kBiased = false>
T ellipse_sector_area(const EdgeEllipse<T>& e, const Vec2<T>& s0, const Vec2<T>& s1, T cross) {
  const T a = std::abs(e.nz);
  return a / T(2) * polygon_atan2<T, kBiased>(a * cross, e.form(s0, s1));
}

// ---- Sectors ------------------------------------------------------------------------------------------------

template <class T> struct ProjectedSector {
  Vec2<T> s0 = Vec2<T>::Zero(), s1 = Vec2<T>::Zero();            // boundaries, counterclockwise, at most 180 degrees
  EdgeEllipse<T> outer, inner;                                   // inner only in the decentral case
  Vec3<T> outer_a = Vec3<T>::Zero(), outer_b = Vec3<T>::Zero();  // the edges' clipped endpoints (local frame)
  Vec3<T> inner_a = Vec3<T>::Zero(), inner_b = Vec3<T>::Zero();
  bool decentral = false;
  T area = 0;
};

// The root of Eq. 6, w^T T w = 0, found around a nearby direction `base` (the current iterate, or the quad's
// start boundary s_k). Blinn 2006 as specialised by Peters (Supplement A.3, not available to us) takes the
// projective root x / y = (-b - sqrt(Delta)) / a of the symmetric part S of T (a = T_xx, 2b = T_xy + T_yx,
// c = T_yy, Delta = b^2 - a c); that is the null direction r of S with r x (S r) > 0 (our derivation). We write
// w = base + tau R base (R: rotation by +90 degrees), so w^T T w = P(tau) = a0 + a1 tau + a2 tau^2, and the
// rule, being invariant under rotations and scalings, becomes r x (S r) = P'(tau) (1 + tau^2) / 2 > 0: the
// root where P increases, tau = (-a1 + sqrt(D)) / (2 a2) = -2 a0 / (a1 + sqrt(D)), D = a1^2 - 4 a0 a2, each
// form used where it does not cancel. The callers build a0, a1, a2 from T's factors, so a0 (the residual term)
// carries no rounding from the terms that vanish exactly at tau = 0.
// Why not Blinn's formula on T's entries (our remedy, issue 4): those entries are O(|C w|^2), and where the
// inner and outer ellipses nearly coincide (a small light far away: a sector 2e-4 rad wide, the ellipses 2.5e-4
// apart relative) the root moves by their rounding, eps / 2.5e-4 rad, which in float exceeded the sector: the
// 1 cm light 40 m away (far-1cm) sampled up to 0.43 light widths off the exact inverse, and did not improve with
// more iterations (chi2 p = 0 at 1e7 samples). Around base, the step tau has rounding relative to itself.
// Returns w up to sign (the callers orient it with the sector's half-vector); 0 when all coefficients vanish.
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

// The scalar in which a float kernel takes the difference of Eq. 1's two ellipse areas: double (float inputs are
// exact in it). Why (our remedy, issue 5): near a sector's tip, where the inner and outer ellipses meet, the area
// between them shrinks faster than either term. At a tip on the horizon the inner ellipse touches the unit
// circle, the area grows with the cube of the angle from the tip, and the terms were up to ~4000 times larger than
// their difference: the float LTC sampler of a light straddling the horizon (polygon-ltc lobe-away) put samples
// near both tips where the float warp's density was off its pdf by 2.9e-4 at xi_0 in [3e-4, 6e-4] and by 8.8e-5
// at xi_0 = 0.99966 (its battery's pdf-consistency failure), against the long double warp. In double the same
// cancellation costs 4000 eps_d, far below float's own rounding. A cancellation-free formula for the area
// between two ellipses near their common point is not known to us. The biased variant (Sec. 6.4) stays in T: its
// approximate atan2 (1.2e-5 rad) dominates the cancellation, and it exists to be cheap.
template <class T, bool kBiased> using EllipseAreaScalar =
    std::conditional_t<std::is_same_v<T, float> && !kBiased, double, T>;

template <class A, class T> EdgeEllipse<A> ellipse_cast(const EdgeEllipse<T>& e) {
  return EdgeEllipse<A>{e.nxy.template cast<A>(), A(e.nz)};
}

// Eq. 1 applied to both ellipses of a decentral sector: the area between them from a counterclockwise to b,
// given cross = a x b (in the wider scalar recomputed from a and b, exactly; a clamped 0 stays 0).
template <class T, bool kBiased = false>
T area_between_ellipses(const ProjectedSector<T>& s, const Vec2<T>& a, const Vec2<T>& b, T cross) {
  using A = EllipseAreaScalar<T, kBiased>;
  const Vec2<A> aa = a.template cast<A>(), ba = b.template cast<A>();
  const A c = std::is_same_v<A, T> || cross == T(0) ? A(cross) : kahan_cross2(aa, ba);
  return T(ellipse_sector_area<A, kBiased>(ellipse_cast<A>(s.outer), aa, ba, c) -
           ellipse_sector_area<A, kBiased>(ellipse_cast<A>(s.inner), aa, ba, c));
}

// The area between the ellipses in the sector from s0 to w (the subtracted terms of Eq. 7).
template <class T, bool kBiased = false> T decentral_area_to(const ProjectedSector<T>& s, const Vec2<T>& w) {
  return area_between_ellipses<T, kBiased>(s, s.s0, w, kahan_cross2(s.s0, w));
}

// The area between the ellipses in the sector from w to s1.
template <class T, bool kBiased = false> T decentral_area_from(const ProjectedSector<T>& s, const Vec2<T>& w) {
  return area_between_ellipses<T, kBiased>(s, w, s.s1, kahan_cross2(w, s.s1));
}

// Eq. 7: residual A_delta(w) = A - area(s0 -> w), measured from the sector's nearer end: for A beyond half the
// sector's area as area(w -> s1) - (A_j - A), equal in exact arithmetic. Why (our remedy, issue 4): the area is a
// difference of two ellipse areas, each up to ~1e3 times larger than it for a small far light, so its rounding
// is eps times the larger terms. Where the chains meet at s1 (the tip of the last sector), the area left to the
// tip is tiny and the difference from s0 cannot resolve it: float samples of the 1 cm light 40 m away with A
// within 5e-4 of A_j were up to 1.7e-2 light widths off and piled up in the corner (chi2 bin +18 sigma at 1e7).
// From s1, both terms shrink with the area they bound.
// `rest` is A_j - A, the area the sample leaves to s1, which the caller may know more accurately than the
// difference (sample_polygon_projected_solid_angle takes it from (1 - xi_0) A_Sigma for xi_0 > 1/2).
template <class T, bool kBiased = false>
T decentral_residual(const ProjectedSector<T>& s, T target, T rest, const Vec2<T>& w) {
  if (target <= rest) return target - decentral_area_to<T, kBiased>(s, w);
  return decentral_area_from<T, kBiased>(s, w) - rest;
}
template <class T, bool kBiased = false> T decentral_residual(const ProjectedSector<T>& s, T target, const Vec2<T>& w) {
  return decentral_residual<T, kBiased>(s, target, s.area - target, w);
}

// Section 3.4: the two-quad initialisation. The quad vertices are lambda_{l,j} s_j (l in {i, o}, j in {k, h});
// an edge of quad k through lambda_{l,h} s_h and lambda_{l,k} s_k has the normal r_l = C_l (lambda_{l,h} s_h +
// lambda_{l,k} s_k) (a chord of the ellipse, normal C (p + q) since p^T C p = q^T C q = 1) and the offset
// D_l = lambda_{l,h} r_l^T s_h. Derivation of Q (Supplement A.4 is not available to us): the ray through w
// meets edge l at D_l w / (r_l^T w), so the area of quad k in the sector from s_k to w is
//   lambda_{o,k} D_o (s_k x w) / (2 r_o^T w) - lambda_{i,k} D_i (s_k x w) / (2 r_i^T w) = A_q;
// with s_k x w = w^T R s_k and multiplying out, w^T Q w = 0 for the paper's
//   Q = lambda_{o,k} D_o R s_k r_i^T - (lambda_{i,k} D_i R s_k + 2 A_q r_i) r_o^T.
// Q is bilinear in (r_i, r_o), so we may scale r_l by any positive factor; we drop 1 / n_{l,z} so that r_l
// stays finite as n_{i,z} -> 0. For quad k = 1 the area is measured from s_1, i.e. it is negative.
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
  // w^T Q w with w = s_k + tau R s_k (increasing_root_around): w . R s_k = tau |s_k|^2, r_l . w = r_l . s_k +
  // tau r_l . R s_k, so P(tau) = lambda_{o,k} D_o tau |s_k|^2 (r_i . w) - (lambda_{i,k} D_i tau |s_k|^2 + 2 A_q r_i .
  // w) (r_o . w).
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
  // T = R w_n x^T - 2 A_delta (C_i w_n)(C_o w_n)^T with x = c_o C_i w_n - c_i C_o w_n (homogeneous C = Ct / n_z^2,
  // c = n_z^2). With w = w_n + tau R w_n (increasing_root_around) and f = w_n^T Ct w_n, g = (R w_n)^T Ct w_n
  // = (n_xy . w_n)(n_xy . R w_n) (the n_z^2 w_n . R w_n term is 0), P(tau) = tau |w_n|^2 (x . w_n + tau x . R w_n)
  // - 2 A_delta (f_i + tau g_i)(f_o + tau g_o). x . w_n = c_o f_i - c_i f_o = (n_{o,z} d_i)^2 - (n_{i,z} d_o)^2 with
  // d = n_xy . w_n, since the |w_n|^2 terms cancel exactly: it is taken as a difference of squares.
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

// The exact inverse lies in the sector [s0, s1] (the area from s0 grows monotonically across it), but where the
// inner and outer ellipses (nearly) coincide, Eq. 5's coefficients are rounding noise and the root can leave
// the sector; there the ray meets the ellipses with nxy.w of the wrong sign, i.e. on the great circle
// mirrored in the horizon (found by fuzz_polygon_projected_double: a sliver polygon seen along its plane,
// sample 7e-4 rad off the light, issue 7). We put such a w back on the nearer boundary.
template <class T> Vec2<T> clamp_to_sector(const ProjectedSector<T>& s, const Vec2<T>& w) {
  if (kahan_cross2(s.s0, w) < T(0)) return l1_normalized(s.s0);
  if (kahan_cross2(w, s.s1) < T(0)) return l1_normalized(s.s1);
  return w;
}

// The decentral inversion: initialisation plus `iterations` steps, each kept inside the sector. `target` is the
// area from s0, `rest` the area to s1 (decentral_residual).
template <class T, bool kBiased = false>
Vec2<T> invert_decentral_sector(const ProjectedSector<T>& s, T target, T rest, int iterations) {
  Vec2<T> w = clamp_to_sector(s, decentral_initialization<T, kBiased>(s, target));
  for (int k = 0; k < iterations; ++k) w = clamp_to_sector(s, decentral_iteration<T, kBiased>(s, target, rest, w));
  return w;
}
template <class T, bool kBiased = false>
Vec2<T> invert_decentral_sector(const ProjectedSector<T>& s, T target, int iterations) {
  return invert_decentral_sector<T, kBiased>(s, target, s.area - target, iterations);
}

// Section 3.2: the central case in closed form. The angle in the Cholesky-transformed circle is
// phi = 2 sqrt|C| A = 2 A / |n_z|; the 2x2 system (-s0^T R w, s0^T C w / sqrt|C|) ~ (sin phi, cos phi),
// with its second row multiplied by |n_z|^2 (homogeneous form), is solved by Cramer's rule. Its determinant
// is -s0^T Ct s0 < 0; w is only needed up to a positive factor, so we multiply by -det instead of dividing.
template <class T> Vec2<T> invert_central_sector(const ProjectedSector<T>& s, T target) {
  const T a = std::abs(s.outer.nz);
  const T phi = a > T(0) ? std::min(T(2) * target / a, kPi<T>) : T(0);
  const T b1 = std::sin(phi), b2 = a * std::cos(phi);
  const Vec2<T> r1(-s.s0.y(), s.s0.x());
  const Vec2<T> r2 = s.outer.times(s.s0);
  return l1_normalized(Vec2<T>(r1.y() * b2 - r2.y() * b1, r2.x() * b1 - r1.x() * b2));
}

// ---- The per-light precomputation ----------------------------------------------------------------------------

template <class T> struct PolygonProjectedView {
  NoSample reason = NoSample::kNone;
  Frame<T> frame = Frame<T>::from_z(Vec3<T>(T(0), T(0), T(1)));
  bool flip_y = false;      // y flipped so that the vertex order winds positively (Sec. 3.1)
  LocalPolygon<T> clipped;  // in the (flipped) shading frame, clipped to z >= 0
  std::array<Vec3<T>, kMaxClippedVertices> edge_normals{};  // n_j = v_j x v_{j+1} (Kahan), not normalised
  // The density's cone test (world space): the light's own edge planes (V_j - x) x (V_{j+1} - V_j), oriented
  // inwards, and the horizon. Not the n_j: those come from rounded V - x, and for an edge shorter than that
  // rounding (1e-15 at coordinates ~20) their direction is noise, so pdf() rejected directions 1.8e-9 rad
  // inside the light (found by fuzz_polygon_projected_double, issue 7); V_{j+1} - V_j of nearby vertices is
  // exact (Sterbenz). The clipped edges lie on the same planes (clip_to_upper_hemisphere).
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

// Whether the clipped polygon's xy projection winds around the zenith (the origin): the azimuth increments
// atan2(a x b, a . b) of its edges add up to 2 pi around it and to 0 outside. Central (Sec. 3.1) is "no edge has
// n_z < 0", but an edge whose n_z is within the rounding of its endpoints' coordinates has a sign of rounding
// noise: a doubled vertex, or a short edge far from the zenith whose line the coordinates do not place to the
// zenith's side of it. One such sign made polygons around the zenith decentral, where the chains of Fig. 3b do
// not exist (found by fuzz_ltc_double with M = I: octagons around the zenith with a doubled vertex, and one seen
// from 5e-9 beside a vertex with a short edge at n_z = -5e-16 whose direction is known to 2e-6 rad, A_Sigma ~1e-33
// instead of 0.11..1.6, issue 7). Such an edge adds an increment of the order of its own noise to the sum, so the
// winding number decides unless the zenith is within rounding of the boundary, where either case is right.
template <class T> bool winds_around_zenith(const LocalPolygon<T>& p) {
  T sum = 0;
  for (int j = 0; j < p.count; ++j) {
    const Vec2<T> a(p.v[j].x(), p.v[j].y()), b(p.v[(j + 1) % p.count].x(), p.v[(j + 1) % p.count].y());
    sum += std::atan2(kahan_cross2(a, b), a.dot(b));
  }
  return sum > kPi<T>;
}

// vertex_rounding: as for check_polygon (polygon.h).
template <class T, bool kBiased = false>
PolygonProjectedView<T> make_polygon_projected_view(const PolygonLightGeometry<T>& g,
                                                    T vertex_rounding = kPolygonVertexRounding<T>) {
  PolygonProjectedView<T> v;
  const PolygonView<T> pv = make_polygon_view(g, vertex_rounding);
  if (!pv.valid()) return v.reason = pv.reason, v;
  // The light must be resolved by its local coordinates. V_k - x is rounded to eps (|V_k|_inf + |x|_inf), and
  // where that is comparable to the light's own extent the local polygon is rounding noise: its turns and the
  // signs of its edges' n_z wind both ways, and the sector chains (Fig. 3b) are not those of any light (found by
  // fuzz_polygon_projected_double 3c4c6d32 and ee5d7338: an octagon of diameter 32 seen from 1.7e17 away, the
  // zenith sampled, 0.64 and 0.85 rad outside, issue 7). Below 64 eps of the coordinates' scale the light is
  // also narrower than the fuzz checks' direction tolerance (fuzz/targets/common.h), so no sample can be told
  // from one of its neighbourhood: "too small" (double: 1.4e-14 of the scale; float: 7.6e-6).
  {
    T extent = 0, scale = 0;
    for (int i = 0; i < g.light.count; ++i) {
      extent = std::max(extent, Vec3<T>(g.light.vertices[i] - g.light.vertices[0]).cwiseAbs().maxCoeff());
      scale = std::max(scale, g.light.vertices[i].cwiseAbs().maxCoeff());
    }
    scale += g.shading.position.cwiseAbs().maxCoeff();
    if (!(extent > T(64) * std::numeric_limits<T>::epsilon() * scale)) return v.reason = NoSample::kTooSmall, v;
    // The same holds across the light's image: seen at an angle, a light of diameter D at distance d from x, x at
    // |plane_distance| from its plane, is D |plane_distance| / d wide in the plane through it normal to the view,
    // and below 64 eps of the scale its local polygon is noise too (found by fuzz_polygon_projected_double
    // 09066122: an octagon 16 across seen from 4.3e13 away, 6.2e-5 rad off edge-on, its image 1e-3 wide against
    // V - x rounded to 2e-3; the edges' n_z signs were noise, the decentral case was taken, A_Sigma came out as
    // 1.8e-16 instead of 5.4e-31 sr, and a biased sample lay 1.5e-14 rad outside, tol 1.4e-14; issue 7). d is bounded
    // below by |plane_distance| and by the nearest vertex's distance less D, so the width is not underestimated:
    // for x over the light (d = |plane_distance|) it is much the test above.
    T diameter = 0, nearest = std::numeric_limits<T>::infinity();
    for (int i = 0; i < g.light.count; ++i) {
      diameter = std::max(diameter, T(2) * Vec3<T>(g.light.vertices[i] - g.light.vertices[0]).stableNorm());
      nearest = std::min(nearest, Vec3<T>(g.light.vertices[i] - g.shading.position).stableNorm());
    }
    const T h = std::abs(pv.plane_distance), d = std::max(h, nearest - diameter);
    if (!(diameter * (h / d) > T(64) * std::numeric_limits<T>::epsilon() * scale))
      return v.reason = NoSample::kTooSmall, v;
  }
  v.frame = pv.frame;
  v.flip_y = pv.plane_distance < T(0);
  {
    const int n = polygon_inward_planes(g, pv, v.inward.data());
    v.inward[n] = pv.normal;
    v.planes = n + 1;
  }
  LocalPolygon<T> local = pv.local;
  if (v.flip_y)
    for (int i = 0; i < local.count; ++i) local.v[i].y() = -local.v[i].y();
  v.clipped = clip_to_upper_hemisphere(local);
  const int m = v.clipped.count;
  bool above = false;
  for (int i = 0; i < m; ++i) above = above || v.clipped.v[i].z() > T(0);
  if (m < 3 || !above) return v.reason = NoSample::kBelowHorizon, v;

  std::array<int, kMaxClippedVertices> sign{};
  std::array<EdgeEllipse<T>, kMaxClippedVertices> ell{};
  bool any_negative = false, any_positive = false;
  for (int j = 0; j < m; ++j) {
    v.edge_normals[j] = kahan_cross(v.clipped.v[j], v.clipped.v[(j + 1) % m]);
    const T nz = v.edge_normals[j].z();  // = kahan_cross2 of the xy parts: the sorting comparison
    sign[j] = nz > T(0) ? 1 : (nz < T(0) ? -1 : 0);
    any_negative = any_negative || sign[j] < 0;
    any_positive = any_positive || sign[j] > 0;
    ell[j] = edge_ellipse(safe_normalized(v.edge_normals[j]));
  }
  if (!any_positive) return v.reason = NoSample::kTooSmall, v;  // no projected area representable
  auto xy = [&](int i) { return Vec2<T>(v.clipped.v[(i % m + m) % m].x(), v.clipped.v[(i % m + m) % m].y()); };
  // A vertex at the zenith (make_polygon_view puts one within rounding of it there) puts the zenith on the boundary:
  // the central decomposition is then exact, each edge's sector a triangle with its apex at the zenith (the two
  // edges at that vertex radial, of area 0), and every other edge has the zenith on its inner side, so an n_z < 0 is
  // rounding noise (its sector gets area 0). The winding number sees only the other edges there and gives the
  // decentral case, whose chains do not exist: the radial edges have sign 0, and a noise sign became the only inner
  // chain (found by fuzz_ltc_double 403f9cc0...: M = I, an edge 4e-15 long with n_z = -1e-17, A_Sigma 4.9e-32
  // instead of 0.708; issue 7).
  bool zenith_vertex = false;
  for (int i = 0; i < m; ++i)
    zenith_vertex = zenith_vertex || (v.clipped.v[i].x() == T(0) && v.clipped.v[i].y() == T(0));
  v.central = !any_negative || zenith_vertex || winds_around_zenith(v.clipped);
  if (v.central) {
    // Sec. 3.1, Fig. 3a: one sector per edge. Its sine s0 x s1 is n_{j,z} >= 0 by construction.
    for (int j = 0; j < m; ++j) {
      ProjectedSector<T>& s = v.sectors[v.sector_count++];
      s.s0 = xy(j), s.s1 = xy(j + 1), s.outer = ell[j];
      s.outer_a = v.clipped.v[j], s.outer_b = v.clipped.v[(j + 1) % m];
      s.area = std::max(T(0), ellipse_sector_area<T, kBiased>(s.outer, s.s0, s.s1, v.edge_normals[j].z()));
    }
  } else {
    // Fig. 3b: find the clockwise end c and the counterclockwise end e of the outer chain, then merge the chains:
    // the outer chain runs forward from c to e, the inner one backward from c to e. The ends are where the signs
    // change between the runs of outer (+) and inner (-) edges, skipping edges of sign 0 (radial, or of length 0 in
    // xy): such an edge can lie inside a run (a doubled vertex, three collinear vertices on a ray), and
    // stopping a chain there lost the rest of the light (found by fuzz_ltc_double with M = I, c37ad58b: a
    // triangle with a doubled vertex cut by the horizon, A_Sigma 9.3e-22 instead of 1.57e-4, issue 7). Where
    // rounding still leaves more than one run of each sign (edges within rounding of a ray that point the wrong
    // way), the true ends are the most clockwise run start and the most counterclockwise run end; the edges
    // between them are assigned to the chains by position, and a sector of negative width gets area 0 below.
    auto nonzero_sign = [&](int j, int step) {
      for (int k = 1; k < m; ++k)
        if (const int sg = sign[((j + step * k) % m + m) % m]; sg != 0) return sg;
      return 0;
    };
    int c = -1, e = -1;
    for (int j = 0; j < m; ++j) {
      if (sign[j] <= 0) continue;
      if (nonzero_sign(j, -1) < 0 && (c < 0 || kahan_cross2(xy(c), xy(j)) < T(0))) c = j;
      if (nonzero_sign(j, 1) < 0 && (e < 0 || kahan_cross2(xy(e), xy(j + 1)) > T(0))) e = (j + 1) % m;
    }
    if (c < 0 || e < 0 || c == e) return v.reason = NoSample::kTooSmall, v;
    std::array<int, kMaxClippedVertices + 1> ov{}, oe{}, iv{}, ie{};
    const int no = (e - c + m) % m, ni = m - no;
    ov[0] = c, iv[0] = c;
    for (int k = 0; k < no; ++k) oe[k] = (c + k) % m, ov[k + 1] = (c + k + 1) % m;
    for (int k = 0; k < ni; ++k) ie[k] = (c - k - 1 + m) % m, iv[k + 1] = ie[k];
    int a = 0, bi = 0;
    Vec2<T> cur = xy(ov[0]);
    while (a < no && bi < ni && v.sector_count < kMaxClippedVertices) {
      const Vec2<T> next_o = xy(ov[a + 1]), next_i = xy(iv[bi + 1]);
      const T order = kahan_cross2(next_o, next_i);
      ProjectedSector<T>& s = v.sectors[v.sector_count++];
      s.decentral = true;
      s.outer = ell[oe[a]], s.inner = ell[ie[bi]];
      s.outer_a = v.clipped.v[oe[a]], s.outer_b = v.clipped.v[(oe[a] + 1) % m];
      s.inner_a = v.clipped.v[ie[bi]], s.inner_b = v.clipped.v[(ie[bi] + 1) % m];
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
  }
  T total = 0;
  for (int k = 0; k < v.sector_count; ++k) total += v.sectors[k].area;
  // The density cos / A_Sigma must be representable too: a light 1e154 away has A_Sigma ~ 1e-308 and 1 / A_Sigma
  // overflows (found by fuzz_polygon_projected_double, issue 7).
  if (!(total > T(0)) || !std::isfinite(total) || !std::isfinite(T(1) / total))
    return v.reason = NoSample::kTooSmall, v;
  v.projected_solid_angle = total;
  return v;
}

// ---- Sampling and density ------------------------------------------------------------------------------------

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
  // Sector selection by xi_0 (Sec. 3.2): A = xi_0 A_Sigma - sum_{k<j} A_k in [0, A_j). For xi_0 > 1/2 we count
  // from the other end instead: rest = A_j - A = (1 - xi_0) A_Sigma - sum_{k>j} A_k (1 - xi_0 is exact there).
  // Why (our remedy, issue 5): the subtraction from xi_0 A_Sigma leaves an absolute error of eps A_Sigma, and
  // near the last sector's tip, where the area to s1 grows with the cube of the angle (a tip on the horizon),
  // that moved float samples of polygon-ltc lobe-away far enough that the density at them was off the warp's by
  // 1.4e-4 at xi_0 = 1 - 3e-4 (measured against the long double warp); counted from the end, the area left to
  // the tip carries its own relative rounding only, as the first sector's area from its tip always did.
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
  // Sec. 3.2 / 3.3: the squared radius is interpolated linearly in xi_1 between the inner boundary (the
  // origin in the central case) and the outer one, r^2 = (1 - xi_1) r_i^2 + xi_1 r_o^2 (with r^2 = 1 / (w^T C w)
  // for unit w, Eq. 3); z^2 = 1 - r^2 is interpolated in the same way, from each boundary's own z^2 (no
  // cancellation near the horizon). Boundary points from the edges' endpoints: edge_boundary_point.
  Vec2<T> w;
  T ri2 = 0, zi2 = 1, ro2, zo2;
  if (!s.decentral) {
    // Kept in the sector: the biased variant's sector areas come from atan2_approx (Sec. 6.4), so its closed-form
    // angle 2 A / |n_z| can overshoot s1 by the approximation's error (found by fuzz_polygon_projected_double:
    // u_0 = 1 - ulp, sample 5.8e-6 rad outside, issue 7).
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

// Section 6.4, the biased variant: no iteration and the approximate atan2 everywhere the areas need one.
// Its pdf is the one a renderer would use, cos / A_Sigma with the approximate A_Sigma; the true density of
// its samples differs from it by the initialisation's error (that is the bias).
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
  static constexpr const char* description = kBiased ? "projected solid angle, Peters 2021 Sec. 6.4 (biased)"
                                                     : "projected solid angle, Peters 2021 Sec. 3 (2 iterations)";
  using Scalar = T;
  using Geometry = PolygonLightGeometry<T>;
  using View = PolygonProjectedView<T>;
  static View view(const Geometry& g) { return make_polygon_projected_view<T, kBiased>(g); }
  static DirectionSample<T> sample(const View& v, const Vec2<T>& u) {
    return sample_polygon_projected_solid_angle<T, kBiased>(v, u, kBiased ? 0 : 2);
  }
  static T pdf(const View& v, const Vec3<T>& w) { return pdf_polygon_projected_solid_angle(v, w); }
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
