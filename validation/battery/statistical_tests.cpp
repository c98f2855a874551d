// The battery's statistical tests (tests.h): chi-square on an equal-area grid over the bounding cap with
// expected counts by quadrature, chi-square on aggregates of that grid (its rings, its columns, a coarse grid),
// and Kolmogorov-Smirnov on the two marginals in the cap's frame.
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/kolmogorov_smirnov.hpp>
#include <cmath>
#include <numeric>
#include <sstream>

#include "battery/cap_grid.h"
#include "battery/tests.h"

namespace warpcheck::validation::battery {

std::vector<std::pair<Real, Real>> pool_low_expected(std::vector<std::pair<Real, Real>> cells, double min_expected,
                                                     std::size_t& pooled) {
  // Every cell expected to hold fewer than min_expected samples joins one pool; if the pool is still too small,
  // it is folded into the smallest regular cell.
  std::sort(cells.begin(), cells.end());
  Real pool_e = 0, pool_x = 0;
  pooled = 0;
  std::vector<std::pair<Real, Real>> kept;
  for (const auto& c : cells) {
    if (c.first < min_expected)
      pool_e += c.first, pool_x += c.second, ++pooled;
    else
      kept.push_back(c);
  }
  if (pool_e > 0 || pool_x > 0) {
    if (pool_e >= min_expected || kept.empty())
      kept.emplace_back(pool_e, pool_x);
    else
      kept.front().first += pool_e, kept.front().second += pool_x;
  }
  return kept;
}

std::vector<Real> reference_bin_masses(const SamplerUnderTest& s, const BatteryOptions& o) {
  const int R = o.radial_bins, A = o.azimuth_bins;
  std::vector<Real> mass(std::size_t(R) * A);
  parallel_for(mass.size(), thread_count(o), [&](std::size_t k) {
    const int ri = int(k / A), ai = int(k % A);
    mass[k] = integrate_cap_region(s.pdf, s.bounding_cap, Real(ri) / R, Real(ri + 1) / R, kTwoPi<Real> * ai / A,
                                   kTwoPi<Real> * (ai + 1) / A, o.quadrature_tolerance, 1, 1, boundary_of(s));
  });
  return mass;
}

namespace {

// Pearson's statistic over the cells (expected, observed) into r.statistic, and its p-value from Boost's chi-square
// survival with cells - 1 degrees of freedom (1 with fewer than two cells); returns the degrees of freedom.
double pearson(const std::vector<std::pair<Real, Real>>& cells, TestResult& r) {
  Real chi2 = 0;
  for (const auto& [e, obs] : cells)
    if (e > 0) chi2 += (obs - e) * (obs - e) / e;
  const double dof = double(cells.size()) - 1;
  r.statistic = double(chi2);
  if (dof < 1) {
    r.p_value = 1.0;
  } else {
    boost::math::chi_squared dist(dof);
    r.p_value = double(boost::math::cdf(boost::math::complement(dist, double(chi2))));
  }
  return dof;
}

// Appends the cell of the samples outside the cap, declined or non-finite, compared with the pdf's mass outside;
// when the pdf puts (almost) no mass there, returns those samples as impossible instead.
std::uint64_t add_elsewhere_cell(std::vector<std::pair<Real, Real>>& cells, Real expected, std::uint64_t observed) {
  if (expected < 1e-3L && observed > 0) return observed;
  cells.emplace_back(expected, Real(observed));
  return 0;
}

}  // namespace

TestResult chi_square(const SamplerUnderTest& s, const BatteryOptions& o, const Draws& d, const Expected& ex) {
  const std::vector<Real>& mass = ex.mass;
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
  impossible += add_elsewhere_cell(bins, expected_elsewhere, observed_elsewhere);
  std::ostringstream detail;
  if (impossible > 0) {
    r.statistic = std::numeric_limits<double>::infinity();
    r.p_value = 0.0;
    detail << impossible << " samples where the pdf puts no mass (outside " << d.outside << ", declined " << d.declined
           << ", non-finite " << d.non_finite << ")";
    r.detail = detail.str();
    return r;
  }
  std::size_t pooled = 0;
  const std::vector<std::pair<Real, Real>> kept = pool_low_expected(std::move(bins), o.min_expected, pooled);
  const double dof = pearson(kept, r);
  if (dof < 1) {
    detail << "fewer than two bins after pooling";
  } else {
    detail << "dof " << dof << ", " << mass.size() << " bins (" << o.radial_bins << "x" << o.azimuth_bins << "), "
           << pooled << " pooled; expected counts by " << ex.quadrature;
  }
  r.detail = detail.str();
  return r;
}

std::vector<GridAggregate> grid_aggregates(int radial_bins, int azimuth_bins) {
  return {{"chi2-rings", radial_bins, 1},
          {"chi2-columns", 1, azimuth_bins},
          {"chi2-coarse", std::min(4, radial_bins), std::min(8, azimuth_bins)}};
}

void aggregate_chi_squares(const SamplerUnderTest& s, const BatteryOptions& o, const Draws& d, const Expected& ex,
                           std::vector<TestResult>& out) {
  const int R = o.radial_bins, A = o.azimuth_bins;
  const Real n = Real(o.samples);
  const Real inside = std::accumulate(ex.mass.begin(), ex.mass.end(), Real(0));
  const Real expected_elsewhere = std::max<Real>(0, n * (1 - inside));
  const std::uint64_t observed_elsewhere = d.outside + d.declined + d.non_finite;
  for (const GridAggregate& g : grid_aggregates(R, A)) {
    TestResult r = make_result(s, g.test);
    std::vector<std::pair<Real, Real>> cells(std::size_t(g.rows) * std::size_t(g.cols), {0, 0});
    for (int ri = 0; ri < R; ++ri)
      for (int ai = 0; ai < A; ++ai) {
        auto& c = cells[std::size_t(g.cell(ri, ai, R, A))];
        c.first += n * ex.mass[std::size_t(ri * A + ai)], c.second += Real(d.counts[std::size_t(ri * A + ai)]);
      }
    std::size_t impossible = 0;
    for (const auto& [e, obs] : cells)
      if (e <= 0 && obs > 0) impossible += std::size_t(obs);
    impossible += add_elsewhere_cell(cells, expected_elsewhere, observed_elsewhere);
    std::ostringstream detail;
    if (impossible > 0) {
      r.statistic = std::numeric_limits<double>::infinity(), r.p_value = 0.0;
      detail << impossible << " samples where the pdf puts no mass";
    } else {
      std::size_t pooled = 0;
      const double dof = pearson(pool_low_expected(std::move(cells), o.min_expected, pooled), r);
      detail << "dof " << dof << ", " << g.rows << "x" << g.cols << " cells of the " << R << "x" << A << " grid, "
             << pooled << " pooled";
    }
    r.detail = detail.str();
    out.push_back(std::move(r));
  }
}

namespace {

// Kolmogorov-Smirnov against a CDF known at nodes x[0..M] (increasing). D is taken at the nodes only, where
// the CDF is known to quadrature accuracy, instead of interpolating between them (linear interpolation of a
// CDF with a kink, a polygon's vertex, errs by ~h * jump / 4, which at 1e7 samples is as large as the effect
// being tested). D_nodes <= D, so the p-value from the continuous KS distribution is conservative: the
// false-positive rate stays at most alpha, and with ~1000 nodes the loss of power is below what the sample
// count resolves (the calibration test checks the p-values for uniformity).
// slabs[k]: the samples whose coordinate has slab k (SlabLocator), so that their running sum at node k is the number
// of values <= x[k], and at the last node every finite value; n counts every sample.
TestResult kolmogorov_smirnov(const SamplerUnderTest& s, std::string name, const std::vector<std::uint64_t>& slabs,
                              std::uint64_t n, const std::vector<Real>& x, const std::vector<Real>& F) {
  TestResult r = make_result(s, std::move(name));
  const double nd = double(n);
  double D = 0;
  std::uint64_t i = 0;  // number of values <= x[k]
  for (std::size_t k = 0; k < x.size(); ++k) {
    i += slabs[k];
    // At the last node the empirical CDF counts every finite sample; samples beyond (outside the cap,
    // declined) leave it below 1.
    D = std::max(D, std::abs(double(F[k]) - double(i) / nd));
  }
  r.statistic = D;
  boost::math::kolmogorov_smirnov_distribution<double> dist(nd);
  // Far in the tail Boost's survival series gives -0: the p-value is +0 there.
  r.p_value = std::max(0.0, boost::math::cdf(boost::math::complement(dist, D)));
  std::ostringstream detail;
  detail << "n " << n << ", D at " << x.size() << " nodes of the CDF from quadrature, mass " << double(F.back());
  r.detail = detail.str();
  return r;
}

}  // namespace

KsCdfs ks_nodes(const BatteryOptions& o) {
  const int M = o.ks_cdf_nodes;
  // Radial nodes clustered at both ends (Chebyshev-Lobatto), where the densities of visible-area and
  // horizon-cut samplers are singular or steep; azimuth nodes equally spaced.
  KsCdfs c;
  c.xr.resize(std::size_t(M) + 1), c.xa.resize(std::size_t(M) + 1);
  for (int k = 0; k <= M; ++k) {
    c.xr[std::size_t(k)] = (1 - std::cos(kPi<Real> * k / M)) / 2;
    c.xa[std::size_t(k)] = Real(k) / M;
  }
  c.xr.front() = 0, c.xr.back() = 1;
  return c;
}

KsCdfs reference_ks_cdfs(const SamplerUnderTest& s, const BatteryOptions& o) {
  const int M = o.ks_cdf_nodes;
  const Cap<Real>& cap = s.bounding_cap;
  KsCdfs nodes = ks_nodes(o);
  std::vector<Real> xr = std::move(nodes.xr), xa = std::move(nodes.xa), dr(M, 0), da(M, 0);
  // The CDFs need far less than the bins: KS at 1e7 samples resolves D ~ 1.36 / sqrt(n) = 4e-4, and slab errors
  // of 1e-6 relative sum to at most 1e-6 in F. Each of the 1024 azimuth slabs spans the whole cap, silhouette
  // included, so this is where a tight tolerance costs most. Each slab's radial lines start with one panel per
  // chi-square ring (as the radial slabs start with one azimuth panel per column), so that a lobe narrower than
  // the first rule's node spacing (a near-singular LTC's) cannot fall between the nodes.
  const Real ks_tol = std::max<Real>(o.quadrature_tolerance, 1e-6L);
  // And an absolute accuracy per slab of 1e-3 of D's resolution 1.36 / sqrt(n) shared by the M slabs (4.2e-10 at
  // 1e7 samples): the slabs' errors then move F by at most 1e-3 of what KS can resolve, and the lines that barely
  // touch a float pdf's support (whose jumps its rounding blurs) stop there instead of at their panel budget.
  const Real ks_abs = Real(1e-3) * Real(1.36) / std::sqrt(Real(o.samples)) / Real(M);
  parallel_for(std::size_t(2 * M), thread_count(o), [&](std::size_t k) {
    if (k < std::size_t(M))
      dr[k] = integrate_cap_region(s.pdf, cap, xr[k], xr[k + 1], 0, kTwoPi<Real>, ks_tol, o.azimuth_bins, 1,
                                   boundary_of(s), ks_abs);
    else
      da[k - M] = integrate_cap_region(s.pdf, cap, 0, 1, kTwoPi<Real> * xa[k - M], kTwoPi<Real> * xa[k - M + 1], ks_tol,
                                       1, o.radial_bins, boundary_of(s), ks_abs);
  });
  std::vector<Real> Fr(M + 1, 0), Fa(M + 1, 0);
  for (int k = 0; k < M; ++k) Fr[k + 1] = Fr[k] + dr[k], Fa[k + 1] = Fa[k] + da[k];
  if (o.progress) o.progress("ks", 0.5);
  return {std::move(xr), std::move(Fr), std::move(xa), std::move(Fa)};
}

void ks_tests(const SamplerUnderTest& s, const KsCdfs& c, const Draws& d, std::vector<TestResult>& out) {
  out.push_back(kolmogorov_smirnov(s, "ks-radial", d.radial_slabs, d.n, c.xr, c.Fr));
  out.push_back(kolmogorov_smirnov(s, "ks-azimuth", d.azimuth_slabs, d.n, c.xa, c.Fa));
}

}  // namespace warpcheck::validation::battery
