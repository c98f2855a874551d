// Google Benchmark of the battery's own cost (build/warpcheck_bench_battery), the speed targets of
// docs/measurements.md "Battery speed". Every battery call here runs on one thread (BatteryOptions::threads = 1),
// the calling one, and is timed by that thread's CPU clock (the "Time" column, manual time, and every counter in
// s or ns; on a machine shared with other jobs the wall clock counts their time too): counters *wall* give the
// wall clock of the same work.
//
//  fixed_cost/KERNEL/SCALAR/CONFIG   the work of a registry case that does not grow with the sample count (expected
//                 counts, KS CDFs, pdf integral, pdf-consistency, normalisations) at the default 10^7 samples:
//                 run_battery_seeds(case, options, {}) does exactly that work and draws nothing. One case per
//                 kernel family and scalar type (float, double). Time in seconds.
//  fixed_cost/median   counter median_s: the median of the fixed_cost cases run before it (target: <= 0.5 s).
//  fixed_cost_parts/KERNEL/SCALAR/CONFIG   the same work split into the battery's internal steps (counters in s).
//  per_sample/KERNEL/SCALAR   one seed's per-sample work of the battery (draw: sampling, binning; chi-square; KS
//                 with its sort) against the kernel's own loop (K::sample on a prebuilt view over pre-generated
//                 numbers, as bench_kernels.cpp), 2^20 samples each, both in each of 2 iterations. Counters per
//                 sample: battery_ns (draw_ns of it in draw()) and kernel_ns; battery_over_kernel = battery_ns /
//                 kernel_ns, overhead_over_kernel = (battery_ns - kernel_ns) / kernel_ns (target: <= 2). The
//                 geometry is one light per family.
//  user_sampler/pdf_call   one pdf call (Google Benchmark's own timing) of a user's sampler written with lambdas
//                 (no bind_kernel, no block forms): a cosine-weighted cap whose pdf inverts the warp by bisection
//                 in long double, ~5 us a call.
//  user_sampler/battery   the default battery on that sampler at 10^6 samples (target: <= 60 s); counters passed
//                 (1 when every test passes at alpha 0.01, Holm) and pdf_us (the pdf's CPU time per call).
// The build's type and flags are in the context block (build_type, cxx_flags). Run: scripts/bench_battery.sh.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "battery/drawing.h"
#include "battery/tests.h"
#include "warpcheck/catalogue.h"
#include "warpcheck/validation/battery.h"
#include "warpcheck/validation/registry.h"

namespace warpcheck::validation {
namespace {

// The calling thread's CPU time and the wall clock since construction, in seconds.
class Stopwatch {
 public:
  Stopwatch() : wall0_(std::chrono::steady_clock::now()), cpu0_(thread_cpu()) {}
  double cpu() const { return thread_cpu() - cpu0_; }
  double wall() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count(); }

 private:
  static double thread_cpu() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
  }
  std::chrono::steady_clock::time_point wall0_;
  double cpu0_;
};

BatteryOptions one_thread(std::uint64_t samples) {
  BatteryOptions o;
  o.samples = samples;
  o.threads = 1;
  return o;
}

// ---- Fixed cost --------------------------------------------------------------------------------------------

struct CaseName {
  const char* kernel;
  const char* scalar;
  const char* config;
};
// One case per family and scalar type, each near its family's median fixed cost at f34b2b65.
constexpr CaseName kFixedCases[] = {
    {"sphere-solid-angle", "float", "near"},
    {"sphere-solid-angle", "double", "near"},
    {"polygon-projected-solid-angle", "float", "decentral-square"},
    {"polygon-projected-solid-angle", "double", "decentral-square"},
    {"sphere-projected-cap", "float", "case3"},
    {"sphere-projected-cap", "double", "case3"},
    {"sptd-uniform-cap", "float", "pivot-0.3"},
    {"sptd-cosine-cap", "double", "crossing"},
    {"polygon-ltc", "float", "random"},
    {"polygon-ltc", "double", "random"},
};

const Registry& registry() {
  static const Registry r = default_registry();
  return r;
}

SamplerUnderTest make_case(const CaseName& c) {
  for (const Case& k : registry().cases())
    if (k.kernel == c.kernel && k.scalar == c.scalar && k.config == c.config) return k.make();
  throw std::runtime_error(std::string("no registry case ") + c.kernel + " / " + c.scalar + " / " + c.config);
}

// The fixed_cost cases run so far: CPU and wall seconds.
std::vector<double> fixed_cpu, fixed_wall;

// With no seed, run_battery_seeds does the seed-independent work and nothing else. Its pdf-consistency check alone
// evaluates the warp ~2e4 times (2048 points, a 4th-order stencil each), so less than 1 ms means it skipped the work.
void bm_fixed_cost(benchmark::State& state, CaseName c) {
  const SamplerUnderTest s = make_case(c);
  for (auto _ : state) {
    const Stopwatch t;
    benchmark::DoNotOptimize(run_battery_seeds(s, one_thread(10'000'000), {}));
    if (t.cpu() < 1e-3) return state.SkipWithError("run_battery_seeds with no seed did no work");
    state.SetIterationTime(t.cpu());
    fixed_cpu.push_back(t.cpu()), fixed_wall.push_back(t.wall());
    state.counters["wall_s"] = fixed_wall.back();
  }
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

void bm_fixed_cost_median(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(fixed_cpu.data());
  if (fixed_cpu.empty()) return state.SkipWithError("no fixed_cost benchmark ran before this one");
  state.counters["median_s"] = median(fixed_cpu);
  state.counters["median_wall_s"] = median(fixed_wall);
  state.counters["cases"] = double(fixed_cpu.size());
}

// The steps of the battery's seed-independent work (battery.cpp's prepare), each timed. The options as the
// battery checks them: a float sampler's quadrature tolerance is raised to 16 FLT_EPSILON.
void bm_fixed_cost_parts(benchmark::State& state, CaseName c) {
  using namespace battery;
  const SamplerUnderTest s = make_case(c);
  BatteryOptions o = one_thread(10'000'000);
  o.quadrature_tolerance = std::max(o.quadrature_tolerance, 16 * double(scalar_epsilon(s.scalar)));
  double t_expected = 0, t_integral = 0, t_consistency = 0, t_norm = 0;
  for (auto _ : state) {
    const Stopwatch t;
    const Expected e = expected_integrals(s, o);
    t_expected += t.cpu();
    benchmark::DoNotOptimize(pdf_integral(s, o, e, outside_integral(s, o)));
    t_integral += t.cpu() - t_expected;
    benchmark::DoNotOptimize(pdf_consistency(s, o));
    t_consistency += t.cpu() - t_expected - t_integral;
    benchmark::DoNotOptimize(normalizations(s));
    t_norm += t.cpu() - t_expected - t_integral - t_consistency;
    state.SetIterationTime(t.cpu());
  }
  const double n = double(state.iterations());
  state.counters["expected_counts_and_cdfs_s"] = t_expected / n;
  state.counters["pdf_integral_s"] = t_integral / n;
  state.counters["pdf_consistency_s"] = t_consistency / n;
  state.counters["normalizations_s"] = t_norm / n;
}

// ---- Per-sample cost ---------------------------------------------------------------------------------------

constexpr std::uint64_t kPerSampleCount = 1 << 20;

// One seed's per-sample work: the draws (with their KS slab counts), the chi-square and the two KS tests. The expected
// masses and the KS CDFs are uniform stand-ins: their values do not change this work, and computing them is the fixed
// cost measured above. Returns the CPU seconds of the draws alone.
double battery_seed_work(const SamplerUnderTest& s, const BatteryOptions& o) {
  using namespace battery;
  const std::size_t bins = std::size_t(o.radial_bins) * o.azimuth_bins;
  const std::vector<Real> mass(bins, Real(1) / Real(bins));
  KsCdfs cdfs;
  for (int k = 0; k <= o.ks_cdf_nodes; ++k) {
    const Real x = Real(k) / o.ks_cdf_nodes;
    cdfs.xr.push_back(x), cdfs.Fr.push_back(x), cdfs.xa.push_back(x), cdfs.Fa.push_back(x);
  }
  Expected e;
  e.mass = mass, e.ks = cdfs;
  const Stopwatch t;
  const Draws d = draw(s, o, cdfs.xr, cdfs.xa);
  const double t_draw = t.cpu();
  std::vector<TestResult> out{chi_square(s, o, d, e)};
  ks_tests(s, cdfs, d, out);
  benchmark::DoNotOptimize(out.data());
  return t_draw;
}

// One light per family (the registry's sphere "near"; a unit square 1 above, offset 1.5 sideways; the SPTD and LTC
// of bench_kernels.cpp on them).
template <class T> SphereLightGeometry<T> bench_sphere() {
  return {ShadingPoint<T>{Vec3<T>::Zero(), Vec3<T>(T(0.2), T(-0.1), T(1)).normalized()},
          SphereLight<T>{Vec3<T>(T(0.3), T(0.2), T(1.6)), T(1)}};
}
template <class T> PolygonLightGeometry<T> bench_polygon() {
  PolygonLight<T> light{Vec3<T>(T(1), T(-0.5), T(1)), Vec3<T>(T(2), T(-0.5), T(1)), Vec3<T>(T(2), T(0.5), T(1)),
                        Vec3<T>(T(1), T(0.5), T(1))};
  return {ShadingPoint<T>{Vec3<T>::Zero(), Vec3<T>(T(0), T(0), T(1))}, light};
}
template <class G> G bench_geometry(const G*);
template <class T> SphereLightGeometry<T> bench_geometry(const SphereLightGeometry<T>*) { return bench_sphere<T>(); }
template <class T> PolygonLightGeometry<T> bench_geometry(const PolygonLightGeometry<T>*) { return bench_polygon<T>(); }
template <class T> SptdCapGeometry<T> bench_geometry(const SptdCapGeometry<T>*) {
  SptdCapGeometry<T> g;
  g.sptd.pivot = Vec3<T>(T(0.2), T(0.1), T(0.5));
  g.cap = make_sphere_view(bench_sphere<T>()).cap();
  return g;
}
template <class T> LtcPolygonGeometry<T> bench_geometry(const LtcPolygonGeometry<T>*) {
  Mat3<T> m;
  m << T(0.4115), T(-0.1846), T(-0.4395), T(0.0704), T(0.8373), T(-0.1615), T(0), T(0), T(1);
  return LtcPolygonGeometry<T>{bench_polygon<T>(), m};
}

template <template <class> class K, class T> void bm_per_sample(benchmark::State& state) {
  using G = typename K<T>::Geometry;
  const G g = bench_geometry(static_cast<const G*>(nullptr));
  const SamplerUnderTest s = bind_kernel<K<T>>("bench", g);
  const BatteryOptions o = one_thread(kPerSampleCount);
  std::vector<T> u0(kPerSampleCount), u1(kPerSampleCount);
  std::mt19937_64 rng(1);
  for (std::size_t i = 0; i < kPerSampleCount; ++i)
    u0[i] = to_unit<T>(battery::uniform01(rng)), u1[i] = to_unit<T>(battery::uniform01(rng));
  double t_battery = 0, t_kernel = 0, t_draw = 0;
  for (auto _ : state) {
    const Stopwatch kernel;
    const auto v = K<T>::view(g);
    T acc = 0;
    for (std::size_t i = 0; i < kPerSampleCount; ++i) {
      const auto x = K<T>::sample(v, Vec2<T>(u0[i], u1[i]));
      acc += x.direction.x() + x.pdf;
    }
    benchmark::DoNotOptimize(acc);
    t_kernel += kernel.cpu();
    const Stopwatch battery;
    t_draw += battery_seed_work(s, o);
    t_battery += battery.cpu();
    state.SetIterationTime(kernel.cpu());
  }
  const double n = double(state.iterations()) * double(kPerSampleCount);
  const double battery_ns = 1e9 * t_battery / n, kernel_ns = 1e9 * t_kernel / n;
  state.counters["battery_ns"] = battery_ns;
  state.counters["kernel_ns"] = kernel_ns;
  state.counters["draw_ns"] = 1e9 * t_draw / n;
  state.counters["battery_over_kernel"] = battery_ns / kernel_ns;
  state.counters["overhead_over_kernel"] = (battery_ns - kernel_ns) / kernel_ns;
}

// ---- A user's sampler with an expensive pdf ----------------------------------------------------------------

// Cosine-weighted directions in a cap of half-angle theta_max about the unit axis a: sin^2(theta) = u0
// sin^2(theta_max), phi = 2 pi u1, density cos(theta) / (pi sin^2(theta_max)) (du0 du1 = 2 sin cos dtheta dphi /
// (2 pi sin^2(theta_max)) per solid angle sin dtheta dphi). Its pdf, as a user who knows only the forward warp
// would write it: the u0 whose theta(u0) = asin(sqrt(u0) sin(theta_max)) equals the direction's theta, found by
// bisection in long double to 2^-64 (64 halvings of [0, 1], each an asin), then the density at that u0.
struct CosineCap {
  Vec3L a, b1, b2;  // axis and an orthonormal frame about it
  long double sin2_max, cos_max;

  explicit CosineCap(Vec3L axis, long double theta_max)
      : a(axis.normalized()), sin2_max(std::sin(theta_max) * std::sin(theta_max)), cos_max(std::cos(theta_max)) {
    const Vec3L e = std::abs(a.x()) < 0.9L ? Vec3L(1, 0, 0) : Vec3L(0, 1, 0);
    b1 = a.cross(e).normalized();
    b2 = a.cross(b1);
  }
  Sample sample(double u0, double u1) const {
    const double s2 = u0 * double(sin2_max), sin_t = std::sqrt(s2), cos_t = std::sqrt(1 - s2);
    const double phi = 2 * std::numbers::pi * u1;
    const Vec3L w = (sin_t * std::cos(phi)) * b1 + (sin_t * std::sin(phi)) * b2 + cos_t * a;
    return Sample{w, Real(cos_t / (std::numbers::pi * double(sin2_max))), true};
  }
  Real pdf(const Vec3L& w) const {
    const long double c = w.dot(a);
    if (c < cos_max) return 0;
    const long double theta = std::acos(std::min(1.0L, c)), sin_max = std::sqrt(sin2_max);
    long double lo = 0, hi = 1;
    for (int k = 0; k < 64; ++k) {
      const long double mid = lo + (hi - lo) / 2;
      (std::asin(std::sqrt(mid) * sin_max) < theta ? lo : hi) = mid;
    }
    return std::sqrt(1 - lo * sin2_max) / (std::numbers::pi_v<long double> * sin2_max);
  }
};

SamplerUnderTest user_sampler() {
  const CosineCap cap(Vec3L(0.3L, -0.2L, 1), 40 * std::numbers::pi_v<long double> / 180);
  SamplerUnderTest s;
  s.kernel = "user-cosine-cap-bisection", s.scalar = "double", s.config = "40deg";
  s.sample = [cap](double u0, double u1) { return cap.sample(u0, u1); };
  s.pdf = [cap](const Vec3L& w) { return cap.pdf(w); };
  s.bounding_cap = Cap<Real>{cap.a, 1 - cap.cos_max};
  return s;
}

void bm_user_pdf_call(benchmark::State& state) {
  const SamplerUnderTest s = user_sampler();
  std::vector<Vec3L> w;
  std::mt19937_64 rng(2);
  for (int i = 0; i < 4096; ++i) w.push_back(s.sample(battery::uniform01(rng), battery::uniform01(rng)).direction);
  std::size_t i = 0;
  Real acc = 0;
  for (auto _ : state) acc += s.pdf(w[i++ % w.size()]);
  benchmark::DoNotOptimize(acc);
  state.SetItemsProcessed(state.iterations());
}

void bm_user_battery(benchmark::State& state) {
  const SamplerUnderTest s = user_sampler();
  std::vector<TestResult> r;
  for (auto _ : state) {
    const Stopwatch t;
    r = validate(s, one_thread(1'000'000));
    state.SetIterationTime(t.cpu());
    state.counters["wall_s"] = t.wall();
  }
  state.counters["passed"] = all_passed(r) ? 1 : 0;
  // The pdf's cost per call, measured here too so that the battery's time and the pdf's cost share one run.
  const Vec3L w = s.sample(0.3, 0.7).direction;
  const Stopwatch t;
  Real acc = 0;
  for (int k = 0; k < 20000; ++k) acc += s.pdf(w);
  benchmark::DoNotOptimize(acc);
  state.counters["pdf_us"] = 1e6 * t.cpu() / 20000;
}

template <template <class> class K> void register_per_sample() {
  for (const char* scalar : {"float", "double"})
    benchmark::RegisterBenchmark((std::string("per_sample/") + K<double>::name + "/" + scalar).c_str(),
                                 std::string(scalar) == "float" ? bm_per_sample<K, float> : bm_per_sample<K, double>)
        ->Unit(benchmark::kMillisecond)
        ->UseManualTime()
        ->Iterations(2);
}

void register_all() {
  for (const CaseName& c : kFixedCases)
    benchmark::RegisterBenchmark((std::string("fixed_cost/") + c.kernel + "/" + c.scalar + "/" + c.config).c_str(),
                                 [c](benchmark::State& s) { bm_fixed_cost(s, c); })
        ->Unit(benchmark::kSecond)
        ->UseManualTime()
        ->Iterations(1);
  benchmark::RegisterBenchmark("fixed_cost/median", bm_fixed_cost_median)->Iterations(1);
  for (const CaseName& c : kFixedCases)
    benchmark::RegisterBenchmark(
        (std::string("fixed_cost_parts/") + c.kernel + "/" + c.scalar + "/" + c.config).c_str(),
        [c](benchmark::State& s) { bm_fixed_cost_parts(s, c); })
        ->Unit(benchmark::kSecond)
        ->UseManualTime()
        ->Iterations(1);
  register_per_sample<SphereSolidAngle>();
  register_per_sample<PolygonProjectedSolidAngle>();
  register_per_sample<SphereProjectedCap>();
  register_per_sample<SptdUniformCap>();
  register_per_sample<PolygonLtc>();
  benchmark::RegisterBenchmark("user_sampler/pdf_call", bm_user_pdf_call)->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("user_sampler/battery/samples=1000000/threads=1", bm_user_battery)
      ->Unit(benchmark::kSecond)
      ->UseManualTime()
      ->Iterations(1);
}

}  // namespace
}  // namespace warpcheck::validation

int main(int argc, char** argv) {
  benchmark::AddCustomContext("build_type", WARPCHECK_BENCH_BUILD_TYPE);
  benchmark::AddCustomContext("cxx_flags", WARPCHECK_BENCH_CXX_FLAGS);
  benchmark::AddCustomContext("compiler", WARPCHECK_BENCH_COMPILER);
  warpcheck::validation::register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
