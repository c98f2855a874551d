// warpcheck/polygon.h: convex planar polygon lights: geometry, validation, clipping, bounding caps and the
// independent long double references (projected solid angle by Lambert's edge formula, solid angle by van
// Oosterom & Strackee 1983).
//
// The sampling kernels live in one header per technique, as the house rule asks one header per light shape
// and the polygon has several published techniques whose code shares nothing but this geometry:
//   polygon_projected.h    Peters 2021, Section 3 (projected solid angle) and Section 6.4 (biased variant)
//   polygon_solid_angle.h  Peters 2021, Section 5 (solid angle, plain and clipped), and the published
//                          polygon baselines Arvo 1995 (spherical triangles, as a fan) and Turk 1992 (area)
//   spherical_rectangle.h  Urena et al. 2013 (rectangles only)
//
// Conventions. A polygon has 3 to 8 vertices in world space, in either winding, and must be planar and
// convex up to its coordinates' rounding, planar to 8 sqrt(eps) of its width (plus that rounding), and wider than the
// planarity tolerance. check_polygon() is the validating constructor's test: it returns kInvalidGeometry or kZeroSize
// (and a message) for anything else. Every kernel calls it, so no kernel ever samples invalid input.
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
// The solid-angle fan adds the midpoint of a horizon edge wider than 90 degrees and of every edge wider than 120
// degrees (polygon_solid_angle.h): a convex spherical polygon's perimeter is at most 2 pi, so at most three in all.
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

template <class T> struct PolygonLightGeometry {
  ShadingPoint<T> shading;
  PolygonLight<T> light;

  template <class U> PolygonLightGeometry<U> cast() const {
    return {ShadingPoint<U>{shading.position.template cast<U>(), shading.normal.template cast<U>()},
            light.template cast<U>()};
  }
};

// ---- Small numerical helpers ------------------------------------------------------------------------------

// a d - b c by Kahan's algorithm with fused multiply-adds: accurate to a few ulps and with the correct sign
// (Jeannerod, Louvet & Muller 2013), which Peters 2021 Sec. 3.7 relies on for short edges.
template <class T> T kahan_det(T a, T b, T c, T d) {
  const T w = b * c;
  const T e = std::fma(-b, c, w);  // the rounding error of b c, exactly
  const T f = std::fma(a, d, -w);
  return f + e;
}

// Cross product with every entry by kahan_det (Peters 2021 Sec. 3.7: cancellation-free edge normals).
template <class T> Vec3<T> kahan_cross(const Vec3<T>& a, const Vec3<T>& b) {
  return Vec3<T>(kahan_det(a.y(), a.z(), b.y(), b.z()), kahan_det(a.z(), a.x(), b.z(), b.x()),
                 kahan_det(a.x(), a.y(), b.x(), b.y()));
}

// z component of a x b for 2D vectors, by Kahan.
template <class T> T kahan_cross2(const Vec2<T>& a, const Vec2<T>& b) { return kahan_det(a.x(), a.y(), b.x(), b.y()); }

// Normalises without overflow or underflow (scales by the largest entry first); zero stays zero.
template <class T> Vec3<T> safe_normalized(const Vec3<T>& v) {
  const T m = v.cwiseAbs().maxCoeff();
  if (!(m > T(0)) || !std::isfinite(m)) return Vec3<T>::Zero();
  const Vec3<T> s = v / m;
  return s / s.norm();
}

// ---- Validation (the validating constructor) -------------------------------------------------------------

// Newell's normal of the polygon (twice its vector area for a planar polygon), from vertex differences so
// that a small polygon far from the origin keeps its precision.
template <class T> Vec3<T> polygon_area_vector(const PolygonLight<T>& p) {
  Vec3<T> n = Vec3<T>::Zero();
  for (int i = 1; i + 1 < p.count; ++i)
    n += kahan_cross<T>(p.vertices[i] - p.vertices[0], p.vertices[i + 1] - p.vertices[0]);
  return n;  // = 2 * area * unit normal (right-hand rule)
}

// The relative rounding of input vertex coordinates that check_polygon forgives in a reflex turn, by default: half
// an ulp per coordinate is eps / 2 of |V|_inf; 4 eps leaves room for a conversion or a transform before us.
template <class T> constexpr T kPolygonVertexRounding = T(4) * std::numeric_limits<T>::epsilon();

// check_polygon's planarity tolerance (a length): vertices may leave the plane of the area vector by this much.
// Input rounding of coordinates of size `magnitude` moves a vertex by ~eps magnitude; beyond that we allow
// 8 sqrt(eps) of the polygon's width (a clearly non-planar or reflex polygon exceeds it by far). The width, not
// the diameter: a thin polygon whose vertices may leave its plane by a fraction of its diameter has no
// meaningful plane (found by fuzz_polygon_solid_angle_double, 4252de58...: width 11, diameter 1.3e8, one vertex
// 7.9 off the plane of the others accepted with the old tolerance 16, samples 9.2e-3 rad outside the light in
// that campaign; issue 4). For a convex polygon |area2| / diameter = 2 area / diameter lies between the width w
// and 2 w (it contains a triangle on its diameter of height >= w / 2 and lies in a strip of width w).
template <class T> T polygon_planarity_tolerance(T width, T magnitude) {
  const T eps = std::numeric_limits<T>::epsilon();
  return T(8) * std::sqrt(eps) * width + T(64) * eps * magnitude;
}

// An edge e = V_j+1 - V_j in the plane of unit normal nhat: its projection onto the plane, scaled by a power of two
// (exact) so that its largest entry is in [1/2, 1), and err (the rounding of its ends, delta_j + delta_j+1) scaled
// alike. Unscaled, the squares in the length of an edge shorter than sqrt(denorm_min) (1.5e-162 in double)
// underflow to 0, and the cross products with an edge a few denorm_min long have a direction quantised to the
// subnormal grid (a plane 0.08 rad off, fuzz_polygon_projected_double a5885e87...; issue 7). Returns false when the
// projection is no longer than err: the edge is a point in the plane up to rounding, and has no direction there.
template <class T> bool edge_in_plane(const Vec3<T>& e, T err, const Vec3<T>& nhat, Vec3<T>& scaled, T& scaled_err) {
  int scale = 0;
  std::frexp(e.cwiseAbs().maxCoeff(), &scale);
  const Vec3<T> es = ldexp(e, -scale);
  scaled = es - nhat.dot(es) * nhat;
  scaled_err = std::ldexp(err, -scale);
  return scaled.norm() > scaled_err;
}

// kNone for a valid light; otherwise kNonFinite, kZeroSize or kInvalidGeometry, with a message if asked.
// vertex_rounding: each vertex V_k is known to vertex_rounding |V_k|_inf (a caller that computed the vertices,
// such as ltc.h's M^-1 P, passes its own bound).
template <class T> NoSample check_polygon(const PolygonLight<T>& p, std::string* message = nullptr,
                                          T vertex_rounding = kPolygonVertexRounding<T>) {
  auto fail = [&](NoSample r, const char* why) {
    if (message) *message = why;
    return r;
  };
  if (p.count < 3) return fail(NoSample::kInvalidGeometry, "a polygon needs at least 3 vertices");
  if (p.count > kMaxPolygonVertices) return fail(NoSample::kInvalidGeometry, "more than 8 vertices");
  for (int i = 0; i < p.count; ++i)
    if (!all_finite(p.vertices[i])) return fail(NoSample::kNonFinite, "non-finite vertex");
  T diameter = 0, magnitude = 0;
  for (int i = 0; i < p.count; ++i) {
    magnitude = std::max(magnitude, p.vertices[i].cwiseAbs().maxCoeff());
    for (int j = i + 1; j < p.count; ++j) diameter = std::max(diameter, (p.vertices[i] - p.vertices[j]).norm());
  }
  for (int i = 0; i < p.count; ++i)
    if (p.vertices[i] == p.vertices[(i + 1) % p.count])
      return fail(NoSample::kInvalidGeometry, "two consecutive vertices coincide");
  // A vertex visited twice: no convex polygon does that, and the turning test can pass it when the loop between
  // the visits has zero area (found by fuzz_polygon_solid_angle_double 804609b5...: (-4, 0, 0) as vertices 1 and 4
  // of 7, sample 0.52 rad outside, issue 7).
  for (int i = 0; i < p.count; ++i)
    for (int j = i + 2; j < p.count; ++j)
      if (p.vertices[i] == p.vertices[j] && !(i == 0 && j == p.count - 1))
        return fail(NoSample::kInvalidGeometry, "a vertex repeats");
  const Vec3<T> area2 = polygon_area_vector(p);
  const T area2_norm = area2.norm();
  if (!(area2_norm > T(0)) || !std::isfinite(area2_norm)) return fail(NoSample::kZeroSize, "zero area");
  const Vec3<T> nhat = area2 / area2_norm;
  const T eps = std::numeric_limits<T>::epsilon();
  const T width = area2_norm / diameter;
  const T tol = polygon_planarity_tolerance(width, magnitude);
  // A polygon narrower than its own planarity tolerance (in effect, narrower than its coordinates' rounding) has
  // an undetermined plane: rotated about its long axis it stays within the tolerance. Its area vector is rounding
  // noise, and kernels and references disagree about which side of it a direction lies on (found by
  // fuzz_polygon_solid_angle_double, 6815131d...: eight vertices within 1e-16 of a line, pdf > 0 half a radian
  // outside; issue 4; the float slivers of fuzz/README.md's known limits).
  if (!(width > tol))
    return fail(NoSample::kZeroSize, "narrower than its planarity tolerance (zero area up to rounding)");
  for (int i = 0; i < p.count; ++i)
    if (std::abs(nhat.dot(p.vertices[i] - p.vertices[0])) > tol)
      return fail(NoSample::kInvalidGeometry, "vertices are not coplanar");
  // Convexity: every turn goes the same way as the area vector, and the turns add up to one revolution
  // (rejects star polygons such as a pentagram, whose turns all agree but add up to two).
  //
  // The turns are taken between consecutive edges whose projection onto the plane is longer than their ends'
  // rounding. An edge within rounding of a point (in the plane) has no direction there, and its two turns are
  // rounding noise: the turn that counts is the one between its neighbours, which dropping it joins into one (the
  // sum stays a multiple of 2 pi). Testing every vertex's own two edges instead let a reflex turn hide behind such
  // an edge: a denorm_min edge along the normal between (16, 0) and (4, 0.5) in a clockwise pentagon
  // (fuzz_polygon_projected_double c42d6431..., a biased sample 0.016 rad outside), and a reflex corner of 90
  // degrees at the origin of the pentagon (-1, 0) (0, -1) (0.5, 0) (0, 2) (0, 0) in the plane x = 0, behind an edge
  // along x and two edges 1e-307 long (fuzz_polygon_solid_angle_double 641e4492..., a clipped sample 0.26 rad
  // outside; issue 7). Dropping such an edge also lets the turning sum of a polygon wound twice count two
  // revolutions where the edge's own turns, underflowed to 0, made it one (fuzz_polygon_solid_angle_double
  // b6ebf498..., test APolygonWoundTwiceWithASubnormalEdgeIsNotSimple).
  // Each edge is scaled by a power of two (edge_in_plane) before its length in the plane and its turns are taken:
  // unscaled, the squares in the length of an edge shorter than sqrt(denorm_min) underflowed to 0, so a real edge
  // 1e15 times longer than its rounding was dropped, and the reflex turn of a notch made of such edges went unseen
  // (test AReflexNotchOfEdgesShorterThanTheSquareRootOf...); and the cross and dot products of two kept edges 1e-160
  // long would underflow to 0, a turn of atan2(0, 0) = 0. Scaling changes neither a turn's angle nor the tests
  // below, whose bounds are scaled alike.
  //
  // A reflex turn is forgiven only as far as the input's rounding explains it. Vertex k is known to
  // delta_k = vertex_rounding |V_k|_inf, so an edge from V_j to V_j+1 is off by at most delta_j + delta_j+1, and
  // s = nhat . (a x b) of two edges a, b by |a| err_b + |b| err_a + err_a err_b. Not the planarity tolerance: that
  // one is a length, so an edge shorter than it could point anywhere, and every kernel's inside test (the planes
  // through x and each edge, polygon_inward_planes) would then cut a slice off the light that its sampler still
  // samples: pdf() 0 at its own samples (fuzz_ltc_double a8864f7e..., d3e18c5b..., 1e7d91f3...: edges of length
  // 7.5e-9 to 8 reflex by up to 0.8 rad in lights of diameter 16 to 1e14; issue 7).
  auto rounding = [&](int k) { return vertex_rounding * p.vertices[(k + p.count) % p.count].cwiseAbs().maxCoeff(); };
  // A spike: b runs back along a, the computed turn atan2(s, c) is within rounding of +-pi, and which of the two it
  // is depends on the sign of a rounding error in s (the kernels' edge planes use the exact differences a and b,
  // and s from kahan_cross is accurate to a few eps |a| |b|). The turning sum can still come to one revolution and
  // the reflex turn next to it can be within the vertices' rounding (an edge an ulp long), so the spike passed as
  // convex, and the plane through the reversed edge faced outwards in every kernel (found by
  // fuzz_polygon_projected_double da03856c... and fuzz_polygon_solid_angle_double 3091f781..., issue 7). No convex
  // polygon turns by pi (an interior angle of 0). Not measured against the vertices' rounding: a short edge after a
  // long one is exact (Sterbenz) and turns by what it says (a collinear vertex an ulp before a corner turns by
  // 3 pi / 4 with |s| = |c| = eps), and M^-1 P under an ill-conditioned M (ltc.h) is a legitimate needle whose ends
  // turn by pi - 1e-8. Tested at every vertex, short edges included (the kernels have a plane for each edge), and
  // again between the kept edges below.
  auto is_spike = [&](const Vec3<T>& a, const Vec3<T>& b, T s) {
    return a.dot(b) < T(0) && std::abs(s) <= T(8) * eps * a.norm() * b.norm();
  };
  for (int i = 0; i < p.count; ++i) {
    const Vec3<T> a = p.vertices[i] - p.vertices[(i + p.count - 1) % p.count];
    const Vec3<T> b = p.vertices[(i + 1) % p.count] - p.vertices[i];
    if (is_spike(a, b, nhat.dot(kahan_cross<T>(a, b))))
      return fail(NoSample::kInvalidGeometry, "polygon is not convex (a spike)");
  }
  struct KeptEdge {
    Vec3<T> e;  // V_j+1 - V_j in the plane, scaled by a power of two (edge_in_plane)
    T err;      // its rounding bound delta_j + delta_j+1, scaled alike
  };
  std::array<KeptEdge, kMaxPolygonVertices> kept;
  int nk = 0;
  for (int i = 0; i < p.count; ++i) {
    const Vec3<T> e = p.vertices[(i + 1) % p.count] - p.vertices[i];
    KeptEdge k;
    if (edge_in_plane<T>(e, rounding(i) + rounding(i + 1), nhat, k.e, k.err)) kept[nk++] = k;
  }
  if (nk < 3) return fail(NoSample::kZeroSize, "fewer than three edges longer than their rounding");
  T turning = 0;
  for (int i = 0; i < nk; ++i) {
    const KeptEdge &ka = kept[(i + nk - 1) % nk], &kb = kept[i];
    const T s = nhat.dot(kahan_cross<T>(ka.e, kb.e)), c = ka.e.dot(kb.e);
    const T s_err = ka.e.norm() * kb.err + kb.e.norm() * ka.err + ka.err * kb.err;
    if (s < -s_err) return fail(NoSample::kInvalidGeometry, "polygon is not convex");
    if (is_spike(ka.e, kb.e, s)) return fail(NoSample::kInvalidGeometry, "polygon is not convex (a spike)");
    turning += std::atan2(s, c);
  }
  if (std::abs(turning - kTwoPi<T>) > T(0.5)) return fail(NoSample::kInvalidGeometry, "polygon is not simple");
  if (message) message->clear();
  return NoSample::kNone;
}

// ---- Clipping to the upper hemisphere (Peters 2021 Sec. 3.1; Supplement A.1 is not available to us) --------

// A polygon of directions in a local frame (vertices need not be unit length; only their directions count).
template <class T> struct LocalPolygon {
  std::array<Vec3<T>, kMaxClippedVertices> v;
  int count = 0;
  LocalPolygon() { v.fill(Vec3<T>::Zero()); }
};

// Sutherland-Hodgman against the half-space z >= 0, derived here: keep vertices with z >= 0 and insert the
// crossing point where an edge changes side. The crossing of p (z > 0) and q (z < 0) is
// (q_z p - p_z q) / (q_z - p_z): the denominator adds two magnitudes (no cancellation), and we set its z to
// exactly 0. It lies on the segment, so it lies on the edge's great circle: edge normals of clipped edges are
// parallel to the originals. A convex polygon gains at most one vertex.
template <class T> LocalPolygon<T> clip_to_upper_hemisphere(const LocalPolygon<T>& in) {
  LocalPolygon<T> out;
  for (int i = 0; i < in.count; ++i) {
    const Vec3<T>& p = in.v[i];
    const Vec3<T>& q = in.v[(i + 1) % in.count];
    const bool p_in = p.z() >= T(0), q_in = q.z() >= T(0);
    if (p_in && out.count < kMaxClippedVertices) out.v[out.count++] = p;
    if (p_in != q_in && p.z() != T(0) && q.z() != T(0) && out.count < kMaxClippedVertices) {
      const T d = q.z() - p.z();
      Vec3<T> x = (q.z() * p - p.z() * q) / d;
      x.z() = T(0);
      out.v[out.count++] = x;
    }
  }
  return out;
}

// ---- The polygon seen from a shading point (shared by all polygon kernels) ----------------------------------

template <class T> struct PolygonView {
  NoSample reason = NoSample::kNone;
  Vec3<T> normal = Vec3<T>::Zero();                              // unit shading normal
  Frame<T> frame = Frame<T>::from_z(Vec3<T>(T(0), T(0), T(1)));  // z: the shading normal
  Vec3<T> plane_normal = Vec3<T>::Zero();                        // unit right-hand normal of the vertex order
  T plane_distance = 0;   // plane_normal . (V_0 - x): > 0 when the vertex order winds positively seen from x
  LocalPolygon<T> local;  // V_k - x in the shading frame (flattened, see lift), not clipped
  // lift[k] = plane_normal . (V_k - x) - plane_distance: how far vertex k is off the light's plane. Where the light
  // is non-planar beyond the offsets' rounding, `local` holds the vertices moved onto the plane, V_k - x - lift[k]
  // plane_normal, and polygon_inward_planes the flattened light's planes (flattened = true; make_polygon_view).
  std::array<T, kMaxPolygonVertices> lift{};
  bool flattened = false;
  T vertex_rounding = kPolygonVertexRounding<T>;  // as passed to check_polygon (make_polygon_view)
  bool valid() const { return reason == NoSample::kNone; }
};

// Validates the input and expresses the polygon in the shading frame. Edge-on (x in the plane of the light,
// which includes x on the light) gives kEdgeOn.
// vertex_rounding: as for check_polygon.
template <class T>
PolygonView<T> make_polygon_view(const PolygonLightGeometry<T>& g, T vertex_rounding = kPolygonVertexRounding<T>) {
  PolygonView<T> v;
  v.vertex_rounding = vertex_rounding;
  if (!all_finite(g.shading.position)) return v.reason = NoSample::kNonFinite, v;
  if (!all_finite(g.shading.normal)) return v.reason = NoSample::kNonFinite, v;
  if (const NoSample r = check_polygon(g.light, nullptr, vertex_rounding); r != NoSample::kNone) return v.reason = r, v;
  if (!normalize_normal(g.shading.normal, v.normal)) return v.reason = NoSample::kBadNormal, v;
  v.frame = Frame<T>::from_z(v.normal);
  v.plane_normal = safe_normalized(polygon_area_vector(g.light));
  // Signed distance from the centroid (averaging reduces the rounding of a single vertex).
  Vec3<T> centroid = Vec3<T>::Zero();
  for (int i = 0; i < g.light.count; ++i) centroid += g.light.vertices[i] - g.shading.position;
  centroid /= T(g.light.count);
  if (!all_finite(centroid)) return v.reason = NoSample::kNonFinite, v;
  v.plane_distance = v.plane_normal.dot(centroid);
  // Edge-on up to rounding: the offsets V_k - x and the normal carry a few eps of relative error, so
  // plane_distance is known only to a few eps max_k |V_k - x|_inf. Below 8 times that, which side of the light
  // x is on is not determined, and the kernels' samples and densities could pick different sides (found by
  // fuzz_polygon_projected_double / fuzz_polygon_solid_angle_double with x on the light, issue 7).
  T reach = 0;
  for (int i = 0; i < g.light.count; ++i)
    reach = std::max(reach, Vec3<T>(g.light.vertices[i] - g.shading.position).cwiseAbs().maxCoeff());
  if (!(std::abs(v.plane_distance) > T(8) * std::numeric_limits<T>::epsilon() * reach))
    return v.reason = NoSample::kEdgeOn, v;
  // Within the light's non-planarity: check_polygon accepts vertices up to its planarity tolerance off the plane,
  // and a shading point closer to the plane than that can have vertices on both sides. The light seen from it is
  // then no convex spherical polygon (its edges wind both ways), and which side x is on is undetermined, as
  // above: edge-on. A vertex counts as on the other side only beyond its own rounding (vertex_rounding
  // |V_k|_inf, which for ltc.h's M^-1 P includes cond(M)) plus the offset's 8 eps reach. (Found by
  // fuzz_polygon_projected_double fe6b6d80... and fuzz_polygon_solid_angle_double 5c7b9846..., issue 7.)
  for (int i = 0; i < g.light.count; ++i) {
    const T side = v.plane_normal.dot(Vec3<T>(g.light.vertices[i] - g.shading.position));
    const T err =
        vertex_rounding * g.light.vertices[i].cwiseAbs().maxCoeff() + T(8) * std::numeric_limits<T>::epsilon() * reach;
    if ((v.plane_distance > T(0) ? -side : side) > err) return v.reason = NoSample::kEdgeOn, v;
  }
  // check_polygon accepts a light off its plane by up to its planarity tolerance (input rounding of its coordinates,
  // and more), and seen from x closer to the plane than a few times that, the cone of the vertices is no convex
  // spherical polygon: each vertex moves within the plane by up to its distance from x times lift / h as seen
  // from x (gnomonically), so the turns of the light seen from x no longer all agree, and the projected-solid-
  // angle kernels' sector formulas break (found by fuzz_ltc_double 5692ae35: M = I, a light of size 30 at
  // y = 3.2e9, off its plane by 6.4e-8 from the coordinates' rounding, x 24 away and 2.6e-7 off the plane:
  // A_Sigma 1.4e-15 instead of the flattened light's 1.4e-11, issue 7). Such a light is accepted as the planar
  // light it is near, so the kernels see that one: beyond the offsets' own rounding (8 eps reach, below which
  // flattening would only add noise), the vertices are moved onto the plane of the area vector through the
  // centroid, along its normal. Flattening is invisible to check_polygon's convexity test (its turns are taken
  // along the normal) and moves each vertex by at most the non-planarity.
  const T eps = std::numeric_limits<T>::epsilon();
  T off = 0;
  for (int i = 0; i < g.light.count; ++i) {
    v.lift[i] = v.plane_normal.dot(Vec3<T>(g.light.vertices[i] - g.shading.position)) - v.plane_distance;
    off = std::max(off, std::abs(v.lift[i]));
  }
  v.flattened = off > T(8) * eps * reach;
  if (!v.flattened) v.lift.fill(T(0));
  v.local.count = g.light.count;
  for (int i = 0; i < g.light.count; ++i) {
    Vec3<T> l = v.frame.to_local(Vec3<T>(g.light.vertices[i] - g.shading.position - v.lift[i] * v.plane_normal));
    // A vertex within rounding of the horizon is on it: to_local's dot product carries an error of a few
    // eps |V - x|. Left as it is, its clip point lies a rounding error away, and the edge between them has a
    // normal made of rounding noise (found by fuzz_polygon_projected_double: samples up to 0.58 rad outside a
    // polygon touching the horizon, issue 7).
    if (std::abs(l.z()) <= T(8) * std::numeric_limits<T>::epsilon() * l.cwiseAbs().maxCoeff()) l.z() = T(0);
    // Likewise a vertex within rounding of the zenith is at it: its azimuth is rounding noise, and a subnormal xy
    // (x a subnormal away from the vertex's vertical) has too few digits for the sectors' cross products (found
    // by fuzz_ltc_double 156dd709...: M = I, x = (-4.9e-324, 0, 0) under the vertex (0, -4, 0) with n = -y:
    // A_Sigma 0.912 instead of 0.680, issue 7). polygon_projected.h then takes the central case.
    const T xy_rounding = T(8) * std::numeric_limits<T>::epsilon() * l.cwiseAbs().maxCoeff();
    if (std::abs(l.x()) <= xy_rounding && std::abs(l.y()) <= xy_rounding) l.x() = l.y() = T(0);
    v.local.v[i] = l;
  }
  return v;
}

// The planes through x and the light's own edges, (V_j - x) x (V_{j+1} - V_j), oriented inwards (by the side of
// the light x is on): a direction w is in the light's cone iff every plane's dot product with w is >= 0. From the
// world coordinates, not from rounded directions V - x: V_{j+1} - V_j of nearby vertices is exact (Sterbenz), so
// a short edge keeps its direction (polygon_projected.h, ltc.h). Each edge is taken in the light's plane, scaled
// by a power of two (edge_in_plane): e_j - (n . e_j) n. Of a flattened light (PolygonView::lift) that is the
// flattened edge, and the vertex is V_j - x - lift_j n (the lifts differ by n . e_j). Of a light planar up to
// rounding, an edge a few denorm_min long along the normal (a vertex off the plane by its rounding) made the plane
// through x and that edge cut the light in two, and the subnormal grid turned a plane of an edge denorm_min long
// by 0.08 rad: pdf() 0 at the sampler's directions 0.01 rad inside (fuzz_polygon_projected_double a5885e87...;
// issue 7). An edge that is a point in the plane up to its ends' rounding (edge_in_plane false, as check_polygon
// drops it from its turns) has no direction and bounds nothing: it takes the plane of the edge before it, so the
// planes are those of the edges check_polygon found convex. Returns the number of planes, g.light.count.
template <class T> int polygon_inward_planes(const PolygonLightGeometry<T>& g, const PolygonView<T>& pv, Vec3<T>* out) {
  const int n = g.light.count;
  const T orient = pv.plane_distance < T(0) ? T(-1) : T(1);
  const Vec3<T>& nh = pv.plane_normal;
  auto rounding = [&](int k) { return pv.vertex_rounding * g.light.vertices[k % n].cwiseAbs().maxCoeff(); };
  std::array<bool, kMaxPolygonVertices> has_direction{};
  int last = -1;
  for (int j = 0; j < n; ++j) {
    const Vec3<T> edge = g.light.vertices[(j + 1) % n] - g.light.vertices[j];
    Vec3<T> e;
    T err;
    has_direction[j] = edge_in_plane<T>(edge, rounding(j) + rounding(j + 1), nh, e, err);
    if (has_direction[j]) last = j;
    out[j] = orient * kahan_cross(Vec3<T>(g.light.vertices[j] - g.shading.position - pv.lift[j] * nh), e);
  }
  for (int j = 0, prev = last; j < n && last >= 0; ++j) {
    if (has_direction[j])
      prev = j;
    else
      out[j] = out[prev];
  }
  return n;
}

// ---- Bounding caps ---------------------------------------------------------------------------------------

// A small cap containing the convex spherical polygon spanned by the given directions (a cap of half-angle
// below 90 degrees is convex, so containing the vertices suffices). The axis starts at the normalised mean
// and is refined by a few steps of Badoiu-Clarkson (move towards the farthest vertex by a shrinking step),
// keeping the best; the radius is measured by chord length so that tiny caps keep their precision. A relative
// slack of 64 eps covers the rounding of the vertices' normalisation.
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

// ---- Independent references (long double) ---------------------------------------------------------------
//
// These share no code with the kernels beyond the PolygonLight type: their own clipping, their own frames.

// The polygon as directions from x in a frame whose z axis is the unit normal n, clipped to z >= 0 by
// parametric intersection (a different formula from clip_to_upper_hemisphere).
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
    const Vec3<L>& b = loc[(i + 1) % m];
    // A polygon that is convex in T up to rounding may cross the horizon more than twice in long double; the
    // output has room for kMaxClippedVertices, and a longer result is no convex clipped polygon: 0 (found by
    // fuzz_ltc_double 34d22625...: ASan stack-buffer-overflow here, issue 7).
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

// Projected solid angle (the cosine-weighted solid angle, integral of max(0, n.w) dw) of the polygon seen from
// the shading point, by Lambert's formula for polygons: (1/2) sum_j gamma_j (n . m_j), where gamma_j is the
// angle subtended by edge j and m_j the unit normal of the plane through x and edge j, oriented inwards.
inline long double reference_projected_solid_angle(const PolygonLightGeometry<long double>& g) {
  using L = long double;
  Vec3<L> c[kMaxClippedVertices];
  const int k = reference_clipped_local(g, c);
  if (k < 3) return 0;
  L sum = 0;
  for (int j = 0; j < k; ++j) {
    const Vec3<L> a = c[j].normalized(), b = c[(j + 1) % k].normalized();
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
        (g.light.vertices[i] - g.shading.position).cross(g.light.vertices[(i + 1) % n] - g.shading.position);
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
