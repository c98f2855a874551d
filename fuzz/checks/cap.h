// fuzz/checks/cap.h: long double references for spherical caps shared by projected_cap.h and sptd.h: the angle
// between two directions, a cap's half-angle, and the projected solid angle of a cap by quadrature.
#pragma once

#include <algorithm>
#include <vector>

#include <boost/math/quadrature/tanh_sinh.hpp>

#include "common.h"

namespace warpcheck::fuzz {

// Angle between two nonzero vectors (long double, atan2 form: accurate for tiny and near-pi angles).
inline L angle_between(const Vec3<L>& a, const Vec3<L>& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// Half-angle of a cap of 1 - cos = omc in [0, 2], from the chord: psi = 2 asin(sqrt(omc / 2)).
inline L half_angle_of(L omc) { return 2 * std::asin(std::sqrt(std::clamp(omc / 2, L(0), L(1)))); }

// ---- The projected solid angle of a cap ---------------------------------------------------------------------
//
// P(t, psi) = integral over the cap {angle(w, a) <= psi} of max(0, n.w) dw, t = angle(a, n) in [0, pi], psi in
// [0, pi]. Derived here (no paper's path is used): in polar coordinates (theta, phi) around a with phi = 0 towards
// n, n.w = b + c cos(phi) with b = cos(theta) cos(t), c = sin(theta) sin(t) >= 0, so the ring at theta contributes
// sin(theta) I(theta), I = int_0^2pi max(0, b + c cos phi) dphi:
//   b - c = cos(theta + t) >= 0 (ring entirely above the horizon):  I = 2 pi b
//   b + c = cos(theta - t) <= 0 (entirely below):                   I = 0
//   otherwise, with cos(phi0) = -b / c, sin(phi0) = sqrt(c^2 - b^2) / c, c^2 - b^2 = -cos(theta + t) cos(theta - t):
//   I = 2 (b phi0 + c sin phi0) = 2 c S(phi0),  S(x) = sin x - x cos x,
//   and for phi0 > pi/2 equivalently I = 2 pi b + 2 c S(pi - phi0) (substitute phi0 = pi - phi1).
// S cancels for small x (S ~ x^3 / 3): a series there, S = sum_{k>=1} (-1)^(k+1) 2k x^(2k+1) / (2k+1)!.
// The rings touch the horizon where cos(theta +- t) = 0: theta in {pi/2 - t, 3pi/2 - t, t - pi/2, t + pi/2}, the
// only kinks (the integrand behaves like (theta - kink)^(3/2) there); tanh-sinh on each smooth piece.
inline L sin_minus_x_cos(L x) {
  if (x < L(0.5)) {
    const L x2 = x * x;
    L term = x * x2 / 3, sum = 0;  // k = 1: 2 x^3 / 3! = x^3 / 3
    for (int k = 1; k <= 14; ++k) {
      sum += term;
      // term_{k+1} / term_k = -x^2 (2k + 2) / (2k (2k + 2) (2k + 3)) = -x^2 / (2k (2k + 3))
      term *= -x2 / L(2 * k * (2 * k + 3));
    }
    return sum;
  }
  return std::sin(x) - x * std::cos(x);
}

inline L ring_cosine_integral(L theta, L t) {
  const L b = std::cos(theta) * std::cos(t), c = std::sin(theta) * std::sin(t);
  const L above = std::cos(theta + t), below = std::cos(theta - t);  // b - c and b + c
  if (!(c > 0) || above >= 0) return std::max(L(0), kTwoPi<L> * b);
  if (below <= 0) return 0;
  const L phi0 = std::atan2(std::sqrt(-above * below), -b);
  return phi0 <= kPi<L> / 2 ? 2 * c * sin_minus_x_cos(phi0) : kTwoPi<L> * b + 2 * c * sin_minus_x_cos(kPi<L> - phi0);
}

struct Quadrature {
  L value = 0, error = 0;  // error: tanh-sinh's own absolute estimate, summed over the pieces
};

inline Quadrature reference_cap_projected_solid_angle(L t, L psi) {
  Quadrature q;
  if (!(psi > 0) || !std::isfinite(psi) || !std::isfinite(t)) return q;
  // One object for the process (its abscissas are computed once; integrate() is non-const in Boost 1.81).
  // 10 refinements: a piece that has not converged by then reports its error estimate, which the callers add
  // to their tolerance, instead of recursing (a piece of width ~1e-19 next to a kink never converges).
  static boost::math::quadrature::tanh_sinh<L> ts(10);
  std::vector<L> cuts = {0};  // the ends and the kinks between them
  for (L k : {kPi<L> / 2 - t, 3 * kPi<L> / 2 - t, t - kPi<L> / 2, t + kPi<L> / 2})
    if (k > psi * L(1e-12) && k < psi * (1 - L(1e-12))) cuts.push_back(k);  // kinks this close to an end: not split
  cuts.push_back(psi);
  std::sort(cuts.begin(), cuts.end());
  const int n = int(cuts.size());
  auto f = [t](L theta) { return std::sin(theta) * ring_cosine_integral(theta, t); };
  for (int i = 0; i + 1 < n; ++i) {
    const L a = cuts[i], b = cuts[i + 1];
    if (!(b > a)) continue;  // coincident kinks (t = 0 or pi: pi/2 - t = t - pi/2 or t + pi/2)
    // A piece too narrow for tanh-sinh's abscissas to resolve (its change of variables then evaluates at the
    // endpoints): its contribution is at most its width times the integrand's size there, counted as error.
    if (b - a <= L(1e-12) * b) {
      const L bound = (b - a) * std::max(std::abs(f(a)), std::abs(f(b)));
      q.value += bound / 2, q.error += bound;
      continue;
    }
    L err = 0;
    q.value += ts.integrate(f, a, b, L(1e-17), &err);
    q.error += err;  // absolute (Boost scales it with the interval)
  }
  return q;
}

}  // namespace warpcheck::fuzz
