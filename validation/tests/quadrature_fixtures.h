// Densities with known integrals over the battery's chi-square grid, for the quadrature tests.
#pragma once

#include <cmath>

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

}  // namespace warpcheck::validation
