// The battery's random streams, threads and draws (drawing.h).
#include "battery/drawing.h"

#include <array>
#include <cfloat>
#include <cmath>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace warpcheck::validation::battery {
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

}  // namespace

std::mt19937_64 stream(std::uint64_t seed, const SamplerUnderTest& s, std::uint64_t purpose, std::uint64_t chunk) {
  std::uint64_t x = seed ^ fnv1a(s.kernel + '\x1f' + s.scalar + '\x1f' + s.config);
  x ^= splitmix64(x) + purpose * 0x632be59bd9b4e019ULL;
  x ^= splitmix64(x) + chunk;
  return std::mt19937_64(splitmix64(x));
}

Real scalar_epsilon(const std::string& scalar) {
  if (scalar == "float") return FLT_EPSILON;
  if (scalar == "long double") return LDBL_EPSILON;
  return DBL_EPSILON;
}

int thread_count(const BatteryOptions& o) {
  if (o.threads > 0) return o.threads;
  return std::max(1u, std::thread::hardware_concurrency());
}

namespace {

// Equal values, zeros of the same sign; any two NaNs agree.
bool same(Real a, Real b) { return (a == b && std::signbit(a) == std::signbit(b)) || (std::isnan(a) && std::isnan(b)); }

bool same(const Sample& a, const Sample& b) {
  return a.valid == b.valid && same(a.pdf, b.pdf) && same(a.direction.x(), b.direction.x()) &&
         same(a.direction.y(), b.direction.y()) && same(a.direction.z(), b.direction.z());
}

[[noreturn]] void block_form_disagrees(const SamplerUnderTest& s, const char* block, const char* single,
                                       const std::string& where) {
  throw std::invalid_argument("SamplerUnderTest " + s.kernel + " / " + s.scalar + " / " + s.config + ": " + block +
                              " disagrees with " + single + " at " + where + " (was " + single +
                              " replaced after bind_kernel? replace or clear " + block + " too)");
}

}  // namespace

void check_block_forms(const SamplerUnderTest& s) {
  // Primary samples spread over the square, one near each corner: the directions where a replaced sample or pdf
  // (a negative control's tilt, a test's wrapper) differs from the bound kernel's.
  constexpr std::array<double, 8> u0{0.5, 0.125, 0.875, 0.3, 0.7, 0.01, 0.99, 0.999},
      u1{0.5, 0.875, 0.125, 0.7, 0.3, 0.02, 0.98, 0.001};
  std::array<Sample, u0.size()> block;
  if (s.sample_block) {
    s.sample_block(u0, u1, block);
    for (std::size_t i = 0; i < u0.size(); ++i)
      if (!same(block[i], s.sample(u0[i], u1[i])))
        block_form_disagrees(s, "sample_block", "sample",
                             "u = (" + std::to_string(u0[i]) + ", " + std::to_string(u1[i]) + ")");
  } else {
    for (std::size_t i = 0; i < u0.size(); ++i) block[i] = s.sample(u0[i], u1[i]);
  }
  if (!s.pdf_block) return;
  // The samples' directions (where the pdf is nonzero, however thin the support) and points of the bounding cap.
  std::vector<Vec3L> w;
  for (const Sample& x : block)
    if (x.valid && all_finite(x.direction)) w.push_back(x.direction);
  for (Real t : {Real(0), Real(0.5), Real(1)})
    for (Real phi : {Real(0.5), Real(2.5), Real(4.5)}) w.push_back(cap_direction(s.bounding_cap, t, phi));
  std::vector<Real> p(w.size());
  s.pdf_block(w, p);
  for (std::size_t i = 0; i < w.size(); ++i)
    if (!same(p[i], s.pdf(w[i]))) {
      std::ostringstream where;
      where.precision(17);
      where << "w = (" << double(w[i].x()) << ", " << double(w[i].y()) << ", " << double(w[i].z()) << ")";
      block_form_disagrees(s, "pdf_block", "pdf", where.str());
    }
}

// Each chunk of kChunk samples has its own stream (the unit of work of a thread); within it the sampler is called
// on blocks of kBlock primary samples, drawn in the stream's order (u0, u1 of the first sample, then the next).
constexpr std::uint64_t kChunk = 1 << 16;
constexpr std::size_t kBlock = 256;

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
    std::array<double, kBlock> u0, u1;
    std::array<Sample, kBlock> block;
    for (std::size_t b = c * kChunk; b < end; b += kBlock) {
      const std::size_t m = std::min(kBlock, end - b);
      for (std::size_t j = 0; j < m; ++j) u0[j] = uniform01(g), u1[j] = uniform01(g);
      sample_many(s, {u0.data(), m}, {u1.data(), m}, {block.data(), m});
      for (std::size_t j = 0; j < m; ++j) {
        const std::size_t i = b + j;
        const Sample& x = block[j];
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
    }
    std::lock_guard lock(m);
    for (std::size_t k = 0; k < local.size(); ++k) d.counts[k] += local[k];
    d.outside += outside, d.declined += declined, d.non_finite += non_finite;
    const std::size_t n = ++done;
    if (o.progress && (n % 16 == 0 || n == chunks)) o.progress("sampling", double(n) / chunks);
  });
  return d;
}

}  // namespace warpcheck::validation::battery
