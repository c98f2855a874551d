// Boundary circles in a cap's frame (circles.h).
#include "battery/circles.h"

#include <algorithm>
#include <cmath>

namespace warpcheck::validation::battery {

std::vector<Circle> local_circles(const Boundary& b, const Frame<Real>& fr) {
  std::vector<Circle> out;
  for (const Vec3L& p : b.planes)
    if (p.norm() > 0) out.push_back({fr.to_local(p.normalized()), 0});
  for (const Cap<Real>& k : b.caps)
    if (k.axis.norm() > 0 && k.one_minus_cos > 0 && k.one_minus_cos < 2)
      out.push_back({fr.to_local(k.axis.normalized()), 1 - k.one_minus_cos});
  return out;
}

// On the line, m.w = m_z cos(theta) + (m_x c + m_y s) sin(theta) = rho cos(theta - delta) with
// delta = atan2(m_x c + m_y s, m_z): theta = delta +- acos(c_m / rho); a great circle once, at
// theta = atan2(-m_z, m_x c + m_y s) mod pi.
void line_crossing_angles(const std::vector<Circle>& circles, Real c, Real s, std::vector<Real>& theta) {
  for (const Circle& k : circles) {
    const Real a = k.m.z(), b = k.m.x() * c + k.m.y() * s;
    if (k.c == 0) {
      const Real x = std::atan2(-a, b);
      theta.push_back(x < 0 ? x + kPi<Real> : x);
      continue;
    }
    const Real rho = std::hypot(a, b);
    if (!(rho > std::abs(k.c))) continue;
    const Real delta = std::atan2(b, a), half = std::acos(k.c / rho);
    for (Real x : {delta - half, delta + half}) {
      if (x < 0) x += kTwoPi<Real>;
      if (x > 0 && x < kPi<Real>) theta.push_back(x);
    }
  }
}

// On the ring, m.w = m_z cos(theta) + sin(theta) rho cos(phi - psi) = c_m.
void ring_crossing_azimuths(const std::vector<Circle>& circles, Real cos_t, Real sin_t, std::vector<Real>& phi) {
  for (const Circle& k : circles) {
    const Real rho = std::hypot(k.m.x(), k.m.y()), psi = std::atan2(k.m.y(), k.m.x());
    if (!(rho > 0) || !(sin_t > 0)) continue;
    const Real arg = (k.c - k.m.z() * cos_t) / (sin_t * rho);
    if (!(std::abs(arg) <= 1)) continue;
    for (Real sign : {Real(-1), Real(1)}) {
      Real x = std::fmod(psi + sign * std::acos(arg), kTwoPi<Real>);
      if (x < 0) x += kTwoPi<Real>;
      if (x > 0 && x < kTwoPi<Real>) phi.push_back(x);
    }
  }
}

// w = alpha m1 + beta m2 + gamma (m1 x m2) with m_i.w = c_i and |w| = 1 (1 - (m1.m2)^2 = |m1 x m2|^2); for two
// great circles +-(m1 x m2) / |m1 x m2|.
std::vector<Vec3L> circle_intersections(const Circle& a, const Circle& b) {
  const Vec3L n = a.m.cross(b.m);
  const Real n2 = n.squaredNorm();
  if (!(n2 > 0)) return {};
  if (a.c == 0 && b.c == 0) return {n.normalized(), -n.normalized()};
  const Real g = a.m.dot(b.m);
  const Vec3L p = ((a.c - g * b.c) / n2) * a.m + ((b.c - g * a.c) / n2) * b.m;
  const Real rest = 1 - p.squaredNorm();
  if (!(rest > 0)) return {};
  const Vec3L q = std::sqrt(rest / n2) * n;
  return {p + q, p - q};
}

// A circle of angular radius r about a centre at polar angle theta_m spans |theta_m - r| to
// min(theta_m + r, 2 pi - theta_m - r); a great circle atan2(|m_z|, rho) and pi minus that.
std::vector<Real> polar_tangencies(const std::vector<Circle>& circles) {
  std::vector<Real> theta;
  for (const Circle& k : circles) {
    const Real rho = std::hypot(k.m.x(), k.m.y());
    if (k.c == 0) {
      const Real x = std::atan2(std::abs(k.m.z()), rho);
      theta.push_back(x), theta.push_back(kPi<Real> - x);
      continue;
    }
    const Real theta_m = std::atan2(rho, k.m.z()), r = std::acos(std::clamp<Real>(k.c, -1, 1));
    theta.push_back(std::abs(theta_m - r)), theta.push_back(std::min(theta_m + r, kTwoPi<Real> - theta_m - r));
  }
  return theta;
}

// In terms of the circle's smaller disk (centre m' = +-m at polar angle theta', radius r' <= pi / 2):
// sin(beta) = sin(r') / sin(theta') about the centre's azimuth, when theta' > r' and theta' + r' < pi.
std::vector<Real> azimuth_tangencies(const std::vector<Circle>& circles) {
  std::vector<Real> phi;
  for (const Circle& k : circles) {
    if (k.c == 0) continue;
    const Vec3L centre = k.c > 0 ? k.m : Vec3L(-k.m);
    const Real rho = std::hypot(centre.x(), centre.y()), theta = std::atan2(rho, centre.z());
    const Real r = std::acos(std::min<Real>(1, std::abs(k.c)));
    if (!(theta > r && theta + r < kPi<Real>)) continue;
    const Real beta = std::asin(std::min<Real>(1, sine(r) / rho)), psi = std::atan2(centre.y(), centre.x());
    for (Real x : {psi - beta, psi + beta}) {
      x = std::fmod(x, kTwoPi<Real>);
      phi.push_back(x < 0 ? x + kTwoPi<Real> : x);
    }
  }
  return phi;
}

}  // namespace warpcheck::validation::battery
