// Densities with known integrals over the battery's chi-square grid, for the quadrature tests, and the closed-form
// azimuth slab masses of the registry's LTC lobes.
#pragma once

#include <cmath>
#include <vector>

#include "catalogue/sptd_samplers.h"
#include "warpcheck/validation/battery.h"

namespace warpcheck::validation {

inline const Cap<Real> kBounding{Vec3L(0, 0, 1), Real(0.3)};  // half-angle 45.6 deg, the chi-square grid's cap

// Uniform density on a second cap C2 (axis tilted by beta in the xz plane, half-angle alpha) that lies inside the
// bounding cap and whose edge cuts the grid's bins obliquely: the hardest case for bin quadrature, a jump along
// a curve.
struct TiltedCap {
  Real beta = Real(0.25), alpha = Real(0.3);
  Vec3L axis() const { return Vec3L(std::sin(beta), 0, std::cos(beta)); }
  Real density() const { return 1 / (kTwoPi<Real> * (1 - std::cos(alpha))); }
  Real pdf(const Vec3L& w) const { return w.dot(axis()) >= std::cos(alpha) ? density() : 0; }
  // Exact mass of the bin t in [t0, t1], phi in [phi0, phi1] of kBounding, computed independently of
  // integrate_cap_region: for fixed phi the set of polar angles theta inside C2 solves
  //   sin(theta) cos(phi) sin(beta) + cos(theta) cos(beta) = R cos(theta - delta) >= cos(alpha)
  // in closed form, |theta - delta| <= acos(cos(alpha) / R); the mass of that theta-interval is the
  // difference of cosines. Only the smooth outer integral over phi is numerical (with a 4000-panel budget
  // and a 1e-15 tolerance, far beyond the accuracy being tested).
  Real bin_mass(Real t0, Real t1, Real phi0, Real phi1) const {
    const Real th0 = std::acos(1 - t0 * kBounding.one_minus_cos), th1 = std::acos(1 - t1 * kBounding.one_minus_cos);
    auto inner = [&](Real phi) -> Real {
      const Real A = std::cos(phi) * std::sin(beta), B = std::cos(beta);
      const Real R = std::hypot(A, B), delta = std::atan2(A, B);
      if (std::cos(alpha) > R) return 0;
      const Real gamma = std::acos(std::cos(alpha) / R);
      const Real lo = std::max(th0, delta - gamma), hi = std::min(th1, delta + gamma);
      return hi > lo ? (std::cos(lo) - std::cos(hi)) * density() : Real(0);
    };
    return integrate_adaptive(inner, phi0, phi1, 1e-15L, 1e-20L, 4000).value;
  }
};

// The part of a polygon (vertices seen from the origin) on the side v . n >= 0 of a plane through the origin:
// Sutherland-Hodgman, one plane.
inline std::vector<Vec3L> clip_by_plane(const std::vector<Vec3L>& p, const Vec3L& n) {
  std::vector<Vec3L> out;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3L &a = p[i], &b = p[(i + 1) % p.size()];
    const Real da = a.dot(n), db = b.dot(n);
    if (da >= 0) out.push_back(a);
    if ((da >= 0) != (db >= 0)) out.push_back(a + da / (da - db) * (b - a));
  }
  return out;
}

// The LTC's mass in each azimuth slab [2 pi x_k, 2 pi x_k+1] of the cap: the wedge's sides are planes through the
// cap's axis, so the polygon cut by the wedge is a polygon, and its mass is Lambert's formula on M^-1 of it over
// Lambert's formula on M^-1 P (Eq. 10), in long double, independent of the kernel and of any quadrature.
inline std::vector<Real> ltc_azimuth_slab_masses(const LtcPolygonGeometry<Real>& g, const Cap<Real>& cap,
                                                 const std::vector<Real>& xa) {
  const Vec3L o = g.polygon.shading.position;
  std::vector<Vec3L> p;
  for (int i = 0; i < g.polygon.light.count; ++i) p.push_back(g.polygon.light.vertices[i] - o);
  const Real whole = ltc_reference_projected_solid_angle(g);
  const Frame<Real> f = Frame<Real>::from_z(cap.axis);
  auto side = [&](Real x) {  // the normal of the half-plane at azimuth 2 pi x, towards larger azimuths
    const Real phi = kTwoPi<Real> * x;
    return Vec3L(cap.axis.cross(std::cos(phi) * f.x + std::sin(phi) * f.y));
  };
  std::vector<Real> mass;
  for (std::size_t k = 0; k + 1 < xa.size(); ++k) {
    const std::vector<Vec3L> q = clip_by_plane(clip_by_plane(p, side(xa[k])), -side(xa[k + 1]));
    if (q.size() < 3) {
      mass.push_back(0);
      continue;
    }
    LtcPolygonGeometry<Real> part = g;
    part.polygon.light.count = int(q.size());
    for (std::size_t i = 0; i < q.size(); ++i) part.polygon.light.vertices[i] = q[i] + o;
    mass.push_back(ltc_reference_projected_solid_angle(part) / whole);
  }
  return mass;
}

}  // namespace warpcheck::validation
