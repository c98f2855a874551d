// Sphere-light kernels (catalogue.h's SphereKernels) and their named configurations.
#include <string_view>

#include "catalogue/random_geometries.h"
#include "warpcheck/catalogue.h"
#include "warpcheck/validation/registry.h"

namespace warpcheck::validation {
namespace {

struct SphereConfig {
  const char* name;
  const char* description;
  SphereLightGeometry<Real> g;
};

SphereLightGeometry<Real> geom(Vec3L x, Vec3L n, Vec3L c, Real r) {
  return {ShadingPoint<Real>{x, n}, SphereLight<Real>{c, r}};
}

template <class T> SphereLightGeometry<T> cast(const SphereLightGeometry<Real>& g) {
  return {ShadingPoint<T>{g.shading.position.cast<T>(), g.shading.normal.cast<T>()},
          SphereLight<T>{g.light.center.cast<T>(), T(g.light.radius)}};
}

// Solid angle of the cone, 2 pi (1 - sqrt(d^2 - r^2) / d), from the raw long double geometry: a different
// formula from the kernel's r^2 / (d^2 (1 + cos)).
Real reference_solid_angle(const SphereLightGeometry<Real>& g) {
  const Real d = (g.light.center - g.shading.position).norm(), r = g.light.radius;
  return kTwoPi<Real> * (1 - std::sqrt(d * d - r * r) / d);
}

// Area of the visible cap by Archimedes: 2 pi r h with cap height h = r - r^2 / d.
Real reference_visible_area(const SphereLightGeometry<Real>& g) {
  const Real d = (g.light.center - g.shading.position).norm(), r = g.light.radius;
  return kTwoPi<Real> * r * (r - r * r / d);
}

const SphereConfig kConfigs[] = {
    {"near", "unit sphere 1.65 away, half-angle 37 deg, tilted normal",
     geom(Vec3L(0, 0, 0), Vec3L(0.2L, -0.1L, 1), Vec3L(0.3L, 0.2L, 1.6L), 1)},
    {"far", "radius 0.5 at distance 50 (half-angle 0.57 deg)",
     geom(Vec3L(1, 1, 0), Vec3L(0, 0, 1), Vec3L(4, -3, 50), 0.5L)},
    {"grazing", "centre 6.8 deg above the horizon, half-angle 5.7 deg",
     geom(Vec3L(0, 0, 0), Vec3L(0, 0, 1), Vec3L(10, 0, 1.2L), 1)},
    {"tiny", "radius 1e-2 at distance 5 (half-angle 2e-3 rad)",
     geom(Vec3L(0, 0, 0), Vec3L(0, 0, 1), Vec3L(3, 0, 4), 1e-2L)},
    {"near-touching", "unit sphere 1e-3 above the shading point (half-angle 87 deg)",
     geom(Vec3L(0, 0, 0), Vec3L(0, 0, 1), Vec3L(0, 0, 1.001L), 1)},
    {"partly-below-horizon", "centre 8.5 deg above the horizon, half-angle 29 deg",
     geom(Vec3L(0, 0, 0), Vec3L(0, 0, 1), Vec3L(2, 0, 0.3L), 1)},
    {"below-horizon", "entirely below the horizon: no sample",
     geom(Vec3L(0, 0, 0), Vec3L(0, 0, 1), Vec3L(0, 1, -3), 1)},
};

// Why the float visible-area sampler fails (measured at 1e7 samples, seed 1: `warpcheck validate --kernel
// sphere-visible-area --scalar float`): near: pdf-integral 3.1e-4, chi2 p = 0, pdf(direction) = 0 for some sampled
// directions; far: pdf-integral 5.7e-4. Its density dist^2 / (A cos_light) has cos_light = sqrt(disc) / r with
// disc = r^2 - |f - (f.w) w|^2, whose absolute rounding error is ~eps |f|^2 in float: within that band of the
// silhouette the float pdf is wrong by 100% and the sampler can land outside it. The band carries mass
// ~sqrt(eps |f|^2 / r^2) of a density ~1/sqrt(disc) (sqrt(FLT_EPSILON) = 3.5e-4): the measured errors. No
// reformulation removes it in float (the silhouette is defined by that difference); a renderer that needs it
// evaluates disc in double. Double and long double pass.
constexpr const char* kVisibleAreaFloat =
    "float visible-area sampling: the density ~1/cos_light is wrong by O(1) within ~eps|f|^2 of the silhouette "
    "(disc = r^2 - |f_perp|^2 cancels), a band of mass ~sqrt(FLT_EPSILON) = 3.5e-4; measured pdf-integral 3.1e-4 "
    "(near) to 5.7e-4 (far) at 1e7 samples; see validation/catalogue/sphere.cpp";

// The normalisation check of each sphere kernel: what its normaliser measures, and the independent reference.
struct SphereKernelCheck {
  std::string_view kernel;
  const char* what;
  Real (*reference)(const SphereLightGeometry<Real>&);
  const char* float_limitation;  // Case::known_limitation of the float cases
};
constexpr SphereKernelCheck kChecks[] = {
    {"sphere-solid-angle", "cone solid angle", reference_solid_angle, ""},
    {"sphere-visible-area", "visible cap area", reference_visible_area, kVisibleAreaFloat},
};
constexpr const SphereKernelCheck* check_of(std::string_view kernel) {
  for (const SphereKernelCheck& c : kChecks)
    if (c.kernel == kernel) return &c;
  return nullptr;
}

// The visible-area kernel's normaliser, read off a sample: pdf = dist^2 / (cos_light A), so
// A = dist^2 / (cos_light pdf), with dist and cos_light recomputed from the sampled direction.
template <template <class> class K, class T> Real normaliser_from_a_sample(const SphereLightGeometry<Real>& g) {
  // The sample (direction and pdf) in T; the geometry of the ray in long double.
  const Sample s = to_sample(K<T>::sample(K<T>::view(cast<T>(g)), Vec2<T>(T(0.37L), T(0.61L))));
  const Vec3L f = g.shading.position - g.light.center;
  const Real b = f.dot(s.direction), disc = g.light.radius * g.light.radius - (f - b * s.direction).squaredNorm();
  const Real t = -b - std::sqrt(disc), cos_light = std::sqrt(disc) / g.light.radius;
  return t * t / (cos_light * s.pdf);
}

// The kernel's side of the check: its normaliser, or for a kernel whose density never forms one (visible area)
// the normaliser its pdf implies at a sample.
template <template <class> class K, class T> Normalization normalization(const SphereConfig& c) {
  Normalization n;
  n.what = check_of(K<T>::name)->what;
  if constexpr (requires(const typename K<T>::View& v) { K<T>::normaliser(v); })
    n.kernel = [g = cast<T>(c.g)] { return Real(K<T>::normaliser(K<T>::view(g))); };
  else
    n.kernel = [g = c.g] { return normaliser_from_a_sample<K, T>(g); };
  n.reference = check_of(K<T>::name)->reference(c.g);
  return n;
}

template <template <class> class K, class T> void add_case(Registry& r, const SphereConfig& c) {
  Case k;
  const bool valid = make_sphere_view(c.g).valid();
  k.known_limitation = valid && std::is_same_v<T, float> ? check_of(K<T>::name)->float_limitation : "";
  k.kernel = K<T>::name;
  k.scalar = scalar_name<T>();
  k.config = c.name;
  k.description = c.description;
  k.make = [c, valid] {
    SamplerUnderTest s = bind_kernel<K<T>, K<Real>>(c.name, cast<T>(c.g), c.g);
    s.expect_no_sample = !valid;
    if (valid) s.normalizations.push_back(normalization<K, T>(c));
    if constexpr (std::is_same_v<T, float>) {
      // Twice the largest deterministic statistic of either float kernel's valid configurations outside its
      // known limitation, rounded up: solid angle 6.7e-7 (pdf-integral, near-touching: 1 - cos(theta_max) from
      // r / d = 0.999), measured with `warpcheck validate --kernel 'sphere-*' --scalar float` (1e7 samples, seed 1).
      s.tolerance = 2e-6L;
      s.tolerance_note = "float: twice the measured largest error, 6.7e-7 (pdf-integral, near-touching)";
    }
    return s;
  };
  r.add(std::move(k));
}

}  // namespace

std::vector<Case> sphere_geometry_cases(const char* name, const char* description, const SphereLightGeometry<Real>& g) {
  Registry r;
  const SphereConfig c{name, description, g};
  SphereKernels::for_each([&]<template <class> class K>() {
    add_case<K, double>(r, c);
    add_case<K, Real>(r, c);
  });
  return r.cases();
}

void register_sphere_kernels(Registry& r) {
  for (const SphereConfig& c : kConfigs)
    SphereKernels::for_each([&]<template <class> class K>() {
      static_assert(check_of(K<Real>::name), "a sphere kernel without its entry in kChecks");
      add_case<K, float>(r, c);
      add_case<K, double>(r, c);
      add_case<K, Real>(r, c);
    });
}

}  // namespace warpcheck::validation
