// The statistical battery: sampling, chi-square, Kolmogorov-Smirnov, pdf integral, pdf/Jacobian consistency,
// normalisation, and the family-wise correction. See battery.h for what each test means.
#include "warpcheck/validation/battery.h"

#include <algorithm>
#include <atomic>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/kolmogorov_smirnov.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <numeric>
#include <random>
#include <sstream>
#include <thread>

namespace warpcheck::validation {

const char* to_string(Correction c) { return c == Correction::kSidak ? "sidak" : "holm"; }

// ---- Cap coordinates and quadrature -----------------------------------------------------------------------

Vec3L cap_direction(const Cap<Real>& cap, Real t, Real phi) {
  const Frame<Real> f = Frame<Real>::from_z(cap.axis);
  const Real omc = t * cap.one_minus_cos;  // 1 - cos(theta)
  const Real cos_t = 1 - omc;
  const Real sin_t = std::sqrt(std::max<Real>(0, omc * (2 - omc)));
  return f.to_world(Vec3L(sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t));
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

// Globally adaptive Gauss-Kronrod (G7/K15) with an interval budget. Boost supplies the rule and its error
// estimate (integrate with max_depth 0: one panel); Boost's own adaptivity is depth-first with no evaluation
// budget, and on an integrand whose rounding noise exceeds the tolerance (a float pdf near a silhouette) it
// bisects every panel down to max_depth, 2^depth panels. This driver instead always splits the panel with the
// largest error estimate and stops at the tolerance or at the budget, whichever comes first, and reports the
// error estimate it reached, so a caller can see when the budget, not the tolerance, ended the work.
QuadratureResult integrate_adaptive(const std::function<Real(Real)>& f, Real a, Real b, Real rel_tol, Real abs_tol,
                                    int max_panels, int initial_panels) {
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
  // weights agree by symmetry; (3) sees the parent's true error, and the forced first split below gives every
  // panel a parent. Measured on a tilted uniform cap (validation/tests/test_battery.cpp): with (1) alone 10% of
  // the grid's radial lines through the cap's edge stopped early, some 0.8% off, and bin masses were off by
  // 2.6e-6; with (1)-(3), of 40000 lines through two cut bins none is off by more than 1.1e-10, and the worst of
  // the 512 bins by 8.5e-9 (tol 1e-8).
  const auto& x = GK::abscissa();  // x[0] = 0 < ... < x[7] = 0.9915..., Boost's Kronrod nodes on [0, 1]
  const Real outer = x[7], inner = x[6];
  auto panel = [&](Real lo, Real hi) {
    const Real c = (lo + hi) / 2, h = (hi - lo) / 2;
    Real f_lo_outer = 0, f_lo_inner = 0, f_hi_outer = 0, f_hi_inner = 0;
    auto recording = [&](Real t) {
      const Real v = f(t);
      if (t == c - h * outer)
        f_lo_outer = v;
      else if (t == c - h * inner)
        f_lo_inner = v;
      else if (t == c + h * outer)
        f_hi_outer = v;
      else if (t == c + h * inner)
        f_hi_inner = v;
      return v;
    };
    // Boost maps a finite [lo, hi] to [-1, 1] as t = c + h x, the arithmetic repeated above.
    Real err = 0;
    const Real v = GK::integrate(recording, lo, hi, 0, 0, &err);
    err *= h;
    const Real gap = h * (1 - outer);
    auto end_gap = [&](Real f_end, Real f_outer, Real f_inner) {
      const Real step = std::abs(f_end - f_outer);
      return std::isfinite(f_end) && step > std::abs(f_outer - f_inner) ? gap * step : Real(0);
    };
    err += end_gap(f(lo), f_lo_outer, f_lo_inner) + end_gap(f(hi), f_hi_outer, f_hi_inner);
    return Panel{lo, hi, v, err};
  };
  auto split = [&](const Panel& p, Panel& l, Panel& r) {
    const Real mid = (p.a + p.b) / 2;
    if (!(mid > p.a && mid < p.b)) return false;  // cannot split further in this precision
    l = panel(p.a, mid), r = panel(mid, p.b);
    const Real half_disagreement = std::abs(p.value - l.value - r.value) / 2;
    l.error = std::max(l.error, half_disagreement), r.error = std::max(r.error, half_disagreement);
    return true;
  };
  std::vector<Panel> heap;
  max_panels = std::max(max_panels, 2 * initial_panels);
  heap.reserve(std::size_t(std::max(max_panels, 2)) + 1);
  Panel l, r;
  if (initial_panels > 1) {
    for (int k = 0; k < initial_panels; ++k)
      heap.push_back(panel(a + (b - a) * k / initial_panels,
                           k + 1 == initial_panels ? b : a + (b - a) * (k + 1) / initial_panels));
  } else {
    const Panel root = panel(a, b);
    if (split(root, l, r))
      heap.push_back(l), heap.push_back(r);
    else
      heap.push_back(root);
  }
  std::make_heap(heap.begin(), heap.end());
  Real value = 0, error = 0;
  for (const Panel& p : heap) value += p.value, error += p.error;
  // Stagnation: on a smooth piece, a jump or a kink, every split of the worst panel cuts the total error
  // estimate (by 2 for a jump, far more for smooth pieces). On rounding noise (a float pdf near a silhouette)
  // a panel's estimate is its width times the noise, so splitting leaves the total unchanged: when 16 splits
  // have not cut it to 0.7 of what it was, the rest of the budget would be spent on noise, and we stop (the
  // returned error says the tolerance was not met). Measured on sphere-visible-area float near: 4.7e6
  // evaluations per chi-square bin at the silhouette without this rule.
  constexpr int kWindow = 16;
  Real error_at_window_start = error;
  int splits = 0;
  while (int(heap.size()) < max_panels && error > std::max(abs_tol, rel_tol * std::abs(value))) {
    std::pop_heap(heap.begin(), heap.end());
    const Panel worst = heap.back();
    heap.pop_back();
    if (!split(worst, l, r)) {
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

QuadratureResult integrate_cap_region_with_error(const std::function<Real(const Vec3L&)>& f, const Cap<Real>& cap,
                                                 Real t0, Real t1, Real phi0, Real phi1, Real tol, int azimuth_panels,
                                                 int radial_panels, const std::vector<Vec3L>& boundary_planes,
                                                 Real abs_tol) {
  // Panel budget per line: a jump needs ~35 bisections to reach 1e-10 of the line's integral; 64 leaves room
  // for two jumps, and bounds the cost of a noisy integrand at 64 * 15 evaluations per line.
  constexpr int kMaxPanels = 64;
  const Frame<Real> fr = Frame<Real>::from_z(cap.axis);
  const Real omc_cap = cap.one_minus_cos;
  // The region's integral is omc_cap * (outer integral over phi of the lines' integrals): half of abs_tol to the
  // outer rule, half to the lines, spread over the azimuth range.
  const Real outer_abs = abs_tol / (2 * omc_cap),
             line_abs = abs_tol / (2 * omc_cap * std::max<Real>(phi1 - phi0, 1e-300L));
  Real inner_error = 0;  // sum over the outer rule's evaluations, weighted below only roughly: reported as is
  auto inner = [&](Real phi) {
    const Real c = std::cos(phi), s = std::sin(phi);
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
    // Breakpoints where the line crosses a boundary great circle m.w = 0 (SamplerUnderTest::boundary_planes):
    // w(theta) = cos(theta) a + sin(theta) u with u the line's direction, so m.a cos(theta) + m.u sin(theta) = 0
    // at theta = atan2(-m.a, m.u) mod pi; t = (1 - cos theta) / omc_cap, and v inverts the substitution,
    // v = 1/2 - sin(asin(1 - 2 s) / 3) for s = (t - t0) / (t1 - t0). Each piece is then integrated on its own: a
    // jump or kink of f between the rule's nodes can no longer hide a thin part of the support (the tip of a
    // polygon's acute corner, 1e-5 rad wide, between nodes 3e-4 apart).
    std::vector<Real> cuts{0, 1};
    if (!boundary_planes.empty()) {
      const Vec3L a = cap.axis, u = fr.to_world(Vec3L(c, s, 0));
      for (const Vec3L& m : boundary_planes) {
        Real theta = std::atan2(-m.dot(a), m.dot(u));
        if (theta < 0) theta += kPi<Real>;
        const Real t = (1 - std::cos(theta)) / omc_cap;
        if (!(t > t0 && t < t1)) continue;
        const Real sv = (t - t0) / (t1 - t0);
        const Real v = Real(0.5) - std::sin(std::asin(std::clamp<Real>(1 - 2 * sv, -1, 1)) / 3);
        if (v > 0 && v < 1) cuts.push_back(v);
      }
      std::sort(cuts.begin(), cuts.end());
    }
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
  // Azimuth breakpoints at the corners of the boundary (where two boundary great circles meet inside the region):
  // at an acute corner whose sides run nearly radially, the lines cross the support only within a sliver of
  // azimuth around the corner's, which the outer rule's nodes would step over.
  std::vector<Real> phi_cuts{phi0, phi1};
  auto add_phi_cut = [&](Real phi) {  // phi in (-2 pi, 2 pi), kept when inside the region's azimuth range
    if (phi < 0) phi += kTwoPi<Real>;
    if (phi > phi0 && phi < phi1) phi_cuts.push_back(phi);
  };
  for (std::size_t i = 0; i < boundary_planes.size(); ++i)
    for (std::size_t j = i + 1; j < boundary_planes.size(); ++j) {
      const Vec3L p = boundary_planes[i].cross(boundary_planes[j]);
      if (!(p.norm() > 0)) continue;
      for (const Vec3L& q : {Vec3L(p.normalized()), Vec3L(-p.normalized())}) {
        const Vec3L l = fr.to_local(q);
        const Real t = (1 - l.z()) / omc_cap;
        if (!(t >= t0 && t <= t1)) continue;
        add_phi_cut(std::atan2(l.y(), l.x()));
      }
    }
  // And where a boundary circle crosses the region's inner or outer ring (polar angle theta_c): between these
  // azimuths every radial line crosses the same boundaries, so the inner integral is smooth in phi; a strip
  // narrower than the outer rule's nodes would otherwise be missed. In the cap's frame, m.w = 0 on the ring is
  // m_x cos(phi) + m_y sin(phi) = -m_z cot(theta_c), i.e. phi = psi +- acos(-m_z cot(theta_c) / hypot(m_x, m_y)).
  for (const Vec3L& m : boundary_planes) {
    const Vec3L ml = fr.to_local(m);
    const Real rho = std::hypot(ml.x(), ml.y()), psi = std::atan2(ml.y(), ml.x());
    if (!(rho > 0)) continue;
    for (Real t : {t0, t1}) {
      const Real cos_c = 1 - t * omc_cap;
      if (!(t > 0) || !(cos_c > -1)) continue;
      const Real sin_c = std::sqrt(std::max<Real>(0, (1 - cos_c) * (1 + cos_c)));
      const Real arg = -ml.z() * cos_c / (sin_c * rho);
      if (!(std::abs(arg) <= 1)) continue;
      for (Real sign : {Real(-1), Real(1)}) add_phi_cut(std::fmod(psi + sign * std::acos(arg), kTwoPi<Real>));
    }
  }
  std::sort(phi_cuts.begin(), phi_cuts.end());
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
                          Real phi1, Real tol, int azimuth_panels, int radial_panels,
                          const std::vector<Vec3L>& boundary_planes, Real abs_tol) {
  return integrate_cap_region_with_error(f, cap, t0, t1, phi0, phi1, tol, azimuth_panels, radial_panels,
                                         boundary_planes, abs_tol)
      .value;
}

namespace {

std::uint64_t splitmix64(std::uint64_t& x) {
  std::uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

std::uint64_t fnv1a(const std::string& s, std::uint64_t h = 1469598103934665603ULL) {
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ULL;
  return h;
}

// Independent, reproducible stream per (seed, sampler, purpose, chunk): the battery is deterministic whatever
// the thread count.
std::mt19937_64 stream(std::uint64_t seed, const SamplerUnderTest& s, std::uint64_t purpose, std::uint64_t chunk) {
  std::uint64_t x = seed ^ fnv1a(s.kernel + '\x1f' + s.scalar + '\x1f' + s.config);
  x ^= splitmix64(x) + purpose * 0x632be59bd9b4e019ULL;
  x ^= splitmix64(x) + chunk;
  return std::mt19937_64(splitmix64(x));
}

double uniform01(std::mt19937_64& g) { return double(g() >> 11) * 0x1.0p-53; }  // in [0, 1)

Real scalar_epsilon(const std::string& scalar) {
  if (scalar == "float") return FLT_EPSILON;
  if (scalar == "long double") return LDBL_EPSILON;
  return DBL_EPSILON;
}

int thread_count(const BatteryOptions& o) {
  if (o.threads > 0) return o.threads;
  return std::max(1u, std::thread::hardware_concurrency());
}

// Runs body(i) for i in [0, n) on the battery's threads.
template <class F> void parallel_for(std::size_t n, int threads, F&& body) {
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i; (i = next.fetch_add(1)) < n;) body(i);
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
}

struct Draws {
  std::vector<double> t, phi;         // cap coordinates; +inf for samples outside the cap or declined
  std::vector<std::uint64_t> counts;  // chi-square grid counts
  std::uint64_t outside = 0, declined = 0, non_finite = 0;
};

constexpr std::uint64_t kChunk = 1 << 16;

Draws draw(const SamplerUnderTest& s, const BatteryOptions& o) {
  const int R = o.radial_bins, A = o.azimuth_bins;
  Draws d;
  d.t.resize(o.samples);
  d.phi.resize(o.samples);
  d.counts.assign(std::size_t(R) * A, 0);
  // A sample may land a rounding error beyond the cap's edge: t's error is about eps * sqrt(2 / omc) (the
  // angle's error over the cap's angular radius). Within that slack it counts in the outermost ring.
  const Real eps = scalar_epsilon(s.scalar);
  const Real slack = 64 * eps * (1 + std::sqrt(2 / s.bounding_cap.one_minus_cos));
  const std::size_t chunks = (o.samples + kChunk - 1) / kChunk;
  std::mutex m;
  std::atomic<std::size_t> done{0};
  parallel_for(chunks, thread_count(o), [&](std::size_t c) {
    std::mt19937_64 g = stream(o.seed, s, 1, c);
    std::vector<std::uint64_t> local(d.counts.size(), 0);
    std::uint64_t outside = 0, declined = 0, non_finite = 0;
    const std::size_t end = std::min<std::size_t>(o.samples, (c + 1) * kChunk);
    for (std::size_t i = c * kChunk; i < end; ++i) {
      const double u0 = uniform01(g), u1 = uniform01(g);
      const Sample x = s.sample(u0, u1);
      constexpr double kInf = std::numeric_limits<double>::infinity();
      if (!x.valid) {
        ++declined, d.t[i] = kInf, d.phi[i] = kInf;
        continue;
      }
      if (!all_finite(x.direction) || !std::isfinite(x.pdf)) {
        ++non_finite, d.t[i] = kInf, d.phi[i] = kInf;
        continue;
      }
      Real t, phi;
      cap_coordinates(s.bounding_cap, x.direction.normalized(), t, phi);
      if (!(t <= 1 + slack)) {
        ++outside, d.t[i] = kInf, d.phi[i] = kInf;
        continue;
      }
      t = std::min<Real>(t, 1);
      d.t[i] = double(t);
      d.phi[i] = double(phi / kTwoPi<Real>);
      const int ri = std::min(R - 1, int(t * R));
      const int ai = std::min(A - 1, int(phi / kTwoPi<Real> * A));
      ++local[std::size_t(ri) * A + ai];
    }
    std::lock_guard lock(m);
    for (std::size_t k = 0; k < local.size(); ++k) d.counts[k] += local[k];
    d.outside += outside, d.declined += declined, d.non_finite += non_finite;
    const std::size_t n = ++done;
    if (o.progress && (n % 16 == 0 || n == chunks)) o.progress("sampling", double(n) / chunks);
  });
  return d;
}

// Expected mass of each chi-square bin, by quadrature of the pdf.
std::vector<Real> bin_masses(const SamplerUnderTest& s, const BatteryOptions& o) {
  const int R = o.radial_bins, A = o.azimuth_bins;
  std::vector<Real> mass(std::size_t(R) * A);
  parallel_for(mass.size(), thread_count(o), [&](std::size_t k) {
    const int ri = int(k / A), ai = int(k % A);
    mass[k] = integrate_cap_region(s.pdf, s.bounding_cap, Real(ri) / R, Real(ri + 1) / R, kTwoPi<Real> * ai / A,
                                   kTwoPi<Real> * (ai + 1) / A, o.quadrature_tolerance, 1, 1, s.boundary_planes);
  });
  return mass;
}

TestResult make_result(const SamplerUnderTest& s, std::string test) {
  TestResult r;
  r.kernel = s.kernel, r.scalar = s.scalar, r.config = s.config, r.test = std::move(test);
  return r;
}

TestResult chi_square(const SamplerUnderTest& s, const BatteryOptions& o, const Draws& d,
                      const std::vector<Real>& mass) {
  TestResult r = make_result(s, "chi2");
  const Real n = Real(o.samples);
  // Mass the pdf puts outside the cap (or nowhere): the complement of what the bins hold. Declined and
  // outside samples are compared against it.
  const Real inside = std::accumulate(mass.begin(), mass.end(), Real(0));
  const Real expected_elsewhere = std::max<Real>(0, n * (1 - inside));
  const std::uint64_t observed_elsewhere = d.outside + d.declined + d.non_finite;
  std::vector<std::pair<Real, Real>> bins;  // (expected, observed)
  std::size_t impossible = 0;
  for (std::size_t k = 0; k < mass.size(); ++k) {
    const Real e = n * mass[k];
    if (e <= 0 && d.counts[k] > 0) impossible += d.counts[k];
    bins.emplace_back(e, Real(d.counts[k]));
    r.observed.push_back(double(d.counts[k]));
    r.expected.push_back(double(e));
  }
  r.map_rows = o.radial_bins, r.map_cols = o.azimuth_bins;
  if (expected_elsewhere < 1e-3L && observed_elsewhere > 0)
    impossible += observed_elsewhere;
  else
    bins.emplace_back(expected_elsewhere, Real(observed_elsewhere));
  std::ostringstream detail;
  if (impossible > 0) {
    r.statistic = std::numeric_limits<double>::infinity();
    r.p_value = 0.0;
    detail << impossible << " samples where the pdf puts no mass (outside " << d.outside << ", declined " << d.declined
           << ", non-finite " << d.non_finite << ")";
    r.detail = detail.str();
    return r;
  }
  // Pool every bin expected to hold fewer than min_expected samples into one; if the pool is still too
  // small, fold it into the smallest regular bin.
  std::sort(bins.begin(), bins.end());
  Real pool_e = 0, pool_o = 0;
  std::size_t pooled = 0;
  std::vector<std::pair<Real, Real>> kept;
  for (const auto& b : bins) {
    if (b.first < o.min_expected)
      pool_e += b.first, pool_o += b.second, ++pooled;
    else
      kept.push_back(b);
  }
  if (pool_e > 0 || pool_o > 0) {
    if (pool_e >= o.min_expected || kept.empty())
      kept.emplace_back(pool_e, pool_o);
    else
      kept.front().first += pool_e, kept.front().second += pool_o;
  }
  Real chi2 = 0;
  for (const auto& [e, obs] : kept)
    if (e > 0) chi2 += (obs - e) * (obs - e) / e;
  const double dof = double(kept.size()) - 1;
  r.statistic = double(chi2);
  if (dof < 1) {
    r.p_value = 1.0;
    detail << "fewer than two bins after pooling";
  } else {
    boost::math::chi_squared dist(dof);
    r.p_value = double(boost::math::cdf(boost::math::complement(dist, double(chi2))));
    detail << "dof " << dof << ", " << mass.size() << " bins (" << o.radial_bins << "x" << o.azimuth_bins << "), "
           << pooled << " pooled";
  }
  r.detail = detail.str();
  return r;
}

// Kolmogorov-Smirnov against a CDF known at nodes x[0..M] (increasing). D is taken at the nodes only, where
// the CDF is known to quadrature accuracy, instead of interpolating between them (linear interpolation of a
// CDF with a kink, a polygon's vertex, errs by ~h * jump / 4, which at 1e7 samples is as large as the effect
// being tested). D_nodes <= D, so the p-value from the continuous KS distribution is conservative: the
// false-positive rate stays at most alpha, and with ~1000 nodes the loss of power is below what the sample
// count resolves (the calibration test checks the p-values for uniformity).
TestResult kolmogorov_smirnov(const SamplerUnderTest& s, std::string name, std::vector<double> values,
                              const std::vector<Real>& x, const std::vector<Real>& F) {
  TestResult r = make_result(s, std::move(name));
  std::sort(values.begin(), values.end());
  const double n = double(values.size());
  double D = 0;
  std::size_t i = 0;  // number of values <= x[k]
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double xk = k + 1 == x.size() ? std::numeric_limits<double>::max() : double(x[k]);
    while (i < values.size() && values[i] <= xk) ++i;
    // At the last node the empirical CDF counts every finite sample; samples beyond (outside the cap,
    // declined) leave it below 1.
    D = std::max(D, std::abs(double(F[k]) - double(i) / n));
  }
  r.statistic = D;
  boost::math::kolmogorov_smirnov_distribution<double> dist(n);
  r.p_value = boost::math::cdf(boost::math::complement(dist, D));
  std::ostringstream detail;
  detail << "n " << values.size() << ", D at " << x.size() << " nodes of the CDF from quadrature, mass "
         << double(F.back());
  r.detail = detail.str();
  return r;
}

// The two marginal CDFs of the KS tests, known at nodes (seed-independent: computed once per sampler).
struct KsCdfs {
  std::vector<Real> xr, Fr, xa, Fa;
};

KsCdfs ks_cdfs(const SamplerUnderTest& s, const BatteryOptions& o) {
  const int M = o.ks_cdf_nodes;
  const Cap<Real>& cap = s.bounding_cap;
  // Radial marginal: nodes clustered at both ends (Chebyshev-Lobatto), where the densities of visible-area
  // and horizon-cut samplers are singular or steep, so that linear interpolation stays far below 1/sqrt(n).
  std::vector<Real> xr(M + 1), xa(M + 1), dr(M, 0), da(M, 0);
  for (int k = 0; k <= M; ++k) {
    xr[k] = (1 - std::cos(kPi<Real> * k / M)) / 2;
    xa[k] = Real(k) / M;
  }
  xr[0] = 0, xr[M] = 1;
  // The CDFs need far less than the bins: KS at 1e7 samples resolves D ~ 1.36 / sqrt(n) = 4e-4, and slab errors
  // of 1e-6 relative sum to at most 1e-6 in F. Each of the 1024 azimuth slabs spans the whole cap, silhouette
  // included, so this is where a tight tolerance costs most. For the same reason each slab's radial lines start
  // with one panel per chi-square ring (as the radial slabs start with one azimuth panel per column): from a single
  // pair of 15-point rules per line, a lobe 1e-4 rad wide fell between the nodes (polygon-ltc near-singular,
  // |M| = 1e-8: the azimuth marginal's mass came out 0.997687, ks-azimuth p = 5e-47 at 1e7 samples; with one
  // panel per ring 1 - 1e-12, in the same time, and 0.8 -> 4.3 s for a smooth SPTD, measured with a scratch
  // program on the registry's cases).
  const Real ks_tol = std::max<Real>(o.quadrature_tolerance, 1e-6L);
  // And an absolute accuracy per slab of 1e-3 of D's resolution 1.36 / sqrt(n) shared by the M slabs (4.2e-10 at
  // 1e7 samples): the slabs' errors then move F by at most 1e-3 of what KS can resolve. Without it, the lines
  // that barely touch a float pdf's support (whose jumps its rounding blurs) ran to their panel budget: a
  // sliver's rings (nearly-edge-on, float, with boundary planes) took 1136 s of CPU, 160 s with it; in double the
  // rings' sums were unchanged to 14 digits (measured with a scratch program on the registry's case).
  const Real ks_abs = Real(1e-3) * Real(1.36) / std::sqrt(Real(o.samples)) / Real(M);
  parallel_for(std::size_t(2 * M), thread_count(o), [&](std::size_t k) {
    if (k < std::size_t(M))
      dr[k] = integrate_cap_region(s.pdf, cap, xr[k], xr[k + 1], 0, kTwoPi<Real>, ks_tol, o.azimuth_bins, 1,
                                   s.boundary_planes, ks_abs);
    else
      da[k - M] = integrate_cap_region(s.pdf, cap, 0, 1, kTwoPi<Real> * xa[k - M], kTwoPi<Real> * xa[k - M + 1], ks_tol,
                                       1, o.radial_bins, s.boundary_planes, ks_abs);
  });
  std::vector<Real> Fr(M + 1, 0), Fa(M + 1, 0);
  for (int k = 0; k < M; ++k) Fr[k + 1] = Fr[k] + dr[k], Fa[k + 1] = Fa[k] + da[k];
  if (o.progress) o.progress("ks", 0.5);
  return {std::move(xr), std::move(Fr), std::move(xa), std::move(Fa)};
}

void ks_tests(const SamplerUnderTest& s, const KsCdfs& c, Draws& d, std::vector<TestResult>& out) {
  out.push_back(kolmogorov_smirnov(s, "ks-radial", std::move(d.t), c.xr, c.Fr));
  out.push_back(kolmogorov_smirnov(s, "ks-azimuth", std::move(d.phi), c.xa, c.Fa));
}

TestResult pdf_integral(const SamplerUnderTest& s, const BatteryOptions& o, const std::vector<Real>& mass) {
  TestResult r = make_result(s, "pdf-integral");
  const Real inside = std::accumulate(mass.begin(), mass.end(), Real(0));
  // The rest of the sphere: t from 1 (the cap's edge) to 2 / omc (the antipode).
  const Real outside = integrate_cap_region(s.pdf, s.bounding_cap, 1, 2 / s.bounding_cap.one_minus_cos, 0, kTwoPi<Real>,
                                            o.quadrature_tolerance, o.azimuth_bins, 1, s.boundary_planes);
  const Real total = inside + outside;
  r.statistic = double(std::abs(total - 1));
  r.passed = std::isfinite(r.statistic) && r.statistic <= double(s.tolerance);
  std::ostringstream detail;
  detail.precision(12);
  detail << "integral " << double(total) << " (outside the bounding cap " << double(outside) << "), tolerance "
         << double(s.tolerance);
  r.detail = detail.str();
  return r;
}

// Inverse area element of the warp at (u0, u1) by 4th-order central differences in the reference warp.
// Returns NaN when a stencil point declines.
Real warp_density(const std::function<Sample(Real, Real)>& warp, Real u0, Real u1, Real h) {
  static constexpr Real c[4] = {1, -8, 8, -1};
  static constexpr int off[4] = {-2, -1, 1, 2};
  Vec3L d0 = Vec3L::Zero(), d1 = Vec3L::Zero();
  for (int k = 0; k < 4; ++k) {
    const Sample a = warp(u0 + off[k] * h, u1), b = warp(u0, u1 + off[k] * h);
    if (!a.valid || !b.valid) return std::numeric_limits<Real>::quiet_NaN();
    d0 += c[k] * a.direction, d1 += c[k] * b.direction;
  }
  d0 /= 12 * h, d1 /= 12 * h;
  return 1 / d0.cross(d1).norm();
}

TestResult pdf_consistency(const SamplerUnderTest& s, const BatteryOptions& o) {
  TestResult r = make_result(s, "pdf-consistency");
  const auto& warp = s.reference_sample ? s.reference_sample : std::function<Sample(Real, Real)>([&](Real a, Real b) {
    return s.sample(double(a), double(b));
  });
  std::mt19937_64 g = stream(o.seed, s, 2, 0);
  Real worst_self = 0, worst_jac = 0;
  Real worst_u[2] = {0, 0};
  std::size_t checked = 0, skipped = 0, declined = 0, unresolved = 0;
  // The primary sample as the kernel receives it: SamplerUnderTest::sample takes doubles, and a float kernel
  // rounds them to float. The reference's area element is taken at that rounded point; at the unrounded one a
  // float kernel looked wrong by the rounding's effect on its warp (near u0 = 1 a relative change
  // 6e-8 / (1 - u0) of the area left over: 4.6e-5 in the float projected-cap pdf at u0 = 0.9998, measured).
  const bool float_kernel = s.scalar == "float";
  auto as_received = [float_kernel](Real u) { return float_kernel ? Real(float(u)) : Real(double(u)); };
  for (int k = 0; k < o.consistency_points; ++k) {
    const Real u0 = as_received(uniform01(g)), u1 = as_received(uniform01(g));
    // Step: 1e-4, shrunk near the domain's edges and documented kinks so that the stencil stays on one
    // smooth piece (near u0 = 0 a cone warp behaves like sqrt(u0); h <= u0 / 50 keeps the 4th-order
    // truncation error below 1e-7 relative there).
    Real dist = std::min({u0, 1 - u0, u1, 1 - u1});
    for (Real kink : s.kinks_u0) dist = std::min(dist, std::abs(u0 - kink));
    for (Real kink : s.kinks_u1) dist = std::min(dist, std::abs(u1 - kink));
    const Real h = std::min<Real>(1e-4L, dist / 50);
    if (h < 1e-7L) {
      ++skipped;
      continue;
    }
    const Sample x = s.sample(double(u0), double(u1));
    if (!x.valid) {
      ++declined;
      continue;
    }
    const Real self = s.pdf(x.direction);
    const Real jac = warp_density(warp, u0, u1, h);
    // Resolution: the same difference with 2h. Where the two disagree by more than a quarter of the tolerance,
    // rounding noise of the reference warp (~eps_L / h relative, amplified by cancellation in the kernel, e.g.
    // a 1 mm light 40 m away: 1e-6 at h = 1e-5, measured) or a kink inside the stencil dominates, and the point
    // says nothing about the kernel: it is counted as unresolved, not checked. A warp whose density is wrong is
    // wrong at both steps alike, so this does not hide a bias; too many unresolved points fail the test.
    const Real jac2 = warp_density(warp, u0, u1, 2 * h);
    if (std::isfinite(jac) && std::isfinite(jac2) && !(std::abs(jac / jac2 - 1) <= s.tolerance / 4)) {
      ++unresolved;
      continue;
    }
    const Real e_self = std::abs(self / x.pdf - 1);
    const Real e_jac = std::isfinite(jac) ? std::abs(x.pdf / jac - 1) : std::numeric_limits<Real>::infinity();
    if (!(e_self <= worst_self)) worst_self = std::isnan(e_self) ? std::numeric_limits<Real>::infinity() : e_self;
    if (!(e_jac <= worst_jac)) {
      worst_jac = std::isnan(e_jac) ? std::numeric_limits<Real>::infinity() : e_jac;
      worst_u[0] = u0, worst_u[1] = u1;
    }
    ++checked;
  }
  r.statistic = double(std::max(worst_self, worst_jac));
  // At most 5% of the points unresolved: beyond that the check has lost its power and fails.
  r.passed = declined == 0 && checked > 0 && 20 * unresolved <= std::size_t(o.consistency_points) &&
             r.statistic <= double(s.tolerance);
  std::ostringstream detail;
  detail << "max |pdf(dir)/pdf - 1| " << double(worst_self) << ", max |pdf * area element - 1| " << double(worst_jac)
         << " at u=(" << double(worst_u[0]) << "," << double(worst_u[1]) << "); " << checked << " points, " << skipped
         << " skipped at kinks/edges, " << unresolved << " unresolved (steps h and 2h disagree by > tolerance / 4; "
         << "at most 5% allowed), " << declined << " declined; tolerance " << double(s.tolerance);
  if (!s.tolerance_note.empty()) detail << " (" << s.tolerance_note << ")";
  r.detail = detail.str();
  return r;
}

// For geometry that has no sample: every draw declines and the pdf is zero at random directions.
TestResult no_sample(const SamplerUnderTest& s, const BatteryOptions& o) {
  TestResult r = make_result(s, "no-sample");
  std::mt19937_64 g = stream(o.seed, s, 3, 0);
  std::size_t produced = 0, nonzero_pdf = 0;
  const int n = o.consistency_points;
  for (int k = 0; k < n; ++k) {
    if (s.sample(uniform01(g), uniform01(g)).valid) ++produced;
    // A uniformly random direction on the sphere.
    const Real z = 2 * Real(uniform01(g)) - 1, phi = kTwoPi<Real> * Real(uniform01(g));
    const Real rho = std::sqrt(std::max<Real>(0, 1 - z * z));
    if (s.pdf(Vec3L(rho * std::cos(phi), rho * std::sin(phi), z)) != 0) ++nonzero_pdf;
    if (s.pdf(cap_direction(s.bounding_cap, Real(uniform01(g)), kTwoPi<Real> * Real(uniform01(g)))) != 0) ++nonzero_pdf;
  }
  r.statistic = double(produced + nonzero_pdf);
  r.passed = produced == 0 && nonzero_pdf == 0;
  r.detail = std::to_string(produced) + " of " + std::to_string(n) + " draws produced a sample, " +
             std::to_string(nonzero_pdf) + " of " + std::to_string(2 * n) + " directions had a nonzero pdf";
  return r;
}

std::string fmt(double v, int prec = 4) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", prec, v);
  return buf;
}

std::string json_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\')
      o += '\\', o += c;
    else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      o += buf;
    } else
      o += c;
  }
  return o;
}

// JSON has no infinity; 1e999 is a valid JSON number that parsers read as +Infinity.
std::string json_number(double v) {
  if (std::isnan(v)) return "null";
  if (std::isinf(v)) return v > 0 ? "1e999" : "-1e999";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// Validates the options and the sampler; returns the options the battery really uses.
BatteryOptions checked_options(const SamplerUnderTest& s, const BatteryOptions& options) {
  // A float pdf carries rounding noise of a few FLT_EPSILON relative; asking the quadrature for 1e-8 of it only
  // spends every line's panel budget on noise (measured: sphere-visible-area float near took > 10 min of
  // quadrature instead of seconds). The tolerance is raised to 16 epsilon of the sampler's scalar type, 1.9e-6
  // for float: still 10^3 below the chi-square's resolution at 10^7 samples (a bin of 2e4 expected has a
  // relative standard deviation of 7e-3). Double and long double keep quadrature_tolerance.
  BatteryOptions o = options;
  o.quadrature_tolerance = std::max(o.quadrature_tolerance, 16 * double(scalar_epsilon(s.scalar)));
  if (!s.sample || !s.pdf) throw std::invalid_argument("SamplerUnderTest needs sample and pdf");
  if (!(s.bounding_cap.one_minus_cos > 0 && s.bounding_cap.one_minus_cos <= 2) || !all_finite(s.bounding_cap.axis))
    throw std::invalid_argument("SamplerUnderTest needs a bounding cap with 0 < 1 - cos(half-angle) <= 2");
  if (o.samples < 1000 || o.radial_bins < 1 || o.azimuth_bins < 1 || o.ks_cdf_nodes < 16)
    throw std::invalid_argument("battery options out of range (samples >= 1000, bins >= 1, ks_cdf_nodes >= 16)");
  return o;
}

// Everything of a battery run that does not depend on the seed: the bins' masses and the KS marginals by
// quadrature, and the deterministic tests (pdf integral, pdf consistency, normalisations).
struct Prepared {
  std::vector<Real> mass;
  KsCdfs ks;
  std::vector<TestResult> deterministic;
};

Prepared prepare(const SamplerUnderTest& s, const BatteryOptions& o) {
  Prepared p;
  if (o.progress) o.progress("quadrature", 0);
  p.mass = bin_masses(s, o);
  p.ks = ks_cdfs(s, o);
  p.deterministic.push_back(pdf_integral(s, o, p.mass));
  p.deterministic.push_back(pdf_consistency(s, o));
  for (const Normalization& nz : s.normalizations) {
    TestResult r = make_result(s, "normalization:" + nz.what);
    const Real k = nz.kernel();
    r.statistic = double(std::abs(k / nz.reference - 1));
    r.passed = r.statistic <= double(s.tolerance);
    r.detail = "kernel " + fmt(double(k), 17) + ", reference " + fmt(double(nz.reference), 17);
    p.deterministic.push_back(r);
  }
  return p;
}

// The seed's draws and the statistical tests on them, then the deterministic results: the order of run_battery.
std::vector<TestResult> run_seed(const SamplerUnderTest& s, const BatteryOptions& o, const Prepared& p) {
  std::vector<TestResult> out;
  Draws d = draw(s, o);
  out.push_back(chi_square(s, o, d, p.mass));
  ks_tests(s, p.ks, d, out);
  out.insert(out.end(), p.deterministic.begin(), p.deterministic.end());
  return out;
}

}  // namespace

std::vector<TestResult> run_battery(const SamplerUnderTest& s, const BatteryOptions& options) {
  return run_battery_seeds(s, options, {options.seed}).front();
}

std::vector<std::vector<TestResult>> run_battery_seeds(const SamplerUnderTest& s, const BatteryOptions& options,
                                                       const std::vector<std::uint64_t>& seeds) {
  const BatteryOptions o = checked_options(s, options);
  std::vector<std::vector<TestResult>> runs;
  if (s.expect_no_sample) {
    for (std::uint64_t seed : seeds) {
      BatteryOptions os = o;
      os.seed = seed;
      runs.push_back({no_sample(s, os)});
    }
    return runs;
  }
  const Prepared p = prepare(s, o);
  for (std::uint64_t seed : seeds) {
    BatteryOptions os = o;
    os.seed = seed;
    runs.push_back(run_seed(s, os, p));
  }
  return runs;
}

std::size_t apply_correction(std::vector<TestResult>& results, double alpha, Correction c) {
  std::vector<TestResult*> stat;
  for (auto& r : results)
    if (r.p_value) stat.push_back(&r);
  const std::size_t m = stat.size();
  if (m == 0) return 0;
  if (c == Correction::kSidak) {
    const double threshold = -std::expm1(std::log1p(-alpha) / double(m));  // 1 - (1 - alpha)^(1/m)
    for (auto* r : stat) r->passed = *r->p_value > threshold;
  } else {
    std::stable_sort(stat.begin(), stat.end(), [](auto* a, auto* b) { return *a->p_value < *b->p_value; });
    bool rejecting = true;
    for (std::size_t i = 0; i < m; ++i) {
      rejecting = rejecting && *stat[i]->p_value <= alpha / double(m - i);
      stat[i]->passed = !rejecting;
    }
  }
  return m;
}

bool all_passed(const std::vector<TestResult>& results) {
  return std::all_of(results.begin(), results.end(),
                     [](const TestResult& r) { return r.passed || !r.known_limitation.empty(); });
}

std::string format_table(const std::vector<TestResult>& results) {
  std::ostringstream o;
  char line[512];
  std::snprintf(line, sizeof line, "%-38s %-11s %-24s %-30s %12s %10s  %s\n", "kernel", "scalar", "config", "test",
                "statistic", "p-value", "verdict");
  o << line;
  for (const auto& r : results) {
    std::snprintf(line, sizeof line, "%-38s %-11s %-24s %-30s %12s %10s  %s\n", r.kernel.c_str(), r.scalar.c_str(),
                  r.config.c_str(), r.test.c_str(), fmt(r.statistic).c_str(),
                  r.p_value ? fmt(*r.p_value, 3).c_str() : "-",
                  r.passed ? "pass" : (r.known_limitation.empty() ? "FAIL" : "fail (known limitation)"));
    o << line;
  }
  return o.str();
}

std::string to_json(const std::vector<TestResult>& results, double alpha, Correction c,
                    const std::string& extra_members) {
  std::size_t m = 0;
  for (const auto& r : results) m += r.p_value.has_value();
  std::ostringstream o;
  o << "{\"alpha\":" << json_number(alpha) << ",\"correction\":\"" << to_string(c) << "\",\"statistical_tests\":" << m
    << (extra_members.empty() ? "" : ",") << extra_members << ",\"results\":[";
  for (std::size_t i = 0; i < results.size(); ++i) {
    const auto& r = results[i];
    o << (i ? ",\n" : "\n") << "{\"kernel\":\"" << json_escape(r.kernel) << "\",\"scalar\":\"" << json_escape(r.scalar)
      << "\",\"config\":\"" << json_escape(r.config) << "\",\"test\":\"" << json_escape(r.test)
      << "\",\"statistic\":" << json_number(r.statistic)
      << ",\"p_value\":" << (r.p_value ? json_number(*r.p_value) : "null")
      << ",\"passed\":" << (r.passed ? "true" : "false") << ",\"detail\":\"" << json_escape(r.detail) << "\"";
    if (!r.known_limitation.empty()) o << ",\"known_limitation\":\"" << json_escape(r.known_limitation) << "\"";
    if (r.map_rows > 0) {
      // Expected counts to 9 significant digits: enough for residual maps, a third of the bytes of %.17g.
      char buf[32];
      o << ",\"map\":{\"rows\":" << r.map_rows << ",\"cols\":" << r.map_cols << ",\"observed\":[";
      for (std::size_t k = 0; k < r.observed.size(); ++k) o << (k ? "," : "") << std::uint64_t(r.observed[k]);
      o << "],\"expected\":[";
      for (std::size_t k = 0; k < r.expected.size(); ++k) {
        std::snprintf(buf, sizeof buf, "%.9g", r.expected[k]);
        o << (k ? "," : "") << buf;
      }
      o << "]}";
    }
    o << "}";
  }
  o << "\n]}\n";
  return o.str();
}

std::vector<TestResult> validate(const SamplerUnderTest& s, const BatteryOptions& options, double alpha, Correction c) {
  std::vector<TestResult> r = run_battery(s, options);
  apply_correction(r, alpha, c);
  return r;
}

}  // namespace warpcheck::validation
