// warpcheck/polygon.h: convex planar polygon lights: geometry, validation, clipping, bounding caps and the
// independent long double references (projected solid angle by Lambert's edge formula, solid angle by van
// Oosterom & Strackee 1983).
//
// The kernels: polygon_projected.h (Peters 2021 Sec. 3, 6.4), polygon_solid_angle.h (Sec. 5, Arvo 1995, Turk 1992),
// spherical_rectangle.h (Urena et al. 2013), ltc.h (Sec. 4.1).
//
// A polygon has 3 to 8 vertices in world space, in either winding, and must be convex up to its coordinates'
// rounding, planar to 8 sqrt(eps) of its width, and wider than that tolerance. Every kernel calls check_polygon(),
// so none samples invalid input. The reasoning behind the tolerances: docs/derivations/polygon-geometry.md.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <string>
#include <vector>

#include "warpcheck/core.h"

namespace warpcheck {

inline constexpr int kMaxPolygonVertices = 8;
// Clipping a convex polygon to a half-space adds at most one vertex.
inline constexpr int kMaxClippedVertices = kMaxPolygonVertices + 1;
// The solid-angle fan adds at most three midpoints (polygon_solid_angle.h).
inline constexpr int kMaxFanVertices = kMaxClippedVertices + 3;

template <class T> struct PolygonLight {
  std::array<Vec3<T>, kMaxPolygonVertices> vertices{};
  int count = 0;

  PolygonLight() { vertices.fill(Vec3<T>::Zero()); }
  PolygonLight(std::initializer_list<Vec3<T>> vs) {
    vertices.fill(Vec3<T>::Zero());
    for (const auto& v : vs) {
      if (count < kMaxPolygonVertices) vertices[count] = v;
      ++count;  // may exceed the maximum: check_polygon() then rejects it
    }
  }
  template <class U> PolygonLight<U> cast() const {
    PolygonLight<U> p;
    p.count = count;
    for (int i = 0; i < std::min(count, kMaxPolygonVertices); ++i) p.vertices[i] = vertices[i].template cast<U>();
    return p;
  }
};

template <class T> struct PreparedPolygonLight;

template <class T> struct PolygonLightGeometry {
  ShadingPoint<T> shading;
  PolygonLight<T> light;
  // Optional: prepare_polygon_light(light), made once per light. Used only while its vertices equal light's.
  const PreparedPolygonLight<T>* prepared = nullptr;

  template <class U> PolygonLightGeometry<U> cast() const {
    return {ShadingPoint<U>{shading.position.template cast<U>(), shading.normal.template cast<U>()},
            light.template cast<U>()};
  }
};

// ---- Small numerical helpers ----

// a d - b c by Kahan's algorithm with FMAs: a few ulps and the correct sign (Jeannerod, Louvet & Muller 2013), as
// Peters 2021 Sec. 3.7 needs for short edges.
// In x87 long double the FMAs are an emulation, several times the plain difference: where fl(a d) - fl(b c) keeps at
// least half of |a d| + |b c| (no cancellation, both products finite, the difference normal), its relative error is
// at most 3u (u = eps / 2) against Kahan's 2u, with the exact sign, and it is taken instead.
template <class T> T kahan_det(T a, T b, T c, T d) {
  if constexpr (std::is_same_v<T, long double> && kX87LongDouble) {
    const T ad = a * d, bc = b * c, det = ad - bc, scale = std::abs(ad) + std::abs(bc);
    if (std::isfinite(scale) && std::abs(det) >= std::numeric_limits<T>::min() && T(2) * std::abs(det) >= scale)
      return det;
  }
  const T w = b * c;
  const T e = negated_product_error(b, c, w);  // w - b c, exactly
  const T f = fused_multiply_add(a, d, -w);
  return f + e;
}

// Cross product with every entry by kahan_det (Peters 2021 Sec. 3.7: cancellation-free edge normals).
template <class T> Vec3<T> kahan_cross(const Vec3<T>& a, const Vec3<T>& b) {
  return Vec3<T>(kahan_det(a.y(), a.z(), b.y(), b.z()), kahan_det(a.z(), a.x(), b.z(), b.x()),
                 kahan_det(a.x(), a.y(), b.x(), b.y()));
}

// z component of a x b for 2D vectors, by Kahan.
template <class T> T kahan_cross2(const Vec2<T>& a, const Vec2<T>& b) { return kahan_det(a.x(), a.y(), b.x(), b.y()); }

// The sign of a d - b c (-1, 0 or 1), always kahan_det's. The plainly rounded difference decides where it exceeds
// its rounding error, about eps (|a d| + |b c|) plus the least subnormal, so below 4 eps (|a d| + |b c|) once that
// sum is normal (a floating-point filter, as in Shewchuk 1997's orientation tests); there kahan_det's sign is the
// exact one too. Elsewhere (near-singular, subnormal, Inf, NaN) kahan_det decides: its FMAs are library calls, or in
// x87 long double an emulation, several times the cost of the filter.
template <class T> int det_sign(T a, T b, T c, T d) {
  const T ad = a * d, bc = b * c, det = ad - bc, scale = std::abs(ad) + std::abs(bc);
  if (scale >= std::numeric_limits<T>::min() && std::abs(det) > T(4) * std::numeric_limits<T>::epsilon() * scale)
    return det > T(0) ? 1 : -1;
  const T k = kahan_det(a, b, c, d);
  return (k > T(0)) - (k < T(0));
}
template <class T> int cross2_sign(const Vec2<T>& a, const Vec2<T>& b) { return det_sign(a.x(), a.y(), b.x(), b.y()); }

// i mod n in [0, n) for n > 0, as ((i % n) + n) % n, without the integer division where i is in [-n, 2n) (the
// neighbours in a vertex loop): GCC emits an idiv for % by a run-time count, on each view's critical path.
inline int wrap_index(int i, int n) {
  if (i >= 0 && i < n) return i;
  if (i >= n && i < 2 * n) return i - n;
  if (i < 0 && i >= -n) return i + n;
  return (i % n + n) % n;
}

// Normalises without overflow or underflow (scales by the largest entry first); zero stays zero.
template <class T> Vec3<T> safe_normalized(const Vec3<T>& v) {
  const T m = max_abs(v);
  if (!(m > T(0)) || !std::isfinite(m)) return Vec3<T>::Zero();
  const Vec3<T> s = v / m;
  return s / s.norm();
}

// ---- Validation (the validating constructor) ----

// Newell's normal (twice the vector area), from vertex differences: a small polygon far away keeps its precision.
template <class T> Vec3<T> polygon_area_vector(const PolygonLight<T>& p) {
  Vec3<T> n = Vec3<T>::Zero();
  for (int i = 1; i + 1 < p.count; ++i)
    n += kahan_cross<T>(p.vertices[i] - p.vertices[0], p.vertices[i + 1] - p.vertices[0]);
  return n;  // = 2 * area * unit normal (right-hand rule)
}

// The relative rounding of input vertices that check_polygon forgives by default (half an ulp, with room to spare).
template <class T> constexpr T kPolygonVertexRounding = T(4) * std::numeric_limits<T>::epsilon();

// check_polygon's planarity tolerance (a length): 8 sqrt(eps) of the polygon's width (not its diameter), plus the
// rounding of coordinates of size `magnitude`. 2 area / diameter lies between the width and twice it.
template <class T> T polygon_planarity_tolerance(T width, T magnitude) {
  const T eps = std::numeric_limits<T>::epsilon();
  return T(8) * std::sqrt(eps) * width + T(64) * eps * magnitude;
}

// An edge's projection onto the plane of unit normal nhat, scaled exactly to [1/2, 1) (no underflow, no subnormal
// grid), and its ends' rounding err scaled alike. False when no longer than err: no direction in the plane.
template <class T> bool edge_in_plane(const Vec3<T>& e, T err, const Vec3<T>& nhat, Vec3<T>& scaled, T& scaled_err) {
  int scale = 0;
  std::frexp(max_abs(e), &scale);
  const Vec3<T> es = ldexp(e, -scale);
  scaled = es - nhat.dot(es) * nhat;
  scaled_err = scale_by_power_of_two(err, -scale);
  return scaled.norm() > scaled_err;
}

namespace polygon_check_detail {

// A check's verdict: kNone, or the reason and why.
struct Verdict {
  NoSample reason = NoSample::kNone;
  const char* why = "";
  bool ok() const { return reason == NoSample::kNone; }
};

// 3 to 8 finite vertices, no two consecutive ones equal, none visited twice (no convex polygon does that, and the
// turning test can pass a zero-area loop).
template <class T> Verdict check_vertices(const PolygonLight<T>& p) {
  if (p.count < 3) return {NoSample::kInvalidGeometry, "a polygon needs at least 3 vertices"};
  if (p.count > kMaxPolygonVertices) return {NoSample::kInvalidGeometry, "more than 8 vertices"};
  for (int i = 0; i < p.count; ++i)
    if (!all_finite(p.vertices[i])) return {NoSample::kNonFinite, "non-finite vertex"};
  for (int i = 0; i < p.count; ++i)
    if (p.vertices[i] == p.vertices[wrap_index(i + 1, p.count)])
      return {NoSample::kInvalidGeometry, "two consecutive vertices coincide"};
  for (int i = 0; i < p.count; ++i)
    for (int j = i + 2; j < p.count; ++j)
      if (p.vertices[i] == p.vertices[j] && !(i == 0 && j == p.count - 1))
        return {NoSample::kInvalidGeometry, "a vertex repeats"};
  return {};
}

// A nonzero area, wider than the planarity tolerance (else no determined plane), every vertex within that tolerance
// of the plane. Sets area2, Newell's vector (polygon_area_vector), and nhat = area2 / |area2|.
template <class T> Verdict check_plane(const PolygonLight<T>& p, Vec3<T>& area2, Vec3<T>& nhat) {
  T diameter = 0, magnitude = 0;
  for (int i = 0; i < p.count; ++i) {
    magnitude = std::max(magnitude, max_abs(p.vertices[i]));
    for (int j = i + 1; j < p.count; ++j) diameter = std::max(diameter, (p.vertices[i] - p.vertices[j]).norm());
  }
  area2 = polygon_area_vector(p);
  const T area2_norm = area2.norm();
  if (!(area2_norm > T(0)) || !std::isfinite(area2_norm)) return {NoSample::kZeroSize, "zero area"};
  nhat = area2 / area2_norm;
  const T width = area2_norm / diameter;
  const T tol = polygon_planarity_tolerance(width, magnitude);
  if (!(width > tol)) return {NoSample::kZeroSize, "narrower than its planarity tolerance (zero area up to rounding)"};
  for (int i = 0; i < p.count; ++i)
    if (std::abs(nhat.dot(p.vertices[i] - p.vertices[0])) > tol)
      return {NoSample::kInvalidGeometry, "vertices are not coplanar"};
  return {};
}

// A spike (b back along a: a turn of +-pi by the sign of a rounding error in s = nhat . (a x b)) is never convex.
template <class T> bool is_spike(const Vec3<T>& a, const Vec3<T>& b, T s) {
  return a.dot(b) < T(0) && std::abs(s) <= T(8) * std::numeric_limits<T>::epsilon() * a.norm() * b.norm();
}

// Convexity: no spike at any vertex; the turns between the edges longer than their rounding (edge_in_plane) agree
// with nhat and add up to one revolution. A reflex turn is forgiven only within the vertices' rounding: s is off by
// at most |a| err_b + |b| err_a + err_a err_b.
template <class T> Verdict check_convexity(const PolygonLight<T>& p, const Vec3<T>& nhat, T vertex_rounding) {
  auto rounding = [&](int k) { return vertex_rounding * max_abs(p.vertices[wrap_index(k, p.count)]); };
  for (int i = 0; i < p.count; ++i) {
    const Vec3<T> a = p.vertices[i] - p.vertices[wrap_index(i - 1, p.count)];
    const Vec3<T> b = p.vertices[wrap_index(i + 1, p.count)] - p.vertices[i];
    if (is_spike(a, b, nhat.dot(kahan_cross<T>(a, b))))
      return {NoSample::kInvalidGeometry, "polygon is not convex (a spike)"};
  }
  struct KeptEdge {
    Vec3<T> e;  // V_j+1 - V_j in the plane, scaled by a power of two (edge_in_plane)
    T err;      // its rounding bound delta_j + delta_j+1, scaled alike
  };
  std::array<KeptEdge, kMaxPolygonVertices> kept;
  int nk = 0;
  for (int i = 0; i < p.count; ++i) {
    const Vec3<T> e = p.vertices[wrap_index(i + 1, p.count)] - p.vertices[i];
    KeptEdge k;
    if (edge_in_plane<T>(e, rounding(i) + rounding(i + 1), nhat, k.e, k.err)) kept[nk++] = k;
  }
  if (nk < 3) return {NoSample::kZeroSize, "fewer than three edges longer than their rounding"};
  T turning = 0;
  for (int i = 0; i < nk; ++i) {
    const KeptEdge &ka = kept[wrap_index(i - 1, nk)], &kb = kept[i];
    const T s = nhat.dot(kahan_cross<T>(ka.e, kb.e)), c = ka.e.dot(kb.e);
    const T s_err = ka.e.norm() * kb.err + kb.e.norm() * ka.err + ka.err * kb.err;
    if (s < -s_err) return {NoSample::kInvalidGeometry, "polygon is not convex"};
    if (is_spike(ka.e, kb.e, s)) return {NoSample::kInvalidGeometry, "polygon is not convex (a spike)"};
    turning += std::atan2(s, c);
  }
  if (std::abs(turning - kTwoPi<T>) > T(0.5)) return {NoSample::kInvalidGeometry, "polygon is not simple"};
  return {};
}

// check_polygon (below), also giving Newell's vector of a valid light.
template <class T>
NoSample check_polygon_and_area(const PolygonLight<T>& p, std::string* message, T vertex_rounding, Vec3<T>& area2) {
  Vec3<T> nhat = Vec3<T>::Zero();
  area2 = Vec3<T>::Zero();
  Verdict v = check_vertices(p);
  if (v.ok()) v = check_plane(p, area2, nhat);
  if (v.ok()) v = check_convexity(p, nhat, vertex_rounding);
  if (message) *message = v.why;
  return v.reason;
}

}  // namespace polygon_check_detail

// kNone for a valid light; otherwise kNonFinite, kZeroSize or kInvalidGeometry, with a message if asked. Each vertex
// is known to vertex_rounding |V_k|_inf (ltc.h passes its own bound for M^-1 P).
template <class T> NoSample check_polygon(const PolygonLight<T>& p, std::string* message = nullptr,
                                          T vertex_rounding = kPolygonVertexRounding<T>) {
  Vec3<T> area2;
  return polygon_check_detail::check_polygon_and_area(p, message, vertex_rounding, area2);
}

// ---- The light prepared once: the part of every view that does not depend on the shading point ----

// The light's edges V_j+1 - V_j in the plane of unit normal nh (edge_in_plane: scaled by a power of two), and
// whether each is longer than its ends' rounding, vertex_rounding |V_k|_inf each.
template <class T> void polygon_edges_in_plane(const PolygonLight<T>& p, const Vec3<T>& nh, T vertex_rounding,
                                               std::array<Vec3<T>, kMaxPolygonVertices>& edge,
                                               std::array<bool, kMaxPolygonVertices>& has_direction) {
  auto rounding = [&](int k) { return vertex_rounding * max_abs(p.vertices[wrap_index(k, p.count)]); };
  for (int j = 0; j < p.count; ++j) {
    T err;
    const Vec3<T> e = p.vertices[wrap_index(j + 1, p.count)] - p.vertices[j];
    has_direction[j] = edge_in_plane<T>(e, rounding(j) + rounding(j + 1), nh, edge[j], err);
  }
}

// check_polygon's verdict, Newell's vector and its unit normal, the light's edges in its plane (edge_in_plane, as
// polygon_inward_planes takes them) and its extents (as the projected solid angle's resolved_by_coordinates takes
// them). A renderer prepares each light once and points PolygonLightGeometry::prepared
// at it; every view of that light then skips the work, and its results are the same bit for bit.
template <class T> struct PreparedPolygonLight {
  PolygonLight<T> light;
  T vertex_rounding = kPolygonVertexRounding<T>;
  NoSample reason = NoSample::kInvalidGeometry;
  Vec3<T> area2 = Vec3<T>::Zero();
  Vec3<T> plane_normal = Vec3<T>::Zero();           // safe_normalized(area2)
  std::array<Vec3<T>, kMaxPolygonVertices> edge{};  // V_j+1 - V_j in the plane, scaled by a power of two
  std::array<bool, kMaxPolygonVertices> has_direction{};
  // The light's extents: max_k |V_k - V_0|_inf, max_k |V_k|_inf, 2 max_k |V_k - V_0|
  T extent = 0, magnitude = 0, diameter = 0;
};

// The light's extents as PreparedPolygonLight holds them.
template <class T> void polygon_extents(const PolygonLight<T>& p, T& extent, T& magnitude, T& diameter) {
  extent = magnitude = diameter = 0;
  for (int i = 0; i < p.count; ++i) {
    extent = std::max(extent, max_abs(Vec3<T>(p.vertices[i] - p.vertices[0])));
    magnitude = std::max(magnitude, max_abs(p.vertices[i]));
    diameter = std::max(diameter, T(2) * stable_norm(Vec3<T>(p.vertices[i] - p.vertices[0])));
  }
}

template <class T>
PreparedPolygonLight<T> prepare_polygon_light(const PolygonLight<T>& p, T vertex_rounding = kPolygonVertexRounding<T>) {
  PreparedPolygonLight<T> r;
  r.light = p;
  r.vertex_rounding = vertex_rounding;
  r.reason = polygon_check_detail::check_polygon_and_area(p, nullptr, vertex_rounding, r.area2);
  if (r.reason != NoSample::kNone) return r;
  r.plane_normal = safe_normalized(r.area2);
  polygon_edges_in_plane(p, r.plane_normal, vertex_rounding, r.edge, r.has_direction);
  polygon_extents(p, r.extent, r.magnitude, r.diameter);
  return r;
}

// g.prepared if it was made from g.light's vertices (compared exactly) with this vertex rounding, else null.
template <class T>
const PreparedPolygonLight<T>* matching_preparation(const PolygonLightGeometry<T>& g, T vertex_rounding) {
  const PreparedPolygonLight<T>* p = g.prepared;
  if (!p || p->light.count != g.light.count || p->vertex_rounding != vertex_rounding) return nullptr;
  for (int i = 0; i < std::min(g.light.count, kMaxPolygonVertices); ++i)
    if (p->light.vertices[i] != g.light.vertices[i]) return nullptr;
  return p;
}

// ---- Clipping to the upper hemisphere (Peters 2021 Sec. 3.1) ----

// A polygon of directions in a local frame (vertices need not be unit length; only their directions count).
template <class T> struct LocalPolygon {
  std::array<Vec3<T>, kMaxClippedVertices> v;
  int count = 0;
  LocalPolygon() { v.fill(Vec3<T>::Zero()); }
};

// Sutherland-Hodgman against z >= 0: the crossing (q_z p - p_z q) / (q_z - p_z) does not cancel, gets z = 0 exactly,
// and lies on the edge's great circle. A convex polygon gains at most one vertex.
// Written into out (not in), whose vertices beyond its new count are left as they were.
template <class T> void clip_to_upper_hemisphere(const LocalPolygon<T>& in, LocalPolygon<T>& out) {
  out.count = 0;
  for (int i = 0; i < in.count; ++i) {
    const Vec3<T>& p = in.v[i];
    const Vec3<T>& q = in.v[wrap_index(i + 1, in.count)];
    const bool p_in = p.z() >= T(0), q_in = q.z() >= T(0);
    if (p_in && out.count < kMaxClippedVertices) out.v[out.count++] = p;
    if (p_in != q_in && p.z() != T(0) && q.z() != T(0) && out.count < kMaxClippedVertices) {
      const T d = q.z() - p.z();
      Vec3<T> x = (q.z() * p - p.z() * q) / d;
      x.z() = T(0);
      out.v[out.count++] = x;
    }
  }
}

template <class T> LocalPolygon<T> clip_to_upper_hemisphere(const LocalPolygon<T>& in) {
  LocalPolygon<T> out;
  clip_to_upper_hemisphere(in, out);
  return out;
}

// ---- The polygon seen from a shading point (shared by all polygon kernels) ----

template <class T> struct PolygonView {
  NoSample reason = NoSample::kNone;
  Vec3<T> normal = Vec3<T>::Zero();                              // unit shading normal
  Frame<T> frame = Frame<T>::from_z(Vec3<T>(T(0), T(0), T(1)));  // z: the shading normal
  Vec3<T> plane_normal = Vec3<T>::Zero();                        // unit right-hand normal of the vertex order
  T plane_distance = 0;   // plane_normal . (V_0 - x): > 0 when the vertex order winds positively seen from x
  LocalPolygon<T> local;  // V_k - x in the shading frame (flattened, see lift), not clipped
  // How far vertex k is off the light's plane; nonzero only for a light flattened by make_polygon_view, whose
  // `local` vertices are V_k - x - lift[k] plane_normal.
  std::array<T, kMaxPolygonVertices> lift{};
  bool flattened = false;
  T vertex_rounding = kPolygonVertexRounding<T>;      // as passed to check_polygon (make_polygon_view)
  const PreparedPolygonLight<T>* prepared = nullptr;  // the geometry's preparation where it matches its light
  bool valid() const { return reason == NoSample::kNone; }
};

// Validates the input and expresses the polygon in the shading frame; x in the light's plane gives kEdgeOn.
template <class T> NoSample fill_polygon_view(const PolygonLightGeometry<T>& g, T vertex_rounding, PolygonView<T>& v) {
  v.vertex_rounding = vertex_rounding;
  if (!all_finite(g.shading.position)) return NoSample::kNonFinite;
  if (!all_finite(g.shading.normal)) return NoSample::kNonFinite;
  Vec3<T> area2;
  const PreparedPolygonLight<T>* prep = v.prepared = matching_preparation(g, vertex_rounding);
  const NoSample checked =
      prep ? prep->reason : polygon_check_detail::check_polygon_and_area(g.light, nullptr, vertex_rounding, area2);
  if (checked != NoSample::kNone) return checked;
  if (prep) area2 = prep->area2;
  if (!normalize_normal(g.shading.normal, v.normal)) return NoSample::kBadNormal;
  v.frame = Frame<T>::from_z(v.normal);
  v.plane_normal = prep ? prep->plane_normal : safe_normalized(area2);  // Newell's vector, as polygon_area_vector
  const int n = g.light.count;
  std::array<Vec3<T>, kMaxPolygonVertices> to_vertex;  // V_k - x
  for (int i = 0; i < n; ++i) to_vertex[i] = g.light.vertices[i] - g.shading.position;
  // Signed distance from the centroid (averaging reduces the rounding of a single vertex).
  Vec3<T> centroid = Vec3<T>::Zero();
  for (int i = 0; i < n; ++i) centroid += to_vertex[i];
  centroid /= T(n);
  if (!all_finite(centroid)) return NoSample::kNonFinite;
  v.plane_distance = v.plane_normal.dot(centroid);
  // Edge-on up to rounding (8 eps of the reach): which side x is on is not determined.
  const T eps = std::numeric_limits<T>::epsilon();
  T reach = 0;
  for (int i = 0; i < n; ++i) reach = std::max(reach, max_abs(to_vertex[i]));
  if (!(std::abs(v.plane_distance) > T(8) * eps * reach)) return NoSample::kEdgeOn;
  // Edge-on too when vertices lie on both sides of x beyond their rounding: no convex spherical polygon.
  // Flattening: a light off its plane (within tolerance) is no convex spherical polygon from close by; beyond the
  // offsets' rounding its vertices are moved onto the plane through the centroid (check_polygon's turns agree).
  T off = 0;
  for (int i = 0; i < n; ++i) {
    const T side = v.plane_normal.dot(to_vertex[i]);
    const T err = vertex_rounding * max_abs(g.light.vertices[i]) + T(8) * eps * reach;
    if ((v.plane_distance > T(0) ? -side : side) > err) return NoSample::kEdgeOn;
    v.lift[i] = side - v.plane_distance;
    off = std::max(off, std::abs(v.lift[i]));
  }
  v.flattened = off > T(8) * eps * reach;
  if (!v.flattened) v.lift.fill(T(0));
  v.local.count = n;
  for (int i = 0; i < n; ++i) {
    const Vec3<T>& a = to_vertex[i];  // a - lift n, written out: GCC left Eigen's expression as a call
    const Vec3<T>& pn = v.plane_normal;
    Vec3<T> l =
        v.frame.to_local(Vec3<T>(a.x() - v.lift[i] * pn.x(), a.y() - v.lift[i] * pn.y(), a.z() - v.lift[i] * pn.z()));
    // A vertex within rounding of the horizon is on it, and one within rounding of the zenith is at it.
    if (std::abs(l.z()) <= T(8) * eps * max_abs(l)) l.z() = T(0);
    const T xy_rounding = T(8) * eps * max_abs(l);
    if (std::abs(l.x()) <= xy_rounding && std::abs(l.y()) <= xy_rounding) l.x() = l.y() = T(0);
    v.local.v[i] = l;
  }
  return NoSample::kNone;
}

template <class T>
PolygonView<T> make_polygon_view(const PolygonLightGeometry<T>& g, T vertex_rounding = kPolygonVertexRounding<T>) {
  PolygonView<T> v;  // filled in place: no copy of the view on return
  v.reason = fill_polygon_view(g, vertex_rounding, v);
  return v;
}

// The planes (V_j - x) x (V_{j+1} - V_j) through x and the light's edges, oriented inwards: w is in the light's cone
// iff all dot products are >= 0. From exact world edges taken in the light's plane (edge_in_plane); an edge without
// a direction takes the plane before it; pv is g's view (its preparation's edges when it has one). Returns the number
// of planes, g.light.count.
template <class T> int polygon_inward_planes(const PolygonLightGeometry<T>& g, const PolygonView<T>& pv, Vec3<T>* out) {
  const int n = g.light.count;
  const T orient = pv.plane_distance < T(0) ? T(-1) : T(1);
  const Vec3<T>& nh = pv.plane_normal;
  std::array<Vec3<T>, kMaxPolygonVertices> own_edge;
  std::array<bool, kMaxPolygonVertices> own_has_direction{};
  if (!pv.prepared) polygon_edges_in_plane(g.light, nh, pv.vertex_rounding, own_edge, own_has_direction);
  const auto& edge = pv.prepared ? pv.prepared->edge : own_edge;
  const auto& has_direction = pv.prepared ? pv.prepared->has_direction : own_has_direction;
  int last = -1;
  for (int j = 0; j < n; ++j) {
    if (has_direction[j]) last = j;
    out[j] = orient * kahan_cross(Vec3<T>(g.light.vertices[j] - g.shading.position - pv.lift[j] * nh), edge[j]);
  }
  for (int j = 0, prev = last; j < n && last >= 0; ++j) {
    if (has_direction[j])
      prev = j;
    else
      out[j] = out[prev];
  }
  return n;
}

// ---- Bounding caps ----

// A small cap containing the convex spherical polygon of the given directions: from the normalised mean, a few
// Badoiu-Clarkson steps (towards the farthest vertex), the best kept; radius by chord length, slack 64 eps.
template <class T> Cap<T> bounding_cap_of_directions(const Vec3<T>* dirs, int n) {
  std::array<Vec3<T>, kMaxFanVertices> u;
  Vec3<T> mean = Vec3<T>::Zero();
  for (int i = 0; i < n; ++i) mean += (u[i] = safe_normalized(dirs[i]));
  auto radius2 = [&](const Vec3<T>& axis, int* far) {
    T r = 0;
    for (int i = 0; i < n; ++i) {
      const T d = (u[i] - axis).squaredNorm();
      if (d >= r) r = d, *far = i;
    }
    return r;
  };
  Vec3<T> axis = safe_normalized(mean);
  if (axis.isZero()) return Cap<T>{};  // directions cancel: the whole sphere
  int far = 0;
  T best = radius2(axis, &far);
  Vec3<T> best_axis = axis;
  for (int k = 1; k <= 24; ++k) {
    axis = safe_normalized(Vec3<T>(axis + (u[far] - axis) / T(k + 1)));
    const T r = radius2(axis, &far);
    if (r < best) best = r, best_axis = axis;
  }
  radius2(best_axis, &far);
  const T one_minus_cos = std::min(T(2), best / T(2) * (T(1) + T(64) * std::numeric_limits<T>::epsilon()));
  return Cap<T>{best_axis, one_minus_cos};
}

// ---- Independent references (long double; no code shared with the kernels) ----

// The polygon seen from x in a frame of z = n, clipped to z >= 0 by parametric intersection.
inline int reference_clipped_local(const PolygonLightGeometry<long double>& g, Vec3<long double>* out) {
  using L = long double;
  const Vec3<L> n = g.shading.normal.normalized();
  const Vec3<L> helper = std::abs(n.x()) < L(0.6) ? Vec3<L>(1, 0, 0) : Vec3<L>(0, 1, 0);
  const Vec3<L> ex = (helper - helper.dot(n) * n).normalized(), ey = n.cross(ex);
  const int m = g.light.count;
  Vec3<L> loc[kMaxPolygonVertices];
  for (int i = 0; i < m; ++i) {
    const Vec3<L> d = g.light.vertices[i] - g.shading.position;
    loc[i] = Vec3<L>(d.dot(ex), d.dot(ey), d.dot(n));
  }
  int k = 0;
  for (int i = 0; i < m; ++i) {
    const Vec3<L>& a = loc[i];
    const Vec3<L>& b = loc[wrap_index(i + 1, m)];
    // A polygon convex in T up to rounding may cross the horizon more than twice in long double: no convex
    // clipped polygon, 0.
    if (a.z() >= 0) {
      if (k >= kMaxClippedVertices) return 0;
      out[k++] = a;
    }
    if ((a.z() > 0 && b.z() < 0) || (a.z() < 0 && b.z() > 0)) {
      if (k >= kMaxClippedVertices) return 0;
      const L t = a.z() / (a.z() - b.z());
      Vec3<L> c = a + t * (b - a);
      c.z() = 0;
      out[k++] = c;
    }
  }
  return k;
}

// Projected solid angle (integral of max(0, n.w) dw) by Lambert's formula: (1/2) sum_j gamma_j (n . m_j), gamma_j the
// angle of edge j and m_j its plane's inward unit normal.
inline long double reference_projected_solid_angle(const PolygonLightGeometry<long double>& g) {
  using L = long double;
  Vec3<L> c[kMaxClippedVertices];
  const int k = reference_clipped_local(g, c);
  if (k < 3) return 0;
  L sum = 0;
  for (int j = 0; j < k; ++j) {
    const Vec3<L> a = c[j].normalized(), b = c[wrap_index(j + 1, k)].normalized();
    const Vec3<L> m = a.cross(b);
    const L s = m.norm();
    if (s == 0) continue;
    const L gamma = std::atan2(s, a.dot(b));
    sum += gamma * m.z() / s;
  }
  return std::abs(sum) / 2;  // the sign is the polygon's winding as seen from x
}

// Solid angle of the whole polygon (not clipped) by van Oosterom & Strackee 1983 on a fan from vertex 0:
// tan(Omega / 2) = det(a, b, c) / (1 + a.b + a.c + b.c) for unit a, b, c.
inline long double reference_solid_angle(const PolygonLightGeometry<long double>& g, bool clipped = false) {
  using L = long double;
  Vec3<L> c[kMaxClippedVertices];
  int k = 0;
  if (clipped) {
    k = reference_clipped_local(g, c);
  } else {
    for (int i = 0; i < g.light.count; ++i) c[k++] = g.light.vertices[i] - g.shading.position;
  }
  if (k < 3) return 0;
  L sum = 0;
  const Vec3<L> a = c[0].normalized();
  for (int j = 1; j + 1 < k; ++j) {
    const Vec3<L> b = c[j].normalized(), d = c[j + 1].normalized();
    sum += 2 * std::atan2(a.dot(b.cross(d)), 1 + a.dot(b) + a.dot(d) + b.dot(d));
  }
  return std::abs(sum);
}

// ---- Helpers of the polygon kernels' catalogue traits (warpcheck/catalogue.h) ----------------------------------

// A cap containing the light's vertices seen from the shading point (for geometry the kernels reject).
template <class T> Cap<T> polygon_bounding_cap(const PolygonLightGeometry<T>& g) {
  std::array<Vec3<T>, kMaxPolygonVertices> w;
  for (int i = 0; i < g.light.count; ++i) w[i] = g.light.vertices[i] - g.shading.position;
  return bounding_cap_of_directions(w.data(), g.light.count);
}

// Unit normals of the planes through the shading point and each edge (degenerate edges skipped).
template <class T> std::vector<Vec3<T>> polygon_edge_planes(const PolygonLightGeometry<T>& g) {
  std::vector<Vec3<T>> planes;
  const int n = g.light.count;
  for (int i = 0; i < n; ++i) {
    const Vec3<T> e =
        (g.light.vertices[i] - g.shading.position).cross(g.light.vertices[wrap_index(i + 1, n)] - g.shading.position);
    if (e.norm() > T(0)) planes.push_back(e.normalized());
  }
  return planes;
}

// The great circles on which a polygon kernel's density may jump or kink: the edges' planes and the horizon
// (where the clipped supports end and the projected density's cosine reaches 0).
template <class T> std::vector<Vec3<T>> polygon_boundary_planes(const PolygonLightGeometry<T>& g) {
  std::vector<Vec3<T>> planes = polygon_edge_planes(g);
  if (g.shading.normal.norm() > T(0)) planes.push_back(g.shading.normal.normalized());
  return planes;
}

// Kinks in u0 of a warp that picks a piece (fan triangle, sector) by u0 in proportion to its area: the
// cumulative fractions sum_{i<=k} A_i / A_total strictly inside (0, 1), over the pieces of positive area.
template <class T, class It> std::vector<T> cumulative_area_fractions(It first, It last) {
  T total = 0;
  for (It i = first; i != last; ++i) total += T(*i);
  std::vector<T> kinks;
  T sum = 0;
  if (!(total > T(0))) return kinks;
  for (It i = first; i != last; ++i) {
    sum += T(*i);
    if (T(*i) > T(0) && sum < total) kinks.push_back(sum / total);
  }
  return kinks;
}

}  // namespace warpcheck
