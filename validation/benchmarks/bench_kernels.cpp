// Google Benchmark of every kernel of lib/warpcheck/catalogue.h in the papers' configurations.
//
// Names: KERNEL/SCALAR/CONFIG/spl=S, KERNEL the catalogue name, S samples per light. spl=1: each iteration takes
// kLights lights, one precomputation (view) and one sample each. spl=500: each iteration takes one light, one
// precomputation and 500 samples (Peters & Dachsbacher 2019 Sec. 3.7 split). items_per_second counts samples, so
// the time per sample is 1 / items_per_second. "baseline" only reads the random numbers (and the geometry, for
// spl=1): the papers subtract such a baseline (2019 Table 2; 2021 Table 1), and so does bench_table.
// sphere-solid-angle/SCALAR/CONFIG/spl=500/batch is the batch API (batch.h) of the same kernel.
// Polygon lights are prepared once (prepare_polygon_light, polygon.h), as a renderer does when it loads the scene;
// POLYGON-KERNEL/SCALAR/CONFIG/spl=1/unprepared views the same lights without it (each view validates the light).
//
// Configurations, by the kernel's geometry:
//  sphere  qz=Q     Peters & Dachsbacher 2019 Fig. 9 / Table 2: the plane z = 0 (normal +z) lit by a unit
//                   sphere centred at (0, 0, Q), Q in {2, 0.1, -0.1, -0.9}. Shading points uniform in the
//                   square [-4, 4]^2 of the plane (our choice: the paper's camera is not given), excluding
//                   points within distance 1.01 of the centre (inside or on the light).
//  polygon central-N / decentral-N   Peters 2021 Table 1: a regular N-gon (N = 3, 4, 5; 4 only for kernels that
//                   take rectangles only) of circumradius 1, horizontal at height 1 above the plane z = 0 (normal
//                   +z). Central (the polygon contains the zenith, Fig. 3): shading points uniform in the disk of
//                   radius 0.3 below its centre. Decentral: shading points at horizontal distance 2 to 4 from its
//                   centre.
//  LTC              the polygon scenes with the battery's "random" LTC (catalogue/sptd.cpp), its third row set to
//                   (0, 0, 1) so that M^-1 keeps every light above the horizon (with the row -0.37, 0.075, 1 about
//                   21% of the decentral lights had no sample);
//  SPTD cap         the sphere scenes' caps (the light's cone from the shading point) under an SPTD with pivot
//                   (0.2, 0.1, 0.5) in world space (|r_p| 0.55) and, for the clamped cosine, base axis +z.
// The LTC and SPTD geometry is formed from the scene's light inside the timed loop, with the view.
// Random numbers: pre-generated with std::mt19937_64 seed 1, as T, in [0, 1).
#include <benchmark/benchmark.h>

#include <list>
#include <random>
#include <string>
#include <vector>

#include "warpcheck/batch.h"
#include "warpcheck/catalogue.h"

namespace warpcheck {
namespace {

constexpr int kLights = 256;
constexpr int kManySamples = 500;

template <class T> struct RandomNumbers {
  std::vector<T> u0, u1;
  explicit RandomNumbers(int n) {
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> U(0, 1);
    for (int i = 0; i < n; ++i) {
      u0.push_back(std::min(T(U(rng)), std::nextafter(T(1), T(0))));
      u1.push_back(std::min(T(U(rng)), std::nextafter(T(1), T(0))));
    }
  }
};

template <class T> std::vector<SphereLightGeometry<T>> sphere_scene(double qz) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> U(-4, 4);
  std::vector<SphereLightGeometry<T>> out;
  while (int(out.size()) < kLights) {
    const double x = U(rng), y = U(rng);
    if (x * x + y * y + qz * qz <= 1.01 * 1.01) continue;
    out.push_back(
        {ShadingPoint<T>{Vec3<T>(T(x), T(y), 0), Vec3<T>(0, 0, 1)}, SphereLight<T>{Vec3<T>(0, 0, T(qz)), T(1)}});
  }
  return out;
}

template <class T> std::vector<PolygonLightGeometry<T>> polygon_scene(int n, bool central) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(0, 1);
  PolygonLight<T> light;
  light.count = n;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * std::numbers::pi * k / n;
    light.vertices[k] = Vec3<T>(T(std::cos(a)), T(std::sin(a)), T(1));
  }
  // Prepared once, as a renderer prepares its lights when it loads the scene; kept for the program's lifetime.
  static std::list<PreparedPolygonLight<T>> prepared;
  prepared.push_back(prepare_polygon_light(light));
  std::vector<PolygonLightGeometry<T>> out;
  for (int i = 0; i < kLights; ++i) {
    const double phi = 2 * std::numbers::pi * U(rng);
    const double rho = central ? 0.3 * std::sqrt(U(rng)) : 2 + 2 * U(rng);
    const Vec3<T> x(T(rho * std::cos(phi)), T(rho * std::sin(phi)), T(0));
    out.push_back({ShadingPoint<T>{x, Vec3<T>(0, 0, 1)}, light, &prepared.back()});
  }
  return out;
}

// Runs K::sample(K::view(to_geometry(light)), u) in the two modes; accumulates outputs so nothing is optimised away.
template <template <class> class K, class T, class Light, class ToGeometry>
void run(benchmark::State& state, const std::vector<Light>& scene, ToGeometry to_geometry, int spl) {
  static const RandomNumbers<T> rn(kLights * kManySamples);
  T acc = 0;
  std::size_t light = 0, offset = 0, declined = 0;
  for (auto _ : state) {
    if (spl == 1) {
      for (int i = 0; i < kLights; ++i) {
        const auto s = K<T>::sample(K<T>::view(to_geometry(scene[i])), Vec2<T>(rn.u0[offset + i], rn.u1[offset + i]));
        acc += s.direction.x() + s.pdf;
        declined += !s.valid();
      }
      offset = (offset + kLights) % (rn.u0.size() - kLights);
    } else {
      const auto v = K<T>::view(to_geometry(scene[light]));
      for (int i = 0; i < kManySamples; ++i) {
        const auto s = K<T>::sample(v, Vec2<T>(rn.u0[offset + i], rn.u1[offset + i]));
        acc += s.direction.x() + s.pdf;
        declined += !s.valid();
      }
      light = (light + 1) % scene.size();
      offset = (offset + kManySamples) % (rn.u0.size() - kManySamples);
    }
    benchmark::DoNotOptimize(acc);
  }
  state.SetItemsProcessed(state.iterations() * (spl == 1 ? kLights : kManySamples));
  state.counters["declined_fraction"] =
      double(declined) / double(state.iterations() * (spl == 1 ? kLights : kManySamples));
}

// The baseline: the same loops, reading the geometry and the random numbers only.
template <class T, class G> void run_baseline(benchmark::State& state, const std::vector<G>& scene, int spl) {
  static const RandomNumbers<T> rn(kLights * kManySamples);
  T acc = 0;
  std::size_t offset = 0;
  for (auto _ : state) {
    const int n = spl == 1 ? kLights : kManySamples;
    for (int i = 0; i < n; ++i) acc += rn.u0[offset + i] + rn.u1[offset + i];
    if (spl == 1) acc += scene[offset % scene.size()].shading.position.x();
    offset = (offset + n) % (rn.u0.size() - n);
    benchmark::DoNotOptimize(acc);
  }
  state.SetItemsProcessed(state.iterations() * (spl == 1 ? kLights : kManySamples));
}

// The batch API: one light, kManySamples samples per call.
template <class T> void run_batch(benchmark::State& state, const std::vector<SphereLightGeometry<T>>& scene) {
  static const RandomNumbers<T> rn(kLights * kManySamples);
  std::vector<T> x(kManySamples), y(kManySamples), z(kManySamples), pdf(kManySamples);
  std::size_t light = 0, offset = 0;
  T acc = 0;
  for (auto _ : state) {
    const auto v = make_sphere_view(scene[light]);
    sample_sphere_solid_angle_batch(v, rn.u0.data() + offset, rn.u1.data() + offset, kManySamples,
                                    DirectionBatch<T>{x.data(), y.data(), z.data(), pdf.data()});
    acc += x[kManySamples - 1] + pdf[0];
    benchmark::DoNotOptimize(x.data());
    benchmark::DoNotOptimize(acc);
    light = (light + 1) % scene.size();
    offset = (offset + kManySamples) % (rn.u0.size() - kManySamples);
  }
  state.SetItemsProcessed(state.iterations() * kManySamples);
}

template <class Light> struct Scene {
  std::string config;
  std::vector<Light> lights;
  int vertices = 0;  // polygons
};

template <class T> std::vector<Scene<SphereLightGeometry<T>>> scenes(const SphereLightGeometry<T>*) {
  std::vector<Scene<SphereLightGeometry<T>>> out;
  for (double qz : {2.0, 0.1, -0.1, -0.9}) {
    char qs[16];
    std::snprintf(qs, sizeof qs, "qz=%g", qz);
    out.push_back({qs, sphere_scene<T>(qz)});
  }
  return out;
}
template <class T> std::vector<Scene<PolygonLightGeometry<T>>> scenes(const PolygonLightGeometry<T>*) {
  std::vector<Scene<PolygonLightGeometry<T>>> out;
  for (bool central : {true, false})
    for (int n : {3, 4, 5})
      out.push_back({(central ? "central-" : "decentral-") + std::to_string(n), polygon_scene<T>(n, central), n});
  return out;
}

// The scenes' light of each kernel geometry, and the kernel's geometry from it (see the top).
template <class G> struct SceneLight { using type = G; };
template <class T> struct SceneLight<SptdCapGeometry<T>> { using type = SphereLightGeometry<T>; };
template <class T> struct SceneLight<LtcPolygonGeometry<T>> { using type = PolygonLightGeometry<T>; };
template <class G> G from_light(const G& g, const G*) { return g; }
template <class T> SptdCapGeometry<T> from_light(const SphereLightGeometry<T>& g, const SptdCapGeometry<T>*) {
  SptdCapGeometry<T> c;
  c.sptd.pivot = Vec3<T>(T(0.2), T(0.1), T(0.5));
  c.cap = make_sphere_view(g).cap();
  return c;
}
template <class T> LtcPolygonGeometry<T> from_light(const PolygonLightGeometry<T>& g, const LtcPolygonGeometry<T>*) {
  Mat3<T> m;
  m << T(0.4115), T(-0.1846), T(-0.4395), T(0.0704), T(0.8373), T(-0.1615), T(0), T(0), T(1);
  return LtcPolygonGeometry<T>{g, m};
}

template <class T, class Light> std::string name(const char* kernel, const Scene<Light>& scene, int spl) {
  return std::string(kernel) + "/" + (std::is_same_v<T, float> ? "float" : "double") + "/" + scene.config +
         "/spl=" + std::to_string(spl);
}

// The polygon scene's lights without their preparation: every view validates the light again.
template <class T> std::vector<PolygonLightGeometry<T>> unprepared(std::vector<PolygonLightGeometry<T>> lights) {
  for (auto& g : lights) g.prepared = nullptr;
  return lights;
}

// Kernel K on every scene of its geometry, in both modes; a polygon kernel also at 1 spl on unprepared lights.
template <template <class> class K, class T> void register_kernel() {
  using G = typename K<T>::Geometry;
  using Light = typename SceneLight<G>::type;
  const auto to_geometry = [](const Light& light) { return from_light(light, static_cast<const G*>(nullptr)); };
  for (const Scene<Light>& scene : scenes(static_cast<const Light*>(nullptr))) {
    if (kernel_takes_only_rectangles<K<T>>() && scene.vertices != 4) continue;
    for (int spl : {1, kManySamples})
      benchmark::RegisterBenchmark(name<T>(K<T>::name, scene, spl).c_str(),
                                   [=, l = scene.lights](benchmark::State& s) { run<K, T>(s, l, to_geometry, spl); });
    if constexpr (std::is_same_v<Light, PolygonLightGeometry<T>>)
      benchmark::RegisterBenchmark(
          (name<T>(K<T>::name, scene, 1) + "/unprepared").c_str(),
          [=, l = unprepared(scene.lights)](benchmark::State& s) { run<K, T>(s, l, to_geometry, 1); });
  }
}

// The baselines of every scene, and the batch API.
template <class T, class Light> void register_baselines() {
  for (const Scene<Light>& scene : scenes(static_cast<const Light*>(nullptr))) {
    for (int spl : {1, kManySamples})
      benchmark::RegisterBenchmark(name<T>("baseline", scene, spl).c_str(),
                                   [spl, l = scene.lights](benchmark::State& s) { run_baseline<T>(s, l, spl); });
    if constexpr (std::is_same_v<Light, SphereLightGeometry<T>>)
      benchmark::RegisterBenchmark((name<T>(SphereSolidAngle<T>::name, scene, kManySamples) + "/batch").c_str(),
                                   [l = scene.lights](benchmark::State& s) { run_batch<T>(s, l); });
  }
}

template <class T> void register_all() {
  register_baselines<T, SphereLightGeometry<T>>();
  register_baselines<T, PolygonLightGeometry<T>>();
  AllKernels::for_each([]<template <class> class K>() { register_kernel<K, T>(); });
}

}  // namespace
}  // namespace warpcheck

int main(int argc, char** argv) {
  warpcheck::register_all<float>();
  warpcheck::register_all<double>();
  benchmark::AddCustomContext("build_type", WARPCHECK_BENCH_BUILD_TYPE);
  benchmark::AddCustomContext("cxx_flags", WARPCHECK_BENCH_CXX_FLAGS);
  benchmark::AddCustomContext("compiler", WARPCHECK_BENCH_COMPILER);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
