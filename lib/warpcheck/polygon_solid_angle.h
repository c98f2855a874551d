// warpcheck/polygon_solid_angle.h: solid-angle sampling of convex polygons, Peters 2021 Section 5 (plain and
// clipped to the upper hemisphere), and the published baselines for polygons: Arvo 1995 (stratified
// sampling of spherical triangles, applied to a triangle fan) and Turk 1992 (uniform area sampling, density
// reported per solid angle).
//
// Densities:  solid angle  pdf(w) = 1 / Omega inside the polygon's cone (clipped or not);
//             Arvo 1995    the same, with Omega = sum of the fan triangles' alpha + beta + gamma - pi;
//             Turk 1992    pdf(w) = h^2 / (|N.w|^3 Area) where the ray meets the polygon (h: distance of the
//                          shading point from the light's plane, N: unit normal of the plane).
// The unclipped kernels sample the whole polygon, also where it lies below the shading horizon (those
// samples carry a zero cosine for the caller); only a light entirely below it gives "no sample".
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
  std::array<T, kMaxFanVertices> len{};      // |p_k| by stableNorm (norm() underflows for |p| < 1e-154)
  // The cone is {w : inward_j . w >= 0, j < planes}: unclipped, inward_j = p_j x p_{j+1}; clipped, the
  // light's own edge planes (from V_j - x) and the horizon, never planes through two clip points, whose
  // normal is undetermined when the clip points (nearly) coincide (found by fuzz_polygon_solid_angle_double:
  // pdf 0 for a sample 2e-10 rad inside the clipped polygon).
  // Both also have the plane through x parallel to the light's (its far side): the edge planes all pass through x,
  // so near a sliver's vertex they hold its antipode too, up to a margin of the sliver's width that rounds to 0
  // (found by fuzz_polygon_solid_angle_double de04c20e...: a hexagon 8 long and 1.4e-9 wide, pdf 9e18 at the
  // antipode of a vertex's direction, issue 7).
  std::array<Vec3<T>, kMaxFanVertices> inward{};
  int planes = 0;
  Vec3<T> plane_normal = Vec3<T>::Zero();  // unit
  T plane_distance = 0;                    // |plane_normal . p_0| > 0
  bool valid() const { return reason == NoSample::kNone; }
};

// u_b - u_a for u = p / |p|, from the edge e = p_b - p_a without cancellation:
// u_b - u_a = (e |p_a| - p_a (|p_b| - |p_a|)) / (|p_a| |p_b|), |p_b| - |p_a| = e.(p_a + p_b) / (|p_a| + |p_b|).
// na = |p_a|, nb = |p_b| (PolygonFanView::len).
template <class T> Vec3<T> unit_difference(const Vec3<T>& pa, T na, const Vec3<T>& pb, T nb, const Vec3<T>& e) {
  // Grouped as (e - u_a (|p_b| - |p_a|)) / |p_b| with the dot product taken against (p_a + p_b) / (|p_a| + |p_b|):
  // no product of two lengths, which underflows for a light ~1e-160 from x (UBSan: division by zero, found by
  // fuzz_polygon_solid_angle_double 0f46b33f..., issue 7).
  const T dn = e.dot(Vec3<T>((pa + pb) / (na + nb)));
  return (e - (pa / na) * dn) / nb;
}

// split_wide_edges (Section 5's sampler, make_polygon_solid_angle_view): every edge of the fan wider than 120 degrees
// gets its midpoint as an extra vertex, and the fan is rooted at the first (see the end of this function).
template <class T>
PolygonFanView<T> make_polygon_fan_view(const PolygonLightGeometry<T>& g, bool clipped, bool split_wide_edges = false) {
  PolygonFanView<T> f;
  const PolygonView<T> pv = make_polygon_view(g);
  if (!pv.valid()) return f.reason = pv.reason, f;
  f.plane_normal = pv.plane_normal;
  f.plane_distance = std::abs(pv.plane_distance);
  bool above = false;
  for (int i = 0; i < pv.local.count; ++i) above = above || pv.local.v[i].z() > T(0);
  if (!above) return f.reason = NoSample::kBelowHorizon, f;
  const bool reverse = pv.plane_distance < T(0);
  bool horizon_rooted = false;  // the clipped fan is rooted at a horizon edge's midpoint
  if (!clipped) {
    const int m = g.light.count;
    f.count = m;
    // The flattened light's vertices where the light is non-planar (PolygonView::lift; zero lifts otherwise, and
    // then the same values as V - x and V - V_0), like the clipped fan's and the planes below.
    const Vec3<T>& nh = pv.plane_normal;
    for (int k = 0; k < m; ++k) {
      const int src = reverse ? (m - k) % m : k;  // keeps vertex 0 first
      f.p[k] = g.light.vertices[src] - g.shading.position - pv.lift[src] * nh;
      f.e[k] = g.light.vertices[src] - g.light.vertices[0] - (pv.lift[src] - pv.lift[0]) * nh;
    }
  } else {
    const LocalPolygon<T> c = clip_to_upper_hemisphere(pv.local);
    bool strictly_above = false;
    for (int i = 0; i < c.count; ++i) strictly_above = strictly_above || c.v[i].z() > T(0);
    if (c.count < 3 || !strictly_above) return f.reason = NoSample::kBelowHorizon, f;
    // A horizon edge (both ends at z = 0) wider than 90 degrees gets its midpoint as an extra vertex. Its ends
    // are nearly antipodal when the light's plane passes close to x: the fan triangle holding them then has an
    // edge whose great circle (and Eq. 13's area, 0 / 0) is rounding noise, although the edge lies on the
    // horizon (found by fuzz_polygon_solid_angle_double: x 2.4e-10 off a rectangle, sample 2.3e-10 rad outside,
    // issue 7). The midpoint is n x (u_b - u_a), turned towards the light's plane (every direction of the light
    // has plane_normal . w of the sign of plane_distance): no cancellation. At most one such edge exists, the
    // horizon part of a polygon in the upper hemisphere spanning at most 180 degrees.
    // The fan is then rooted at that midpoint. Rooted at a clip point, the fan still had a triangle holding both
    // nearly antipodal ends of the horizon edge, joined by a diagonal whose great circle is rounding noise
    // although it should be the horizon (Eq. 13's 0 / 0 again): found by fuzz_polygon_solid_angle_double
    // (dd70aa66...: x 4.6e-23 off a triangle of size 5e-16, sample 2.9e-10 rad outside; issue 4), and on random
    // lights seen from 1e-14..1e-2 of their size off their plane samples up to 0.96 rad outside (test_polygon.cpp,
    // SolidAngleSamplesLieInsideTheLightSeenFromCloseToItsPlane). The midpoint is 90 degrees from both ends; the
    // clipped polygon lies in the lune between the horizon and the light's plane (seen from x), so within the
    // lune's angle of the midpoint, and only a lune near 180 degrees (the light's plane close to the tangent plane
    // with x just below it) brings a vertex near the midpoint's antipode.
    std::array<Vec3<T>, kMaxFanVertices> q;
    int nq = 0, root = 0;
    const Vec3<T> light_normal = pv.frame.to_local(pv.plane_normal);
    for (int i = 0; i < c.count; ++i) {
      const Vec3<T>&a = c.v[i], &b = c.v[(i + 1) % c.count];
      q[nq++] = a;
      if (a.z() != T(0) || b.z() != T(0) || nq + (c.count - 1 - i) >= kMaxFanVertices) continue;  // room for the rest
      const Vec3<T> ua = safe_normalized(a), ub = safe_normalized(b);
      if (!(ua.dot(ub) < T(0))) continue;
      Vec3<T> mid = safe_normalized(Vec3<T>(ua.y() - ub.y(), ub.x() - ua.x(), T(0)));
      if (light_normal.dot(mid) * pv.plane_distance < T(0)) mid = -mid;
      if (!mid.isZero()) root = nq, q[nq++] = mid * ((a.norm() + b.norm()) / T(2)), horizon_rooted = true;
    }
    f.count = nq;
    for (int k = 0; k < nq; ++k) f.p[k] = pv.frame.to_world(q[reverse ? (root - k + nq) % nq : (root + k) % nq]);
    for (int k = 0; k < nq; ++k) f.e[k] = f.p[k] - f.p[0];
  }
  for (int k = 0; k < f.count; ++k) {
    f.u[k] = safe_normalized(f.p[k]);
    f.len[k] = f.p[k].stableNorm();
    if (f.u[k].isZero()) return f.reason = NoSample::kNonFinite, f;
  }
  if (!clipped) {
    // The light's own edge planes (polygon_inward_planes: from the exact world edges V_{j+1} - V_j, not from p_{j+1}
    // - p_j, whose direction is rounding noise for an edge shorter than the rounding of V - x: its plane rejected
    // directions 5e-8 rad inside the light, found by fuzz_polygon_solid_angle_double, issue 7; and in the light's
    // plane, scaled, without a plane for an edge that is a point up to rounding), then the light's plane.
    const int m = polygon_inward_planes(g, pv, f.inward.data());
    f.inward[m] = reverse ? Vec3<T>(-pv.plane_normal) : pv.plane_normal;
    f.planes = m + 1;
  } else {
    // The clipped polygon is pv.local's, flattened where the light is non-planar: its planes likewise.
    const int m = polygon_inward_planes(g, pv, f.inward.data());
    const T orient = reverse ? T(-1) : T(1);
    f.inward[m] = pv.normal;  // m <= kMaxPolygonVertices = kMaxFanVertices - 2
    f.inward[m + 1] = orient * pv.plane_normal;
    f.planes = m + 2;
  }
  if (split_wide_edges) {
    // An edge wider than 120 degrees gets its midpoint, and the fan is rooted at the first such midpoint (unless
    // the clipped fan is already rooted at a horizon edge's). Eq. 13 and the sampler's G1, G2 take sums of unit
    // vectors, and a fan triangle with two nearly antipodal vertices has 1 + u0.uk + u0.uk1 + uk.uk1 = G1 + G2 as
    // the difference of two numbers near 2 (or a G1 = uk1 . (u0 + uk) whose u0 + uk lost its component along
    // u0 to rounding), when the triangle's true denominator is as small as the square of the vertices' offsets
    // from antipodal. That happens for a long light seen from close by, whose vertices all lie near two
    // antipodal directions (found by fuzz_polygon_solid_angle_double 2a3027c9: a strip 6 wide and 3.9e11 long
    // seen from 8 off its plane, all seven vertices within 2.5e-10 rad of +-y; the fan triangle (V0, V1, V2)
    // with V0, V1 near +y and V2 near -y had G1 + G2 = -2 + 2 = 0 instead of ~1e-20, area pi; solid angle
    // 3.748 instead of 0.686 (Girard's formula from the edge planes, long double), and 3339 of a 65 x 65 grid of
    // samples outside the light, up to 0.0215 rad; issue 7). The light's edges between the two clusters are the
    // wide ones: rooted at the midpoint of one, no fan triangle has two nearly antipodal vertices. (120 degrees,
    // not 90: the horizon midpoint's edges are 90 degrees wide up to rounding, and need no split.) The midpoint of
    // the edge from u_a to u_b on the great circle of normal m (m . u_a = m . u_b = 0 up to rounding, m pointing
    // into the cone) is m x (u_a - u_b) (= u_a + u_b up to scale when m = u_a x u_b,
    // without cancellation for nearly antipodal ends, like the horizon's midpoint above); m is the edge plane of
    // the cone that holds both ends best: the fan's edges lie on the light's edge planes and on the horizon
    // (the cone's last plane, the light's own, is not an edge). A convex spherical polygon has a perimeter of at
    // most 2 pi, so it has at most two edges wider than 120 degrees (kMaxFanVertices, polygon.h).
    std::array<Vec3<T>, kMaxFanVertices> q;
    int nq = 0, root = -1;
    for (int k = 0; k < f.count; ++k) {
      const int k1 = (k + 1) % f.count;
      q[nq++] = f.p[k];
      if (!(f.u[k].dot(f.u[k1]) < T(-0.5)) || nq + (f.count - 1 - k) >= kMaxFanVertices) continue;
      int best = -1;
      T best_residual = std::numeric_limits<T>::infinity();
      for (int j = 0; j + 1 < f.planes; ++j) {
        const Vec3<T> mj = safe_normalized(f.inward[j]);
        const T r = std::max(std::abs(mj.dot(f.u[k])), std::abs(mj.dot(f.u[k1])));
        if (r < best_residual) best_residual = r, best = j;
      }
      if (best < 0) continue;
      Vec3<T> mid = safe_normalized(kahan_cross(safe_normalized(f.inward[best]), Vec3<T>(f.u[k] - f.u[k1])));
      if (mid.isZero()) continue;
      // Two planes can hold both ends equally well: a sliver's two long edges lie on one great circle with opposite
      // inward normals, and the other edge's normal gives the antipode of the midpoint (found by
      // fuzz_polygon_solid_angle_double c8680af4: a triangle 3.3 long and ~6e-14 wide seen from 0.84, its two
      // 146-degree edges split at antipodal "midpoints"; solid angle 6.26 instead of ~6e-17 sr, samples 0.7 rad
      // outside; issue 7). The midpoint lies on the short arc, mid . (u_a + u_b) > 0, and on the light's side of
      // the plane through x parallel to the light (the cone's last plane), like every direction of the light: its
      // sign from whichever of the two is larger (u_a + u_b is rounding noise for nearly antipodal ends, the
      // light's side for x close to its plane).
      const T by_arc = mid.dot(Vec3<T>(f.u[k] + f.u[k1])), by_side = mid.dot(safe_normalized(f.inward[f.planes - 1]));
      if ((std::abs(by_arc) >= std::abs(by_side) ? by_arc : by_side) < T(0)) mid = -mid;
      if (root < 0) root = nq;
      q[nq++] = mid * ((f.len[k] + f.len[k1]) / T(2));
    }
    if (nq > f.count) {
      if (horizon_rooted || root < 0) root = 0;
      for (int k = 0; k < nq; ++k) f.p[k] = q[(root + k) % nq];
      f.count = nq;
      for (int k = 0; k < f.count; ++k) {
        f.e[k] = f.p[k] - f.p[0];
        f.u[k] = safe_normalized(f.p[k]);
        f.len[k] = f.p[k].stableNorm();
        if (f.u[k].isZero()) return f.reason = NoSample::kNonFinite, f;
      }
    }
  }
  return f;
}

template <class T> bool in_fan_cone(const PolygonFanView<T>& f, const Vec3<T>& w) {
  for (int j = 0; j < f.planes; ++j)
    if (f.inward[j].dot(w) < T(0)) return false;
  return true;
}

// ---- Peters 2021 Section 5 -------------------------------------------------------------------------------

template <class T> struct PolygonSolidAngleView {
  PolygonFanView<T> fan;
  std::array<T, kMaxFanVertices> g0{}, g1{}, g2{}, area{};  // per fan triangle (0, k, k+1), stored at index k
  T solid_angle = 0;
  NoSample reason = NoSample::kNone;
  bool valid() const { return reason == NoSample::kNone; }
};

// Eq. 13 (van Oosterom & Strackee) per fan triangle. G0 = det(v0, v1, v2) is computed as
// p0 . (e1 x e2) / (|p0| |p1| |p2|) from the light's edges: a determinant of three nearly parallel unit vectors
// cancels catastrophically for small, distant lights. (Peters uses a Householder reflection, Supplement C,
// which is not available to us; this is our own remedy.)
template <class T>
PolygonSolidAngleView<T> make_polygon_solid_angle_view(const PolygonLightGeometry<T>& g, bool clipped = false) {
  PolygonSolidAngleView<T> v;
  v.fan = make_polygon_fan_view(g, clipped, /*split_wide_edges=*/true);
  if (!v.fan.valid()) return v.reason = v.fan.reason, v;
  const auto& f = v.fan;
  for (int k = 1; k + 1 < f.count; ++k) {
    // As u_0 . ((e_k / |p_k|) x (e_{k+1} / |p_{k+1}|)): each factor scaled before the product, because
    // |p_0| |p_k| |p_{k+1}| underflows to 0 for a light ~1e-110 from x (UBSan: division by zero, found by
    // fuzz_polygon_solid_angle_double 0f46b33f..., issue 7), and the scaled edges have the size of the light's
    // angular extent.
    v.g0[k] = f.u[0].dot(kahan_cross(Vec3<T>(f.e[k] / f.len[k]), Vec3<T>(f.e[k + 1] / f.len[k + 1])));
    // Eq. 13's denominator 1 + u0.uk + u0.uk1 + uk.uk1 = G2 + G1 with G2 = 1 + u0.uk, G1 = uk1 . (u0 + uk), stored
    // for the sampler, which must use the same values as the area (an area from one rounding and a sample from
    // another put the sample past the triangle's far edge: 8.9e-8 rad outside a thin fan triangle, found by
    // fuzz_polygon_solid_angle_double 8ad0e6a8..., issue 7). G2 = 1 + u0.uk cancels for nearly antipodal u0, uk
    // (x next to the edge or diagonal 0k); there |u0 + uk|^2 / 2 keeps its relative precision down to
    // |u0 + uk| ~ eps (found by 7739f49d...: x 7e-10 from an edge's midpoint, 1 + u0.u1 = 2.4e-19 computed as
    // rounding noise, sample 1 rad outside).
    const Vec3<T> sum = f.u[0] + f.u[k];
    const T dot = f.u[0].dot(f.u[k]);
    v.g2[k] = dot < T(0) ? sum.squaredNorm() / T(2) : T(1) + dot;
    v.g1[k] = f.u[k + 1].dot(sum);
    const T denom = v.g1[k] + v.g2[k];
    v.area[k] = std::max(T(0), T(2) * std::atan2(v.g0[k], denom));
    v.solid_angle += v.area[k];
  }
  // 1 / Omega must be representable too (as for the projected solid angle; issue 7).
  if (!(v.solid_angle > T(0)) || !std::isfinite(v.solid_angle) || !std::isfinite(T(1) / v.solid_angle))
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

// Arvo's second step (Arvo 1995; used by Section 5): a direction on the arc from b towards c (unit vectors)
// at the angle phi from b with 1 - cos(phi) = xi (1 - b.c), given d = c - b (accurately).
// Our formulation, in half angles of the arc's angle theta: sin(theta/2) = |d| / 2, cos(theta/2) = |b + c| / 2,
//   sin(phi/2) = sqrt(xi) sin(theta/2),  cos(phi/2) = sqrt(cos^2(theta/2) + (1 - xi) sin^2(theta/2)),
// and for the rest psi = theta - phi, without cancellation,
//   sin(psi/2) = (1 - xi) sin^2(theta/2) / (sin(theta/2) cos(phi/2) + cos(theta/2) sin(phi/2)).
// The point is measured from the nearer end (tangents t_b towards c, t_c towards b): cos(phi) b + sin(phi) t_b
// or cos(psi) c + sin(psi) t_c. A tangent is the component of the other end orthogonal to this one, made
// orthogonal once more after the subtraction: for nearly antipodal ends that component is as small as the ends'
// distance from antipodal and carries their rounding. Written from b alone, as b (1 - xi h) + sqrt(xi h (2 - xi h)) t_b
// with h = 1 - b.c, the far end of an arc between nearly antipodal b and c came out as -b: 2 - xi h cancels, and c's
// small offset from -b was lost. Such arcs occur in fan triangles that are nearly hemispheres (x close to the light's
// plane, above the triangle): on random lights seen from 1e-14..1e-2 of their size off their plane, samples up
// to 1.6e-8 rad outside in double (test_polygon.cpp, SolidAngleSamplesLieInsideTheLightSeenFromCloseToItsPlane; our
// remedy, issue 4).
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

// Section 5: the new vertex v2' on the edge v0 v2 with triangle (v0, v1, v2') of solid angle A:
//   r = (G0 cos(A/2) - G1 sin(A/2)) v0 + G2 sin(A/2) v2,  v2' = -v0 + 2 (v0.r / |r|^2) r,
// rewritten without cancellation as v2' = v0 + 2 r x (r x v0) / |r|^2 (the identity a x (b x c) =
// b (a.c) - c (a.b)), where r x v0 = G2 sin(A/2) (v2 x v0) and v2 x v0 = (e2 x p0) / (|p2| |p0|).
// Then Arvo's arc sampling from v1 to v2' with xi_1.
template <class T> DirectionSample<T> sample_polygon_solid_angle(const PolygonSolidAngleView<T>& v, const Vec2<T>& u) {
  if (!v.valid()) return DirectionSample<T>::none(v.reason);
  const auto& f = v.fan;
  T a = 0;
  const int k = pick_fan_triangle(v.area, f.count, u[0] * v.solid_angle, &a);
  if (k < 0) return DirectionSample<T>::none(NoSample::kTooSmall);
  const Vec3<T>&v0 = f.u[0], &v1 = f.u[k], &v2 = f.u[k + 1];
  const T g0 = v.g0[k], g1 = v.g1[k], g2 = v.g2[k];  // as for the area (make_polygon_solid_angle_view)
  const T c = std::cos(a / 2), s = std::sin(a / 2);
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

// ---- Baseline: Arvo 1995, "Stratified Sampling of Spherical Triangles", as published ---------------------
//
// Per triangle (A, B, C) with interior angles alpha, beta, gamma and area alpha + beta + gamma - pi:
//   A^ = xi_1 area; s = sin(A^ - alpha); t = cos(A^ - alpha); u = t - cos alpha; v = s + sin alpha cos c;
//   q = ((v t - u s) cos alpha - v) / ((v s + u t) sin alpha);  C^ = q A + sqrt(1 - q^2) |C - (C.A) A|^;
//   z = 1 - xi_2 (1 - C^.B);  P = z B + sqrt(1 - z^2) |C^ - (C^.B) B|^
// (c is the arc AB). Polygons are sampled as the fan (v0, v_k, v_{k+1}), triangles chosen by Arvo's areas.
// The angle sum cancels for small triangles: that is the published method's weakness, kept on purpose.

template <class T> struct ArvoFanView {
  PolygonFanView<T> fan;
  std::array<T, kMaxClippedVertices> alpha{}, area{};
  T solid_angle = 0;
  NoSample reason = NoSample::kNone;
  bool valid() const { return reason == NoSample::kNone; }
};

template <class T> T spherical_angle(const Vec3<T>& at, const Vec3<T>& b, const Vec3<T>& c) {
  const Vec3<T> nb = at.cross(b), nc = at.cross(c);
  return std::atan2(nb.cross(nc).norm(), nb.dot(nc));
}

template <class T> ArvoFanView<T> make_arvo_fan_view(const PolygonLightGeometry<T>& g) {
  ArvoFanView<T> v;
  v.fan = make_polygon_fan_view(g, false);
  if (!v.fan.valid()) return v.reason = v.fan.reason, v;
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
  const T s = std::sin(ahat - alpha), t = std::cos(ahat - alpha);
  const T uu = t - std::cos(alpha), vv = s + std::sin(alpha) * A.dot(B);
  // Arvo 1995's q; a zero denominator (found by the sanitizer replay of fuzz_polygon_arvo_*: float-divide-by-zero)
  // takes the limit of the clamped quotient, +-1 by the numerator's sign, without dividing.
  const T q_num = (vv * t - uu * s) * std::cos(alpha) - vv, q_den = (vv * s + uu * t) * std::sin(alpha);
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

// ---- Baseline: Turk 1992, "Generating Random Points in Triangles", as published ---------------------------
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
  TurkAreaView<T> v;
  v.fan = make_polygon_fan_view(g, false);
  if (!v.fan.valid()) return v.reason = v.fan.reason, v;
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
