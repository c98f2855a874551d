// warpcheck/sphere.h: sphere lights, sampled by solid angle and by visible area.
//
// Both kernels share one per-light view, SphereView (the cone the light subtends; Peters & Dachsbacher 2019 Sec. 3.7).
//
// Solid angle (Wang 1992 / Shirley 1996 Sec. 3.2.2, as retold by Schutte 2018): uniform in the cone of half-angle
// theta_max = asin(r / d), cos(theta) = 1 - u0 (1 - cos(theta_max)), phi = 2 pi u1, pdf = 1 / (2 pi (1 - cos)).
// The whole cone is sampled, also below the shading horizon; only a light entirely below it gives "no sample".
//
// Visible area: uniform on the visible cap (cos(alpha) >= r / d at the centre, area A = 2 pi r^2 (1 - r / d)), not
// the whole sphere, whose back is self-occluded. pdf(w) = dist^2 / (cos_light A) per solid angle, unbounded but
// integrable towards the silhouette.
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
  Vec3<T> normal = Vec3<T>::Zero();  // unit shading normal
  // z: the unit direction from the shading point to the centre
  Frame<T> frame = Frame<T>::from_z(Vec3<T>(T(0), T(0), T(1)));
  T distance = T(0);           // d = |c - x|
  T sin2_theta_max = T(0);     // (r / d)^2
  T one_minus_cos_max = T(0);  // 1 - cos(theta_max), computed without cancellation
  T cos_theta_max = T(0);

  bool valid() const { return reason == NoSample::kNone; }
  Cap<T> cap() const { return Cap<T>{frame.z, one_minus_cos_max}; }
};

template <class T> NoSample fill_sphere_view(const SphereLightGeometry<T>& g, SphereView<T>& v) {
  const Vec3<T>& x = g.shading.position;
  const Vec3<T>& c = g.light.center;
  const T r = g.light.radius;
  if (!all_finite(x) || !all_finite(c) || !all_finite(g.shading.normal) || !std::isfinite(r))
    return NoSample::kNonFinite;
  if (!normalize_normal(g.shading.normal, v.normal)) return NoSample::kBadNormal;
  if (r < T(0)) return NoSample::kNegativeSize;
  if (r == T(0)) return NoSample::kZeroSize;
  const Vec3<T> to_c = c - x;
  if (!all_finite(to_c)) return NoSample::kNonFinite;  // the difference overflowed
  const T d = stable_norm(to_c);
  if (!std::isfinite(d)) return NoSample::kNonFinite;
  if (d <= r) return NoSample::kInsideLight;
  v.distance = d;
  v.frame = Frame<T>::from_z(to_c / d);
  const T s = r / d;  // sin(theta_max) < 1
  v.sin2_theta_max = s * s;
  const T cos_max = std::sqrt(std::max(T(0), T(1) - v.sin2_theta_max));
  v.cos_theta_max = cos_max;
  // 1 - cos = sin^2 / (1 + cos): no cancellation for tiny cones.
  v.one_minus_cos_max = v.sin2_theta_max / (T(1) + cos_max);
  // The density 1 / (2 pi (1 - cos)) must be representable (r / d ~ 4e-155 in double overflows it).
  if (!(v.one_minus_cos_max > T(0)) || !has_finite_reciprocal(kTwoPi<T> * v.one_minus_cos_max))
    return NoSample::kTooSmall;
  // Entirely below the horizon: n.axis <= -sin(theta_max).
  if (v.normal.dot(v.frame.z) <= -s) return NoSample::kBelowHorizon;
  return NoSample::kNone;
}

template <class T> SphereView<T> make_sphere_view(const SphereLightGeometry<T>& g) {
  SphereView<T> v;  // filled in place: no copy of the view on return
  v.reason = fill_sphere_view(g, v);
  return v;
}

// ---- Solid-angle sampling (Shirley 1996, Sec. 3.2.2) ----

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
  T sin_phi, cos_phi;
  sine_cosine(phi, sin_phi, cos_phi);
  s.direction = renormalized(v.frame.to_world(Vec3<T>(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)));
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

// ---- Visible-cap area sampling ----

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
  T sin_phi, cos_phi;
  sine_cosine(phi, sin_phi, cos_phi);
  const Vec3<T> local(r * sin_a * cos_phi, r * sin_a * sin_phi, d - r * cos_a);
  const T dist = stable_norm(local);
  // |p - x|^2 = r^2 + d^2 - 2 d r cos_a <= d^2 - r^2 on the visible cap, so dist is finite for a valid view; tested
  // all the same before local / dist, which a non-finite norm would turn into NaN.
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

// Density of the visible-cap area sampler: dist^2 / (cos_light A) at the ray's nearest hit. With q = d sin(theta) / r,
// cos_light = sqrt((1 - q)(1 + q)) and t = d cos(theta) - r cos_light, all scaled by r (no overflow for huge d / r).
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
  static constexpr const char* description = "uniform in the light's cone, Shirley 1996";
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
