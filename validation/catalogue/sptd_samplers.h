// The battery's samplers for the SPTD family's kernels (catalogue.h's SptdKernels), shared by the registrar
// (sptd.cpp) and the tests: each kernel bound with its long double self as the reference warp, and its
// normalisation check.
#pragma once

#include <string>
#include <vector>

#include "warpcheck/catalogue.h"
#include "warpcheck/validation/sampler.h"

namespace warpcheck::validation {

// An SPTD over a cap (K: SptdUniformCap or SptdCosineCap) in scalar T. Normalisation check: the kernel's integral
// of D over C (Eq. 10, through g(C)) against `reference_integral`, an independently computed value the caller
// supplies (quadrature of Eq. 8 over C); skipped when reference_integral <= 0.
template <template <class> class K, class T> SamplerUnderTest sptd_cap_sampler(const std::string& config,
                                                                               const SptdCapGeometry<Real>& g,
                                                                               Real reference_integral = 0) {
  SamplerUnderTest s = bind_kernel<K<T>, K<Real>>(config, g.template cast<T>(), g);
  if (reference_integral > 0) {
    Normalization n;
    n.what = "integral of D over C (Eq. 10 vs quadrature of Eq. 8)";
    n.kernel = [gt = g.template cast<T>()] { return Real(K<T>::normaliser(K<T>::view(gt))); };
    n.reference = reference_integral;
    s.normalizations.push_back(n);
  }
  return s;
}

// The normalisation of Eq. 10 computed independently: Lambert's formula (polygon.h's long double reference)
// on M^-1 P, with M^-1 from Eigen in long double and the shading frame's coordinates.
inline Real ltc_reference_projected_solid_angle(const LtcPolygonGeometry<Real>& g) {
  const Vec3L n = g.polygon.shading.normal.normalized();
  const Frame<Real> f = Frame<Real>::from_z(n);
  const Eigen::Matrix<Real, 3, 3> mi = g.m.inverse();
  PolygonLightGeometry<Real> t;
  t.shading.position = Vec3L::Zero();
  t.shading.normal = Vec3L(0, 0, 1);
  t.light.count = g.polygon.light.count;
  for (int i = 0; i < g.polygon.light.count; ++i)
    t.light.vertices[i] = mi * f.to_local(Vec3L(g.polygon.light.vertices[i] - g.polygon.shading.position));
  return reference_projected_solid_angle(t);
}

// The registry's LTC configurations (sptd.cpp): a polygon and M, from the identity to near-singular.
struct LtcConfig {
  const char* name;
  const char* description;
  LtcPolygonGeometry<Real> g;
};
std::vector<LtcConfig> ltc_configs();

// LTC sampling of a polygon in scalar T (M in the shading frame Frame<T>::from_z(normal)), with the normalisation
// check of Eq. 10 against ltc_reference_projected_solid_angle.
template <class T> SamplerUnderTest ltc_sampler(const std::string& config, const LtcPolygonGeometry<Real>& g) {
  SamplerUnderTest s = bind_kernel<PolygonLtc<T>, PolygonLtc<Real>>(config, g.template cast<T>(), g);
  s.expect_no_sample = !PolygonLtc<Real>::sample(PolygonLtc<Real>::view(g), Vec2<Real>(0.5L, 0.5L)).valid();
  if (s.expect_no_sample) return s;
  Normalization n;
  n.what = "projected solid angle of M^-1 P (Eq. 10; Lambert)";
  n.kernel = [gt = g.template cast<T>()] { return Real(PolygonLtc<T>::normaliser(PolygonLtc<T>::view(gt))); };
  n.reference = ltc_reference_projected_solid_angle(g);
  s.normalizations.push_back(n);
  return s;
}

}  // namespace warpcheck::validation
