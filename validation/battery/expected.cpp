// The expected counts and CDFs of the statistical tests (tests.h): the grid quadrature (cap_grid.h) where its
// two orders of integration agree to the accuracy each test needs, the nested adaptive quadrature otherwise.
// docs/derivations/battery-quadrature.md derives the bounds.
#include <cmath>
#include <numeric>
#include <sstream>

#include "battery/cap_grid.h"
#include "battery/tests.h"

namespace warpcheck::validation::battery {

Real chi_square_shift_budget(int bins) { return Real(1e-3) * std::sqrt(2 * std::max<Real>(bins - 1, 1)); }

Real chi_square_shift(const std::vector<Real>& expected, const std::vector<Real>& error, Real min_expected) {
  // A bin expecting e with relative error eps = err / e shifts E[(O - e')^2 / e'] by about -eps + e eps^2; bins
  // expecting fewer than min_expected are pooled, as chi_square pools them, and count as one.
  Real shift = 0, pool_e = 0, pool_err = 0;
  auto add = [&](Real e, Real err) {
    const Real eps = err / e;
    shift += std::abs(eps) + e * eps * eps;
  };
  for (std::size_t k = 0; k < expected.size(); ++k) {
    if (expected[k] >= min_expected)
      add(expected[k], error[k]);
    else
      pool_e += expected[k], pool_err += error[k];
  }
  if (pool_e > 0) add(pool_e, pool_err);
  return shift;
}

Real ks_cdf_tolerance(std::uint64_t n) {
  // 1e-3 of the KS critical distance 1.36 / sqrt(n) (alpha = 0.05): D moves by at most the CDF's error.
  return Real(1e-3) * Real(1.36) / std::sqrt(Real(n));
}

namespace {

// Largest |F(node) - G(node)| over the nodes x where G, the cumulative sums of `mass` along one axis, is known.
Real cdf_gap(const std::vector<Real>& x, const std::vector<Real>& F, const std::vector<Real>& edge_mass) {
  Real worst = 0, cumulative = 0;
  const std::size_t n = edge_mass.size();
  for (std::size_t k = 0; k <= n; ++k) {
    const Real edge = Real(k) / Real(n);
    const auto it = std::lower_bound(x.begin(), x.end(), edge);
    if (it != x.end() && *it == edge) worst = std::max(worst, std::abs(F[std::size_t(it - x.begin())] - cumulative));
    if (k < n) cumulative += edge_mass[k];
  }
  return worst;
}

// Why the grid's result is not good enough, or empty.
std::string grid_shortfall(const SamplerUnderTest& s, const BatteryOptions& o, const CapGrid& g, const KsCdfs& ks,
                           const QuadratureResult& adaptive) {
  const int R = o.radial_bins, A = o.azimuth_bins;
  const Real n = Real(o.samples);
  const Real ks_tol = ks_cdf_tolerance(o.samples);
  std::ostringstream why;
  std::vector<Real> expected(g.bins.size()), error(g.bins.size());
  for (std::size_t k = 0; k < g.bins.size(); ++k)
    expected[k] = n * g.bins[k], error[k] = n * (g.bins[k] - g.bins_check[k]);
  const Real shift = chi_square_shift(expected, error, Real(o.min_expected)), budget = chi_square_shift_budget(R * A);
  if (!(shift <= budget)) why << "bins disagree: chi-square shift " << double(shift) << " > " << double(budget) << "; ";
  std::vector<Real> rings(std::size_t(R), 0), columns(std::size_t(A), 0);
  for (int j = 0; j < R; ++j)
    for (int c = 0; c < A; ++c)
      rings[std::size_t(j)] += g.bins[std::size_t(j * A + c)],
          columns[std::size_t(c)] += g.bins_check[std::size_t(j * A + c)];
  const Real ks_gap = std::max(cdf_gap(ks.xr, ks.Fr, rings), cdf_gap(ks.xa, ks.Fa, columns));
  if (!(ks_gap <= ks_tol)) why << "KS CDFs disagree by " << double(ks_gap) << " > " << double(ks_tol) << "; ";
  const Real total = std::accumulate(g.bins.begin(), g.bins.end(), Real(0));
  const Real total_gap = std::abs(total - std::accumulate(g.bins_check.begin(), g.bins_check.end(), Real(0)));
  // The pdf-integral test's decision stays the same: the gap is a tenth of its tolerance, or of the distance of
  // |integral - 1| from the tolerance, whichever is larger.
  const Real allowed = std::max(s.tolerance, std::abs(std::abs(total - 1) - s.tolerance)) / 10;
  if (!(total_gap <= allowed)) why << "totals disagree by " << double(total_gap) << " > " << double(allowed) << "; ";
  // Both orders can miss the same narrow peak (an SPTD whose pivot nears the unit sphere): the whole cap's
  // integral by the nested adaptive quadrature, one region started from the chi-square grid's panels, is a third
  // estimate with its own error control.
  // Allowed: the bound above plus that quadrature's own error estimate.
  if (!(std::abs(total - adaptive.value) <= allowed + adaptive.error))
    why << "the adaptive quadrature's total differs by " << double(std::abs(total - adaptive.value)) << " > "
        << double(allowed + adaptive.error) << "; ";
  return why.str();
}

Expected reference_integrals(const SamplerUnderTest& s, const BatteryOptions& o, Expected e, const std::string& why) {
  e.quadrature =
      why.empty() ? "adaptive quadrature" : "adaptive quadrature (grid: " + why.substr(0, why.size() - 2) + ")";
  e.mass = reference_bin_masses(s, o);
  e.ks = reference_ks_cdfs(s, o);
  e.inside_error = 0;
  add_rim(s, o, e);
  return e;
}

}  // namespace

// A float pdf is rounded as its samples are: at its support's edge it is 0 on a band just inside and positive on one
// just outside, of about equal mass (5e-6 each on a 2e-3 rad cone). The band's fine structure is rounding, which no
// adaptive rule resolves, so a fixed one: pieces halving towards the edge down to 2^-16 of the rim, Gauss-Legendre
// 2 in t, and the midpoints of the KS azimuth slabs in phi.
void add_rim(const SamplerUnderTest& s, const BatteryOptions& o, Expected& e) {
  const Cap<Real>& cap = s.bounding_cap;
  const Real end = std::min(1 + rounding_slack(s), 2 / cap.one_minus_cos);  // t = 2 / omc: the antipode
  const int M = int(e.ks.xa.size()) - 1, A = o.azimuth_bins, R = o.radial_bins;
  std::vector<Real> edges{1};
  for (int k = 16; k >= 0; --k) edges.push_back(1 + (end - 1) * std::ldexp(Real(1), -k));
  std::vector<Vec3L> w(std::size_t(M) * 2);
  std::vector<Real> pdf(w.size()), slab(std::size_t(M), 0);
  for (std::size_t p = 0; p + 1 < edges.size(); ++p) {
    const Real a = edges[p], h = edges[p + 1] - a, g = (1 - 1 / std::sqrt(Real(3))) / 2;
    for (int j = 0; j < M; ++j)
      for (int i = 0; i < 2; ++i)
        w[std::size_t(2 * j + i)] = cap_direction(cap, a + h * (i ? 1 - g : g), kTwoPi<Real> * (j + Real(0.5)) / M);
    pdf_many(s, w, pdf);
    // dOmega = omc dt dphi; each node weighs h / 2 in t and 2 pi / M in phi.
    for (int j = 0; j < M; ++j)
      slab[std::size_t(j)] +=
          (pdf[std::size_t(2 * j)] + pdf[std::size_t(2 * j + 1)]) * cap.one_minus_cos * h / 2 * kTwoPi<Real> / M;
  }
  Real cumulative = 0;
  for (int j = 0; j < M; ++j) {
    e.mass[std::size_t((R - 1) * A + int((j + Real(0.5)) / M * A))] += slab[std::size_t(j)];
    cumulative += slab[std::size_t(j)];
    e.ks.Fa[std::size_t(j + 1)] += cumulative;
  }
  e.ks.Fr.back() += cumulative;
  e.rim = cumulative;
}

Expected expected_integrals(const SamplerUnderTest& s, const BatteryOptions& o) {
  Expected e;
  e.ks = ks_nodes(o);
  if (o.reference_quadrature) return reference_integrals(s, o, std::move(e), "");
  // The third estimate of the grid's total (grid_shortfall), computed beside the grid, to a quarter of the least
  // gap grid_shortfall allows (the sampler's tolerance / 10): finer buys that check nothing, and on a float pdf
  // whose rounding noise is near its tolerance the rule would refine noise to its panel budget on every line.
  auto adaptive = beside(o, [&s, &o] {
    return integrate_cap_region_with_error(s.pdf, s.bounding_cap, 0, 1, 0, kTwoPi<Real>, o.quadrature_tolerance,
                                           o.azimuth_bins, o.radial_bins, boundary_of(s), s.tolerance / 40);
  });
  CapGridSpec spec;
  spec.radial_bins = o.radial_bins, spec.azimuth_bins = o.azimuth_bins;
  spec.xr = e.ks.xr, spec.xa = e.ks.xa;
  spec.rel_tol = o.quadrature_tolerance, spec.threads = thread_count(o);
  spec.resolution = rounding_slack(s);  // in t and phi
  // Halving beside a bend buys accuracy far below a float pdf's rounding, and where that rounding is coarse (a
  // near-singular LTC's lobe, 1e-4 rad wide, in float directions) more nodes there move the grid's total by
  // 4.6e-5, which the chi-square's outside cell (1 - total) reads as missing samples.
  spec.beside_bends = s.scalar != "float";
  CapGrid g = integrate_cap_grid(s, spec);
  auto shortfall = [&](const CapGrid& grid) {
    return grid_shortfall(s, o, grid, KsCdfs{e.ks.xr, grid.Fr, e.ks.xa, grid.Fa}, adaptive.get());
  };
  std::string why = shortfall(g);
  // A peak or sliver narrower than the slabs' bend test sees: once more with a 10 times stricter test and 4 more
  // halvings (a few times the grid's cost, against 20 to 100 times for the adaptive quadrature).
  const bool float_rounding = s.scalar == "float";
  bool refined = false;
  if (!why.empty() && !float_rounding) {
    spec.bend /= 10, spec.max_depth += 4;
    CapGrid finer = integrate_cap_grid(s, spec);
    if (shortfall(finer).empty()) g = std::move(finer), why.clear(), refined = true;
  }
  e.ks.Fr = std::move(g.Fr), e.ks.Fa = std::move(g.Fa);
  const Real total = std::accumulate(g.bins.begin(), g.bins.end(), Real(0));
  e.inside_error = std::abs(total - std::accumulate(g.bins_check.begin(), g.bins_check.end(), Real(0)));
  // A float pdf is defined only to its rounding: near its support's edges it differs from the exact density by
  // more than the bounds above, and the two orders see different roundings. The adaptive quadrature integrates
  // the same rounded function no better, only 20 to 500 times slower: for a float sampler the grid's result
  // stands, and the details say by how much its two orders differ.
  if (!why.empty() && !float_rounding) return reference_integrals(s, o, std::move(e), why);
  e.quadrature = std::string(refined ? "grid quadrature with the stricter bend test" : "grid quadrature") +
                 " (its two orders differ by " + format_g(double(e.inside_error), 2) + " in all" +
                 (why.empty() ? ")"
                              : "; beyond the accuracy targets, as the float pdf's rounding allows: " +
                                    why.substr(0, why.size() - 2) + ")");
  e.mass = std::move(g.bins);
  add_rim(s, o, e);
  return e;
}

}  // namespace warpcheck::validation::battery
