// Cap coordinates and the battery's quadrature: globally adaptive Gauss-Kronrod on an interval, nested over a
// region of a cap in (t, phi). See battery.h for the interfaces.
#include <algorithm>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <cmath>

#include "battery/circles.h"
#include "warpcheck/validation/battery.h"

namespace warpcheck::validation {

Vec3L cap_direction(const Cap<Real>& cap, Real t, Real phi) {
  const Frame<Real> f = Frame<Real>::from_z(cap.axis);
  const Real omc = t * cap.one_minus_cos;  // 1 - cos(theta)
  const Real cos_t = 1 - omc;
  const Real sin_t = std::sqrt(std::max<Real>(0, omc * (2 - omc)));
  return f.to_world(Vec3L(sin_t * cosine(phi), sin_t * sine(phi), cos_t));
}

void cap_coordinates(const Cap<Real>& cap, const Vec3L& w, Real& t, Real& phi) {
  const Frame<Real> f = Frame<Real>::from_z(cap.axis);
  const Vec3L l = f.to_local(w);
  // 1 - cos(theta) = |w - axis|^2 / 2 keeps its precision for tiny caps.
  t = (w - cap.axis).squaredNorm() / 2 / cap.one_minus_cos;
  phi = std::atan2(l.y(), l.x());
  if (phi < 0) phi += kTwoPi<Real>;
  if (phi >= kTwoPi<Real>) phi = 0;
}

namespace {

using GK = boost::math::quadrature::gauss_kronrod<Real, 15>;

struct Panel {
  Real a, b, value, error;
  bool operator<(const Panel& o) const { return error < o.error; }
};

// A panel's error estimate is the larger of (1) |K15 - G7| on the panel (Boost's single-panel estimate is on
// [-1, 1]: scaled back by half the width), plus (2) an end-gap term, and (3) half the disagreement between
// its parent's K15 and the sum of the two children's K15. Why (2) and (3): |K15 - G7| is blind to a jump in
// two places. (a) Between the outermost node (at 0.9915 of the half-width) and the panel's end: every node
// sees one smooth piece, K15 and G7 agree, and the piece between the jump and the end is integrated with the
// wrong value; a right child shares its parent's right end, so comparing with the parent does not see it
// either. (2) evaluates f at both ends and, when the step from the outermost node to the end is larger than
// the step from the outermost node to its neighbour (about five times what a smooth f gives: the gap is 0.2
// of that node spacing), adds gap * |step|. (b) Near the middle, where the cumulative Kronrod and Gauss
// weights agree by symmetry; (3) sees the parent's true error, and integrate_adaptive's forced first split
// gives every panel a parent. test_battery.cpp checks the bin masses of a density that jumps along a tilted
// cap's edge.
class PanelRule {
 public:
  explicit PanelRule(const std::function<Real(Real)>& f) : f_(f) {}

  Panel panel(Real lo, Real hi) const {
    const Real c = (lo + hi) / 2, h = (hi - lo) / 2;
    Real f_lo_outer = 0, f_lo_inner = 0, f_hi_outer = 0, f_hi_inner = 0;
    auto recording = [&](Real t) {
      const Real v = f_(t);
      if (t == c - h * outer_)
        f_lo_outer = v;
      else if (t == c - h * inner_)
        f_lo_inner = v;
      else if (t == c + h * outer_)
        f_hi_outer = v;
      else if (t == c + h * inner_)
        f_hi_inner = v;
      return v;
    };
    // Boost maps a finite [lo, hi] to [-1, 1] as t = c + h x, the arithmetic repeated above.
    Real err = 0;
    const Real v = GK::integrate(recording, lo, hi, 0, 0, &err);
    err *= h;
    const Real gap = h * (1 - outer_);
    auto end_gap = [&](Real f_end, Real f_outer, Real f_inner) {
      const Real step = std::abs(f_end - f_outer);
      return std::isfinite(f_end) && step > std::abs(f_outer - f_inner) ? gap * step : Real(0);
    };
    err += end_gap(f_(lo), f_lo_outer, f_lo_inner) + end_gap(f_(hi), f_hi_outer, f_hi_inner);
    return Panel{lo, hi, v, err};
  }

  // Halves p into l and r with the parent's disagreement (3); false when p cannot be split in this precision.
  bool split(const Panel& p, Panel& l, Panel& r) const {
    const Real mid = (p.a + p.b) / 2;
    if (!(mid > p.a && mid < p.b)) return false;
    l = panel(p.a, mid), r = panel(mid, p.b);
    const Real half_disagreement = std::abs(p.value - l.value - r.value) / 2;
    l.error = std::max(l.error, half_disagreement), r.error = std::max(r.error, half_disagreement);
    return true;
  }

 private:
  const std::function<Real(Real)>& f_;
  // Boost's Kronrod nodes on [0, 1]: x[0] = 0 < ... < x[7] = 0.9915...
  const Real outer_ = GK::abscissa()[7], inner_ = GK::abscissa()[6];
};

// The starting panels: initial_panels equal ones, or [a, b] split once.
std::vector<Panel> initial_panels_of(const PanelRule& rule, Real a, Real b, int initial_panels, int max_panels) {
  std::vector<Panel> heap;
  heap.reserve(std::size_t(std::max(max_panels, 2)) + 1);
  if (initial_panels > 1) {
    for (int k = 0; k < initial_panels; ++k)
      heap.push_back(rule.panel(a + (b - a) * k / initial_panels,
                                k + 1 == initial_panels ? b : a + (b - a) * (k + 1) / initial_panels));
  } else {
    Panel l, r;
    const Panel root = rule.panel(a, b);
    if (rule.split(root, l, r))
      heap.push_back(l), heap.push_back(r);
    else
      heap.push_back(root);
  }
  std::make_heap(heap.begin(), heap.end());
  return heap;
}

}  // namespace

// Globally adaptive Gauss-Kronrod (G7/K15) with an interval budget. Boost supplies the rule and its error
// estimate (integrate with max_depth 0: one panel); Boost's own adaptivity is depth-first with no evaluation
// budget, and on an integrand whose rounding noise exceeds the tolerance (a float pdf near a silhouette) it
// bisects every panel down to max_depth, 2^depth panels. This driver instead always splits the panel with the
// largest error estimate and stops at the tolerance or at the budget, whichever comes first, and reports the
// error estimate it reached, so a caller can see when the budget, not the tolerance, ended the work.
QuadratureResult integrate_adaptive(const std::function<Real(Real)>& f, Real a, Real b, Real rel_tol, Real abs_tol,
                                    int max_panels, int initial_panels) {
  const PanelRule rule(f);
  max_panels = std::max(max_panels, 2 * initial_panels);
  std::vector<Panel> heap = initial_panels_of(rule, a, b, initial_panels, max_panels);
  Real value = 0, error = 0;
  for (const Panel& p : heap) value += p.value, error += p.error;
  // Stagnation: on a smooth piece, a jump or a kink, every split of the worst panel cuts the total error
  // estimate (by 2 for a jump, far more for smooth pieces). On rounding noise (a float pdf near a silhouette)
  // a panel's estimate is its width times the noise, so splitting leaves the total unchanged: when 16 splits
  // have not cut it to 0.7 of what it was, the rest of the budget would be spent on noise, and we stop (the
  // returned error says the tolerance was not met).
  constexpr int kWindow = 16;
  Real error_at_window_start = error;
  int splits = 0;
  Panel l, r;
  while (int(heap.size()) < max_panels && error > std::max(abs_tol, rel_tol * std::abs(value))) {
    std::pop_heap(heap.begin(), heap.end());
    const Panel worst = heap.back();
    heap.pop_back();
    if (!rule.split(worst, l, r)) {
      heap.push_back(worst);
      std::push_heap(heap.begin(), heap.end());
      break;
    }
    value += l.value + r.value - worst.value;
    error += l.error + r.error - worst.error;
    heap.push_back(l), std::push_heap(heap.begin(), heap.end());
    heap.push_back(r), std::push_heap(heap.begin(), heap.end());
    if (++splits % kWindow == 0) {
      if (error > Real(0.7) * error_at_window_start) break;
      error_at_window_start = error;
    }
  }
  // Re-sum to shed the running sum's cancellation error.
  value = 0, error = 0;
  for (const Panel& p : heap) value += p.value, error += p.error;
  return {value, error};
}

namespace {

// Breakpoints of a radial line where it crosses a boundary circle (circles.h), in the line's variable v of
// integrate_cap_region_with_error: t = (1 - cos theta) / omc_cap at each crossing's polar angle, and v inverts the
// substitution t(v), v = 1/2 - sin(asin(1 - 2 s) / 3) for s = (t - t0) / (t1 - t0). Integrating each piece on its
// own keeps a jump or kink of f between the rule's nodes from hiding a thin part of the support (the tip of a
// polygon's acute corner). Returns {0, cuts..., 1}.
std::vector<Real> line_cuts(const std::vector<battery::Circle>& circles, Real c, Real s, Real omc_cap, Real t0,
                            Real t1) {
  std::vector<Real> cuts{0, 1}, theta;
  battery::line_crossing_angles(circles, c, s, theta);
  for (Real x : theta) {
    const Real t = (1 - cosine(x)) / omc_cap;
    if (!(t > t0 && t < t1)) continue;
    const Real sv = (t - t0) / (t1 - t0);
    const Real v = Real(0.5) - sine(std::asin(std::clamp<Real>(1 - 2 * sv, -1, 1)) / 3);
    if (v > 0 && v < 1) cuts.push_back(v);
  }
  std::sort(cuts.begin(), cuts.end());
  return cuts;
}

// Azimuth breakpoints of a region [t0, t1] x [phi0, phi1], sorted, ends included. (1) At the corners of the
// boundary (where two boundary circles meet inside the region): at an acute corner whose sides run nearly
// radially, the lines cross the support only within a sliver of azimuth around the corner's, which the outer
// rule's nodes would step over. (2) Where a boundary circle crosses the region's inner or outer ring: between
// these azimuths every radial line crosses the same boundaries, so the inner integral is smooth in phi.
std::vector<Real> azimuth_cuts(const std::vector<battery::Circle>& circles, Real omc_cap, Real t0, Real t1, Real phi0,
                               Real phi1) {
  std::vector<Real> phi_cuts{phi0, phi1}, ring;
  auto add_phi_cut = [&](Real phi) {  // phi in (-2 pi, 2 pi), kept when inside the region's azimuth range
    if (phi < 0) phi += kTwoPi<Real>;
    if (phi > phi0 && phi < phi1) phi_cuts.push_back(phi);
  };
  for (std::size_t i = 0; i < circles.size(); ++i)
    for (std::size_t j = i + 1; j < circles.size(); ++j)
      for (const Vec3L& l : battery::circle_intersections(circles[i], circles[j])) {
        const Real t = (1 - l.z()) / omc_cap;
        if (t >= t0 && t <= t1) add_phi_cut(std::atan2(l.y(), l.x()));
      }
  for (Real t : {t0, t1}) {
    const Real cos_c = 1 - t * omc_cap;
    if (!(t > 0) || !(cos_c > -1)) continue;
    battery::ring_crossing_azimuths(circles, cos_c, std::sqrt(std::max<Real>(0, (1 - cos_c) * (1 + cos_c))), ring);
  }
  for (Real phi : ring) add_phi_cut(phi);
  std::sort(phi_cuts.begin(), phi_cuts.end());
  return phi_cuts;
}

}  // namespace

QuadratureResult integrate_cap_region_with_error(const std::function<Real(const Vec3L&)>& f, const Cap<Real>& cap,
                                                 Real t0, Real t1, Real phi0, Real phi1, Real tol, int azimuth_panels,
                                                 int radial_panels, const Boundary& boundary, Real abs_tol) {
  // Panel budget per line: a jump needs ~35 bisections to reach 1e-10 of the line's integral; 64 leaves room
  // for two jumps, and bounds the cost of a noisy integrand at 64 * 15 evaluations per line.
  constexpr int kMaxPanels = 64;
  const Frame<Real> fr = Frame<Real>::from_z(cap.axis);
  const Real omc_cap = cap.one_minus_cos;
  const std::vector<battery::Circle> circles = battery::local_circles(boundary, fr);
  // The region's integral is omc_cap * (outer integral over phi of the lines' integrals): half of abs_tol to the
  // outer rule, half to the lines, spread over the azimuth range.
  const Real outer_abs = abs_tol / (2 * omc_cap),
             line_abs = abs_tol / (2 * omc_cap * std::max<Real>(phi1 - phi0, 1e-300L));
  Real inner_error = 0;  // the worst line's error estimate
  auto inner = [&](Real phi) {
    const Real c = cosine(phi), s = sine(phi);
    // Substitution t = t0 + (t1 - t0)(3v^2 - 2v^3): dt/dv = 6 (t1 - t0) v (1 - v) vanishes at both ends, which
    // turns an inverse-square-root singularity of f at a ring's edge (the visible-area sampler's silhouette)
    // into a bounded integrand. Harmless for smooth f.
    auto g = [&](Real v) {
      const Real t = t0 + (t1 - t0) * v * v * (3 - 2 * v);
      const Real dt = 6 * (t1 - t0) * v * (1 - v);
      const Real omc = t * omc_cap;
      const Real sin_t = std::sqrt(std::max<Real>(0, omc * (2 - omc)));
      const Vec3L w = fr.to_world(Vec3L(sin_t * c, sin_t * s, 1 - omc));
      const Real val = f(w);
      return std::isfinite(val) ? val * dt : Real(0);
    };
    const std::vector<Real> cuts = line_cuts(circles, c, s, omc_cap, t0, t1);
    Real value = 0, error = 0;
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
      if (!(cuts[i + 1] > cuts[i])) continue;
      const QuadratureResult r = integrate_adaptive(g, cuts[i], cuts[i + 1], tol / 4, line_abs / Real(cuts.size() - 1),
                                                    kMaxPanels, cuts.size() == 2 ? radial_panels : 1);
      value += r.value, error += r.error;
    }
    inner_error = std::max(inner_error, error);
    return value;
  };
  // d(omega) = d(cos theta) d(phi) = omc_cap dt dphi.
  const std::vector<Real> phi_cuts = azimuth_cuts(circles, omc_cap, t0, t1, phi0, phi1);
  QuadratureResult outer{0, 0};
  for (std::size_t i = 0; i + 1 < phi_cuts.size(); ++i) {
    if (!(phi_cuts[i + 1] > phi_cuts[i])) continue;
    const QuadratureResult r =
        integrate_adaptive(inner, phi_cuts[i], phi_cuts[i + 1], tol, outer_abs / Real(phi_cuts.size() - 1), kMaxPanels,
                           phi_cuts.size() == 2 ? azimuth_panels : 1);
    outer.value += r.value, outer.error += r.error;
  }
  // Error: the outer rule's estimate plus the worst inner error spread over the azimuth range.
  return {omc_cap * outer.value, omc_cap * (outer.error + inner_error * (phi1 - phi0))};
}

Real integrate_cap_region(const std::function<Real(const Vec3L&)>& f, const Cap<Real>& cap, Real t0, Real t1, Real phi0,
                          Real phi1, Real tol, int azimuth_panels, int radial_panels, const Boundary& boundary,
                          Real abs_tol) {
  return integrate_cap_region_with_error(f, cap, t0, t1, phi0, phi1, tol, azimuth_panels, radial_panels, boundary,
                                         abs_tol)
      .value;
}

}  // namespace warpcheck::validation
