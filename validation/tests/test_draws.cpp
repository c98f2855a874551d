// Specifications of the battery's draws: the KS statistic from counts per slab between the nodes is the one of the
// sorted sample, the fast placement of a direction in the chi-square bins and KS slabs is the long double one's,
// and the counts do not depend on the thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "battery/drawing.h"
#include "battery/tests.h"
#include "warpcheck/validation/registry.h"

namespace warpcheck::validation::battery {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Counts per slab of the finite values (the infinite ones stand for samples outside the cap or declined).
std::vector<std::uint64_t> slab_counts(const std::vector<Real>& nodes, const std::vector<double>& values) {
  const SlabLocator slab(nodes);
  std::vector<std::uint64_t> c(nodes.size(), 0);
  for (double v : values)
    if (std::isfinite(v)) ++c[slab(v)];
  return c;
}

TestResult ks_of(const std::vector<Real>& x, const std::vector<Real>& F, const std::vector<double>& values) {
  Draws d;
  d.n = values.size();
  d.radial_slabs = d.azimuth_slabs = slab_counts(x, values);
  std::vector<TestResult> out;
  SamplerUnderTest s;
  ks_tests(s, KsCdfs{x, F, x, F}, d, out);
  EXPECT_EQ(out.at(0).statistic, out.at(1).statistic);
  return out.at(0);
}

// Nine values against nodes 0, 1/4, 1/2, 3/4, 1: two equal to the node 1/4 (a value equal to a node counts as <=
// it), one beyond the last node and one infinite. The empirical CDF at the nodes is 0, 3/9, 4/9, 5/9, 8/9: the
// last node counts every finite value, the one beyond it too, and the infinite one nowhere.
TEST(KsFromSlabCounts, DOfAHandMadeSampleIsTheLargestGapAtTheNodes) {
  const std::vector<Real> x{0, 0.25L, 0.5L, 0.75L, 1};
  const std::vector<double> values{0.1, 0.25, 0.25, 0.3, 0.6, 0.9, 1.0, 1.5, kInf};
  // Largest gap at the last node: 1 - 8/9.
  const TestResult last = ks_of(x, {0, 0.3L, 0.45L, 0.55L, 1}, values);
  EXPECT_EQ(last.statistic, std::abs(1.0 - 8.0 / 9));
  EXPECT_NE(last.detail.find("n 9,"), std::string::npos) << last.detail;
  // Largest gap at 1/4, where the two values equal to the node count: |0.1 - 3/9|.
  const TestResult tie = ks_of(x, {0, 0.1L, 0.45L, 0.55L, 0.9L}, values);
  EXPECT_EQ(tie.statistic, std::abs(double(0.1L) - 3.0 / 9));
}

// Nodes clustered at both ends (Chebyshev-Lobatto, as the radial marginal's), so that the slab table has buckets
// with many nodes as well as with one or none.
std::vector<Real> clustered_nodes(int M) {
  std::vector<Real> x(M + 1);
  for (int k = 0; k <= M; ++k) x[k] = (1 - std::cos(kPi<Real> * k / M)) / 2;
  x[0] = 0, x[M] = 1;
  return x;
}

TEST(KsFromSlabCounts, GiveTheSortedSamplesCountAtEveryNode) {
  for (const std::vector<Real>& x : {clustered_nodes(1024), clustered_nodes(37)}) {
    // Values uniform in [0, 1], equal to a node, a double away from one, beyond [0, 1], infinite.
    std::mt19937_64 g(7);
    std::uniform_real_distribution<double> unit(0, 1);
    std::uniform_int_distribution<std::size_t> node(0, x.size() - 1);
    std::vector<double> values;
    for (int i = 0; i < 20000; ++i) {
      const double xk = double(x[node(g)]);
      for (double v : {unit(g), xk, std::nextafter(xk, 2.0), std::nextafter(xk, -1.0)}) values.push_back(v);
    }
    values.insert(values.end(), {1.5, 7.0, kInf, -0.0, 0.0});
    const std::vector<std::uint64_t> slabs = slab_counts(x, values);
    std::vector<double> sorted = values;
    std::sort(sorted.begin(), sorted.end());
    std::uint64_t cumulative = 0;
    for (std::size_t k = 0; k < x.size(); ++k) {
      cumulative += slabs[k];
      // The last node counts every finite value (the sort's loop compared with DBL_MAX there).
      const double xk = k + 1 == x.size() ? std::numeric_limits<double>::max() : double(x[k]);
      const auto at_most = std::upper_bound(sorted.begin(), sorted.end(), xk) - sorted.begin();
      ASSERT_EQ(cumulative, std::uint64_t(at_most)) << "node " << k << " of " << x.size();
    }
  }
}

// common(lo, hi), which the fast placement takes as the slab of a coordinate within its error bound, is the slab of
// both ends where they share one and kNone where they do not: on clustered nodes (many in one bucket of the lookup
// table, or none), uniform ones (a node on every other bucket's edge), ranges from a point to 10^-6 wide, ranges
// with an end on a node, a double beside one or beyond [0, 1].
TEST(SlabLocator, CommonSlabOfARangeIsTheSlabOfBothEndsOrNone) {
  std::vector<Real> uniform(1025);
  for (std::size_t k = 0; k < uniform.size(); ++k) uniform[k] = Real(k) / 1024;
  for (const std::vector<Real>& x : {clustered_nodes(1024), clustered_nodes(37), uniform}) {
    const SlabLocator slab(x);
    std::mt19937_64 g(5);
    std::uniform_real_distribution<double> unit(-0.01, 1.01);
    std::uniform_int_distribution<std::size_t> node(0, x.size() - 1);
    std::size_t common = 0, none = 0;
    auto check = [&](double lo, double hi) {
      const std::uint32_t expected = slab(lo) == slab(hi) ? slab(lo) : SlabLocator::kNone;
      ASSERT_EQ(slab.common(lo, hi), expected) << lo << " " << hi << " of " << x.size() << " nodes";
      ++(expected == SlabLocator::kNone ? none : common);
    };
    for (int i = 0; i < 200000; ++i) {
      const double width = std::ldexp(1.0, -20 - int(g() % 34)) * (i % 7 == 0 ? 0 : 1);
      const double xk = double(x[node(g)]), v = i % 2 ? unit(g) : xk;
      for (double lo : {v, v - width, std::nextafter(v, -2.0), std::nextafter(v, 2.0)}) check(lo, lo + width);
    }
    check(-0.0, 0.0), check(1, 1), check(0.5, 1), check(-1, 0), check(1, 2);
    EXPECT_GT(common, 100000u);
    EXPECT_GT(none, 10000u);
  }
}

TEST(CapBinner, AzimuthPolynomialIsWithinItsStatedError) {
  double worst = 0;
  for (int i = 0; i <= 1 << 22; ++i) {
    const double z = double(i) / (1 << 22);
    worst = std::max(worst, double(std::abs(Real(atan_unit(z)) - std::atan(Real(z)))));
  }
  EXPECT_LE(worst, kAtanError);
  EXPECT_GT(worst, kAtanError / 2);  // the bound is what the fit achieves
  std::mt19937_64 g(3);
  std::normal_distribution<double> normal;
  double worst_fraction = 0;
  for (int i = 0; i < 1000000; ++i) {
    const double x = normal(g), y = normal(g);
    Real phi = std::atan2(Real(y), Real(x));
    if (phi < 0) phi += kTwoPi<Real>;
    worst_fraction = std::max(worst_fraction, double(std::abs(azimuth_fraction(x, y) - phi / kTwoPi<Real>)));
  }
  EXPECT_LE(worst_fraction, (kAtanError + 1e-15) / (2 * M_PI));
}

// A sampler with only what CapBinner reads: the bounding cap and the scalar type (the slack beyond the cap's edge).
SamplerUnderTest capped(Vec3L axis, Real one_minus_cos, const char* scalar) {
  SamplerUnderTest s;
  s.scalar = scalar;
  s.bounding_cap = Cap<Real>{axis.normalized(), one_minus_cos};
  return s;
}

// Directions on and around every edge of the placement (each ring's and column's, each KS node's of both
// marginals, the cap's edge with and without its slack, the azimuth's seam, the axis), nudged by 0 to 10^6 ulps, by
// relative offsets from 1e-16 to 1e-6 and off unit length, and random directions on the sphere and in the cap: place
// gives place_exact's answer on each, and place_fast decides all but a few of those in the cap.
TEST(CapBinner, FastPlacementIsTheLongDoublePlacementOnEveryEdge) {
  const BatteryOptions o;
  const std::vector<Real> xr = clustered_nodes(o.ks_cdf_nodes), xa = clustered_nodes(40);
  for (const SamplerUnderTest& s :
       {capped(Vec3L(0, 0, 1), 0.3L, "double"), capped(Vec3L(0.6L, 0, 0.8L), 2e-6L, "float"),
        capped(Vec3L(0.3L, -0.5L, 0.8L), 0.95L, "long double"), capped(Vec3L(0, 0, -1), 2, "double")}) {
    const CapBinner b(s, o, xr, xa);
    const Cap<Real>& cap = s.bounding_cap;
    std::vector<Real> ts{0, 1, 1 + 64 * scalar_epsilon(s.scalar) * (1 + std::sqrt(2 / cap.one_minus_cos))},
        phis{0, kTwoPi<Real>};
    for (int r = 0; r <= o.radial_bins; ++r) ts.push_back(Real(r) / o.radial_bins);
    for (int a = 0; a <= o.azimuth_bins; ++a) phis.push_back(kTwoPi<Real> * a / o.azimuth_bins);
    ts.insert(ts.end(), xr.begin(), xr.end());
    for (Real v : xa) phis.push_back(kTwoPi<Real> * v);
    std::mt19937_64 g(11);
    std::uniform_real_distribution<double> unit(0, 1);
    std::normal_distribution<double> normal;
    std::size_t checked = 0;
    auto check = [&](const Vec3L& w) {
      ASSERT_EQ(b.place(w), b.place_exact(w)) << double(w.x()) << " " << double(w.y()) << " " << double(w.z());
      ++checked;
    };
    auto around = [&](Real t, Real phi) {
      for (Real rel : {0.0L, 1e-16L, -1e-16L, 1e-13L, -1e-13L, 1e-10L, -1e-10L, 1e-8L, -1e-8L, 1e-6L, -1e-6L}) {
        check(cap_direction(cap, t * (1 + rel) + rel * rel, phi));
        check(cap_direction(cap, t, phi * (1 + rel) + rel));
      }
      const Vec3L w = cap_direction(cap, t, phi);
      for (Real scale : {1 + 1e-7L, 1 - 3e-5L, 1 + 1e-4L, 2.0L}) check(scale * w);  // a float's or no normalisation
      for (double ulps : {1.0, 3.0, 100.0, 1e4, 1e6}) {
        const Vec3L d(Real(double(w.x())), Real(double(w.y())), Real(double(w.z())));
        check(d + ulps * 0x1p-53L * Vec3L(1, -1, 1));
        check(d - ulps * 0x1p-53L * Vec3L(1, 1, -1));
      }
    };
    for (Real t : ts) around(t, kTwoPi<Real> * Real(unit(g)));
    for (Real phi : phis) around(Real(unit(g)), phi);
    around(0, 0);
    std::size_t fast = 0, random = 200000;
    for (std::size_t i = 0; i < random; ++i) {
      const Vec3L w = i % 2 ? Vec3L(normal(g), normal(g), normal(g)).normalized()
                            : cap_direction(cap, Real(unit(g)), kTwoPi<Real> * Real(unit(g)));
      check(w);
      fast += i % 2 == 0 && b.place_fast(w).has_value();
    }
    EXPECT_GT(checked, 20000u);
    EXPECT_GT(fast, random / 2 - random / 2000) << "one in a thousand directions in the cap may need place_exact";
  }
}

TEST(Draws, CountsDoNotDependOnTheThreadCountAndAddUpToTheSamples) {
  const Registry reg = default_registry();
  for (const Case* c : reg.select({"sphere-solid-angle"}, {"near", "tiny"})) {
    const SamplerUnderTest s = c->make();
    BatteryOptions o;
    o.samples = 300'001;  // a last chunk shorter than the others, and a last block shorter than a block
    const std::vector<Real> xr = clustered_nodes(o.ks_cdf_nodes), xa = clustered_nodes(o.ks_cdf_nodes);
    o.threads = 1;
    const Draws one = draw(s, o, xr, xa);
    for (int threads : {2, 3}) {
      o.threads = threads;
      const Draws many = draw(s, o, xr, xa);
      EXPECT_EQ(one.counts, many.counts) << c->scalar << " " << threads;
      EXPECT_EQ(one.radial_slabs, many.radial_slabs) << c->scalar << " " << threads;
      EXPECT_EQ(one.azimuth_slabs, many.azimuth_slabs) << c->scalar << " " << threads;
      EXPECT_EQ(one.outside + one.declined + one.non_finite, many.outside + many.declined + many.non_finite);
    }
    std::uint64_t placed = 0, radial = 0, azimuth = 0;
    for (std::uint64_t k : one.counts) placed += k;
    for (std::uint64_t k : one.radial_slabs) radial += k;
    for (std::uint64_t k : one.azimuth_slabs) azimuth += k;
    EXPECT_EQ(placed + one.outside + one.declined + one.non_finite, o.samples);
    EXPECT_EQ(radial, placed);
    EXPECT_EQ(azimuth, placed);
    EXPECT_LT(one.placed_exactly, o.samples / 1000) << c->scalar << " " << c->config;
  }
}

TEST(Draws, ThroughTheDoubleBlockFormAreTheDrawsThroughSamples) {
  const Registry reg = default_registry();
  int compared = 0;
  for (const Case* c : reg.select({"sphere-solid-angle", "polygon-solid-angle", "sphere-projected-cap"},
                                  {"near", "below-horizon", "triangle", "case3"})) {
    const SamplerUnderTest s = c->make();
    if (c->scalar == "long double") {
      EXPECT_FALSE(s.sample_block_double) << "long double does not round to double exactly";
      continue;
    }
    ASSERT_TRUE(s.sample_block_double) << c->kernel << " / " << c->scalar << " / " << c->config;
    SamplerUnderTest through_samples = s;
    through_samples.sample_block_double = nullptr;
    BatteryOptions o;
    o.samples = 100'003;
    const std::vector<Real> xr = clustered_nodes(o.ks_cdf_nodes), xa = clustered_nodes(o.ks_cdf_nodes);
    const Draws a = draw(s, o, xr, xa), b = draw(through_samples, o, xr, xa);
    const std::string name = c->kernel + " / " + c->scalar + " / " + c->config;
    EXPECT_EQ(a.counts, b.counts) << name;
    EXPECT_EQ(a.radial_slabs, b.radial_slabs) << name;
    EXPECT_EQ(a.azimuth_slabs, b.azimuth_slabs) << name;
    EXPECT_EQ(a.outside, b.outside) << name;
    EXPECT_EQ(a.declined, b.declined) << name;
    EXPECT_EQ(a.non_finite, b.non_finite) << name;
    EXPECT_EQ(a.placed_exactly, b.placed_exactly) << name;
    ++compared;
  }
  EXPECT_GE(compared, 8);
}

TEST(BatteryStream, IsTheStandardMersenneTwister) {
  SamplerUnderTest s;
  s.kernel = "k", s.scalar = "double", s.config = "c";
  for (std::uint64_t seed : {std::uint64_t(0), std::uint64_t(1), ~std::uint64_t(0)}) {
    Rng battery = stream(seed, s, 1, 3), plain(seed);
    std::mt19937_64 standard(stream_seed(seed, s, 1, 3)), standard_plain(seed);
    for (int k = 0; k < 100'000; ++k) {
      ASSERT_EQ(battery(), standard()) << "seed " << seed << ", number " << k;
      ASSERT_EQ(plain(), standard_plain()) << "seed " << seed << ", number " << k;
    }
  }
}

}  // namespace
}  // namespace warpcheck::validation::battery
