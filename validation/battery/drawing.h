// The battery's random streams, threads and draws (internal to the battery).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <future>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include <boost/random/mersenne_twister.hpp>

#include "warpcheck/validation/battery.h"

namespace warpcheck::validation::battery {

// The battery's generator: the 64-bit Mersenne Twister, the same stream as std::mt19937_64 (test
// BatteryStream.IsTheStandardMersenneTwister). Boost's, because libstdc++'s twist branches on each word's random low
// bit and draws about 3 times slower.
using Rng = boost::random::mt19937_64;

// Independent, reproducible stream per (seed, sampler, purpose, chunk): the battery is deterministic whatever
// the thread count. Purposes: 1 the draws, 2 pdf-consistency, 3 no-sample, 4 weight.
// stream() is Rng(stream_seed()).
std::uint64_t stream_seed(std::uint64_t seed, const SamplerUnderTest& s, std::uint64_t purpose, std::uint64_t chunk);
Rng stream(std::uint64_t seed, const SamplerUnderTest& s, std::uint64_t purpose, std::uint64_t chunk);

// In [0, 1): the top 53 bits of one 64-bit number.
template <class G> double uniform01(G& g) { return double(g() >> 11) * 0x1.0p-53; }

// The machine epsilon of a sampler's scalar type ("float", "double", "long double"; others as double).
Real scalar_epsilon(const std::string& scalar);

// How far beyond the bounding cap's edge, in t = (1 - cos theta) / (1 - cos theta_max), a sample still counts in the
// outermost ring, and the resolution in t of the expected counts: a direction in the sampler's scalar type has an
// angular error of a few epsilon, which over the cap's angular radius (about sqrt(2 omc)) is eps sqrt(2 / omc) in t.
Real rounding_slack(const SamplerUnderTest& s);

// One sample of the sampler from the next s.uniforms numbers of g (u holds them afterwards).
Sample draw_one(const SamplerUnderTest& s, Rng& g, std::vector<double>& u);

int thread_count(const BatteryOptions& o);  // options.threads, or the hardware's when 0

// Runs body(i) for i in [0, n) on `threads` threads.
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

// Work that runs on one thread (an adaptive quadrature, pdf-consistency) started beside the parallel work when
// the run may use more than one thread, else deferred to the first get(): the same result either way, since each
// test is a function of the sampler and the options alone.
template <class F> auto beside(const BatteryOptions& o, F f) {
  return std::async(thread_count(o) > 1 ? std::launch::async : std::launch::deferred, std::move(f)).share();
}

// Throws std::invalid_argument when a block form of the sampler (sample_block, pdf_block) disagrees with its
// single form (sample, pdf) at a few fixed primary samples and directions, bit for bit: a block form that
// bind_kernel filled and that was left behind when sample or pdf was replaced would otherwise be tested instead.
void check_block_forms(const SamplerUnderTest& s);

// The KS slab of a coordinate v: the first of the increasing nodes x[0..M] that is >= v, or M when v is beyond
// them all. The number of values <= x[k] is then the number in slabs 0..k for k < M, and every value at k = M. The
// nodes are compared as doubles, as the coordinates are. A table of the first node >= j / 2048 narrows the binary
// search to the nodes of v's bucket (exact: v * 2048 is exact, and lower_bound is monotone in v).
class SlabLocator {
 public:
  explicit SlabLocator(const std::vector<Real>& nodes);  // throws std::logic_error unless increasing
  std::uint32_t operator()(double v) const {
    auto lo = x_.begin(), hi = x_.end() - 1;
    if (v >= 0 && v < 1) {
      const int j = int(v * kBuckets);
      const std::uint32_t k = first_[j];
      // A bucket with at most one node (all of them for ~1000 uniform nodes): one comparison, no branch.
      if (first_[j + 1] - k <= 1) return std::min(last_, k + std::uint32_t(x_[k] < v));
      lo = x_.begin() + k, hi = x_.begin() + first_[j + 1];
    }
    return std::min(last_, std::uint32_t(std::lower_bound(lo, hi, v) - x_.begin()));
  }
  // True when every v in [lo, hi] has slab k (the slab of a v in [lo, hi]).
  bool holds(std::uint32_t k, double lo, double hi) const {
    return (k == 0 || x_[k - 1] < lo) && (k == last_ || hi <= x_[k]);
  }
  // The slab of every v in [lo, hi] (lo <= hi), or kNone when they are not all in one slab. Where lo and hi share a
  // bucket with at most one node, the bucket decides (one comparison with its node).
  static constexpr std::uint32_t kNone = ~std::uint32_t(0);
  std::uint32_t common(double lo, double hi) const {
    if (lo >= 0 && hi < 1) {
      const int j = int(lo * kBuckets);
      const std::uint32_t k = first_[j];
      if (int(hi * kBuckets) == j && first_[j + 1] - k <= 1) {
        const bool above_lo = x_[k] < lo, above_hi = x_[k] < hi;  // x_[k] = +inf past the last node
        return above_lo == above_hi ? std::min(last_, k + std::uint32_t(above_lo)) : kNone;
      }
    }
    const std::uint32_t k = (*this)(lo);
    return holds(k, lo, hi) ? k : kNone;
  }
  std::size_t slabs() const { return last_ + 1; }

 private:
  static constexpr int kBuckets = 2048;
  std::vector<double> x_;             // the nodes, then +inf
  std::vector<std::uint32_t> first_;  // first_[j]: the first node >= j / kBuckets
  std::uint32_t last_;                // M
};

// atan(z) for z in [0, 1]: z Q(z^2), Q of degree 7 fitted to atan(z) / z by least squares reweighted toward the
// minimax (Lawson's iteration); its error in double is at most kAtanError (test
// CapBinner.AzimuthPolynomialIsWithinItsStatedError).
constexpr double kAtanError = 3.8e-8;
inline double atan_unit(double z) {
  constexpr double c[] = {0.99999933557681786, -0.33329860774962033,  0.19946565521188678, -0.13908628812270829,
                          0.09642195259927995, -0.055912296411157456, 0.0218629355239819,  -0.0040545607040289285};
  const double s = z * z;
  double q = c[7];
  for (int k = 6; k >= 0; --k) q = q * s + c[k];
  return z * q;
}

// phi / 2 pi in [0, 1] of the direction (x, y) in a plane, phi = atan2(y, x) mod 2 pi, by atan_unit: within
// kAtanError / 2 pi plus a few rounding errors; NaN at the origin. The octant's reflections are written with copysign
// (c - copysign(c, s) + copysign(p, s) is p for s >= +0 and 2 c - p otherwise, both exactly as rounded), not as
// selects: no branch to mispredict, and the loop over a block vectorises.
inline double azimuth_fraction(double x, double y) {
  const double ax = std::abs(x), ay = std::abs(y), d = ax - ay;
  double p = atan_unit(std::min(ax, ay) / std::max(ax, ay));                        // in [0, pi / 4]
  p = (kPi<double> / 4 - std::copysign(kPi<double> / 4, d)) + std::copysign(p, d);  // [0, pi / 2]
  p = (kPi<double> / 2 - std::copysign(kPi<double> / 2, x)) + std::copysign(p, x);  // [0, pi]
  p = (kPi<double> - std::copysign(kPi<double>, y)) + std::copysign(p, y);          // [0, 2 pi]
  return p * (1 / kTwoPi<double>);
}

// Where a sample's direction falls: beyond the bounding cap (with the rounding slack of the sampler's scalar
// type), or in one chi-square bin (row-major [ring][column]) and one KS slab of each marginal.
struct Placement {
  bool outside = false;
  std::uint32_t bin = 0, radial_slab = 0, azimuth_slab = 0;
  bool operator==(const Placement&) const = default;
};

// Places directions in the cap's frame: t = (1 - cos theta) / (1 - cos theta_max) and phi / 2 pi.
class CapBinner {
 public:
  CapBinner(const SamplerUnderTest& s, const BatteryOptions& o, const std::vector<Real>& ks_radial_nodes,
            const std::vector<Real>& ks_azimuth_nodes);
  // By the long double cap_coordinates of the normalised direction: the definition.
  Placement place_exact(const Vec3L& direction) const;
  // The same in double, or nullopt when the coordinates are within their rounding error bound of an edge (a bin's,
  // a slab's, the cap's, the azimuth's seam) and place_exact must decide.
  std::optional<Placement> place_fast(const Vec3L& direction) const;
  // place_fast in two steps, for a block: the coordinates t and phi / 2 pi in double (NaN where place_fast does
  // not apply) of n directions (x, y, z), then the placement from them.
  void fast_coordinates(std::size_t n, const double* x, const double* y, const double* z, double* t, double* a) const;
  std::optional<Placement> place_coordinates(double t, double a) const;
  Placement place(const Vec3L& direction) const {
    const std::optional<Placement> p = place_fast(direction);
    return p ? *p : place_exact(direction);
  }
  const SlabLocator& radial() const { return radial_; }
  const SlabLocator& azimuth() const { return azimuth_; }

 private:
  Cap<Real> cap_;
  Real slack_;
  int rings_, columns_;
  SlabLocator radial_, azimuth_;
  // place_fast's copies in double: the cap's axis, its frame's x and y, 1 / (2 (1 - cos theta_max)), the largest
  // t inside, and the error bounds of t and of phi / 2 pi.
  std::array<double, 3> axis_, fx_, fy_;
  double half_over_omc_, inside_t_, t_error_, phi_error_;
};

struct Draws {
  std::uint64_t n = 0;                                     // samples drawn
  std::vector<std::uint64_t> counts;                       // chi-square grid counts
  std::vector<std::uint64_t> radial_slabs, azimuth_slabs;  // KS: samples per slab of each marginal's nodes
  std::uint64_t outside = 0, declined = 0, non_finite = 0;
  std::uint64_t placed_exactly = 0;  // samples that place_fast left to place_exact
};

// options.samples draws of the sampler from options.seed, counted on the chi-square grid and in the slabs between
// the KS nodes (ks_nodes, seed-independent).
Draws draw(const SamplerUnderTest& s, const BatteryOptions& o, const std::vector<Real>& ks_radial_nodes,
           const std::vector<Real>& ks_azimuth_nodes);

// The test "weight", for a sampler with an eval: min(options.samples, kWeightSamples) draws of its own stream, each
// with pdf > 0 carrying weight == eval(direction) / pdf to the sampler's tolerance (relative). Every sample is
// checked, not a sample of them: a weight wrong on a tenth of the support is caught by ~6500 of the draws.
constexpr std::uint64_t kWeightSamples = 1 << 16;
TestResult weight_check(const SamplerUnderTest& s, const BatteryOptions& o);

}  // namespace warpcheck::validation::battery
