// warpcheck/validation/projected_cap_configs.h: the named configurations of the projected spherical cap kernels
// (Peters & Dachsbacher 2019) and the helpers their registrar, tests and claims tool share.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "warpcheck/projected_cap.h"
#include "warpcheck/validation/sampler.h"

namespace warpcheck::validation {

struct ProjectedCapConfig {
  const char* name;
  const char* description;
  SphereLightGeometry<Real> g;
};

// Cases 1-4, their boundaries, grazing, near-touching, tiny and huge lights (projected_cap.cpp).
std::vector<ProjectedCapConfig> projected_cap_configs();

// Projected solid angle of the light by long double adaptive quadrature of max(0, n.w) over its cap:
// independent of the kernel's A_E + A_D code path.
Real reference_projected_solid_angle(const SphereLightGeometry<Real>& g, Real tol = 1e-12L);

// The kernel's kinks in u0 (its catalogue trait: the Case-2 threshold tau, the quintic's left-area pi/2) as
// intervals (u, u), where the quadratures over primary sample space split.
template <CutDiskInverse M> std::vector<std::pair<Real, Real>> projected_cap_bands(const SphereLightGeometry<Real>& g);
// Integral of max(0, n.w)^power (power 1: the projected solid angle) over the light's cap, by rings around the
// cap's axis in closed form and long double Gauss-Kronrod across the rings.
Real cap_cosine_moment(const SphereLightGeometry<Real>& g, int power);

// Moments of the Lambertian irradiance estimator X = cos / pdf (unit radiance) of projected-cap kernel K (a
// catalogue trait, e.g. SphereProjectedCap<double>), over primary sample space by nested tanh-sinh quadrature in
// long double (deterministic): m1 = E[X], m1_in = E[X; the ray hits the light], m2 = E[X^2]. (make_case instantiates it
// for the registry's kernels; the quintic and exact kernels in double are instantiated for the tests and tools.)
struct LambertianMoments {
  Real m1 = 0, m1_in = 0, m2 = 0;
};
template <class K> LambertianMoments projected_cap_lambertian_moments(const SphereLightGeometry<Real>& g,
                                                                      Real tol = 1e-10L, bool mean_only = false);

// float's tolerance for a configuration: twice its measured float error (the largest deterministic battery
// statistic of the float kernels, see projected_cap.cpp), rounded up to one digit, at least 1e-6.
Real projected_cap_float_tolerance(const std::string& config);

}  // namespace warpcheck::validation
