// warpcheck/spherical_rectangle.h: the baseline of Urena, Fajardo & King 2013, "An Area-Preserving
// Parametrization for Spherical Rectangles", as published (their Sec. 3-4, written from the formulas).
//
// Rectangle with corner s and orthogonal edges e_x, e_y (from a 4-vertex PolygonLight: s = V0,
// e_x = V1 - V0, e_y = V3 - V0). In the rectangle's frame (x, y along the edges, z = x cross y flipped so that
// the rectangle lies at z0 < 0):
//   corners v00, v01, v10, v11; inner normals n_i of the four planes through the origin and the edges;
//   gamma_i = acos(-n_i.n_{i+1}); S = gamma_0 + gamma_1 + gamma_2 + gamma_3 - 2 pi (the solid angle);
//   sampling: au = xi_0 S + k, k = 2 pi - gamma_2 - gamma_3; fu = (cos(au) b0 - b1) / sin(au);
//   cu = sign(fu) / sqrt(fu^2 + b0^2); xu = -cu z0 / sqrt(1 - cu^2) clamped to [x0, x1];
//   d = sqrt(xu^2 + z0^2); h0 = y0 / sqrt(d^2 + y0^2); h1 = y1 / sqrt(d^2 + y1^2);
//   hv = h0 + xi_1 (h1 - h0); yv = hv d / sqrt(1 - hv^2) (or the end y0 or y1 on hv's side when hv^2 >= 1 - eps).
// pdf = 1 / S inside the rectangle's cone. Like Arvo 1995, S cancels for small rectangles (kept on purpose).
// Two departures: a non-finite result becomes "no sample" (house rule: never NaN), and where hv^2 >= 1 - eps the
// published listing takes y1 whatever hv's sign, which puts the samples of xi_1 ~ 0 on a strip reaching far to -y
// (y0 / d beyond ~3e3 in float, ~7e7 in double) at its other end; here they take y0.
#pragma once

#include "warpcheck/polygon.h"
#include "warpcheck/polygon_solid_angle.h"  // the trait's bounding cap

namespace warpcheck {

template <class T> struct SphericalRectangleView {
  NoSample reason = NoSample::kNone;
  Vec3<T> o = Vec3<T>::Zero(), x = Vec3<T>::Zero(), y = Vec3<T>::Zero(), z = Vec3<T>::Zero();  // shading point, frame
  T x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0;
  T b0 = 0, b1 = 0, k = 0, solid_angle = 0;
  std::array<Vec3<T>, 4> inward{};  // for the density's support test (world space)
  bool valid() const { return reason == NoSample::kNone; }
};

template <class T>
NoSample fill_spherical_rectangle_view(const PolygonLightGeometry<T>& g, SphericalRectangleView<T>& v) {
  const PolygonView<T> pv = make_polygon_view(g);
  if (!pv.valid()) return pv.reason;
  if (g.light.count != 4) return NoSample::kInvalidGeometry;
  const Vec3<T> s = g.light.vertices[0];
  const Vec3<T> ex = g.light.vertices[1] - s, ey = g.light.vertices[3] - s;
  const T exl = ex.norm(), eyl = ey.norm();
  // A rectangle: orthogonal edges and V2 = V0 + ex + ey (to the precision of the input).
  const T tol = T(64) * std::sqrt(std::numeric_limits<T>::epsilon());
  if (std::abs(ex.dot(ey)) > tol * exl * eyl || (g.light.vertices[2] - s - ex - ey).norm() > tol * (exl + eyl))
    return NoSample::kInvalidGeometry;
  bool above = false;
  for (int i = 0; i < 4; ++i) above = above || pv.local.v[i].z() > T(0);
  if (!above) return NoSample::kBelowHorizon;
  v.o = g.shading.position;
  v.x = ex / exl, v.y = ey / eyl, v.z = v.x.cross(v.y);
  const Vec3<T> d = s - v.o;
  v.z0 = d.dot(v.z);
  if (v.z0 > T(0)) v.z = -v.z, v.z0 = -v.z0;
  v.x0 = d.dot(v.x), v.y0 = d.dot(v.y);
  v.x1 = v.x0 + exl, v.y1 = v.y0 + eyl;
  const Vec3<T> v00(v.x0, v.y0, v.z0), v01(v.x0, v.y1, v.z0), v10(v.x1, v.y0, v.z0), v11(v.x1, v.y1, v.z0);
  const Vec3<T> n0 = v00.cross(v10).normalized(), n1 = v10.cross(v11).normalized();
  const Vec3<T> n2 = v11.cross(v01).normalized(), n3 = v01.cross(v00).normalized();
  auto clamped_acos = [](T c) { return std::acos(std::clamp(c, T(-1), T(1))); };
  const T g0 = clamped_acos(-n0.dot(n1)), g1 = clamped_acos(-n1.dot(n2));
  const T g2 = clamped_acos(-n2.dot(n3)), g3 = clamped_acos(-n3.dot(n0));
  v.b0 = n0.z(), v.b1 = n2.z();
  v.k = kTwoPi<T> - g2 - g3;
  v.solid_angle = g0 + g1 - v.k;
  if (!(v.solid_angle > T(0)) || !std::isfinite(v.solid_angle)) return NoSample::kTooSmall;
  // Support test in world space: inward normals of the rectangle's cone.
  std::array<Vec3<T>, 4> c;
  for (int i = 0; i < 4; ++i) c[i] = g.light.vertices[i] - g.shading.position;
  const T orient = pv.plane_distance > T(0) ? T(1) : T(-1);
  for (int i = 0; i < 4; ++i) v.inward[i] = orient * kahan_cross(c[i], c[(i + 1) % 4]);
  return NoSample::kNone;
}

template <class T> SphericalRectangleView<T> make_spherical_rectangle_view(const PolygonLightGeometry<T>& g) {
  SphericalRectangleView<T> v;  // filled in place: no copy of the view on return
  v.reason = fill_spherical_rectangle_view(g, v);
  return v;
}

template <class T>
DirectionSample<T> sample_spherical_rectangle(const SphericalRectangleView<T>& v, const Vec2<T>& xi) {
  if (!v.valid()) return DirectionSample<T>::none(v.reason);
  const T au = xi[0] * v.solid_angle + v.k;
  // sin(au) = 0 at the ends of the range: fu is +-infinite there (its limit; Urena et al. 2013 Sec. 4), without
  // dividing by zero.
  T sin_au, cos_au;
  sine_cosine(au, sin_au, cos_au);
  const T fu_num = cos_au * v.b0 - v.b1;
  const T fu = sin_au != T(0) ? fu_num / sin_au
                              : std::copysign(std::numeric_limits<T>::infinity(), fu_num) * std::copysign(T(1), sin_au);
  // The same for the other quotients below: a zero denominator takes the clamped limit instead of dividing.
  const T cu_den = std::sqrt(fu * fu + v.b0 * v.b0), cu_sign = fu > T(0) ? T(1) : T(-1);
  T cu = cu_den > T(0) ? cu_sign / cu_den : cu_sign;
  cu = std::clamp(cu, T(-1), T(1));
  const T xu_num = -(cu * v.z0), xu_den = std::sqrt(T(1) - cu * cu);
  T xu = xu_den > T(0) ? xu_num / xu_den : (xu_num < T(0) ? v.x0 : v.x1);
  xu = std::clamp(xu, v.x0, v.x1);
  const T d = std::sqrt(xu * xu + v.z0 * v.z0);
  auto sine_of = [d](T y) {  // y / sqrt(d^2 + y^2), 0 when both vanish
    const T r = std::sqrt(d * d + y * y);
    return r > T(0) ? y / r : T(0);
  };
  const T h0 = sine_of(v.y0), h1 = sine_of(v.y1);
  const T hv = h0 + xi[1] * (h1 - h0), hv2 = hv * hv;
  // Where |hv| rounds to 1, the quotient's limit: the end of [y0, y1] on hv's side.
  const T y_end = hv > T(0) ? v.y1 : v.y0;
  const T yv = hv2 < T(1) - std::numeric_limits<T>::epsilon() ? hv * d / std::sqrt(T(1) - hv2) : y_end;
  const Vec3<T> p = xu * v.x + yv * v.y + v.z0 * v.z;
  DirectionSample<T> out;
  if (!all_finite(p)) return DirectionSample<T>::none(NoSample::kNonFinite);
  out.direction = safe_normalized(p);
  if (out.direction.isZero()) return DirectionSample<T>::none(NoSample::kNonFinite);
  out.pdf = T(1) / v.solid_angle;
  return out;
}

template <class T> T pdf_spherical_rectangle(const SphericalRectangleView<T>& v, const Vec3<T>& w) {
  if (!v.valid() || !all_finite(w)) return T(0);
  for (const auto& n : v.inward)
    if (n.dot(w) < T(0)) return T(0);
  return T(1) / v.solid_angle;
}

template <class T> DirectionSample<T> sample_spherical_rectangle(const PolygonLightGeometry<T>& g, const Vec2<T>& xi) {
  return sample_spherical_rectangle(make_spherical_rectangle_view(g), xi);
}
template <class T> T pdf_spherical_rectangle(const PolygonLightGeometry<T>& g, const Vec3<T>& w) {
  return pdf_spherical_rectangle(make_spherical_rectangle_view(g), w);
}

// ---- Catalogue trait (warpcheck/catalogue.h) -----------------------------------------------------------------

template <class T> struct BaselineUrenaRectangle {
  static constexpr const char* name = "baseline-urena-rectangle";
  static constexpr const char* description = "spherical rectangle, Urena et al. 2013, as published";
  static constexpr bool rectangles_only = true;
  using Scalar = T;
  using Geometry = PolygonLightGeometry<T>;
  using View = SphericalRectangleView<T>;
  static View view(const Geometry& g) { return make_spherical_rectangle_view(g); }
  static DirectionSample<T> sample(const View& v, const Vec2<T>& u) { return sample_spherical_rectangle(v, u); }
  static T pdf(const View& v, const Vec3<T>& w) { return pdf_spherical_rectangle(v, w); }
  static Cap<T> bounding_cap(const Geometry& g) { return polygon_fan_bounding_cap<T, false>(g); }
  static T normaliser(const View& v) { return v.solid_angle; }
  // One smooth warp (Urena et al. 2013 Sec. 4): no kinks.
  static std::vector<Vec3<T>> boundary_planes(const Geometry& g) { return polygon_boundary_planes(g); }
};

}  // namespace warpcheck
