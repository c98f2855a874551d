// Sphere-light kernels and their named configurations.
#include "warpcheck/sphere.h"
#include "warpcheck/validation/registry.h"

namespace warpcheck::validation {
namespace {

template <class T> struct SphereSolidAngle {
  using Scalar = T;
  using Geometry = SphereLightGeometry<T>;
  static DirectionSample<T> sample(const Geometry& g, const Vec2<T>& u) { return sample_sphere_solid_angle(g, u); }
  static T pdf(const Geometry& g, const Vec3<T>& w) { return pdf_sphere_solid_angle(g, w); }
  static Cap<T> bounding_cap(const Geometry& g) { return make_sphere_view(g).cap(); }
};

template <class T> struct SphereVisibleArea {
  using Scalar = T;
  using Geometry = SphereLightGeometry<T>;
  static DirectionSample<T> sample(const Geometry& g, const Vec2<T>& u) { return sample_sphere_visible_area(g, u); }
  static T pdf(const Geometry& g, const Vec3<T>& w) { return pdf_sphere_visible_area(g, w); }
  static Cap<T> bounding_cap(const Geometry& g) { return make_sphere_view(g).cap(); }
};

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
const char* const kVisibleAreaFloat =
    "float visible-area sampling: the density ~1/cos_light is wrong by O(1) within ~eps|f|^2 of the silhouette "
    "(disc = r^2 - |f_perp|^2 cancels), a band of mass ~sqrt(FLT_EPSILON) = 3.5e-4; measured pdf-integral 3.1e-4 "
    "(near) to 5.7e-4 (far) at 1e7 samples; see registry_sphere.cpp";

template <template <class> class K, class T> void add_case(Registry& r, const char* kernel, const SphereConfig& c,
                                                           Normalization (*norm)(const SphereConfig&),
                                                           const char* known_limitation = "") {
  Case k;
  k.known_limitation = make_sphere_view(c.g).valid() ? known_limitation : "";  // no-sample cases pass
  k.kernel = kernel;
  k.scalar = scalar_name<T>();
  k.config = c.name;
  k.description = c.description;
  k.make = [c, kernel, norm] {
    SamplerUnderTest s = bind_kernel<K<T>, K<Real>>(kernel, c.name, cast<T>(c.g), c.g);
    s.expect_no_sample = !make_sphere_view(c.g).valid();
    if (!s.expect_no_sample) s.normalizations.push_back(norm(c));
    if constexpr (std::is_same_v<T, float>) {
      // Measured, not derived: at 1e7 samples (seed 1) the float solid-angle kernel's pdf integrates to 1 - 5.2e-6 on
      // "tiny" (cap half-angle 2e-3 rad, 1 - cos = 2e-6, a few float ulps of 1); the others stay below 1e-6. The
      // battery's quadrature itself runs at 16 FLT_EPSILON = 1.9e-6 for float samplers (battery.cpp).
      s.tolerance = 1e-5L;
      s.tolerance_note = "float: measured pdf-integral error up to 5.2e-6 (tiny cap, 1 - cos(theta_max) = 2e-6)";
    }
    return s;
  };
  r.add(std::move(k));
}

template <class T> Normalization solid_angle_norm(const SphereConfig& c) {
  Normalization n;
  n.what = "cone solid angle";
  n.kernel = [g = cast<T>(c.g)] { return Real(1 / sphere_solid_angle_density(make_sphere_view(g))); };
  n.reference = reference_solid_angle(c.g);
  return n;
}

// The visible-area kernel's normaliser, read off a sample: pdf = dist^2 / (cos_light A), so
// A = dist^2 / (cos_light pdf), with dist and cos_light recomputed from the sampled direction.
template <class T> Normalization visible_area_norm(const SphereConfig& c) {
  Normalization n;
  n.what = "visible cap area";
  n.kernel = [g = c.g, gt = cast<T>(c.g)] {
    // The sample (direction and pdf) in T; the geometry of the ray in long double.
    const auto st = sample_sphere_visible_area(gt, Vec2<T>(T(0.37L), T(0.61L)));
    const Sample s = to_sample(st);
    const Vec3L f = g.shading.position - g.light.center;
    const Real b = f.dot(s.direction), disc = g.light.radius * g.light.radius - (f - b * s.direction).squaredNorm();
    const Real t = -b - std::sqrt(disc), cos_light = std::sqrt(disc) / g.light.radius;
    return t * t / (cos_light * s.pdf);
  };
  n.reference = reference_visible_area(c.g);
  return n;
}

}  // namespace

void register_sphere_kernels(Registry& r) {
  for (const SphereConfig& c : kConfigs) {
    add_case<SphereSolidAngle, float>(r, "sphere-solid-angle", c, solid_angle_norm<float>);
    add_case<SphereSolidAngle, double>(r, "sphere-solid-angle", c, solid_angle_norm<double>);
    add_case<SphereSolidAngle, Real>(r, "sphere-solid-angle", c, solid_angle_norm<Real>);
    add_case<SphereVisibleArea, float>(r, "sphere-visible-area", c, visible_area_norm<float>, kVisibleAreaFloat);
    add_case<SphereVisibleArea, double>(r, "sphere-visible-area", c, visible_area_norm<double>);
    add_case<SphereVisibleArea, Real>(r, "sphere-visible-area", c, visible_area_norm<Real>);
  }
}

}  // namespace warpcheck::validation
