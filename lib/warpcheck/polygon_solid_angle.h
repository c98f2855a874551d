// warpcheck/polygon_solid_angle.h: solid-angle sampling of convex polygons, Peters 2021 Section 5 (plain and
// clipped to the upper hemisphere), and the published baselines Arvo 1995 (spherical triangles, as a fan) and
// Turk 1992 (uniform area). Densities: 1 / Omega inside the cone (Arvo: Omega from the angle sums); Turk
// h^2 / (|N.w|^3 Area). The unclipped kernels also sample below the shading horizon.
// Derivations and the fan's safeguards: docs/derivations/polygon-solid-angle.md.
#pragma once

#include "warpcheck/polygon.h"

namespace warpcheck {

// The polygon as seen from the shading point, in world space, wound positively (det(p0, p1, p2) > 0).
template <class T> struct PolygonFanView {
  NoSample reason = NoSample::kNone;
  int count = 0;
  std::array<Vec3<T>, kMaxFanVertices> p{};  // vertex - shading point
  std::array<Vec3<T>, kMaxFanVertices> e{};  // p_k - p_0, from the light's own vertices if unclipped
  std::array<Vec3<T>, kMaxFanVertices> u{};  // p_k / |p_k|
  std::array<T, kMaxFanVertices> len{};      // |p_k| by stable_norm (norm() underflows for |p| < 1e-154)
  // The cone {w : inward_j . w >= 0}: the light's edge planes, the horizon (clipped), and the plane through x
  // parallel to the light's (which excludes the antipodes a sliver's edge planes let in).
  std::array<Vec3<T>, kMaxFanVertices> inward{};
  int planes = 0;
  Vec3<T> plane_normal = Vec3<T>::Zero();  // unit
  T plane_distance = 0;                    // |plane_normal . p_0| > 0
  bool valid() const { return reason == NoSample::kNone; }
};

// u_b - u_a for u = p / |p|, from the edge e = p_b - p_a without cancellation: (e - u_a (|p_b| - |p_a|)) / |p_b| with
// |p_b| - |p_a| = e.(p_a + p_b) / (|p_a| + |p_b|), and no product of two lengths (which underflows for tiny p).
// na = |p_a|, nb = |p_b| (PolygonFanView::len).
template <class T> Vec3<T> unit_difference(const Vec3<T>& pa, T na, const Vec3<T>& pb, T nb, const Vec3<T>& e) {
  const T dn = e.dot(Vec3<T>((pa + pb) / (na + nb)));
  return (e - (pa / na) * dn) / nb;
}

namespace polygon_fan_detail {

// The unclipped fan: the (flattened, PolygonView::lift) light's vertices from x, wound positively, vertex 0 first.
template <class T>
void unclipped_fan(const PolygonLightGeometry<T>& g, const PolygonView<T>& pv, bool reverse, PolygonFanView<T>& f) {
  const int m = g.light.count;
  f.count = m;
  const Vec3<T>& nh = pv.plane_normal;
  for (int k = 0; k < m; ++k) {
    const int src = reverse ? wrap_index(m - k, m) : k;  // keeps vertex 0 first
    f.p[k] = g.light.vertices[src] - g.shading.position - pv.lift[src] * nh;
    f.e[k] = g.light.vertices[src] - g.light.vertices[0] - (pv.lift[src] - pv.lift[0]) * nh;
  }
}

// The fan of the light clipped to the upper hemisphere; false when nothing is strictly above the horizon. A horizon
// edge wider than 90 degrees (at most one) gets its midpoint n x (u_b - u_a) as a vertex and the root: no fan
// triangle then joins its nearly antipodal ends by a great circle of rounding noise.
template <class T>
bool clipped_fan(const PolygonView<T>& pv, bool reverse, PolygonFanView<T>& f, bool& horizon_rooted) {
  const LocalPolygon<T> c = clip_to_upper_hemisphere(pv.local);
  bool strictly_above = false;
  for (int i = 0; i < c.count; ++i) strictly_above = strictly_above || c.v[i].z() > T(0);
  if (c.count < 3 || !strictly_above) return false;
  std::array<Vec3<T>, kMaxFanVertices> q;
  int nq = 0, root = 0;
  const Vec3<T> light_normal = pv.frame.to_local(pv.plane_normal);
  for (int i = 0; i < c.count; ++i) {
    const Vec3<T>&a = c.v[i], &b = c.v[wrap_index(i + 1, c.count)];
    q[nq++] = a;
    if (a.z() != T(0) || b.z() != T(0) || nq + (c.count - 1 - i) >= kMaxFanVertices) continue;  // room for the rest
    const Vec3<T> ua = safe_normalized(a), ub = safe_normalized(b);
    if (!(ua.dot(ub) < T(0))) continue;
    Vec3<T> mid = safe_normalized(Vec3<T>(ua.y() - ub.y(), ub.x() - ua.x(), T(0)));
    if (light_normal.dot(mid) * pv.plane_distance < T(0)) mid = -mid;
    if (!mid.isZero()) root = nq, q[nq++] = mid * ((a.norm() + b.norm()) / T(2)), horizon_rooted = true;
  }
  f.count = nq;
  for (int k = 0; k < nq; ++k)
    f.p[k] = pv.frame.to_world(q[reverse ? wrap_index(root - k, nq) : wrap_index(root + k, nq)]);
  for (int k = 0; k < nq; ++k) f.e[k] = f.p[k] - f.p[0];
  return true;
}

// u_k and |p_k| (and e_k = p_k - p_0 if asked) of the fan's vertices; false for a vertex without a direction.
template <class T> bool fan_directions(PolygonFanView<T>& f, bool edges_from_p0) {
  for (int k = 0; k < f.count; ++k) {
    if (edges_from_p0) f.e[k] = f.p[k] - f.p[0];
    f.u[k] = safe_normalized(f.p[k]);
    f.len[k] = stable_norm(f.p[k]);
    if (f.u[k].isZero()) return false;
  }
  return true;
}

// The cone's planes: the light's own edge planes (polygon_inward_planes), the horizon if clipped, then the light's
// plane.
template <class T> void fan_cone(const PolygonLightGeometry<T>& g, const PolygonView<T>& pv, bool reverse, bool clipped,
                                 PolygonFanView<T>& f) {
  const int m = polygon_inward_planes(g, pv, f.inward.data());
  if (!clipped) {
    f.inward[m] = reverse ? Vec3<T>(-pv.plane_normal) : pv.plane_normal;
    f.planes = m + 1;
  } else {
    const T orient = reverse ? T(-1) : T(1);
    f.inward[m] = pv.normal;  // m <= kMaxPolygonVertices = kMaxFanVertices - 2
    f.inward[m + 1] = orient * pv.plane_normal;
    f.planes = m + 2;
  }
}

// The midpoint of the fan edge from u_k to u_k1 (unit), m x (u_k - u_k1) with m the cone's edge plane that holds both
// ends best, signed to lie on the short arc and on the light's side of the cone's last plane (by the larger test);
// zero when there is none.
template <class T> Vec3<T> wide_edge_midpoint(const PolygonFanView<T>& f, int k, int k1) {
  int best = -1;
  T best_residual = std::numeric_limits<T>::infinity();
  for (int j = 0; j + 1 < f.planes; ++j) {
    const Vec3<T> mj = safe_normalized(f.inward[j]);
    const T r = std::max(std::abs(mj.dot(f.u[k])), std::abs(mj.dot(f.u[k1])));
    if (r < best_residual) best_residual = r, best = j;
  }
  if (best < 0) return Vec3<T>::Zero();
  Vec3<T> mid = safe_normalized(kahan_cross(safe_normalized(f.inward[best]), Vec3<T>(f.u[k] - f.u[k1])));
  if (mid.isZero()) return mid;
  const T by_arc = mid.dot(Vec3<T>(f.u[k] + f.u[k1])), by_side = mid.dot(safe_normalized(f.inward[f.planes - 1]));
  if ((std::abs(by_arc) >= std::abs(by_side) ? by_arc : by_side) < T(0)) mid = -mid;
  return mid;
}

// Edges wider than 120 degrees (at most two) get their midpoints as vertices, the fan rooted at the first (unless it
// is rooted at a horizon midpoint): no fan triangle then has Eq. 13's G1 + G2 as a difference of numbers near 2.
// False for a vertex without a direction.
template <class T> bool split_wide_fan_edges(PolygonFanView<T>& f, bool horizon_rooted) {
  std::array<Vec3<T>, kMaxFanVertices> q;
  int nq = 0, root = -1;
  for (int k = 0; k < f.count; ++k) {
    const int k1 = wrap_index(k + 1, f.count);
    q[nq++] = f.p[k];
    if (!(f.u[k].dot(f.u[k1]) < T(-0.5)) || nq + (f.count - 1 - k) >= kMaxFanVertices) continue;
    const Vec3<T> mid = wide_edge_midpoint(f, k, k1);
    if (mid.isZero()) continue;
    if (root < 0) root = nq;
    q[nq++] = mid * ((f.len[k] + f.len[k1]) / T(2));
  }
  if (nq == f.count) return true;
  if (horizon_rooted || root < 0) root = 0;
  for (int k = 0; k < nq; ++k) f.p[k] = q[wrap_index(root + k, nq)];
  f.count = nq;
  return fan_directions(f, true);
}

}  // namespace polygon_fan_detail

// The polygon's fan as seen from the shading point, clipped to the upper hemisphere or not. split_wide_edges
// (Section 5's sampler): fan edges wider than 120 degrees get their midpoints as vertices.
template <class T> NoSample fill_polygon_fan_view(const PolygonLightGeometry<T>& g, bool clipped, bool split_wide_edges,
                                                  PolygonFanView<T>& f) {
  using namespace polygon_fan_detail;
  const PolygonView<T> pv = make_polygon_view(g);
  if (!pv.valid()) return pv.reason;
  f.plane_normal = pv.plane_normal;
  f.plane_distance = std::abs(pv.plane_distance);
  bool above = false;
  for (int i = 0; i < pv.local.count; ++i) above = above || pv.local.v[i].z() > T(0);
  if (!above) return NoSample::kBelowHorizon;
  const bool reverse = pv.plane_distance < T(0);
  bool horizon_rooted = false;  // the clipped fan is rooted at a horizon edge's midpoint
  if (!clipped)
    unclipped_fan(g, pv, reverse, f);
  else if (!clipped_fan(pv, reverse, f, horizon_rooted))
    return NoSample::kBelowHorizon;
  if (!fan_directions(f, false)) return NoSample::kNonFinite;
  fan_cone(g, pv, reverse, clipped, f);
  if (split_wide_edges && !split_wide_fan_edges(f, horizon_rooted)) return NoSample::kNonFinite;
  return NoSample::kNone;
}

template <class T>
PolygonFanView<T> make_polygon_fan_view(const PolygonLightGeometry<T>& g, bool clipped, bool split_wide_edges = false) {
  PolygonFanView<T> f;  // filled in place: no copy of the view on return
  f.reason = fill_polygon_fan_view(g, clipped, split_wide_edges, f);
  return f;
}

template <class T> bool in_fan_cone(const PolygonFanView<T>& f, const Vec3<T>& w) {
  for (int j = 0; j < f.planes; ++j)
    if (f.inward[j].dot(w) < T(0)) return false;
  return true;
}

// ---- Peters 2021 Section 5 ----

template <class T> struct PolygonSolidAngleView {
  PolygonFanView<T> fan;
  std::array<T, kMaxFanVertices> g0{}, g1{}, g2{}, area{};  // per fan triangle (0, k, k+1), stored at index k
  T solid_angle = 0;
  NoSample reason = NoSample::kNone;
  bool valid() const { return reason == NoSample::kNone; }
};

// Eq. 13 (van Oosterom & Strackee) per fan triangle, G0 = det(v0, v1, v2) from the light's edges (no cancellation
// for small, distant lights; Peters uses a Householder reflection, Supplement C).
template <class T>
PolygonSolidAngleView<T> make_polygon_solid_angle_view(const PolygonLightGeometry<T>& g, bool clipped = false) {
  // The fan built in place, not copied.
  PolygonSolidAngleView<T> v{.fan = make_polygon_fan_view(g, clipped, /*split_wide_edges=*/true)};
  if (!v.fan.valid()) {
    v.reason = v.fan.reason;
    return v;
  }
  const auto& f = v.fan;
  for (int k = 1; k + 1 < f.count; ++k) {
    // As u_0 . ((e_k / |p_k|) x (e_{k+1} / |p_{k+1}|)): each factor scaled before the product, which underflows.
    v.g0[k] = f.u[0].dot(kahan_cross(Vec3<T>(f.e[k] / f.len[k]), Vec3<T>(f.e[k + 1] / f.len[k + 1])));
    // Eq. 13's denominator G2 + G1, G2 = 1 + u0.uk (|u0 + uk|^2 / 2 when negative), G1 = uk1 . (u0 + uk), stored for
    // the sampler.
    const Vec3<T> sum = f.u[0] + f.u[k];
    const T dot = f.u[0].dot(f.u[k]);
    v.g2[k] = dot < T(0) ? sum.squaredNorm() / T(2) : T(1) + dot;
    v.g1[k] = f.u[k + 1].dot(sum);
    const T denom = v.g1[k] + v.g2[k];
    v.area[k] = std::max(T(0), T(2) * kernel_atan2(v.g0[k], denom));
    v.solid_angle += v.area[k];
  }
  // 1 / Omega must be representable too.
  if (!(v.solid_angle > T(0)) || !std::isfinite(v.solid_angle) || !has_finite_reciprocal(v.solid_angle))
    v.reason = NoSample::kTooSmall;
  return v;
}

// Picks the fan triangle for xi_0 in proportion to `area`, returning the remaining area in it.
template <class T, std::size_t N>
int pick_fan_triangle(const std::array<T, N>& area, int count, T target, T* remaining) {
  int k = -1;
  for (int i = 1; i + 1 < count; ++i) {
    if (!(area[i] > T(0))) continue;
    k = i;
    if (target < area[i]) break;
    target -= area[i];
  }
  if (k > 0) *remaining = std::clamp(target, T(0), area[k]);
  return k;
}

// Arvo's second step (Arvo 1995; used by Section 5): the direction on the arc from b towards c (unit) with
// 1 - cos(phi) = xi (1 - b.c), given d = c - b, in half angles of the arc (sin(theta/2) = |d| / 2): sin(phi/2) =
// sqrt(xi) sin(theta/2), and the rest psi = theta - phi without cancellation; measured from the nearer end.
template <class T> Vec3<T> sample_arc(const Vec3<T>& b, const Vec3<T>& d, T xi) {
  const Vec3<T> c = b + d, sum = b + c;
  T sh = d.norm() / T(2), ch = sum.norm() / T(2);
  const T r = std::sqrt(sh * sh + ch * ch);  // 1 up to rounding (the chords of a unit b and c)
  if (!(r > T(0)) || !std::isfinite(r)) return Vec3<T>::Zero();
  sh /= r, ch /= r;
  const T s_phi = std::sqrt(xi) * sh, c_phi = std::sqrt(ch * ch + (T(1) - xi) * sh * sh);
  const T den = sh * c_phi + ch * s_phi;
  const T s_psi = den > T(0) ? (T(1) - xi) * sh * sh / den : T(0), c_psi = ch * c_phi + sh * s_phi;
  const T h = d.squaredNorm() / T(2);  // 1 - b.c
  auto tangent = [](const Vec3<T>& at, const Vec3<T>& t) { return safe_normalized(Vec3<T>(t - t.dot(at) * at)); };
  if (s_phi <= s_psi) {
    const Vec3<T> tb = tangent(b, Vec3<T>(d + h * b));
    return safe_normalized(Vec3<T>((T(1) - T(2) * s_phi * s_phi) * b + (T(2) * s_phi * c_phi) * tb));
  }
  const Vec3<T> tc = tangent(c, Vec3<T>(h * c - d));
  return safe_normalized(Vec3<T>((T(1) - T(2) * s_psi * s_psi) * c + (T(2) * s_psi * c_psi) * tc));
}

template <class T> T pdf_polygon_solid_angle(const PolygonSolidAngleView<T>& v, const Vec3<T>& w) {
  if (!v.valid() || !all_finite(w) || !in_fan_cone(v.fan, w)) return T(0);
  return T(1) / v.solid_angle;
}

// Section 5: v2' on the edge v0 v2 with triangle (v0, v1, v2') of solid angle A, r = (G0 cos(A/2) - G1 sin(A/2)) v0 +
// G2 sin(A/2) v2, v2' = -v0 + 2 (v0.r / |r|^2) r = v0 + 2 r x (r x v0) / |r|^2 (no cancellation); then Arvo's arc.
template <class T> DirectionSample<T> sample_polygon_solid_angle(const PolygonSolidAngleView<T>& v, const Vec2<T>& u) {
  if (!v.valid()) return DirectionSample<T>::none(v.reason);
  const auto& f = v.fan;
  T a = 0;
  const int k = pick_fan_triangle(v.area, f.count, u[0] * v.solid_angle, &a);
  if (k < 0) return DirectionSample<T>::none(NoSample::kTooSmall);
  const Vec3<T>&v0 = f.u[0], &v1 = f.u[k], &v2 = f.u[k + 1];
  const T g0 = v.g0[k], g1 = v.g1[k], g2 = v.g2[k];  // as for the area (make_polygon_solid_angle_view)
  T s, c;
  sine_cosine(a / 2, s, c);
  const Vec3<T> r = (g0 * c - g1 * s) * v0 + (g2 * s) * v2;
  const T r2 = r.squaredNorm();
  // Scaled before the product, as G0 in make_polygon_solid_angle_view (|p_2| |p_0| underflows for tiny p).
  const Vec3<T> v2_x_v0 = kahan_cross(Vec3<T>(f.e[k + 1] / f.len[k + 1]), v0);
  const Vec3<T> offset = r2 > T(0) ? Vec3<T>((T(2) * g2 * s / r2) * kahan_cross(r, v2_x_v0)) : Vec3<T>::Zero();
  // d = v2' - v1 = (v0 - v1) + offset, with v0 - v1 from the edge e_k.
  const Vec3<T> d = -unit_difference(f.p[0], f.len[0], f.p[k], f.len[k], f.e[k]) + offset;
  DirectionSample<T> out;
  out.direction = sample_arc(v1, d, u[1]);
  if (out.direction.isZero()) return DirectionSample<T>::none(NoSample::kNonFinite);
  out.pdf = T(1) / v.solid_angle;
  return out;
}

template <class T> DirectionSample<T> sample_polygon_solid_angle(const PolygonLightGeometry<T>& g, const Vec2<T>& u,
                                                                 bool clipped = false) {
  return sample_polygon_solid_angle(make_polygon_solid_angle_view(g, clipped), u);
}
template <class T> T pdf_polygon_solid_angle(const PolygonLightGeometry<T>& g, const Vec3<T>& w, bool clipped = false) {
  return pdf_polygon_solid_angle(make_polygon_solid_angle_view(g, clipped), w);
}

// ---- Baseline: Arvo 1995, "Stratified Sampling of Spherical Triangles", as published ----
//
// Per fan triangle (A, B, C), area alpha + beta + gamma - pi (cancels for small triangles: kept on purpose):
//   A^ = xi_1 area; s = sin(A^ - alpha); t = cos(A^ - alpha); u = t - cos alpha; v = s + sin alpha cos c;
//   q = ((v t - u s) cos alpha - v) / ((v s + u t) sin alpha);  C^ = q A + sqrt(1 - q^2) |C - (C.A) A|^;
//   z = 1 - xi_2 (1 - C^.B);  P = z B + sqrt(1 - z^2) |C^ - (C^.B) B|^

template <class T> struct ArvoFanView {
  PolygonFanView<T> fan;
  std::array<T, kMaxClippedVertices> alpha{}, area{};
  T solid_angle = 0;
  NoSample reason = NoSample::kNone;
  bool valid() const { return reason == NoSample::kNone; }
};

template <class T> T spherical_angle(const Vec3<T>& at, const Vec3<T>& b, const Vec3<T>& c) {
  const Vec3<T> nb = at.cross(b), nc = at.cross(c);
  return kernel_atan2(nb.cross(nc).norm(), nb.dot(nc));
}

template <class T> ArvoFanView<T> make_arvo_fan_view(const PolygonLightGeometry<T>& g) {
  // The fan built in place, not copied.
  ArvoFanView<T> v{.fan = make_polygon_fan_view(g, false)};
  if (!v.fan.valid()) {
    v.reason = v.fan.reason;
    return v;
  }
  const auto& u = v.fan.u;
  for (int k = 1; k + 1 < v.fan.count; ++k) {
    const T al = spherical_angle(u[0], u[k], u[k + 1]);
    const T be = spherical_angle(u[k], u[k + 1], u[0]);
    const T ga = spherical_angle(u[k + 1], u[0], u[k]);
    v.alpha[k] = al;
    v.area[k] = std::max(T(0), al + be + ga - kPi<T>);
    v.solid_angle += v.area[k];
  }
  if (!(v.solid_angle > T(0)) || !std::isfinite(v.solid_angle)) v.reason = NoSample::kTooSmall;
  return v;
}

template <class T> DirectionSample<T> sample_arvo_triangle_fan(const ArvoFanView<T>& v, const Vec2<T>& xi) {
  if (!v.valid()) return DirectionSample<T>::none(v.reason);
  T ahat = 0;
  const int k = pick_fan_triangle(v.area, v.fan.count, xi[0] * v.solid_angle, &ahat);
  if (k < 0) return DirectionSample<T>::none(NoSample::kTooSmall);
  const Vec3<T>&A = v.fan.u[0], &B = v.fan.u[k], &C = v.fan.u[k + 1];
  const T alpha = v.alpha[k];
  T s, t, sin_alpha, cos_alpha;
  sine_cosine(ahat - alpha, s, t);
  sine_cosine(alpha, sin_alpha, cos_alpha);
  const T uu = t - cos_alpha, vv = s + sin_alpha * A.dot(B);
  // Arvo 1995's q; a zero denominator takes the limit of the clamped quotient, +-1 by the numerator's sign.
  const T q_num = (vv * t - uu * s) * cos_alpha - vv, q_den = (vv * s + uu * t) * sin_alpha;
  const T q = q_den != T(0) ? std::clamp(q_num / q_den, T(-1), T(1)) : (q_num < T(0) ? T(-1) : T(1));
  const Vec3<T> chat = q * A + std::sqrt(T(1) - q * q) * safe_normalized(Vec3<T>(C - C.dot(A) * A));
  const T z = T(1) - xi[1] * (T(1) - chat.dot(B));
  const Vec3<T> p = z * B + std::sqrt(std::max(T(0), T(1) - z * z)) * safe_normalized(Vec3<T>(chat - chat.dot(B) * B));
  DirectionSample<T> out;
  out.direction = safe_normalized(p);
  if (out.direction.isZero() || !all_finite(p)) return DirectionSample<T>::none(NoSample::kNonFinite);
  out.pdf = T(1) / v.solid_angle;
  return out;
}

template <class T> DirectionSample<T> sample_arvo_triangle_fan(const PolygonLightGeometry<T>& g, const Vec2<T>& xi) {
  return sample_arvo_triangle_fan(make_arvo_fan_view(g), xi);
}
template <class T> T pdf_arvo_triangle_fan(const ArvoFanView<T>& v, const Vec3<T>& w) {
  if (!v.valid() || !all_finite(w) || !in_fan_cone(v.fan, w)) return T(0);
  return T(1) / v.solid_angle;
}
template <class T> T pdf_arvo_triangle_fan(const PolygonLightGeometry<T>& g, const Vec3<T>& w) {
  return pdf_arvo_triangle_fan(make_arvo_fan_view(g), w);
}

// ---- Baseline: Turk 1992, "Generating Random Points in Triangles", as published ----
//
// A fan triangle is chosen in proportion to its area, then P = (1 - sqrt(xi_0)) A + sqrt(xi_0) (1 - xi_1) B
// + sqrt(xi_0) xi_1 C (xi_0 rescaled within the chosen triangle).

template <class T> struct TurkAreaView {
  PolygonFanView<T> fan;
  std::array<T, kMaxClippedVertices> area{};
  T total_area = 0;
  NoSample reason = NoSample::kNone;
  bool valid() const { return reason == NoSample::kNone; }
};

template <class T> TurkAreaView<T> make_turk_area_view(const PolygonLightGeometry<T>& g) {
  // The fan built in place, not copied.
  TurkAreaView<T> v{.fan = make_polygon_fan_view(g, false)};
  if (!v.fan.valid()) {
    v.reason = v.fan.reason;
    return v;
  }
  for (int k = 1; k + 1 < v.fan.count; ++k) {
    v.area[k] = kahan_cross(v.fan.e[k], v.fan.e[k + 1]).norm() / T(2);
    v.total_area += v.area[k];
  }
  if (!(v.total_area > T(0)) || !std::isfinite(v.total_area)) v.reason = NoSample::kZeroSize;
  return v;
}

// Per solid angle: dA = dist^2 / cos_light dw, dist = h / |N.w|, cos_light = |N.w|.
template <class T> T turk_density(const TurkAreaView<T>& v, const Vec3<T>& w) {
  const T c = std::abs(v.fan.plane_normal.dot(w));
  if (!(c > T(0))) return T(0);  // grazing the light's plane: no area seen (and no division by zero under UBSan)
  const T h = v.fan.plane_distance;
  const T hc = h / c;
  const T pdf = hc * hc / (c * v.total_area);
  return std::isfinite(pdf) ? pdf : T(0);
}

template <class T> DirectionSample<T> sample_turk_area(const TurkAreaView<T>& v, const Vec2<T>& xi) {
  if (!v.valid()) return DirectionSample<T>::none(v.reason);
  T rest = 0;
  const int k = pick_fan_triangle(v.area, v.fan.count, xi[0] * v.total_area, &rest);
  if (k < 0) return DirectionSample<T>::none(NoSample::kTooSmall);
  const T r = std::sqrt(v.area[k] > T(0) ? rest / v.area[k] : T(0));
  const Vec3<T> p = v.fan.p[0] + (r * (T(1) - xi[1])) * v.fan.e[k] + (r * xi[1]) * v.fan.e[k + 1];
  DirectionSample<T> out;
  out.direction = safe_normalized(p);
  if (out.direction.isZero()) return DirectionSample<T>::none(NoSample::kNonFinite);
  out.pdf = turk_density(v, out.direction);
  if (!(out.pdf > T(0))) return DirectionSample<T>::none(NoSample::kOnSilhouette);
  return out;
}

template <class T> DirectionSample<T> sample_turk_area(const PolygonLightGeometry<T>& g, const Vec2<T>& xi) {
  return sample_turk_area(make_turk_area_view(g), xi);
}
template <class T> T pdf_turk_area(const TurkAreaView<T>& v, const Vec3<T>& w) {
  if (!v.valid() || !all_finite(w) || !in_fan_cone(v.fan, w)) return T(0);
  return turk_density(v, Vec3<T>(w.normalized()));
}
template <class T> T pdf_turk_area(const PolygonLightGeometry<T>& g, const Vec3<T>& w) {
  return pdf_turk_area(make_turk_area_view(g), w);
}

// ---- Catalogue traits (warpcheck/catalogue.h) ----------------------------------------------------------------

// Kinks in u0 of the fan samplers: the cumulative area fractions of the fan triangles (0, k, k+1), k >= 1.
template <class T, class View> std::vector<T> polygon_fan_kinks(const View& v) {
  return v.valid() ? cumulative_area_fractions<T>(v.area.begin() + 1, v.area.begin() + std::max(1, v.fan.count - 1))
                   : std::vector<T>{};
}

// A cap containing the fan's vertices: the light, clipped to the horizon if kClipped.
template <class T, bool kClipped> Cap<T> polygon_fan_bounding_cap(const PolygonLightGeometry<T>& g) {
  const PolygonFanView<T> f = make_polygon_fan_view(g, kClipped);
  return f.valid() ? bounding_cap_of_directions(f.p.data(), f.count) : polygon_bounding_cap(g);
}

// kClipped: only the part of the polygon above the shading horizon.
template <class T, bool kClipped> struct PolygonSolidAngleKernel {
  static constexpr const char* name = kClipped ? "polygon-solid-angle-clipped" : "polygon-solid-angle";
  static constexpr const char* description =
      kClipped ? "solid angle above the horizon, Peters 2021 Sec. 5" : "solid angle, Peters 2021 Sec. 5";
  using Scalar = T;
  using Geometry = PolygonLightGeometry<T>;
  using View = PolygonSolidAngleView<T>;
  static View view(const Geometry& g) { return make_polygon_solid_angle_view(g, kClipped); }
  static DirectionSample<T> sample(const View& v, const Vec2<T>& u) { return sample_polygon_solid_angle(v, u); }
  static T pdf(const View& v, const Vec3<T>& w) { return pdf_polygon_solid_angle(v, w); }
  static Cap<T> bounding_cap(const Geometry& g) { return polygon_fan_bounding_cap<T, kClipped>(g); }
  static T normaliser(const View& v) { return v.solid_angle; }
  static std::vector<T> kinks_u0(const Geometry& g) { return polygon_fan_kinks<T>(view(g)); }
  static std::vector<Vec3<T>> boundary_planes(const Geometry& g) { return polygon_boundary_planes(g); }
};
template <class T> using PolygonSolidAngle = PolygonSolidAngleKernel<T, false>;
template <class T> using PolygonSolidAngleClipped = PolygonSolidAngleKernel<T, true>;

template <class T> struct BaselineArvoTriangle {
  static constexpr const char* name = "baseline-arvo-triangle";
  static constexpr const char* description = "Arvo 1995 on a triangle fan, as published";
  using Scalar = T;
  using Geometry = PolygonLightGeometry<T>;
  using View = ArvoFanView<T>;
  static View view(const Geometry& g) { return make_arvo_fan_view(g); }
  static DirectionSample<T> sample(const View& v, const Vec2<T>& u) { return sample_arvo_triangle_fan(v, u); }
  static T pdf(const View& v, const Vec3<T>& w) { return pdf_arvo_triangle_fan(v, w); }
  static Cap<T> bounding_cap(const Geometry& g) { return polygon_fan_bounding_cap<T, false>(g); }
  static T normaliser(const View& v) { return v.solid_angle; }
  static std::vector<T> kinks_u0(const Geometry& g) { return polygon_fan_kinks<T>(view(g)); }
  static std::vector<Vec3<T>> boundary_planes(const Geometry& g) { return polygon_boundary_planes(g); }
};

template <class T> struct BaselineTurkArea {
  static constexpr const char* name = "baseline-turk-area";
  static constexpr const char* description = "uniform in area on a triangle fan, Turk 1992, as published";
  using Scalar = T;
  using Geometry = PolygonLightGeometry<T>;
  using View = TurkAreaView<T>;
  static View view(const Geometry& g) { return make_turk_area_view(g); }
  static DirectionSample<T> sample(const View& v, const Vec2<T>& u) { return sample_turk_area(v, u); }
  static T pdf(const View& v, const Vec3<T>& w) { return pdf_turk_area(v, w); }
  static Cap<T> bounding_cap(const Geometry& g) { return polygon_fan_bounding_cap<T, false>(g); }
  static T normaliser(const View& v) { return v.total_area; }  // the light's area
  static std::vector<T> kinks_u0(const Geometry& g) { return polygon_fan_kinks<T>(view(g)); }
  static std::vector<Vec3<T>> boundary_planes(const Geometry& g) { return polygon_boundary_planes(g); }
};

}  // namespace warpcheck
