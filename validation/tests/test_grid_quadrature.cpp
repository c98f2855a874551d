// Specifications of the battery's expected counts: the grid quadrature (cap_grid.h) against densities whose bin
// masses and CDFs are known in closed form, and the bounds that decide when its result is used (expected.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>

#include "battery/cap_grid.h"
#include "battery/tests.h"
#include "tests/quadrature_fixtures.h"
#include "warpcheck/validation/registry.h"

namespace warpcheck::validation {
namespace {

using battery::CapGrid;
using battery::CapGridSpec;

SamplerUnderTest density_on(const Cap<Real>& cap, std::function<Real(const Vec3L&)> pdf) {
  SamplerUnderTest s;
  s.kernel = "density", s.scalar = "double", s.config = "fixture";
  s.sample = [](double, double) { return Sample{}; };
  s.pdf = std::move(pdf);
  s.bounding_cap = cap;
  return s;
}

CapGrid grid_of(const SamplerUnderTest& s) {
  const BatteryOptions o;
  const battery::KsCdfs nodes = battery::ks_nodes(o);
  CapGridSpec spec;
  spec.xr = nodes.xr, spec.xa = nodes.xa;
  return battery::integrate_cap_grid(s, spec);
}

// The chi-square shift that errors `mass - exact` of the bin masses cause at 10^7 samples, over its budget.
double shift_over_budget(const std::vector<Real>& mass, const std::vector<Real>& exact) {
  std::vector<Real> e(mass.size()), err(mass.size());
  for (std::size_t k = 0; k < mass.size(); ++k) e[k] = 1e7L * exact[k], err[k] = 1e7L * (mass[k] - exact[k]);
  return double(battery::chi_square_shift(e, err, 5) / battery::chi_square_shift_budget(int(mass.size())));
}

TEST(GridQuadrature, AUniformConesBinsAreEqualAndItsCdfsAreTheNodesThemselves) {
  const SamplerUnderTest s = density_on(kBounding, [](const Vec3L& w) {
    return kBounding.contains(w, 1e-15L) ? 1 / (kTwoPi<Real> * kBounding.one_minus_cos) : Real(0);
  });
  const CapGrid g = grid_of(s);
  const battery::KsCdfs nodes = battery::ks_nodes(BatteryOptions{});
  for (std::size_t k = 0; k < g.bins.size(); ++k) {
    EXPECT_NEAR(double(g.bins[k]), 1.0 / 512, 1e-15) << k;
    EXPECT_NEAR(double(g.bins_check[k]), 1.0 / 512, 1e-15) << k;
  }
  for (std::size_t k = 0; k < nodes.xr.size(); ++k) {
    EXPECT_NEAR(double(g.Fr[k]), double(nodes.xr[k]), 1e-14) << k;
    EXPECT_NEAR(double(g.Fa[k]), double(nodes.xa[k]), 1e-14) << k;
  }
}

// The tilted cap's edge is a small circle, not a declared boundary plane: the grid finds it by halving the
// slabs that bend.
TEST(GridQuadrature, BinsOfADensityWithAnUndeclaredObliqueJumpMeetTheChiSquareBoundAtTenToTheSeven) {
  const TiltedCap c;
  const SamplerUnderTest s = density_on(kBounding, [&](const Vec3L& w) { return c.pdf(w); });
  const CapGrid g = grid_of(s);
  std::vector<Real> exact;
  for (int ri = 0; ri < 16; ++ri)
    for (int ai = 0; ai < 32; ++ai)
      exact.push_back(
          c.bin_mass(Real(ri) / 16, Real(ri + 1) / 16, kTwoPi<Real> * ai / 32, kTwoPi<Real> * (ai + 1) / 32));
  EXPECT_LT(shift_over_budget(g.bins, exact), 1);
  EXPECT_LT(shift_over_budget(g.bins_check, exact), 1);
}

// The same jump declared as a boundary cap: every line and ring is split where it crosses the edge, and the slabs
// end where the edge touches a ring or a line, so each piece's integrand is smooth and every bin is as accurate as
// the rules' tolerance (1e-8 of the bin, or of 1e-3 of the whole, whichever is larger).
TEST(GridQuadrature, BinsOfADensityThatJumpsOnADeclaredBoundaryCapMeetTheRulesTolerance) {
  const TiltedCap c;
  SamplerUnderTest s = density_on(kBounding, [&](const Vec3L& w) { return c.pdf(w); });
  s.boundary_caps = {Cap<Real>{c.axis(), 1 - std::cos(c.alpha)}};
  const CapGrid g = grid_of(s);
  Real worst = 0, worst_check = 0;
  for (int ri = 0; ri < 16; ++ri)
    for (int ai = 0; ai < 32; ++ai) {
      const Real exact =
          c.bin_mass(Real(ri) / 16, Real(ri + 1) / 16, kTwoPi<Real> * ai / 32, kTwoPi<Real> * (ai + 1) / 32);
      const Real scale = std::max(exact, Real(1e-3));
      worst = std::max(worst, std::abs(g.bins[std::size_t(ri * 32 + ai)] - exact) / scale);
      worst_check = std::max(worst_check, std::abs(g.bins_check[std::size_t(ri * 32 + ai)] - exact) / scale);
    }
  std::printf("worst relative bin error: lines %.3g, rings %.3g\n", double(worst), double(worst_check));
  EXPECT_LT(worst, 1e-8L);
  EXPECT_LT(worst_check, 1e-8L);
}

// A clamped cosine about a small circle's centre, (m.w - c)+ / (pi (1 - c)^2), integrates to 1 (the circle lies
// inside the bounding cap); its kink on the circle is declared. Where the circle touches a line or a ring, their
// integrals have (x - x0)^(3/2) kinks with large coefficients, which the slabs' second difference does not see.
TEST(GridQuadrature, ALobeKinkedOnADeclaredSmallCircleIntegratesToOneInBothOrders) {
  const Vec3L m = Vec3L(0.3L, -0.2L, 1).normalized();
  const Real c = Real(0.9995);
  SamplerUnderTest s = density_on(
      kBounding, [&](const Vec3L& w) { return std::max<Real>(0, w.dot(m) - c) / (kPi<Real> * (1 - c) * (1 - c)); });
  s.boundary_caps = {Cap<Real>{m, 1 - c}};
  const CapGrid g = grid_of(s);
  const Real lines = std::accumulate(g.bins.begin(), g.bins.end(), Real(0));
  const Real rings = std::accumulate(g.bins_check.begin(), g.bins_check.end(), Real(0));
  std::printf("lines 1 %+.3g, rings 1 %+.3g\n", double(lines - 1), double(rings - 1));
  EXPECT_NEAR(double(lines), 1, 1e-9);
  EXPECT_NEAR(double(rings), 1, 1e-9);
  EXPECT_NEAR(double(g.Fr.back()), 1, 1e-9);
  EXPECT_NEAR(double(g.Fa.back()), 1, 1e-9);
}

// The totals of both orders of a registry case's grid, minus 1.
std::pair<double, double> totals_minus_one(const char* kernel, const char* config) {
  const Registry reg = default_registry();
  for (const Case& k : reg.cases())
    if (k.kernel == kernel && k.scalar == "double" && k.config == config) {
      const CapGrid g = grid_of(k.make());
      const Real lines = std::accumulate(g.bins.begin(), g.bins.end(), Real(0));
      const Real rings = std::accumulate(g.bins_check.begin(), g.bins_check.end(), Real(0));
      std::printf("%s %s: lines 1 %+.3g, rings 1 %+.3g\n", kernel, config, double(lines - 1), double(rings - 1));
      return {double(lines - 1), double(rings - 1)};
    }
  ADD_FAILURE() << kernel << " " << config << " is not registered";
  return {1, 1};
}

// The clamped-cosine SPTD with |r_p| = 0.99: its density peaks at about 4e4 beside a disk 0.0126 rad wide where it
// vanishes (the base's horizon mapped by the pivot, a declared boundary cap), so the lines and rings that touch
// the disk kink with large coefficients. Normalised by Eq. 10 (checked against a quadrature of Eq. 8 to 3e-10).
TEST(GridQuadrature, ThePivotedClampedCosineBesideItsVanishingDiskIntegratesToOneInBothOrders) {
  const auto [lines, rings] = totals_minus_one("sptd-cosine-cap", "pivot-0.99");
  EXPECT_LT(std::abs(lines), 2e-8);
  EXPECT_LT(std::abs(rings), 2e-8);
}

// The pivot phase function with g_p = 0.99 puts 97% of its mass within about 0.01 rad: a slab on the peak's
// flank, near its inflection, barely bends although the 3-point rule's error there is large.
TEST(GridQuadrature, ThePeakOfThePivotPhaseFunctionIntegratesToOneInBothOrders) {
  const auto [lines, rings] = totals_minus_one("sptd-uniform-cap", "phase-g-0.99");
  EXPECT_LT(std::abs(lines), 2e-8);
  EXPECT_LT(std::abs(rings), 2e-8);
}

TEST(GridQuadrature, TheRadialCdfOfAnInverseSquareRootSingularityAtTheCapsEdgeMeetsTheKsBound) {
  // f proportional to 1 / sqrt(1 - t) (the visible-area sampler's silhouette): F(t) = 1 - sqrt(1 - t).
  const SamplerUnderTest s = density_on(kBounding, [](const Vec3L& w) {
    const Real t = (w - kBounding.axis).squaredNorm() / 2 / kBounding.one_minus_cos;
    return t < 1 ? 1 / (2 * std::sqrt(1 - t) * kTwoPi<Real> * kBounding.one_minus_cos) : Real(0);
  });
  const CapGrid g = grid_of(s);
  const battery::KsCdfs nodes = battery::ks_nodes(BatteryOptions{});
  Real worst = 0;
  for (std::size_t k = 0; k < nodes.xr.size(); ++k)
    worst = std::max(worst, std::abs(g.Fr[k] - (1 - std::sqrt(1 - nodes.xr[k]))));
  EXPECT_LT(double(worst), double(battery::ks_cdf_tolerance(10'000'000)));
}

// The float pdf of the 2e-3 rad sphere is 0 or not near its edge by its directions' rounding: at t = 1 - 3e-5 on
// about 3% of each ring's azimuths, at t = 1 on about half. The radial CDF there is an average over that pattern,
// measured here by stratified Monte Carlo over the last KS slabs (400000 points each, its standard error
// estimated from the points); the grid must meet the KS bound at 10^7 against it, with the Monte Carlo's 5 sigma
// counted against the grid. With 480 Gauss-Kronrod azimuths per ring the CDF is off by about 5.6e-7 here, above
// the bound of 4.3e-7.
TEST(GridQuadrature, TheRadialCdfAcrossAFloatPdfsRoundedEdgeMeetsTheKsBoundAgainstMonteCarlo) {
  const Registry reg = default_registry();
  const Case* c = nullptr;
  for (const Case& x : reg.cases())
    if (x.kernel == "sphere-solid-angle" && x.scalar == "float" && x.config == "tiny") c = &x;
  ASSERT_TRUE(c);
  const SamplerUnderTest s = c->make();
  const BatteryOptions o;
  ASSERT_EQ(o.samples, 10'000'000u);
  const battery::Expected e = battery::expected_integrals(s, o);
  const std::size_t m = e.ks.xr.size() - 1, first = m - 8;
  constexpr long kPoints = 400'000;
  std::mt19937_64 g(1);
  std::uniform_real_distribution<double> u(0, 1);
  Real gap = 0, variance = 0, worst = 0;
  for (std::size_t k = first; k < m; ++k) {
    const Real a = e.ks.xr[k], b = e.ks.xr[k + 1];
    const Real weight = s.bounding_cap.one_minus_cos * (b - a) * kTwoPi<Real> / kPoints;
    Real sum = 0, sum2 = 0;
    for (long i = 0; i < kPoints; ++i) {
      const Real t = a + (b - a) * (Real(i) + Real(u(g))) / kPoints;
      const Real p = s.pdf(cap_direction(s.bounding_cap, t, kTwoPi<Real> * Real(u(g))));
      sum += p, sum2 += p * p;
    }
    variance += weight * weight * (sum2 - sum * sum / kPoints);
    const Real grid = e.ks.Fr[k + 1] - e.ks.Fr[k] - (k + 1 == m ? e.rim : Real(0));
    gap += grid - weight * sum;
    worst = std::max(worst, std::abs(gap) + 5 * std::sqrt(variance));
  }
  EXPECT_LT(double(worst), double(battery::ks_cdf_tolerance(o.samples)));
}

TEST(GridQuadrature, ASliversBinsSumToItsExactAreaWhenItsEdgesAreDeclared) {
  const Cap<Real> cap{Vec3L(0, 0, 1), Real(0.05)};
  auto dir = [](Real theta, Real phi) {
    return Vec3L(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  };
  const Vec3L a = dir(Real(0.3), Real(0.1)), b = dir(Real(0.3), Real(2.6));
  const Vec3L c = ((a + b).normalized() + Real(3e-3) * a.cross(b).normalized()).normalized();
  const std::vector<Vec3L> planes{a.cross(b).normalized(), b.cross(c).normalized(), c.cross(a).normalized()};
  const Real orient = planes[0].dot(c) > 0 ? 1 : -1;
  const Real area = 2 * std::atan2(std::abs(a.dot(b.cross(c))), 1 + a.dot(b) + b.dot(c) + c.dot(a));
  SamplerUnderTest s = density_on(cap, [&](const Vec3L& w) {
    for (const Vec3L& m : planes)
      if (orient * m.dot(w) < 0) return Real(0);
    return 1 / area;
  });
  s.boundary_planes = planes;
  const CapGrid g = grid_of(s);
  // Required: a tenth of the pdf-integral test's tolerance 1e-6 (expected.cpp).
  const double lines = double(std::accumulate(g.bins.begin(), g.bins.end(), Real(0)) - 1);
  const double rings = double(std::accumulate(g.bins_check.begin(), g.bins_check.end(), Real(0)) - 1);
  std::printf("sliver's integral - 1: lines %.2g, rings %.2g\n", lines, rings);
  EXPECT_LT(std::abs(lines), 1e-7);
  EXPECT_LT(std::abs(rings), 1e-7);
}

TEST(ChiSquareShift, IsTheSumOfRelativeErrorPlusExpectedTimesItsSquareWithSmallBinsPooled) {
  // e = 100, error 1: 0.01 + 100 * 0.01^2 = 0.02. Two bins of 2 with errors 0.1 pool to 4 and 0.2: 0.05 + 4 *
  // 0.05^2 = 0.06.
  EXPECT_NEAR(double(battery::chi_square_shift({100}, {1}, 5)), 0.02, 1e-15);
  EXPECT_NEAR(double(battery::chi_square_shift({100, 2, 2}, {1, 0.1L, 0.1L}, 5)), 0.08, 1e-15);
  EXPECT_NEAR(double(battery::chi_square_shift({100}, {-1}, 5)), 0.02, 1e-15);  // either sign
  // The budget: 1e-3 of sqrt(2 (512 - 1)).
  EXPECT_NEAR(double(battery::chi_square_shift_budget(512)), 1e-3 * std::sqrt(1022.0), 1e-15);
}

TEST(KsCdfTolerance, IsOneThousandthOfTheCriticalDistanceAtTheSampleCount) {
  EXPECT_NEAR(double(battery::ks_cdf_tolerance(1'000'000)), 1.36e-6, 1e-18);
}

// Every registered LTC lobe, from the identity to |M| = 1e-8 (a peak 1e-4 rad wide holding 94% of the mass in
// one slab of 2 pi / 1024), in double: the battery's azimuth CDF meets the KS bound at 10^7 samples against the
// closed form. The radial coordinate's slabs are cut by small circles, which Lambert's formula does not take.
TEST(GridQuadratureKnownAnswers, TheLtcAzimuthCdfEqualsLambertsFormulaOnThePolygonCutByEachWedge) {
  BatteryOptions o;
  o.threads = 2;
  for (const LtcConfig& c : ltc_configs()) {
    const SamplerUnderTest s = ltc_sampler<double>(c.name, c.g);
    if (s.expect_no_sample) continue;
    const battery::Expected e = battery::expected_integrals(s, o);
    const std::vector<Real> exact = ltc_azimuth_slab_masses(c.g, s.bounding_cap, e.ks.xa);
    Real cdf = 0, gap = 0;
    for (std::size_t k = 0; k < exact.size(); ++k) {
      cdf += exact[k];
      gap = std::max(gap, std::abs(e.ks.Fa[k + 1] - cdf));
    }
    EXPECT_LE(gap, battery::ks_cdf_tolerance(10'000'000)) << c.name << ": " << e.quadrature;
    std::printf("%s: azimuth CDF within %.2Le of the closed form (%s)\n", c.name, gap, e.quadrature.c_str());
  }
}

}  // namespace
}  // namespace warpcheck::validation
