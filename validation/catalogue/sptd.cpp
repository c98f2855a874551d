// SPTD kernels (Dupuy, Heitz & Belcour 2017) and LTC polygon sampling (Peters 2021 Sec. 4.1), catalogue.h's
// SptdKernels, with their named configurations: pivots up to |r_p| = 0.999, all three shapes of the clamped
// cosine's projected cap region, the pivot phase function alone and jointly with a sphere light (configurations
// of the uniform kernel), and LTC transforms from the identity to near-singular.
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string_view>

#include "catalogue/random_geometries.h"
#include "catalogue/sptd_samplers.h"
#include "warpcheck/validation/registry.h"

namespace warpcheck::validation {
namespace {

const Vec3L kZ(0, 0, 1);

struct SptdConfig {
  const char* kernel;
  const char* name;
  const char* description;
  SptdCapGeometry<Real> g;
};

SptdCapGeometry<Real> sptd(Vec3L pivot, SptdBase base, Vec3L base_axis, Cap<Real> cap) {
  SptdCapGeometry<Real> g;
  g.sptd.pivot = pivot;
  g.sptd.base = base;
  g.sptd.base_axis = base_axis;
  g.cap = cap;
  return g;
}
Cap<Real> cap(Vec3L axis, Real omc) { return Cap<Real>{axis.normalized(), omc}; }

std::vector<SptdConfig> sptd_configs() {
  const SptdBase U = SptdBase::kUniform, C = SptdBase::kClampedCosine;
  const Vec3L diag = Vec3L(0.3L, -0.5L, 0.8L).normalized();
  SphereLightGeometry<Real> light;
  light.shading.position = Vec3L(0, 0, 0);
  light.light = SphereLight<Real>{Vec3L(2, 0.5L, 1), 0.6L};
  return {
      {"sptd-uniform-cap", "centre", "pivot at the centre (uniform over the cap), cap half-angle 46 deg",
       sptd(Vec3L(0, 0, 0), U, kZ, cap(Vec3L(0.3L, 0, 1), 0.3L))},
      {"sptd-uniform-cap", "centre-small-cap",
       "pivot at the centre, cap half-angle 20 deg: an image below 30 deg, sampled relative to the pivot",
       sptd(Vec3L(0, 0, 0), U, kZ, cap(Vec3L(0.3L, 0, 1), 0.06L))},
      {"sptd-uniform-cap", "pivot-0.3", "|r_p| = 0.3 off the cap's axis, cap half-angle 46 deg",
       sptd(Vec3L(0.2L, 0.1L, 0.2L).normalized() * 0.3L, U, kZ, cap(Vec3L(0.3L, 0, 1), 0.3L))},
      {"sptd-uniform-cap", "pivot-0.99", "|r_p| = 0.99 towards the cap's edge, cap half-angle 37 deg",
       sptd(Vec3L(0, 0.6L, 0.8L) * 0.99L, U, kZ, cap(Vec3L(0, 0.5L, 1), 0.2L))},
      {"sptd-uniform-cap", "pivot-0.999-inside", "|r_p| = 0.999, pivot direction inside the cap (peaked density)",
       sptd(diag * 0.999L, U, kZ, cap(diag + Vec3L(0.1L, 0, 0), 0.1L))},
      {"sptd-uniform-cap", "pivot-0.999-away", "|r_p| = 0.999, cap on the far side (image cap of 1e-7 sr)",
       sptd(diag * 0.999L, U, kZ, cap(-diag + Vec3L(0, 0.2L, 0), 0.5L))},
      {"sptd-uniform-cap", "large-image", "|r_p| = 0.9, small cap beside the pivot: image larger than a hemisphere",
       sptd(kZ * 0.9L, U, kZ, cap(Vec3L(0.15L, 0, 1), 0.005L))},
      {"sptd-cosine-cap", "ellipse", "clamped cosine, image cap entirely above the horizon",
       sptd(Vec3L(0.1L, 0, 0.4L), C, -kZ, cap(Vec3L(0.2L, 0, 1), 0.2L))},
      {"sptd-cosine-cap", "crossing", "clamped cosine, image cap crossing the horizon, axis above it",
       sptd(Vec3L(0.5L, 0, 0.3L), C, kZ, cap(Vec3L(1, 0, -0.3L), 0.6L))},
      {"sptd-cosine-cap", "crescent", "clamped cosine, image cap crossing the horizon, axis below it",
       sptd(Vec3L(0.2L, 0, 0.3L), C, -kZ, cap(Vec3L(1, 0, 0.2L), 0.3L))},
      {"sptd-cosine-cap", "pivot-0.99", "clamped cosine, |r_p| = 0.99, cap half-angle 60 deg",
       sptd(diag * 0.99L, C, Vec3L(0.2L, 0.1L, 1).normalized(), cap(diag + Vec3L(0.3L, 0.2L, 0), 0.5L))},
      {"sptd-uniform-cap", "phase-g-0.5", "pivot phase function (Eq. 25), g_p = 0.5, whole sphere",
       pivot_phase_geometry<Real>(diag, 0.5L)},
      {"sptd-uniform-cap", "phase-g-minus-0.7", "pivot phase function, g_p = -0.7 (back scattering), whole sphere",
       pivot_phase_geometry<Real>(diag, -0.7L)},
      {"sptd-uniform-cap", "phase-g-0.99", "pivot phase function, g_p = 0.99, whole sphere",
       pivot_phase_geometry<Real>(diag, 0.99L)},
      {"sptd-uniform-cap", "phase-sphere-light-hg-0.9",
       "pivot phase function fitted to HG g = 0.9 (Eq. 27), sampled jointly with a sphere light (Sec. 6.2)",
       pivot_phase_sphere_light_geometry<Real>(Vec3L(1, 0.2L, 0.4L).normalized(), hg_to_pivot(0.9L), light)},
      {"sptd-uniform-cap", "phase-sphere-light-back-0.6", "g_p = -0.6, light behind the propagation direction",
       pivot_phase_sphere_light_geometry<Real>(Vec3L(-1, 0, -0.3L).normalized(), -0.6L, light)},
  };
}

// A priori rounding tolerance in float: the pivot transformation amplifies relative errors by up to
// (1 + |r_p|) / (1 - |r_p|) (the ratio of the Jacobian's extremes, Eq. 4, to the power 1/2); 64 eps times that.
// Double and long double keep the battery's 1e-6. The round trip's tolerance (in u) is the same bound: the inverse
// sees a float direction whose rounding the pivot transformation amplified alike.
template <class T> void set_tolerance(SamplerUnderTest& s, Real amplification, const char* note) {
  if constexpr (std::is_same_v<T, float>) {
    s.tolerance = std::max(1e-6L, 64 * Real(std::numeric_limits<float>::epsilon()) * amplification);
    s.inverse_tolerance = s.tolerance;
    s.tolerance_note = note;
  }
}

// The integral of D over C (Eq. 10's left side) by the battery's quadrature of Eq. 8, independent of the
// cap transform (Eqs. 6-7) and of the closed-form cap integrals.
Real quadrature_of_eq8(const SptdCapGeometry<Real>& g) {
  Sptd<Real> d = g.sptd;
  if (d.base == SptdBase::kClampedCosine) d.base_axis.normalize();
  return integrate_cap_region([d](const Vec3L& w) { return sptd_density(d, w); }, g.cap, 0, 1, 0, kTwoPi<Real>, 1e-10L);
}

template <template <class> class K, class T> void add_sptd(Registry& r, const SptdConfig& c) {
  Case k;
  k.kernel = c.kernel;
  k.scalar = scalar_name<T>();
  k.config = c.name;
  k.description = c.description;
  k.make = [c] {
    const bool whole_sphere = c.g.cap.one_minus_cos >= 2;
    SamplerUnderTest s = sptd_cap_sampler<K, T>(c.name, c.g, whole_sphere ? Real(1) : quadrature_of_eq8(c.g));
    s.expect_no_sample = !K<Real>::view(c.g).valid();
    const Real rp = c.g.sptd.pivot.norm();
    set_tolerance<T>(s, (1 + rp) / (1 - rp), "float rounding: 64 eps (1 + |r_p|) / (1 - |r_p|)");
    return s;
  };
  r.add(std::move(k));
}

// ---- LTC -----------------------------------------------------------------------------------------------------

PolygonLightGeometry<Real> decentral_rectangle() {
  PolygonLightGeometry<Real> g;
  g.shading.position = Vec3L(0, 0, 0);
  g.shading.normal = Vec3L(0.1L, -0.2L, 1);
  g.light = PolygonLight<Real>{Vec3L(0.2L, -0.6L, 1), Vec3L(1.4L, -0.6L, 1), Vec3L(1.4L, 0.2L, 1.2L),
                               Vec3L(0.2L, 0.2L, 1.2L)};
  return g;
}
PolygonLightGeometry<Real> reversed(PolygonLightGeometry<Real> g) {  // the same light, vertices in the other order
  std::reverse(g.light.vertices.begin(), g.light.vertices.begin() + g.light.count);
  return g;
}
PolygonLightGeometry<Real> straddling_rectangle() {  // crosses the shading horizon
  PolygonLightGeometry<Real> g;
  g.shading.position = Vec3L(0, 0, 0);
  g.shading.normal = kZ;
  g.light =
      PolygonLight<Real>{Vec3L(1, -0.5L, -0.3L), Vec3L(1, 0.5L, -0.3L), Vec3L(1, 0.5L, 0.9L), Vec3L(1, -0.5L, 0.9L)};
  return g;
}
Mat3<Real> mat(Real a, Real b, Real c, Real d, Real e, Real f, Real g, Real h, Real i) {
  Mat3<Real> m;
  m << a, b, c, d, e, f, g, h, i;
  return m;
}

}  // namespace

std::vector<LtcConfig> ltc_configs() {
  // "random": drawn once from test_ltc_mis.cpp's random_m (seed 5), rounded to 4 digits.
  const Mat3<Real> random = mat(0.4115L, -0.1846L, -0.4395L, 0.0704L, 0.8373L, -0.1615L, -0.3702L, 0.0751L, 1);
  return {
      {"identity",
       "M = I (projected solid angle sampling), decentral rectangle",
       {decentral_rectangle(), Mat3<Real>::Identity()}},
      {"random", "a random LTC-like M (condition number ~3), decentral rectangle", {decentral_rectangle(), random}},
      {"reversed",
       "the random M, decentral rectangle with its vertices in the other order (Sec. 3.1's flipped y axis)",
       {reversed(decentral_rectangle()), random}},
      {"ill-conditioned",
       "narrow lobe tilted towards the light: |M| = 1.2e-5, condition number ~300",
       {decentral_rectangle(), mat(0.004L, 0, 0.5L, 0, 0.003L, -0.1L, 0, 0, 1)}},
      {"near-singular",
       "|M| = 1e-8, condition number ~1e4 (a near-mirror lobe)",
       {decentral_rectangle(), mat(1e-4L, 0, 0.6L, 0, 1e-4L, -0.15L, 0, 0, 1)}},
      {"straddling-horizon",
       "rectangle crossing the horizon, sheared M: clipped in the transformed space",
       {straddling_rectangle(), mat(0.5L, 0, 0.3L, 0, 0.7L, 0, 0.2L, 0, 1)}},
      {"lobe-away",
       "lobe tilted away from the light: samples also below the shading horizon",
       {straddling_rectangle(), mat(0.3L, 0, -0.6L, 0, 0.3L, 0, 0, 0, 1)}},
  };
}

namespace {

Real condition_number(const Mat3<Real>& m) {
  const Eigen::JacobiSVD<Mat3<Real>> svd(m);
  return svd.singularValues()(0) / svd.singularValues()(2);
}

template <class T> void add_ltc(Registry& r, const LtcConfig& c) {
  Case k;
  k.kernel = PolygonLtc<T>::name;
  k.scalar = scalar_name<T>();
  k.config = c.name;
  k.description = c.description;
  k.make = [c] {
    SamplerUnderTest s = ltc_sampler<T>(c.name, c.g);
    // Float: rounding of M^-1 and of the transformed vertices is amplified by ~cond(M); 64 eps cond(M), stated
    // a priori (not tuned).
    const Real kappa = condition_number(c.g.m);
    set_tolerance<T>(s, kappa, "float rounding: 64 eps cond(M)");
    return s;
  };
  r.add(std::move(k));
}

}  // namespace

std::vector<Case> sptd_geometry_cases(const char* name, const char* description, const SptdCapGeometry<Real>& g) {
  Registry r;
  SptdKernels::for_each([&]<template <class> class K>() {
    if constexpr (std::is_same_v<typename K<Real>::Geometry, SptdCapGeometry<Real>>) {
      if (K<Real>::base != g.sptd.base) return;
      const SptdConfig c{K<Real>::name, name, description, g};
      add_sptd<K, double>(r, c);
      add_sptd<K, Real>(r, c);
    }
  });
  return r.cases();
}

std::vector<Case> ltc_geometry_cases(const char* name, const char* description, const LtcPolygonGeometry<Real>& g) {
  Registry r;
  const LtcConfig c{name, description, g};
  add_ltc<double>(r, c);
  add_ltc<Real>(r, c);
  return r.cases();
}

// Each SPTD configuration names its kernel (one of the cap kernels, with that kernel's base); LTC has its own.
void register_sptd_kernels(Registry& r) {
  const std::vector<SptdConfig> configs = sptd_configs();
  std::size_t registered = 0;
  SptdKernels::for_each([&]<template <class> class K>() {
    if constexpr (std::is_same_v<typename K<Real>::Geometry, SptdCapGeometry<Real>>) {
      for (const SptdConfig& c : configs) {
        if (c.kernel != std::string_view(K<Real>::name) || c.g.sptd.base != K<Real>::base) continue;
        add_sptd<K, float>(r, c);
        add_sptd<K, double>(r, c);
        add_sptd<K, Real>(r, c);
        ++registered;
      }
    } else {
      static_assert(std::is_same_v<K<Real>, PolygonLtc<Real>>, "an SPTD-family kernel without configurations");
      for (const LtcConfig& c : ltc_configs()) {
        add_ltc<float>(r, c);
        add_ltc<double>(r, c);
        add_ltc<Real>(r, c);
      }
    }
  });
  if (registered != configs.size()) throw std::logic_error("an SPTD configuration of no SPTD cap kernel or base");
}

}  // namespace warpcheck::validation
