// warpcheck/sphere.h: sphere lights, sampled by solid angle and by visible area.
//
// Both kernels share one per-light precomputation, SphereView (the cone of directions the light subtends), in
// the spirit of the per-light / per-sample split of Peters & Dachsbacher 2019, Section 3.7.
//
// Solid-angle sampling follows Wang 1992 / Shirley 1996 Section 3.2.2 as retold by Schutte 2018: uniform in
// the cone of half-angle theta_max = asin(r / d) around the direction to the centre,
//   cos(theta) = 1 - u0 (1 - cos(theta_max)),  phi = 2 pi u1,  pdf = 1 / (2 pi (1 - cos(theta_max))).
// The whole cone is sampled, also where part of it is below the shading horizon (those samples carry a zero
// cosine for the caller); only a light entirely below the horizon gives "no sample".
//
// Area sampling samples uniformly the *visible cap* of the sphere (the part of its surface seen from the
// shading point: angle alpha at the centre from the direction to the point with cos(alpha) >= r / d, area
// A = 2 pi r^2 (1 - r / d)), not the whole sphere: a whole-sphere sampler wastes half its samples on the
// self-occluded back and maps two points to each direction. The density is reported per solid angle,
//   pdf(w) = dist^2 / (cos_light A),
// which grows without bound towards the silhouette (cos_light -> 0); it is integrable there.
#pragma once

#include "warpcheck/core.h"

namespace warpcheck {

template <class T> struct SphereLight {
  Vec3<T> center = Vec3<T>::Zero();
  T radius = T(1);
};

template <class T> struct SphereLightGeometry {
  ShadingPoint<T> shading;
  SphereLight<T> light;
};

// Per-light precomputation shared by both sphere kernels.
template <class T> struct SphereView {
  NoSample reason = NoSample::kNone;
  Vec3<T> normal;              // unit shading normal
  Frame<T> frame;              // z: unit direction from the shading point to the centre
  T distance = T(0);           // d = |c - x|
  T sin2_theta_max = T(0);     // (r / d)^2
  T one_minus_cos_max = T(0);  // 1 - cos(theta_max), computed without cancellation
  T cos_theta_max = T(0);

  bool valid() const { return reason == NoSample::kNone; }
  Cap<T> cap() const { return Cap<T>{frame.z, one_minus_cos_max}; }
};

template <class T> SphereView<T> make_sphere_view(const SphereLightGeometry<T>& g) {
  SphereView<T> v;
  const Vec3<T>& x = g.shading.position;
  const Vec3<T>& c = g.light.center;
  const T r = g.light.radius;
  if (!all_finite(x) || !all_finite(c) || !all_finite(g.shading.normal) || !std::isfinite(r))
    return v.reason = NoSample::kNonFinite, v;
  if (!normalize_normal(g.shading.normal, v.normal)) return v.reason = NoSample::kBadNormal, v;
  if (r < T(0)) return v.reason = NoSample::kNegativeSize, v;
  if (r == T(0)) return v.reason = NoSample::kZeroSize, v;
  const Vec3<T> to_c = c - x;
  if (!all_finite(to_c)) return v.reason = NoSample::kNonFinite, v;  // the difference overflowed
  const T d = to_c.stableNorm();
  if (!std::isfinite(d)) return v.reason = NoSample::kNonFinite, v;
  if (d <= r) return v.reason = NoSample::kInsideLight, v;
  v.distance = d;
  v.frame = Frame<T>::from_z(to_c / d);
  const T s = r / d;  // sin(theta_max) < 1
  v.sin2_theta_max = s * s;
  const T cos_max = std::sqrt(std::max(T(0), T(1) - v.sin2_theta_max));
  v.cos_theta_max = cos_max;
  // 1 - cos = sin^2 / (1 + cos): no cancellation for tiny cones.
  v.one_minus_cos_max = v.sin2_theta_max / (T(1) + cos_max);
  // The density 1 / (2 pi (1 - cos)) must be representable too: r / d ~ 4e-155 in double gives a subnormal
  // 1 - cos ~ 7e-310 whose density overflows to Inf (found by fuzz_sphere_double, issue 7).
  if (!(v.one_minus_cos_max > T(0)) || !std::isfinite(T(1) / (kTwoPi<T> * v.one_minus_cos_max)))
    return v.reason = NoSample::kTooSmall, v;
  // Entirely below the horizon: the angle between the normal and the axis is at least pi/2 + theta_max,
  // i.e. n.axis <= -sin(theta_max).
  if (v.normal.dot(v.frame.z) <= -s) return v.reason = NoSample::kBelowHorizon, v;
  return v;
}

// ---- Solid-angle sampling (Shirley 1996, Sec. 3.2.2) --------------------------------------------------

template <class T> T sphere_solid_angle_density(const SphereView<T>& v) {
  return T(1) / (kTwoPi<T> * v.one_minus_cos_max);
}

template <class T> DirectionSample<T> sample_sphere_solid_angle(const SphereView<T>& v, const Vec2<T>& u) {
  if (!v.valid()) return DirectionSample<T>::none(v.reason);
  // 1 - cos(theta) = u0 (1 - cos(theta_max)); sin(theta) from (1 - cos)(1 + cos) keeps tiny cones accurate.
  const T one_minus_cos = u[0] * v.one_minus_cos_max;
  const T cos_theta = T(1) - one_minus_cos;
  const T sin_theta = std::sqrt(std::max(T(0), one_minus_cos * (T(2) - one_minus_cos)));
  const T phi = kTwoPi<T> * u[1];
  DirectionSample<T> s;
  s.direction =
      renormalized(v.frame.to_world(Vec3<T>(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta)));
  s.pdf = sphere_solid_angle_density(v);
  return s;
}

template <class T> DirectionSample<T> sample_sphere_solid_angle(const SphereLightGeometry<T>& g, const Vec2<T>& u) {
  return sample_sphere_solid_angle(make_sphere_view(g), u);
}

template <class T> T pdf_sphere_solid_angle(const SphereView<T>& v, const Vec3<T>& w) {
  if (!v.valid() || !all_finite(w)) return T(0);
  return v.cap().contains(w) ? sphere_solid_angle_density(v) : T(0);
}

template <class T> T pdf_sphere_solid_angle(const SphereLightGeometry<T>& g, const Vec3<T>& w) {
  return pdf_sphere_solid_angle(make_sphere_view(g), w);
}

// ---- Visible-cap area sampling -------------------------------------------------------------------------

template <class T>
DirectionSample<T> sample_sphere_visible_area(const SphereView<T>& v, const SphereLight<T>& light, const Vec2<T>& u) {
  if (!v.valid()) return DirectionSample<T>::none(v.reason);
  const T r = light.radius, d = v.distance;
  const T s = r / d;
  // Uniform on the visible cap: 1 - cos(alpha) = u0 (1 - r/d), alpha measured at the centre from -axis.
  const T one_minus_cos_a = u[0] * (T(1) - s);
  const T cos_a = T(1) - one_minus_cos_a;
  const T sin_a = std::sqrt(std::max(T(0), one_minus_cos_a * (T(2) - one_minus_cos_a)));
  const T phi = kTwoPi<T> * u[1];
  // Point on the sphere relative to the shading point, in the view frame (z towards the centre):
  // p - x = d z + r m, m = (sin_a cos phi, sin_a sin phi, -cos_a).
  const Vec3<T> local(r * sin_a * std::cos(phi), r * sin_a * std::sin(phi), d - r * cos_a);
  const T dist = local.stableNorm();
  // |p - x| beyond the largest finite T (a light of radius ~1e308): the density dist^3 / ... is not representable
  // either, so there is no sample; checked before local / dist, which would be 0 and its renormalisation a
  // division by zero (found by fuzz_sphere_double cf221826, UBSan, issue 7; the sample was already discarded, as its
  // pdf was Inf).
  if (!std::isfinite(dist)) return DirectionSample<T>::none(NoSample::kTooSmall);
  // cos_light * dist = -m.(p - x) = d cos_a - r = (d - r)(1 - u0): exact algebra, no cancellation.
  const T cos_light_times_dist = (d - r) * (T(1) - u[0]);
  if (!(cos_light_times_dist > T(0))) return DirectionSample<T>::none(NoSample::kOnSilhouette);
  // pdf = dist^3 / (cos_light dist * 2 pi r^2 (1 - r/d)), grouped so that no intermediate overflows.
  const T dist_over_r = dist / r;
  DirectionSample<T> out;
  out.direction = renormalized(v.frame.to_world(local / dist));
  out.pdf = dist_over_r * dist_over_r * (dist / cos_light_times_dist) / (kTwoPi<T> * (T(1) - s));
  if (!std::isfinite(out.pdf) || !(out.pdf > T(0))) return DirectionSample<T>::none(NoSample::kTooSmall);
  return out;
}

template <class T> DirectionSample<T> sample_sphere_visible_area(const SphereLightGeometry<T>& g, const Vec2<T>& u) {
  return sample_sphere_visible_area(make_sphere_view(g), g.light, u);
}

// Density of the visible-cap area sampler in direction w: intersect the ray with the sphere (nearest hit),
// then dist^2 / (cos_light A). In the view frame (centre at (0, 0, d)), with theta the angle of w from the
// axis, the ray passes the centre at distance d sin(theta); q = d sin(theta) / r <= 1 inside the cap,
// cos_light = sqrt(1 - q^2) = sqrt((1 - q)(1 + q)) and the nearest hit is at t = d cos(theta) - r cos_light.
// Everything is scaled by r so that huge d / r does not overflow.
template <class T> T pdf_sphere_visible_area(const SphereView<T>& v, const SphereLight<T>& light, const Vec3<T>& w) {
  if (!v.valid() || !all_finite(w)) return T(0);
  if (!v.cap().contains(w)) return T(0);
  const T r = light.radius, d = v.distance;
  const Vec3<T> wl = v.frame.to_local(w);
  const T d_over_r = d / r;
  const T q = d_over_r * std::hypot(wl.x(), wl.y());
  const T cos_light = std::sqrt(std::max(T(0), (T(1) - q) * (T(1) + q)));
  if (!(cos_light > T(0)) || !(wl.z() > T(0))) return T(0);
  const T t_over_r = d_over_r * wl.z() - cos_light;
  const T pdf = t_over_r * t_over_r / (cos_light * kTwoPi<T> * (T(1) - T(1) / d_over_r));
  return std::isfinite(pdf) ? pdf : T(0);
}

template <class T> T pdf_sphere_visible_area(const SphereLightGeometry<T>& g, const Vec3<T>& w) {
  return pdf_sphere_visible_area(make_sphere_view(g), g.light, w);
}

// ---- Catalogue traits (warpcheck/catalogue.h) ----------------------------------------------------------------

template <class T> struct SphereSolidAngle {
  static constexpr const char* name = "sphere-solid-angle";
  static constexpr const char* description = "uniform in the light's cone (Shirley 1996)";
  using Scalar = T;
  using Geometry = SphereLightGeometry<T>;
  using View = SphereView<T>;
  static View view(const Geometry& g) { return make_sphere_view(g); }
  static DirectionSample<T> sample(const View& v, const Vec2<T>& u) { return sample_sphere_solid_angle(v, u); }
  static T pdf(const View& v, const Vec3<T>& w) { return pdf_sphere_solid_angle(v, w); }
  static Cap<T> bounding_cap(const Geometry& g) { return make_sphere_view(g).cap(); }
  static T normaliser(const View& v) { return T(1) / sphere_solid_angle_density(v); }  // the cone's solid angle
};

template <class T> struct SphereVisibleArea {
  static constexpr const char* name = "sphere-visible-area";
  static constexpr const char* description = "uniform on the visible cap of the sphere";
  using Scalar = T;
  using Geometry = SphereLightGeometry<T>;
  struct View {
    SphereView<T> sphere;
    SphereLight<T> light;
  };
  static View view(const Geometry& g) { return {make_sphere_view(g), g.light}; }
  static DirectionSample<T> sample(const View& v, const Vec2<T>& u) {
    return sample_sphere_visible_area(v.sphere, v.light, u);
  }
  static T pdf(const View& v, const Vec3<T>& w) { return pdf_sphere_visible_area(v.sphere, v.light, w); }
  static Cap<T> bounding_cap(const Geometry& g) { return make_sphere_view(g).cap(); }
};

}  // namespace warpcheck
