// warpcheck/validation/nelder_mead.h: the Nelder-Mead simplex method (Nelder & Mead 1965) in any scalar type,
// with box bounds and a deterministic multi-start driver, for the worst-case error searches (searches.h).
//
// Hand-rolled because no library we may use offers it in long double: Boost.Math 1.81 and Eigen 3.4 have no
// Nelder-Mead at all, and the simplex methods of NLopt and GSL work in double only. Peters 2021 (Sec. 3.6) ran
// its search in 80-bit floats so that rounding error does not masquerade as a failure of the method; we do
// the same, so the optimizer must not round its iterates to double.
//
// Local method: the standard coefficients (reflection 1, expansion 2, contraction 1/2, shrink 1/2) and the
// acceptance rules of Lagarias, Reeds, Wright & Wright, "Convergence properties of the Nelder-Mead simplex
// method in low dimensions", SIAM J. Optim. 9(1), 1998 (their Sec. 2, written from the text). Bounds are
// handled by projecting every trial point onto the box (the simplex may then flatten against a face, which
// the restarts make up for). A NaN objective value means "not a valid point" (e.g. a test case violating the
// search's constraints) and ranks below every number.
//
// Multi-start driver (run_chain): the search is split into *chains*, each a pure function of (seed, chain
// index), so results do not depend on thread count, timing or on being interrupted and resumed; shards of a
// search are disjoint sets of chain indices. A chain's first start is the best of `cheap_samples` uniform
// random points (cheaper than a local run per random point, and biased towards promising basins); its later
// starts are Gaussian perturbations of the chain's best so far with a log-uniform scale (intensification:
// worst cases of rounding-type errors sit in narrow spikes that a single local run rarely climbs to the top).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <span>
#include <vector>

namespace warpcheck::validation {

// A box [lo_i, hi_i] in parameter space.
template <class T> struct Bounds {
  std::vector<T> lo, hi;

  std::size_t dim() const { return lo.size(); }
  T width(std::size_t i) const { return hi[i] - lo[i]; }
  T clamp(std::size_t i, T v) const { return std::clamp(v, lo[i], hi[i]); }
};

enum class Goal { kMinimize, kMaximize };

template <class T> struct NelderMeadOptions {
  int max_iterations = 100;  // per local run (the paper's 100 per random initialisation)
  T initial_step = T(0.05);  // initial simplex edge, as a fraction of each box width
  T f_tolerance = T(0);      // stop when |f_worst - f_best| <= f_tolerance (|f_best| + tiny); 0: never
  T x_tolerance = T(0);      // stop when all simplex edges are below x_tolerance box widths; 0: never
  Goal goal = Goal::kMinimize;
};

template <class T> struct LocalResult {
  std::vector<T> x;
  T f = std::numeric_limits<T>::quiet_NaN();  // in the caller's sense (not negated)
  long long evaluations = 0;
  int iterations = 0;
};

namespace detail {
// Internally we always minimise `key`: f for kMinimize, -f for kMaximize, +inf for NaN.
template <class T> T key_of(T f, Goal g) {
  if (std::isnan(f)) return std::numeric_limits<T>::infinity();
  return g == Goal::kMinimize ? f : -f;
}
template <class T> T value_of(T key, Goal g) {
  if (key == std::numeric_limits<T>::infinity()) return std::numeric_limits<T>::quiet_NaN();
  return g == Goal::kMinimize ? key : -key;
}
}  // namespace detail

// One local run of Nelder-Mead from x0 (projected onto the box). F: T(std::span<const T>).
template <class T, class F>
LocalResult<T> nelder_mead(F&& f, const Bounds<T>& box, std::vector<T> x0, const NelderMeadOptions<T>& opt) {
  const std::size_t n = box.dim();
  LocalResult<T> out;
  auto eval = [&](std::vector<T>& x) {
    for (std::size_t i = 0; i < n; ++i) x[i] = box.clamp(i, x[i]);
    ++out.evaluations;
    return detail::key_of(T(f(std::span<const T>(x.data(), n))), opt.goal);
  };
  // Initial simplex: x0 and x0 + step e_i (or - step e_i where + would leave the box).
  std::vector<std::vector<T>> p(n + 1, x0);
  std::vector<T> k(n + 1);
  k[0] = eval(p[0]);
  for (std::size_t i = 0; i < n; ++i) {
    const T step = opt.initial_step * box.width(i);
    p[i + 1][i] = p[0][i] + step <= box.hi[i] ? p[0][i] + step : p[0][i] - step;
    k[i + 1] = eval(p[i + 1]);
  }
  std::vector<std::size_t> order(n + 1);
  std::vector<T> centroid(n), xr(n), xe(n), xc(n);
  auto sort = [&] {
    for (std::size_t i = 0; i <= n; ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return k[a] < k[b]; });
  };
  auto along = [&](std::vector<T>& dst, T t) {  // dst = centroid + t (centroid - worst)
    const std::vector<T>& w = p[order[n]];
    for (std::size_t i = 0; i < n; ++i) dst[i] = centroid[i] + t * (centroid[i] - w[i]);
  };
  sort();
  for (; out.iterations < opt.max_iterations; ++out.iterations) {
    const std::size_t best = order[0], worst = order[n], second = order[n - 1];
    if (opt.f_tolerance > T(0) && std::isfinite(k[worst]) &&
        std::abs(k[worst] - k[best]) <= opt.f_tolerance * (std::abs(k[best]) + std::numeric_limits<T>::min()))
      break;
    if (opt.x_tolerance > T(0)) {
      bool small = true;
      for (std::size_t v = 1; v <= n && small; ++v)
        for (std::size_t i = 0; i < n && small; ++i)
          small = std::abs(p[order[v]][i] - p[best][i]) <= opt.x_tolerance * box.width(i);
      if (small) break;
    }
    std::fill(centroid.begin(), centroid.end(), T(0));
    for (std::size_t v = 0; v < n; ++v)
      for (std::size_t i = 0; i < n; ++i) centroid[i] += p[order[v]][i];
    for (std::size_t i = 0; i < n; ++i) centroid[i] /= T(n);
    along(xr, T(1));  // reflection
    const T kr = eval(xr);
    if (kr < k[best]) {
      along(xe, T(2));  // expansion
      const T ke = eval(xe);
      if (ke < kr)
        p[worst] = xe, k[worst] = ke;
      else
        p[worst] = xr, k[worst] = kr;
    } else if (kr < k[second]) {
      p[worst] = xr, k[worst] = kr;
    } else {
      bool accepted = false;
      if (kr < k[worst]) {
        along(xc, T(0.5));  // outside contraction
        const T kc = eval(xc);
        if (kc <= kr) p[worst] = xc, k[worst] = kc, accepted = true;
      } else {
        along(xc, T(-0.5));  // inside contraction
        const T kc = eval(xc);
        if (kc < k[worst]) p[worst] = xc, k[worst] = kc, accepted = true;
      }
      if (!accepted) {  // shrink towards the best vertex
        for (std::size_t v = 1; v <= n; ++v) {
          std::vector<T>& x = p[order[v]];
          for (std::size_t i = 0; i < n; ++i) x[i] = p[best][i] + T(0.5) * (x[i] - p[best][i]);
          k[order[v]] = eval(x);
        }
      }
    }
    sort();
  }
  out.x = p[order[0]];
  out.f = detail::value_of(k[order[0]], opt.goal);
  return out;
}

template <class T> struct MultiStartOptions {
  NelderMeadOptions<T> local;
  int cheap_samples = 32;      // a chain's first start: the best of this many uniform random valid points
  int max_cheap_tries = 4096;  // give up looking for valid points after this many draws
  int chain_length = 4;        // local runs per chain: 1 from the cheap samples, the rest around the chain's best
  // Perturbation scale of the later starts (and their initial simplex), in box widths, log-uniform. Measured
  // on 6-D Rosenbrock (test_nelder_mead): a floor of 1e-4 beats 1e-5 and 1e-7, whose tiny simplices crawl.
  T refine_scale_min = T(1e-4), refine_scale_max = T(1e-1);
};

template <class T> struct ChainResult {
  std::vector<T> x;  // empty if the chain found no valid point
  T f = std::numeric_limits<T>::quiet_NaN();
  long long evaluations = 0;
};

// SplitMix64 (Steele, Lea & Flood 2014): decorrelates (seed, chain) into a generator seed.
inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// Is a better than b in the sense of goal (NaN is worse than everything)?
template <class T> bool better(T a, T b, Goal g) { return detail::key_of(a, g) < detail::key_of(b, g); }

// One chain of the multi-start search: a pure function of (seed, chain).
template <class T, class F> ChainResult<T> run_chain(F&& f, const Bounds<T>& box, const MultiStartOptions<T>& opt,
                                                     std::uint64_t seed, std::uint64_t chain) {
  const Goal goal = opt.local.goal;
  std::mt19937_64 rng(splitmix64(seed ^ splitmix64(chain)));
  std::uniform_real_distribution<long double> U(0.0L, 1.0L);
  std::normal_distribution<long double> N(0.0L, 1.0L);
  const std::size_t n = box.dim();
  ChainResult<T> out;
  std::vector<T> x(n);
  auto consider = [&](const std::vector<T>& cand, T fv) {
    if (out.x.empty() ? !std::isnan(fv) : better(fv, out.f, goal)) out.x = cand, out.f = fv;
  };
  // First start: the best of cheap_samples valid uniform points.
  int valid = 0;
  for (int tries = 0; tries < opt.max_cheap_tries && valid < opt.cheap_samples; ++tries) {
    for (std::size_t i = 0; i < n; ++i) x[i] = box.lo[i] + T(U(rng)) * box.width(i);
    const T fv = T(f(std::span<const T>(x.data(), n)));
    ++out.evaluations;
    if (std::isnan(fv)) continue;
    ++valid;
    consider(x, fv);
  }
  if (out.x.empty()) return out;
  for (int run = 0; run < opt.chain_length; ++run) {
    std::vector<T> start = out.x;
    NelderMeadOptions<T> local = opt.local;
    if (run > 0) {
      const long double lmin = std::log(static_cast<long double>(opt.refine_scale_min));
      const long double lmax = std::log(static_cast<long double>(opt.refine_scale_max));
      const T scale = T(std::exp(lmin + (lmax - lmin) * U(rng)));
      for (std::size_t i = 0; i < n; ++i) start[i] = box.clamp(i, start[i] + scale * T(N(rng)) * box.width(i));
      local.initial_step = scale;
    }
    const LocalResult<T> r = nelder_mead(f, box, start, local);
    out.evaluations += r.evaluations;
    consider(r.x, r.f);
  }
  return out;
}

// Convenience: chains 0 .. chains-1 in sequence, the best of them.
template <class T, class F> ChainResult<T> multi_start(F&& f, const Bounds<T>& box, const MultiStartOptions<T>& opt,
                                                       std::uint64_t seed, int chains) {
  ChainResult<T> best;
  for (int c = 0; c < chains; ++c) {
    ChainResult<T> r = run_chain(f, box, opt, seed, std::uint64_t(c));
    best.evaluations += r.evaluations;
    if (!r.x.empty() && (best.x.empty() || better(r.f, best.f, opt.local.goal))) best.x = r.x, best.f = r.f;
  }
  return best;
}

}  // namespace warpcheck::validation
