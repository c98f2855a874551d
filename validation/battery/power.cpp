// The battery's power against the standard alternatives, and sample-count planning (power.h).
#include "warpcheck/validation/power.h"

#include <algorithm>
#include <array>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/kolmogorov_smirnov.hpp>
#include <boost/math/distributions/non_central_chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numeric>

#include "battery/tests.h"

namespace warpcheck::validation {

const char* to_string(Alternative a) {
  switch (a) {
    case Alternative::kRegion:
      return "region";
    case Alternative::kTilt:
      return "tilt";
    case Alternative::kWedge:
      return "wedge";
  }
  return "?";
}

double first_step_level(double alpha, Correction c, std::size_t m) {
  const double md = double(std::max<std::size_t>(m, 1));
  return c == Correction::kSidak ? -std::expm1(std::log1p(-alpha) / md) : alpha / md;
}

GridMasses grid_masses(const TestResult& chi2, std::uint64_t n) {
  GridMasses g{chi2.map_rows, chi2.map_cols, {}};
  for (double e : chi2.expected) g.mass.push_back(e / double(n));
  return g;
}

GridMasses grid_masses(const SamplerUnderTest& s, const BatteryOptions& options) {
  BatteryOptions o = options;
  o.quadrature_tolerance = std::max(o.quadrature_tolerance, 16 * double(battery::scalar_epsilon(s.scalar)));
  const battery::Expected e = battery::expected_integrals(s, o);
  GridMasses g{o.radial_bins, o.azimuth_bins, {}};
  for (Real m : e.mass) g.mass.push_back(double(m));
  return g;
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kSub = 8;  // sub-rows per ring and sub-columns per column at which g is resolved

// An alternative's parameters on a grid: the region's edge t10, the tilt's mean t and scale, the wedge's
// compensation -w / (mass - w); and the constant that re-centres g so that p's integral of it is exactly 0.
struct Params {
  Alternative a = Alternative::kRegion;
  bool defined = false;
  int R = 0, A = 0;
  double t10 = 1, mean = 0, scale = 1, outside_wedge = 0, centre = 0;
  double g(double t, double u) const {  // before re-centring
    if (a == Alternative::kWedge) return u < 1.0 / A ? 1 : outside_wedge;
    if (a == Alternative::kRegion) return t <= t10 ? 1 : -1.0 / 9;
    return (t - mean) / scale;
  }
};

Params parameters(int R, int A, Alternative a, const std::vector<double>& ring, const std::vector<double>& column,
                  double total) {
  Params q{a, false, R, A};
  if (!(total > 0)) return q;
  if (a == Alternative::kWedge) {
    const double w = column[0];
    q.outside_wedge = -w / (total - w), q.defined = w > 0 && w < total;
  } else if (a == Alternative::kRegion) {
    // t10: where the ring-interpolated radial CDF reaches a tenth of the mass.
    double cum = 0;
    for (int r = 0; r < R; ++r) {
      if (ring[std::size_t(r)] > 0 && cum + ring[std::size_t(r)] >= total / 10) {
        q.t10 = (r + (total / 10 - cum) / ring[std::size_t(r)]) / R;
        break;
      }
      cum += ring[std::size_t(r)];
    }
    q.defined = true;
  } else {
    // The tilt: t's mean under p, and the support's extent in whole rings.
    int lo = R, hi = -1;
    for (int r = 0; r < R; ++r)
      if (ring[std::size_t(r)] > 0) lo = std::min(lo, r), hi = r, q.mean += ring[std::size_t(r)] * (r + 0.5) / R;
    q.mean /= total;
    q.scale = std::max(q.mean - double(lo) / R, double(hi + 1) / R - q.mean);
    q.defined = true;
  }
  return q;
}

// g's mean over each of the kSub sub-rows of every ring (radial alternatives; the region's edge cuts one sub-row
// in proportion) or sub-columns of every column (the wedge), before re-centring.
std::vector<double> sub_g(const Params& q) {
  const bool radial = q.a != Alternative::kWedge;
  const int parts = (radial ? q.R : q.A) * kSub;
  std::vector<double> g;
  for (int j = 0; j < parts; ++j) {
    const double x0 = double(j) / parts, x1 = double(j + 1) / parts;
    if (q.a == Alternative::kRegion) {
      const double f = std::clamp((q.t10 - x0) / (x1 - x0), 0.0, 1.0);
      g.push_back(f - (1 - f) / 9);
    } else {
      g.push_back(radial ? q.g((x0 + x1) / 2, 0) : q.g(0, (x0 + x1) / 2));
    }
  }
  return g;
}

// An alternative's shape on the grid: the mean of g over each bin (row-major), and the change of mass per unit eps
// of each sub-row (R kSub) and sub-column (A kSub), each bin's mass spread uniformly over its rectangle.
struct Shape {
  Params params;
  std::vector<double> bin_g, sub_row_delta, sub_col_delta, sub_row_mass, sub_col_mass;
};

Shape shape(const GridMasses& m, Alternative a) {
  const int R = m.rows, A = m.cols;
  auto p = [&](int r, int c) { return std::max(0.0, m.mass[std::size_t(r * A + c)]); };
  std::vector<double> ring(std::size_t(R), 0), column(std::size_t(A), 0);
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < A; ++c) ring[std::size_t(r)] += p(r, c), column[std::size_t(c)] += p(r, c);
  const double total = std::accumulate(ring.begin(), ring.end(), 0.0);
  Shape sh;
  sh.params = parameters(R, A, a, ring, column, total);
  if (!sh.params.defined) return sh;
  std::vector<double> g = sub_g(sh.params);
  const bool radial = a != Alternative::kWedge;
  // The mean of g over each ring (radial) or column, then re-centred so that p's integral of g is exactly 0.
  std::vector<double> mean_g(std::size_t(radial ? R : A), 0);
  for (std::size_t j = 0; j < g.size(); ++j) mean_g[j / kSub] += g[j] / kSub;
  double centre = 0;
  for (std::size_t k = 0; k < mean_g.size(); ++k) centre += (radial ? ring : column)[k] * mean_g[k];
  sh.params.centre = centre /= total;
  for (double& x : g) x -= centre;
  for (double& x : mean_g) x -= centre;
  sh.bin_g.resize(std::size_t(R) * A);
  sh.sub_row_delta.assign(std::size_t(R) * kSub, 0), sh.sub_row_mass.assign(std::size_t(R) * kSub, 0);
  sh.sub_col_delta.assign(std::size_t(A) * kSub, 0), sh.sub_col_mass.assign(std::size_t(A) * kSub, 0);
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < A; ++c) {
      const double pk = p(r, c) / kSub;
      sh.bin_g[std::size_t(r * A + c)] = mean_g[std::size_t(radial ? r : c)];
      for (int k = 0; k < kSub; ++k) {
        const std::size_t jr = std::size_t(r * kSub + k), jc = std::size_t(c * kSub + k);
        sh.sub_row_mass[jr] += pk, sh.sub_col_mass[jc] += pk;
        sh.sub_row_delta[jr] += pk * (radial ? g[jr] : mean_g[std::size_t(c)]);
        sh.sub_col_delta[jc] += pk * (radial ? mean_g[std::size_t(r)] : g[jc]);
      }
    }
  return sh;
}

// The non-centrality at which chi-square with dof degrees of freedom exceeds its critical value at `level` with
// probability `target`. Remembered per thread: a run's cases share a few (dof, level) pairs, and run_power is
// called at every checkpoint of a long run.
double critical_non_centrality(double dof, double level, double target) {
  thread_local std::map<std::array<double, 3>, double> known;
  const std::array<double, 3> key{dof, level, target};
  if (const auto it = known.find(key); it != known.end()) return it->second;
  const double critical = boost::math::quantile(boost::math::complement(boost::math::chi_squared(dof), level));
  return known[key] = boost::math::non_central_chi_squared::find_non_centrality(dof, critical, 1 - target);
}

// A chi-square test on cells of the grid (cell_of(r, c)), with the outside cell: the eps at which its power is
// `target` (non-central chi-square, lambda proportional to eps^2).
template <class CellOf> double chi2_eps(const GridMasses& m, const Shape& sh, int cells, CellOf cell_of,
                                        std::uint64_t n, double level, double target, double min_expected) {
  std::vector<std::pair<Real, Real>> e_x(std::size_t(cells), {0, 0});  // (expected count, its change per eps)
  double total = 0;
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c) {
      const std::size_t k = std::size_t(r * m.cols + c);
      const double pk = std::max(0.0, m.mass[k]);
      auto& cell = e_x[std::size_t(cell_of(r, c))];
      cell.first += Real(double(n) * pk), cell.second += Real(double(n) * pk * sh.bin_g[k]);
      total += pk;
    }
  e_x.emplace_back(Real(double(n) * std::max(0.0, 1 - total)), 0);
  std::size_t pooled = 0;
  const auto kept = battery::pool_low_expected(std::move(e_x), min_expected, pooled);
  double lambda1 = 0;
  for (const auto& [e, x] : kept)
    if (e > 0) lambda1 += double(x * x / e);
  const double dof = double(kept.size()) - 1;
  // Cells whose change is rounding (below 1e-12 of the mass per unit eps, lambda1 / n below 1e-24): an
  // alternative this test does not see, as a radial one for the columns.
  if (dof < 1 || !(lambda1 > 1e-24 * double(n))) return kInf;
  return std::sqrt(critical_non_centrality(dof, level, target) / lambda1);
}

// Massey's bound for a KS test whose CDF (sub-interval masses `mass`) moves by `delta` per unit eps.
double ks_eps(const std::vector<double>& mass, const std::vector<double>& delta, std::uint64_t n, double level,
              double target) {
  thread_local std::map<std::pair<std::uint64_t, double>, double> critical;  // per (n, level), as above
  double& d = critical[{n, level}];
  if (d == 0)
    d = boost::math::quantile(
        boost::math::complement(boost::math::kolmogorov_smirnov_distribution<double>(double(n)), level));
  const double z = boost::math::quantile(boost::math::normal(), target);
  double F = 0, h = 0, best = kInf;
  for (std::size_t j = 0; j + 1 < mass.size(); ++j) {
    F += mass[j], h += delta[j];
    if (std::abs(h) > 1e-12)  // beyond rounding, as for the chi-square cells
      best = std::min(best, (d + z * std::sqrt(std::max(0.0, F * (1 - F)) / double(n))) / std::abs(h));
  }
  return best;
}

}  // namespace

std::vector<TestPower> test_power(const GridMasses& g, Alternative a, std::uint64_t n, double level, double target,
                                  double min_expected) {
  const Shape sh = shape(g, a);
  std::vector<TestPower> out;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.push_back({"chi2", sh.params.defined ? chi2_eps(
                                                 g, sh, g.rows * g.cols, [&](int r, int c) { return r * g.cols + c; },
                                                 n, level, target, min_expected)
                                           : nan});
  for (const battery::GridAggregate& agg : battery::grid_aggregates(g.rows, g.cols))
    out.push_back({agg.test, sh.params.defined ? chi2_eps(
                                                     g, sh, agg.rows * agg.cols,
                                                     [&](int r, int c) { return agg.cell(r, c, g.rows, g.cols); }, n,
                                                     level, target, min_expected)
                                               : nan});
  out.push_back({"ks-radial", sh.params.defined ? ks_eps(sh.sub_row_mass, sh.sub_row_delta, n, level, target) : nan});
  out.push_back({"ks-azimuth", sh.params.defined ? ks_eps(sh.sub_col_mass, sh.sub_col_delta, n, level, target) : nan});
  return out;
}

std::vector<PowerFigure> power_figures(const GridMasses& g, std::uint64_t n, double level, double target,
                                       double min_expected) {
  std::vector<PowerFigure> out;
  for (Alternative a : kAlternatives) {
    PowerFigure f{to_string(a), "", kInf};
    for (const TestPower& t : test_power(g, a, n, level, target, min_expected)) {
      if (std::isnan(t.eps)) {  // not defined on this grid: NaN for every test
        f.eps = t.eps;
        break;
      }
      if (t.eps < f.eps) f.eps = t.eps, f.test = t.test;
    }
    out.push_back(f);
  }
  return out;
}

std::function<double(double, double)> relative_error(const GridMasses& g, Alternative a) {
  const Params q = shape(g, a).params;
  if (!q.defined) return {};
  return [q](double t, double u) { return q.g(t, u) - q.centre; };
}

std::vector<CasePower> run_power(const BatteryRun& run) {
  std::vector<CasePower> out;
  if (!run.samples) return out;
  const double level = first_step_level(run.alpha, run.correction, run.statistical_tests());
  for (const TestResult& r : run.results) {
    if (r.map_rows <= 0 || r.expected.size() != std::size_t(r.map_rows) * std::size_t(r.map_cols)) continue;
    CasePower c{r.kernel, r.scalar, r.config, *run.samples, level, 0.9, {}};
    c.figures = power_figures(grid_masses(r, *run.samples), *run.samples, level, c.target);
    out.push_back(std::move(c));
  }
  return out;
}

std::uint64_t samples_needed(const GridMasses& g, Alternative a, double eps, double alpha, Correction c,
                             std::size_t statistical_tests, double target, double min_expected) {
  const double level = first_step_level(alpha, c, statistical_tests);
  auto reached = [&](std::uint64_t n) {
    for (const TestPower& t : test_power(g, a, n, level, target, min_expected))
      if (t.eps <= eps) return true;
    return false;
  };
  std::uint64_t lo = 1, hi = std::uint64_t(1) << 62;
  if (!reached(hi)) return 0;
  // The power grows with n (lambda and sqrt(n) |h| both do); the pooling's steps can break that by a few samples
  // at most, which the bisection tolerates.
  while (hi - lo > 1) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    (reached(mid) ? hi : lo) = mid;
  }
  return hi;
}

}  // namespace warpcheck::validation
