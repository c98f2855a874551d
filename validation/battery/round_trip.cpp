// The battery's test "round-trip" (tests.h), for a sampler with an inverse warp: inverse(sample(u)) == u on a grid
// of primary samples that includes the ends of the warp's pieces, and sample(inverse(w)) == w on a grid of
// directions over the bounding cap.
//
// Errors are in units of u, less what the sampler's rounding explains: a direction is known to about 8 epsilons of
// the sampler's scalar type, which the inverse turns into a u-error of up to 8 eps / sigma, sigma the warp's smallest
// stretch |J du| / |du| at that point (J = dw/du). This is negligible in double (1.8e-15 / sigma) but not in float,
// and it is what makes a point where the warp is not injective (sigma = 0: a polar map's pole) pass whatever
// preimage the inverse picks. An inversion error is a u-error of its own and stays.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "battery/tests.h"

namespace warpcheck::validation::battery {

namespace {

constexpr Real kInf = std::numeric_limits<Real>::infinity();

// Cells per axis of both grids: 32 x 32 cell centres, which keep 1 / 64 away from the seams u = 0 and 1 (the pole
// of a polar map, the azimuth's wrap) and never land on u = 1/2; the primary grid adds the ends of the warp's pieces.
constexpr int kGrid = 32;

// The warp's Jacobian J = (dw/du0, dw/du1) at u by central differences centred on u; ok == false where a point
// declines (a warp may decline on the domain's edge, e.g. at the horizon). The step starts at 1e-4, or at half the
// distance d from u to the nearer edge of [0, 1] where that is less, and grows 4-fold, up to 1/16, until the two
// directions differ by 1024 times the rounding `same` (a float warp of a tiny light moves less than its rounding over
// 1e-4 of u); only a step beyond d / 2 moves the stencil inward. The centre matters at an edge where the warp is
// singular: next to a fan's tip, where the region between two meeting edges closes, w moves as sqrt(u0) (the area
// swept grows as the square of the azimuth), so J at 2e-4 instead of at u0 = 1e-5 would be sqrt(20) = 4.5 times too
// small and the u-error J^+ dw as much too large. With h = d / 2 the difference of sqrt is within 3.5% of its
// derivative; J is a scale here, O(h^2) error is harmless.
struct Jacobian {
  Vec3L j[2];
  bool ok = true;
  Jacobian(const SamplerUnderTest& s, Real u0, Real u1, Real same) {
    for (int axis = 0; axis < 2 && ok; ++axis) {
      const Real u = axis == 0 ? u0 : u1, d = std::min(u, 1 - u);
      for (Real h = d > 0 ? std::min<Real>(1e-4L, d / 2) : 1e-4L;; h *= 4) {
        const Real c = std::clamp<Real>(u, 2 * h, 1 - 2 * h);
        const Sample a = axis == 0 ? s.sample(double(c - h), double(u1)) : s.sample(double(u0), double(c - h));
        const Sample b = axis == 0 ? s.sample(double(c + h), double(u1)) : s.sample(double(u0), double(c + h));
        ok = a.valid && b.valid;
        j[axis] = (b.direction - a.direction) / (2 * h);
        if (!ok || 2 * h * j[axis].norm() >= 1024 * same || h >= Real(1) / 16) break;
      }
    }
  }
  // J^T J = [[a, b], [b, c]].
  Real a() const { return j[0].dot(j[0]); }
  Real b() const { return j[0].dot(j[1]); }
  Real c() const { return j[1].dot(j[1]); }
  // The smallest singular value of J (0 where J is singular or unknown).
  Real sigma_min() const {
    if (!ok) return 0;
    const Real m = (a() + c()) / 2, d = std::hypot((a() - c()) / 2, b());
    return std::sqrt(std::max<Real>(0, m - d));
  }
  // The least-squares du with J du = dw (nullopt where J is singular or unknown).
  std::optional<std::array<Real, 2>> solve(const Vec3L& dw) const {
    const Real det = a() * c() - b() * b();
    if (!ok || !(det > 0)) return std::nullopt;
    const Real r0 = j[0].dot(dw), r1 = j[1].dot(dw);
    return std::array<Real, 2>{(c() * r0 - b() * r1) / det, (a() * r1 - b() * r0) / det};
  }
};

// A u-error less the rounding's share `same` / sigma (file comment), not below 0.
Real beyond_rounding(Real error, Real same, const Jacobian& j) {
  const Real sigma = j.sigma_min();
  return sigma > 0 ? std::max<Real>(0, error - same / sigma) : 0;
}

// The worst error in units of u, and where.
struct Worst {
  Real error = 0;
  Real u[2] = {0, 0};
  void add(Real e, Real u0, Real u1) {
    if (e <= error) return;
    error = std::isnan(e) ? kInf : e;
    u[0] = u0, u[1] = u1;
  }
};

bool in_unit_square(const std::array<Real, 2>& u) { return u[0] >= 0 && u[0] <= 1 && u[1] >= 0 && u[1] <= 1; }

// The sample at a preimage in [0, 1]^2, with a coordinate 1 (the inverse of a direction on the support's edge) taken
// as the largest double below 1: sample takes u in [0, 1).
Sample sample_at_preimage(const SamplerUnderTest& s, const std::array<Real, 2>& u) {
  auto below_one = [](Real x) { return x < 1 ? double(x) : std::nextafter(1.0, 0.0); };
  return s.sample(below_one(u[0]), below_one(u[1]));
}

struct Grid {
  Worst worst;
  std::size_t checked = 0, failed = 0, rounding = 0;  // failed: no valid preimage; rounding: passed by the floor only
  void add(const SamplerUnderTest& s, Real raw, Real floored, Real u0, Real u1) {
    if (raw > s.inverse_tolerance && floored <= s.inverse_tolerance) ++rounding;
    worst.add(floored, u0, u1);
  }
  void fail(Real u0, Real u1) { ++failed, worst.add(kInf, u0, u1); }
};

// inverse(sample(u)) against u at one point: |u' - u| over both coordinates, less the rounding's share at u.
void primary_point(const SamplerUnderTest& s, Real same, Real u0, Real u1, Grid& g) {
  const Sample x = s.sample(double(u0), double(u1));
  if (!x.valid) return;  // a declined sample fails pdf-consistency and chi2
  ++g.checked;
  const auto back = s.inverse(x.direction);
  if (!back || !in_unit_square(*back)) return g.fail(u0, u1);
  const Real e = std::max(std::abs((*back)[0] - u0), std::abs((*back)[1] - u1));
  g.add(s, e, beyond_rounding(e, same, Jacobian(s, u0, u1, same)), u0, u1);
}

// The u of the cell centres, and 0, 1 and 2 of the sampler's epsilons (relative) either side of each declared kink
// in (0, 1): a kink ends a piece of the warp (a sector, a piece of the disk), and there an inversion's clamps and
// rounding guards act, which the cell centres almost never reach.
std::vector<Real> primary_coordinates(const std::vector<Real>& kinks, Real eps) {
  std::vector<Real> u;
  for (int i = 0; i < kGrid; ++i) u.push_back((i + Real(0.5)) / kGrid);
  for (const Real k : kinks)
    if (k > 0 && k < 1)
      for (int m = -2; m <= 2; ++m) u.push_back(std::min<Real>(k * (1 + m * eps), std::nextafter(1.0, 0.0)));
  return u;
}

// inverse(sample(u)) against u on the grid of primary_coordinates in u0 and u1.
Grid primary_grid(const SamplerUnderTest& s, Real same) {
  const Real eps = scalar_epsilon(s.scalar);
  Grid g;
  for (const Real u0 : primary_coordinates(s.kinks_u0, eps))
    for (const Real u1 : primary_coordinates(s.kinks_u1, eps)) primary_point(s, same, u0, u1, g);
  return g;
}

// The u-error of u' = inverse(w): max |u* - u'| over both coordinates, u* the preimage of w under `sample` next to
// u', given the residual r = sample(u') - w and jac = J at u'. To first order u* = u' - J^+ r (least squares), which
// holds while the error is small against the distance over which J changes. Next to a fan's tip that distance is u0
// itself (w moves as sqrt(u0), Jacobian above), and there an error of half of u0 is not small: the first-order step
// misses w by a second-order term across the thin region, which J^+ takes into u1, whose column vanishes at the tip
// (measured: 2.3e-5 for a true error of 5.9e-7 at u0 = 1.2e-6). So Gauss-Newton steps u <- u - J(u)^+ r(u), kept in
// [0, 1], while |r| decreases (at most 8; a warp's kink or seam stops them), and u* = u - J(u)^+ r(u) from the last
// u. jac ends as J at that u (for the rounding's share). Infinite where J is singular.
Real preimage_distance(const SamplerUnderTest& s, const std::array<Real, 2>& from, Vec3L r, const Vec3L& w, Real same,
                       Jacobian& jac) {
  std::array<Real, 2> u = from;
  for (int k = 0; k < 8; ++k) {
    const auto du = jac.solve(r);
    if (!du) break;
    const std::array<Real, 2> next{std::clamp<Real>(u[0] - (*du)[0], 0, 1), std::clamp<Real>(u[1] - (*du)[1], 0, 1)};
    const Sample z = sample_at_preimage(s, next);
    if (!z.valid || !((z.direction - w).norm() < r.norm())) break;
    u = next, r = z.direction - w, jac = Jacobian(s, u[0], u[1], same);
  }
  const auto du = jac.solve(r);
  if (!du) return kInf;
  return std::max(std::abs(u[0] - (*du)[0] - from[0]), std::abs(u[1] - (*du)[1] - from[1]));
}

// sample(inverse(w)) against w for the directions at the cell centres of an equal-area grid over the bounding cap
// where the pdf is positive: the distance from u' = inverse(w) to w's preimage next to it (preimage_distance), less
// the rounding's share. (A support thinner than the grid's cells may hold none of them; the primary grid then checks
// alone.)
Grid direction_grid(const SamplerUnderTest& s, Real same) {
  Grid g;
  for (int i = 0; i < kGrid; ++i)
    for (int j = 0; j < kGrid; ++j) {
      const Vec3L w = cap_direction(s.bounding_cap, (i + Real(0.5)) / kGrid, kTwoPi<Real> * (j + Real(0.5)) / kGrid);
      if (!(s.in_support ? s.in_support(w) : s.pdf(w) > 0)) continue;
      ++g.checked;
      const auto u = s.inverse(w);
      const Sample y = u && in_unit_square(*u) ? sample_at_preimage(s, *u) : Sample{};
      if (!y.valid) {
        g.fail(u ? (*u)[0] : -1, u ? (*u)[1] : -1);
        continue;
      }
      Jacobian jac(s, (*u)[0], (*u)[1], same);
      const Real e = preimage_distance(s, *u, y.direction - w, w, same, jac);
      g.add(s, e, beyond_rounding(e, same, jac), (*u)[0], (*u)[1]);
    }
  return g;
}

}  // namespace

TestResult round_trip(const SamplerUnderTest& s) {
  TestResult r = make_result(s, "round-trip");
  const Real same = 8 * scalar_epsilon(s.scalar);
  const Grid gu = primary_grid(s, same), gw = direction_grid(s, same);
  r.statistic = double(std::max(gu.worst.error, gw.worst.error));
  r.passed = gu.checked > 0 && gu.failed + gw.failed == 0 && r.statistic <= double(s.inverse_tolerance);
  std::ostringstream detail;
  detail << "max |inverse(sample(u)) - u| " << double(gu.worst.error) << " at u=(" << double(gu.worst.u[0]) << ","
         << double(gu.worst.u[1]) << ") over " << gu.checked << " grid points, " << gu.failed
         << " without a preimage in [0,1]^2; u-error of sample(inverse(w)) - w " << double(gw.worst.error) << " at u=("
         << double(gw.worst.u[0]) << "," << double(gw.worst.u[1]) << ") over " << gw.checked << " directions, "
         << gw.failed << " without a valid preimage; errors less 8 eps / (smallest stretch), "
         << "which passed " << gu.rounding + gw.rounding << " points; tolerance " << double(s.inverse_tolerance)
         << " in units of u";
  r.detail = detail.str();
  return r;
}

}  // namespace warpcheck::validation::battery
