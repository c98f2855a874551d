// The battery's random streams, threads and draws (drawing.h).
#include "battery/drawing.h"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>

// On x86-64, an AVX2 clone beside the portable code, picked at run time: twice the vector width, and the same
// results bit for bit (AVX2 without FMA, so no product is contracted).
#if defined(__x86_64__) && defined(__GNUC__)
#define WARPCHECK_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define WARPCHECK_VECTOR_CLONES
#endif

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

std::uint64_t stream_seed(std::uint64_t seed, const SamplerUnderTest& s, std::uint64_t purpose, std::uint64_t chunk) {
  std::uint64_t x = seed ^ fnv1a(s.kernel + '\x1f' + s.scalar + '\x1f' + s.config);
  x ^= splitmix64(x) + purpose * 0x632be59bd9b4e019ULL;
  x ^= splitmix64(x) + chunk;
  return splitmix64(x);
}

Rng stream(std::uint64_t seed, const SamplerUnderTest& s, std::uint64_t purpose, std::uint64_t chunk) {
  return Rng(stream_seed(seed, s, purpose, chunk));
}

Real scalar_epsilon(const std::string& scalar) {
  if (scalar == "float") return FLT_EPSILON;
  if (scalar == "long double") return LDBL_EPSILON;
  return DBL_EPSILON;
}

Real rounding_slack(const SamplerUnderTest& s) {
  return 64 * scalar_epsilon(s.scalar) * (1 + std::sqrt(2 / s.bounding_cap.one_minus_cos));
}

Sample draw_one(const SamplerUnderTest& s, Rng& g, std::vector<double>& u) {
  u.resize(std::size_t(s.uniforms));
  for (double& x : u) x = uniform01(g);
  return sample_at(s, u);
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
    for (std::size_t i = 0; i < u0.size(); ++i) {
      std::vector<double> u(std::size_t(s.uniforms), 0.5);
      u[0] = u0[i], u[1] = u1[i];
      block[i] = sample_at(s, u);
    }
  }
  if (s.sample_block_double) {
    std::array<double, u0.size()> x, y, z, pdf;
    std::array<bool, u0.size()> valid;
    s.sample_block_double(u0, u1, {x, y, z, pdf, valid});
    for (std::size_t i = 0; i < u0.size(); ++i)
      if (!same(Sample{Vec3L(x[i], y[i], z[i]), pdf[i], valid[i]}, block[i]))
        block_form_disagrees(s, "sample_block_double", s.sample_block ? "sample_block" : "sample",
                             "u = (" + std::to_string(u0[i]) + ", " + std::to_string(u1[i]) + ")");
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

SlabLocator::SlabLocator(const std::vector<Real>& nodes)
    : x_(nodes.begin(), nodes.end()), first_(kBuckets + 1), last_(std::uint32_t(nodes.size() - 1)) {
  if (x_.empty() || !std::is_sorted(x_.begin(), x_.end()))
    throw std::logic_error("KS nodes must be increasing (as doubles)");
  for (int j = 0; j <= kBuckets; ++j)
    first_[j] = std::uint32_t(std::lower_bound(x_.begin(), x_.end(), double(j) / kBuckets) - x_.begin());
  x_.push_back(std::numeric_limits<double>::infinity());  // so that x_[first_[j]] exists
}

CapBinner::CapBinner(const SamplerUnderTest& s, const BatteryOptions& o, const std::vector<Real>& ks_radial_nodes,
                     const std::vector<Real>& ks_azimuth_nodes)
    : cap_(s.bounding_cap),
      rings_(o.radial_bins),
      columns_(o.azimuth_bins),
      radial_(ks_radial_nodes),
      azimuth_(ks_azimuth_nodes) {
  // A sample may land a rounding error beyond the cap's edge; within rounding_slack it counts in the outermost ring.
  const Real omc = cap_.one_minus_cos;
  slack_ = rounding_slack(s);
  const Frame<Real> f = Frame<Real>::from_z(cap_.axis);
  for (int i = 0; i < 3; ++i) axis_[i] = double(cap_.axis[i]), fx_[i] = double(f.x[i]), fy_[i] = double(f.y[i]);
  half_over_omc_ = double(1 / (2 * omc));
  inside_t_ = double(1 + slack_);
  // Error bounds of place_fast's coordinates against place_exact's, u = 2^-53 (double's unit roundoff): the
  // direction's components rounded to double and |d|^2 are within 2 u + 3 u, 1 / |d| within 4.5 u and each
  // component of the normalised w within 6.5 u, so e = w - axis is within 7.5 u + u |e|. Then t = |e|^2 / (2 omc),
  // with |e| = sqrt(2 omc t), is within 7.5 u sqrt(2 t / omc) + 28 u^2 / omc + 7.5 u t: for t <= 2 (where
  // place_fast applies) 15 u / sqrt(omc) + 28 u^2 / omc + 15 u, of which t_error_ is 4 times. The frame's
  // coordinates (x, y) are within 15 u, so for sin(theta) = |(x, y)| >= 2^-22 the azimuth is within
  // 15 u 2^22 = 7e-9 plus azimuth_fraction's error, of which phi_error_ is 2.5 times. Both margins also cover the
  // rounding of the comparisons with the edges (a few u) and place_exact's own (long double) rounding.
  constexpr double u = 0x1p-53;
  const double d_omc = double(omc);
  t_error_ = 64 * u * (1 + 1 / std::sqrt(d_omc)) + 128 * u * u / d_omc;
  phi_error_ = 2.5 * (kAtanError + 16 * u * 0x1p22) / kTwoPi<double>;
}

Placement CapBinner::place_exact(const Vec3L& direction) const {
  Real t, phi;
  cap_coordinates(cap_, direction.normalized(), t, phi);
  if (!(t <= 1 + slack_)) return Placement{.outside = true};
  t = std::min<Real>(t, 1);
  const int ri = std::min(rings_ - 1, int(t * rings_));
  const int ai = std::min(columns_ - 1, int(phi / kTwoPi<Real> * columns_));
  return Placement{false, std::uint32_t(ri * columns_ + ai), radial_(double(t)), azimuth_(double(phi / kTwoPi<Real>))};
}

// Branch-free, so that the loop over a block vectorises.
WARPCHECK_VECTOR_CLONES void CapBinner::fast_coordinates(std::size_t n, const double* x, const double* y,
                                                         const double* z, double* t, double* a) const {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i < n; ++i) {
    // 1 / sqrt(1 + delta) by its series to delta^3: for |delta| < 2^-14 the rest is below (35/128) delta^4 < 0.03 u.
    // (std::sqrt may set errno, a call that keeps the loop from vectorising.) delta = |d|^2 - 1 is exact (Sterbenz).
    const double delta = x[i] * x[i] + y[i] * y[i] + z[i] * z[i] - 1;
    const double inv = 1 - delta * (0.5 - delta * (0.375 - delta * 0.3125));
    const double wx = x[i] * inv, wy = y[i] * inv, wz = z[i] * inv;
    const double ex = wx - axis_[0], ey = wy - axis_[1], ez = wz - axis_[2];
    const double lx = wx * fx_[0] + wy * fx_[1] + wz * fx_[2], ly = wx * fy_[0] + wy * fy_[1] + wz * fy_[2];
    const double ti = (ex * ex + ey * ey + ez * ez) * half_over_omc_, ai = azimuth_fraction(lx, ly);
    // NaN where the bounds do not hold: a direction far from unit length (or beyond double's range), or within 2^-22
    // of the axis (a select between constants, added: ti + 0 is ti).
    t[i] = ti + (std::abs(delta) < 0x1p-14 ? 0.0 : kNaN);
    a[i] = ai + (lx * lx + ly * ly >= 0x1p-44 ? 0.0 : kNaN);
  }
}

std::optional<Placement> CapBinner::place_coordinates(double t, double a) const {
  if (!(t <= 2)) return std::nullopt;
  const double t_lo = t - t_error_, t_hi = t + t_error_;
  if (t_lo > inside_t_) return Placement{.outside = true};
  if (!(t_hi <= inside_t_)) return std::nullopt;
  // place_exact clamps t to 1 (the slack's samples count in the outermost ring and the last slab).
  const double c_lo = std::min(t_lo, 1.0), c_hi = std::min(t_hi, 1.0);
  const int ri = std::min(rings_ - 1, int(c_lo * rings_));
  const std::uint32_t rk = radial_.common(c_lo, c_hi);
  if (ri != std::min(rings_ - 1, int(c_hi * rings_)) || rk == SlabLocator::kNone) return std::nullopt;
  const double a_lo = a - phi_error_, a_hi = a + phi_error_;
  if (!(a_lo > 0 && a_hi < 1)) return std::nullopt;  // at the seam
  const int ai = std::min(columns_ - 1, int(a_lo * columns_));
  const std::uint32_t ak = azimuth_.common(a_lo, a_hi);
  if (ai != std::min(columns_ - 1, int(a_hi * columns_)) || ak == SlabLocator::kNone) return std::nullopt;
  return Placement{false, std::uint32_t(ri * columns_ + ai), rk, ak};
}

std::optional<Placement> CapBinner::place_fast(const Vec3L& direction) const {
  const double x = double(direction.x()), y = double(direction.y()), z = double(direction.z());
  double t, a;
  fast_coordinates(1, &x, &y, &z, &t, &a);
  return place_coordinates(t, a);
}

// Each chunk of kChunk samples has its own stream (the unit of work of a thread); within it the sampler is called
// on blocks of kBlock primary samples, drawn in the stream's order (u0, u1 of the first sample, then the next).
// Every count is a sum of the chunks' integer counts: the same whatever the thread count and order.
constexpr std::uint64_t kChunk = 1 << 16;
constexpr std::size_t kBlock = 256;

namespace {

// One chunk's counts (Draws' fields), merged into the draws under a lock.
struct Tally {
  std::vector<std::uint64_t> counts, radial, azimuth;
  std::uint64_t outside = 0, declined = 0, non_finite = 0, exact = 0;

  // A block's samples in double (sample_block_double's output; the directions are zeroed where a sample is not
  // placed) and whether each is finite in the sampler's own type.
  struct Block {
    std::array<double, kBlock> x, y, z, pdf;
    std::array<bool, kBlock> valid, finite;
  };

  explicit Tally(const Draws& d)
      : counts(d.counts.size()), radial(d.radial_slabs.size()), azimuth(d.azimuth_slabs.size()) {}

  // The block's samples placed by place_fast in two passes (the coordinates of the whole block, then each
  // placement), or by place_exact.
  void add(const CapBinner& b, std::span<const Sample> block) {
    Block d;
    for (std::size_t i = 0; i < block.size(); ++i) {
      const Sample& s = block[i];
      d.x[i] = double(s.direction.x()), d.y[i] = double(s.direction.y()), d.z[i] = double(s.direction.z());
      d.valid[i] = s.valid, d.finite[i] = all_finite(s.direction) && std::isfinite(s.pdf);
    }
    count(b, block.size(), d, [&](std::size_t i) { return block[i].direction; });
  }
  // The same for samples in double (sample_block_double): their directions are the Samples' exactly.
  void add(const CapBinner& b, std::size_t n, Block& d) {
    // v - v is 0 for a finite v and NaN otherwise: one comparison per sample, and the loop vectorises.
    for (std::size_t i = 0; i < n; ++i)
      d.finite[i] = (d.x[i] - d.x[i]) + (d.y[i] - d.y[i]) + (d.z[i] - d.z[i]) + (d.pdf[i] - d.pdf[i]) == 0;
    count(b, n, d, [&](std::size_t i) { return Vec3L(d.x[i], d.y[i], d.z[i]); });
  }

  void merge_into(Draws& d) const {
    auto add_to = [](std::vector<std::uint64_t>& to, const std::vector<std::uint64_t>& from) {
      for (std::size_t k = 0; k < to.size(); ++k) to[k] += from[k];
    };
    add_to(d.counts, counts), add_to(d.radial_slabs, radial), add_to(d.azimuth_slabs, azimuth);
    d.outside += outside, d.declined += declined, d.non_finite += non_finite, d.placed_exactly += exact;
  }

 private:
  template <class Direction> void count(const CapBinner& b, std::size_t n, Block& d, Direction direction) {
    std::array<double, kBlock> t, a;
    std::array<bool, kBlock> placed;
    for (std::size_t i = 0; i < n; ++i) {
      declined += !d.valid[i], non_finite += d.valid[i] && !d.finite[i];
      placed[i] = d.valid[i] && d.finite[i];
      if (!placed[i]) d.x[i] = d.y[i] = d.z[i] = 0;
    }
    b.fast_coordinates(n, d.x.data(), d.y.data(), d.z.data(), t.data(), a.data());
    for (std::size_t i = 0; i < n; ++i) {
      if (!placed[i]) continue;
      std::optional<Placement> p = b.place_coordinates(t[i], a[i]);
      if (!p) p = b.place_exact(direction(i)), ++exact;
      if (p->outside) {
        ++outside;
        continue;
      }
      ++counts[p->bin], ++radial[p->radial_slab], ++azimuth[p->azimuth_slab];
    }
  }
};

}  // namespace

Draws draw(const SamplerUnderTest& s, const BatteryOptions& o, const std::vector<Real>& ks_radial_nodes,
           const std::vector<Real>& ks_azimuth_nodes) {
  const CapBinner binner(s, o, ks_radial_nodes, ks_azimuth_nodes);
  Draws d;
  d.n = o.samples;
  d.counts.assign(std::size_t(o.radial_bins) * o.azimuth_bins, 0);
  d.radial_slabs.assign(binner.radial().slabs(), 0);
  d.azimuth_slabs.assign(binner.azimuth().slabs(), 0);
  const std::size_t chunks = (o.samples + kChunk - 1) / kChunk;
  std::mutex m;
  std::size_t done = 0;
  parallel_for(chunks, thread_count(o), [&](std::size_t c) {
    Rng g = stream(o.seed, s, 1, c);
    Tally tally(d);
    std::array<double, kBlock> u0, u1;
    std::array<Sample, kBlock> block;
    Tally::Block doubles;
    const std::size_t end = std::min<std::size_t>(o.samples, (c + 1) * kChunk);
    std::vector<double> u(std::size_t(s.uniforms));
    for (std::size_t b = c * kChunk; b < end; b += kBlock) {
      const std::size_t n = std::min(kBlock, end - b);
      if (s.sample_u) {
        for (std::size_t j = 0; j < n; ++j) block[j] = draw_one(s, g, u);
      } else if (s.sample_block_double) {
        for (std::size_t j = 0; j < n; ++j) u0[j] = uniform01(g), u1[j] = uniform01(g);
        Tally::Block& e = doubles;
        s.sample_block_double(
            {u0.data(), n}, {u1.data(), n},
            {{e.x.data(), n}, {e.y.data(), n}, {e.z.data(), n}, {e.pdf.data(), n}, {e.valid.data(), n}});
        tally.add(binner, n, e);
        continue;
      } else {
        for (std::size_t j = 0; j < n; ++j) u0[j] = uniform01(g), u1[j] = uniform01(g);
        sample_many(s, {u0.data(), n}, {u1.data(), n}, {block.data(), n});
      }
      tally.add(binner, {block.data(), n});
    }
    std::lock_guard lock(m);
    tally.merge_into(d);
    if (o.progress && (++done % 16 == 0 || done == chunks)) o.progress("sampling", double(done) / chunks);
  });
  return d;
}

TestResult weight_check(const SamplerUnderTest& s, const BatteryOptions& o) {
  TestResult r;
  r.kernel = s.kernel, r.scalar = s.scalar, r.config = s.config, r.test = "weight";
  Rng g = stream(o.seed, s, 4, 0);
  std::vector<double> u;
  const std::size_t n = std::min<std::uint64_t>(o.samples, kWeightSamples);
  std::size_t checked = 0, missing = 0, wrong = 0;
  Real worst = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const Sample x = draw_one(s, g, u);
    if (!x.valid || !(x.pdf > 0) || !std::isfinite(x.pdf)) continue;
    if (!x.weight) {
      ++missing;
      continue;
    }
    // Relative error against f / pdf; where f is zero the weight must be zero too (an infinite error otherwise).
    const Real expected = s.eval(x.direction) / x.pdf;
    const Real e = expected != 0 ? std::abs(*x.weight / expected - 1)
                                 : (*x.weight == 0 ? Real(0) : std::numeric_limits<Real>::infinity());
    if (!(e <= s.tolerance)) ++wrong;
    if (!(e <= worst)) worst = std::isnan(e) ? std::numeric_limits<Real>::infinity() : e;
    ++checked;
  }
  r.statistic = double(worst);
  r.passed = checked > 0 && missing == 0 && wrong == 0;
  std::ostringstream detail;
  detail << "max |weight / (eval / pdf) - 1| " << double(worst) << " over " << checked << " samples with pdf > 0 ("
         << wrong << " beyond the tolerance " << double(s.tolerance) << ", " << missing << " without a weight)";
  r.detail = detail.str();
  return r;
}

}  // namespace warpcheck::validation::battery
