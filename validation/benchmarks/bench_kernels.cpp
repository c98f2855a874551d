// Google Benchmark of the kernels in the papers' configurations (issue 9).
//
// Names: KERNEL/SCALAR/CONFIG/spl=S, S samples per light. spl=1: each iteration takes kLights lights, one
// precomputation (view) and one sample each. spl=500: each iteration takes one light, one precomputation and
// 500 samples (Peters & Dachsbacher 2019 Sec. 3.7 split). items_per_second counts samples, so the time per
// sample is 1 / items_per_second. "baseline" only reads the random numbers (and the geometry, for spl=1):
// the papers subtract such a baseline (2019 Table 2; 2021 Table 1), and so does bench_table.
//
// Configurations:
//  sphere  qz=Q     Peters & Dachsbacher 2019 Fig. 9 / Table 2: the plane z = 0 (normal +z) lit by a unit
//                   sphere centred at (0, 0, Q), Q in {2, 0.1, -0.1, -0.9}. Shading points uniform in the
//                   square [-4, 4]^2 of the plane (our choice: the paper's camera is not given), excluding
//                   points within distance 1.01 of the centre (inside or on the light).
//  polygon central-N / decentral-N   Peters 2021 Table 1: a regular N-gon (N = 3, 4, 5) of circumradius 1,
//                   horizontal at height 1 above the plane z = 0 (normal +z). Central (the polygon contains
//                   the zenith, Fig. 3): shading points uniform in the disk of radius 0.3 below its centre.
//                   Decentral: shading points at horizontal distance 2 to 4 from its centre.
// Kernels the papers do not time (no target; in the JSON for the report):
//  polygon_ltc      the polygon scenes with the battery's "random" LTC (registry_sptd.cpp), its third row set to
//                   (0, 0, 1) so that M^-1 keeps every light above the horizon (with the row -0.37, 0.075, 1 about
//                   21% of the decentral lights had no sample);
//  sptd_uniform_cap / sptd_cosine_cap   the sphere scenes' caps (the light's cone from the shading point) under an
//                   SPTD with pivot (0.2, 0.1, 0.5) in world space (|r_p| 0.55) and, for the clamped cosine, base
//                   axis +z.
// Random numbers: pre-generated with std::mt19937_64 seed 1, as T, in [0, 1).
#include <benchmark/benchmark.h>

#include <random>
#include <string>
#include <vector>

#include "warpcheck/batch.h"
#include "warpcheck/ltc.h"
#include "warpcheck/polygon_projected.h"
#include "warpcheck/polygon_solid_angle.h"
#include "warpcheck/projected_cap.h"
#include "warpcheck/sphere.h"
#include "warpcheck/spherical_rectangle.h"
#include "warpcheck/sptd.h"

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
  std::vector<PolygonLightGeometry<T>> out;
  for (int i = 0; i < kLights; ++i) {
    const double phi = 2 * std::numbers::pi * U(rng);
    const double rho = central ? 0.3 * std::sqrt(U(rng)) : 2 + 2 * U(rng);
    const Vec3<T> x(T(rho * std::cos(phi)), T(rho * std::sin(phi)), T(0));
    out.push_back({ShadingPoint<T>{x, Vec3<T>(0, 0, 1)}, light});
  }
  return out;
}

// Runs `sample(make_view(g), u)` in the two modes; accumulates outputs so nothing is optimised away.
template <class T, class G, class MakeView, class Sample>
void run(benchmark::State& state, const std::vector<G>& scene, MakeView make_view, Sample sample, int spl) {
  static const RandomNumbers<T> rn(kLights * kManySamples);
  T acc = 0;
  std::size_t light = 0, offset = 0, declined = 0;
  for (auto _ : state) {
    if (spl == 1) {
      for (int i = 0; i < kLights; ++i) {
        const auto s = sample(make_view(scene[i]), Vec2<T>(rn.u0[offset + i], rn.u1[offset + i]));
        acc += s.direction.x() + s.pdf;
        declined += !s.valid();
      }
      offset = (offset + kLights) % (rn.u0.size() - kLights);
    } else {
      const auto v = make_view(scene[light]);
      for (int i = 0; i < kManySamples; ++i) {
        const auto s = sample(v, Vec2<T>(rn.u0[offset + i], rn.u1[offset + i]));
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

template <class T> void register_all() {
  const std::string t = std::is_same_v<T, float> ? "float" : "double";
  for (double qz : {2.0, 0.1, -0.1, -0.9}) {
    const auto scene = sphere_scene<T>(qz);
    char qs[16];
    std::snprintf(qs, sizeof qs, "qz=%g", qz);
    for (int spl : {1, kManySamples}) {
      const std::string suffix = "/" + t + "/" + qs + "/spl=" + std::to_string(spl);
      benchmark::RegisterBenchmark(("sphere_baseline" + suffix).c_str(),
                                   [=](benchmark::State& s) { run_baseline<T>(s, scene, spl); });
      benchmark::RegisterBenchmark(("sphere_solid_angle" + suffix).c_str(), [=](benchmark::State& s) {
        run<T>(
            s, scene, [](const auto& g) { return make_sphere_view(g); },
            [](const auto& v, const Vec2<T>& u) { return sample_sphere_solid_angle(v, u); }, spl);
      });
      benchmark::RegisterBenchmark(("sphere_visible_area" + suffix).c_str(), [=](benchmark::State& s) {
        run<T>(
            s, scene, [](const auto& g) { return std::make_pair(make_sphere_view(g), g.light); },
            [](const auto& v, const Vec2<T>& u) { return sample_sphere_visible_area(v.first, v.second, u); }, spl);
      });
      benchmark::RegisterBenchmark(("projected_cap" + suffix).c_str(), [=](benchmark::State& s) {
        run<T>(
            s, scene, [](const auto& g) { return make_projected_cap_view(g); },
            [](const auto& v, const Vec2<T>& u) { return sample_projected_spherical_cap(v, u); }, spl);
      });
      for (const SptdBase base : {SptdBase::kUniform, SptdBase::kClampedCosine}) {
        const std::string name = base == SptdBase::kUniform ? "sptd_uniform_cap" : "sptd_cosine_cap";
        benchmark::RegisterBenchmark((name + suffix).c_str(), [=](benchmark::State& s) {
          run<T>(
              s, scene,
              [base](const auto& g) {
                SptdCapGeometry<T> c;
                c.sptd.pivot = Vec3<T>(T(0.2), T(0.1), T(0.5));
                c.sptd.base = base;
                c.cap = make_sphere_view(g).cap();
                return make_sptd_cap_view(c);
              },
              [](const auto& v, const Vec2<T>& u) { return sample_sptd_cap(v, u); }, spl);
        });
      }
      if (spl == kManySamples)
        benchmark::RegisterBenchmark(("sphere_solid_angle_batch" + suffix).c_str(),
                                     [=](benchmark::State& s) { run_batch<T>(s, scene); });
    }
  }
  for (bool central : {true, false}) {
    for (int n : {3, 4, 5}) {
      const auto scene = polygon_scene<T>(n, central);
      for (int spl : {1, kManySamples}) {
        const std::string suffix =
            "/" + t + "/" + (central ? "central-" : "decentral-") + std::to_string(n) + "/spl=" + std::to_string(spl);
        benchmark::RegisterBenchmark(("polygon_baseline" + suffix).c_str(),
                                     [=](benchmark::State& s) { run_baseline<T>(s, scene, spl); });
        benchmark::RegisterBenchmark(("polygon_solid_angle" + suffix).c_str(), [=](benchmark::State& s) {
          run<T>(
              s, scene, [](const auto& g) { return make_polygon_solid_angle_view(g, false); },
              [](const auto& v, const Vec2<T>& u) { return sample_polygon_solid_angle(v, u); }, spl);
        });
        benchmark::RegisterBenchmark(("polygon_solid_angle_clipped" + suffix).c_str(), [=](benchmark::State& s) {
          run<T>(
              s, scene, [](const auto& g) { return make_polygon_solid_angle_view(g, true); },
              [](const auto& v, const Vec2<T>& u) { return sample_polygon_solid_angle(v, u); }, spl);
        });
        benchmark::RegisterBenchmark(("polygon_projected" + suffix).c_str(), [=](benchmark::State& s) {
          run<T>(
              s, scene, [](const auto& g) { return make_polygon_projected_view<T, false>(g); },
              [](const auto& v, const Vec2<T>& u) { return sample_polygon_projected_solid_angle<T, false>(v, u); },
              spl);
        });
        benchmark::RegisterBenchmark(("polygon_projected_biased" + suffix).c_str(), [=](benchmark::State& s) {
          run<T>(
              s, scene, [](const auto& g) { return make_polygon_projected_view<T, true>(g); },
              [](const auto& v, const Vec2<T>& u) { return sample_polygon_projected_solid_angle<T, true>(v, u, 0); },
              spl);
        });
        benchmark::RegisterBenchmark(("polygon_ltc" + suffix).c_str(), [=](benchmark::State& s) {
          Mat3<T> m;
          m << T(0.4115), T(-0.1846), T(-0.4395), T(0.0704), T(0.8373), T(-0.1615), T(0), T(0), T(1);
          run<T>(
              s, scene,
              [m](const auto& g) {
                return make_ltc_polygon_view(LtcPolygonGeometry<T>{g, m});
              },
              [](const auto& v, const Vec2<T>& u) { return sample_ltc_polygon(v, u); }, spl);
        });
        benchmark::RegisterBenchmark(("polygon_arvo" + suffix).c_str(), [=](benchmark::State& s) {
          run<T>(
              s, scene, [](const auto& g) { return make_arvo_fan_view(g); },
              [](const auto& v, const Vec2<T>& u) { return sample_arvo_triangle_fan(v, u); }, spl);
        });
        benchmark::RegisterBenchmark(("polygon_turk_area" + suffix).c_str(), [=](benchmark::State& s) {
          run<T>(
              s, scene, [](const auto& g) { return make_turk_area_view(g); },
              [](const auto& v, const Vec2<T>& u) { return sample_turk_area(v, u); }, spl);
        });
        if (n == 4)
          benchmark::RegisterBenchmark(("spherical_rectangle" + suffix).c_str(), [=](benchmark::State& s) {
            run<T>(
                s, scene, [](const auto& g) { return make_spherical_rectangle_view(g); },
                [](const auto& v, const Vec2<T>& u) { return sample_spherical_rectangle(v, u); }, spl);
          });
      }
    }
  }
}

}  // namespace
}  // namespace warpcheck

int main(int argc, char** argv) {
  warpcheck::register_all<float>();
  warpcheck::register_all<double>();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
