// bench_table: the ratio table of the kernel benchmarks from Google Benchmark JSON (written by build/warpcheck_bench).
//
//   scripts/bench.sh                                  (runs the benchmarks, then this tool)
//   build/bench_table data/bench/results.json [--markdown]
//
// Per-sample time t = 1 / items_per_second (CPU time) of each benchmark (the median over repetitions when the JSON
// has them, --benchmark_repetitions); the baseline of the same scalar,
// configuration and samples-per-light mode ("baseline": reading the random numbers and the geometry only) is
// subtracted, as the papers do. Ratios:
//   sphere-projected-cap / sphere-solid-angle   per q_z, 1 and 500 samples per light (target at 500: <= 2)
//   polygon-projected-solid-angle / polygon-solid-angle   per vertex count, central and decentral (target
//                                               decentral: <= 4)
//   sphere-solid-angle / its batch API          per q_z at 500 (speed-up of the batch; target float: >= 3)
//   every kernel at 1 / at 500 samples per light   per scalar and configuration: the per-light setup's overhead
//                                               (polygon lights prepared once; "unprepared": the ratio without)
//                                               (targets: sphere-solid-angle and the projected caps <= 1.5;
//                                               polygon solid angle, projected solid angle, Arvo and Urena on
//                                               triangles and quads <= 2)
// beside the papers' ratios, computed from the published tables (not measured by us):
//   Peters & Dachsbacher 2019 Table 2 (offline renderer, ns per sample, baseline row subtracted):
//     (ours - baseline) / (solid angle - baseline);
//   Peters 2021 Table 1 (ms per frame, baseline already subtracted there): "Proj., ours" / "Solid angle, ours",
//     "128 lights" for 1 sample per light and "128 samples" for many.
// Exit status 0 always when the file parses (the table reports targets; it is not a test).
#include <boost/json.hpp>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

// Paper ratios (see header). 2019 Table 2: columns qz = 2, 0.1, -0.9 at 1 spl; 2, 0.1, -0.1, -0.9 at 500 spl.
std::optional<double> paper_cap_ratio(const std::string& qz, int spl) {
  struct Row {
    const char* qz;
    int spl;
    double base, solid, ours;
  };
  static const Row rows[] = {
      {"2", 1, 2.1, 8.2, 10.1},     {"0.1", 1, 2.1, 7.4, 12.9},  {"-0.9", 1, 2.2, 6.3, 15.1},
      {"2", 500, 2.0, 4.8, 6.3},    {"0.1", 500, 2.1, 4.0, 6.4}, {"-0.1", 500, 2.0, 3.8, 8.4},
      {"-0.9", 500, 2.1, 3.1, 8.4},
  };
  for (const Row& r : rows)
    if (qz == r.qz && spl == r.spl) return (r.ours - r.base) / (r.solid - r.base);
  return std::nullopt;
}

// 2021 Table 1 (baseline subtracted by the paper): {solid angle ours, proj central ours, proj decentral ours}.
std::optional<double> paper_polygon_ratio(bool central, int n, int spl) {
  if (n < 3 || n > 5) return std::nullopt;
  static const double solid[2][3] = {{5.92, 8.06, 7.59}, {1.12, 1.32, 1.60}};
  static const double proj_central[2][3] = {{8.07, 11.4, 13.9}, {2.13, 2.28, 2.76}};
  static const double proj_decentral[2][3] = {{20.0, 28.9, 39.3}, {11.1, 11.5, 11.9}};
  const int m = spl == 1 ? 0 : 1;
  return (central ? proj_central : proj_decentral)[m][n - 3] / solid[m][n - 3];
}

// The setup-overhead target of a kernel in a configuration (1 spl / 500 spl), if the issue sets one.
std::optional<double> setup_target(const std::string& kernel, const std::string& config) {
  if (kernel == "sphere-solid-angle" || kernel.starts_with("sphere-projected-cap")) return 1.5;
  const bool tri_or_quad = config.ends_with("-3") || config.ends_with("-4");
  if (tri_or_quad && (kernel == "polygon-solid-angle" || kernel == "polygon-projected-solid-angle" ||
                      kernel == "baseline-arvo-triangle" || kernel == "baseline-urena-rectangle"))
    return 2.0;
  return std::nullopt;
}

std::string fmt(std::optional<double> v, const char* f = "%.2f") {
  if (!v) return "-";
  char b[32];
  std::snprintf(b, sizeof b, f, *v);
  return b;
}

// Every kernel's cost per sample at 1 and at 500 samples per light and their ratio (the per-light setup's overhead).
template <class Net, class Ratio>
void print_setup_table(const std::map<std::string, double>& t, const Net& net, const Ratio& ratio) {
  // KERNEL -> SCALAR -> CONFIG, in the JSON's (registration) order of first appearance.
  std::vector<std::string> kernels;
  std::map<std::string, std::vector<std::string>> configs;  // SCALAR + "/" + CONFIG per kernel
  for (const auto& [name, seconds] : t) {
    const auto a = name.find('/'), b = name.find('/', a + 1), c = name.find("/spl=1", b + 1);
    if (a == std::string::npos || b == std::string::npos || c == std::string::npos || c + 6 != name.size()) continue;
    const std::string kernel = name.substr(0, a);
    if (kernel == "baseline") continue;
    if (!configs.contains(kernel)) kernels.push_back(kernel);
    configs[kernel].push_back(name.substr(a + 1, c - a - 1));
  }
  std::printf("\nPer-light setup: cost per sample at 1 sample per light / at 500 (both baseline subtracted)\n");
  std::printf("%-31s %-7s %-12s %10s %10s %8s %7s %6s %12s\n", "kernel", "scalar", "config", "1 spl ns", "500 spl ns",
              "ratio", "target", "met?", "unprepared");
  for (const std::string& kernel : kernels)
    for (const std::string& sc : configs[kernel]) {
      const std::string scalar = sc.substr(0, sc.find('/')), config = sc.substr(sc.find('/') + 1);
      const auto one = net(kernel, "/" + sc + "/spl=1"), many = net(kernel, "/" + sc + "/spl=500");
      const auto unprepared = net(kernel, "/" + sc + "/spl=1", "/unprepared");
      const auto r = ratio(one, many), ru = ratio(unprepared, many);
      const auto target = setup_target(kernel, config);
      std::printf("%-31s %-7s %-12s %10s %10s %8s %7s %6s %12s\n", kernel.c_str(), scalar.c_str(), config.c_str(),
                  fmt(one ? std::optional(*one * 1e9) : std::nullopt).c_str(),
                  fmt(many ? std::optional(*many * 1e9) : std::nullopt).c_str(), fmt(r).c_str(), fmt(target).c_str(),
                  target && r ? (*r <= *target ? "yes" : "NO") : "", fmt(ru).c_str());
    }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: bench_table RESULTS.json\n";
    return 2;
  }
  std::ifstream in(argv[1]);
  std::stringstream ss;
  ss << in.rdbuf();
  // Google Benchmark writes a 0/0 counter (declined_fraction's coefficient of variation) as NaN, which is no JSON.
  const std::string text = std::regex_replace(ss.str(), std::regex(R"(:\s*-?(NaN|nan|inf|Infinity)\b)"), ": null");
  boost::json::value root;
  try {
    root = boost::json::parse(text);
  } catch (const std::exception& e) {
    std::cerr << "bench_table: cannot parse " << argv[1] << ": " << e.what() << "\n";
    return 2;
  }
  // name -> seconds per sample: the median aggregate if there is one, else the (last) single run.
  std::map<std::string, double> t, median;
  for (const auto& b : root.at("benchmarks").as_array()) {
    const auto& o = b.as_object();
    if (!o.contains("items_per_second")) continue;
    const double seconds = 1.0 / o.at("items_per_second").to_number<double>();
    const bool aggregate = o.contains("run_type") && o.at("run_type").as_string() == "aggregate";
    if (!aggregate)
      t[std::string(o.at("name").as_string())] = seconds;
    else if (o.at("aggregate_name").as_string() == "median")
      median[std::string(o.at("run_name").as_string())] = seconds;
  }
  for (const auto& [name, seconds] : median) t[name] = seconds;
  std::string flags = "(not recorded)", build_type = "?", compiler = "?";
  if (const auto* ctx = root.as_object().if_contains("context")) {
    auto get = [&](const char* key, std::string& out) {
      if (const auto* v = ctx->as_object().if_contains(key); v && v->is_string()) out = v->as_string().c_str();
    };
    get("cxx_flags", flags), get("build_type", build_type), get("compiler", compiler);
  }
  // KERNEL/SCALAR/CONFIG/spl=S[suffix] minus baseline/SCALAR/CONFIG/spl=S; rest = /SCALAR/CONFIG/spl=S.
  auto net = [&](const std::string& kernel, const std::string& rest,
                 const std::string& suffix = "") -> std::optional<double> {
    const auto k = t.find(kernel + rest + suffix), base = t.find("baseline" + rest);
    if (k == t.end() || base == t.end()) return std::nullopt;
    return k->second - base->second;
  };
  auto ratio = [](std::optional<double> a, std::optional<double> b) -> std::optional<double> {
    if (!a || !b || !(*b > 0)) return std::nullopt;
    return *a / *b;
  };

  std::printf("Per-sample costs (ns, baseline subtracted) and ratios; measured from %s\n", argv[1]);
  std::printf("Build: %s, %s, flags \"%s\"; %s\n\n", build_type.c_str(), compiler.c_str(), flags.c_str(),
              median.empty() ? "one run per benchmark" : "median over repetitions");
  std::printf("Projected spherical cap / sphere solid angle (Peters & Dachsbacher 2019 Table 2 configurations)\n");
  std::printf("%-7s %-5s %5s %10s %10s %8s %8s %7s\n", "scalar", "qz", "spl", "solid ns", "proj ns", "ratio", "paper",
              "<=2?");
  for (const char* T : {"float", "double"})
    for (int spl : {1, 500})
      for (const char* qz : {"2", "0.1", "-0.1", "-0.9"}) {
        const std::string rest = std::string("/") + T + "/qz=" + qz + "/spl=" + std::to_string(spl);
        const auto s = net("sphere-solid-angle", rest), p = net("sphere-projected-cap", rest);
        const auto r = ratio(p, s);
        std::printf("%-7s %-5s %5d %10s %10s %8s %8s %7s\n", T, qz, spl,
                    fmt(s ? std::optional(*s * 1e9) : std::nullopt).c_str(),
                    fmt(p ? std::optional(*p * 1e9) : std::nullopt).c_str(), fmt(r).c_str(),
                    fmt(paper_cap_ratio(qz, spl)).c_str(), spl == 500 && r ? (*r <= 2 ? "yes" : "NO") : "");
      }

  std::printf("\nPolygon projected / polygon solid angle (Peters 2021 Table 1 configurations)\n");
  std::printf("%-7s %-12s %5s %10s %10s %8s %8s %7s\n", "scalar", "config", "spl", "solid ns", "proj ns", "ratio",
              "paper", "<=4?");
  for (const char* T : {"float", "double"})
    for (int spl : {1, 500})
      for (bool central : {false, true})
        for (int n : {3, 4, 5}) {
          const std::string config = std::string(central ? "central-" : "decentral-") + std::to_string(n);
          const std::string rest = std::string("/") + T + "/" + config + "/spl=" + std::to_string(spl);
          const auto s = net("polygon-solid-angle", rest), p = net("polygon-projected-solid-angle", rest);
          const auto r = ratio(p, s);
          std::printf("%-7s %-12s %5d %10s %10s %8s %8s %7s\n", T, config.c_str(), spl,
                      fmt(s ? std::optional(*s * 1e9) : std::nullopt).c_str(),
                      fmt(p ? std::optional(*p * 1e9) : std::nullopt).c_str(), fmt(r).c_str(),
                      fmt(paper_polygon_ratio(central, n, spl)).c_str(), !central && r ? (*r <= 4 ? "yes" : "NO") : "");
        }

  std::printf("\nBatch API speed-up: scalar sphere solid angle / batch, 500 samples per light (target float: >= 3)\n");
  std::printf("%-7s %-5s %10s %10s %8s %7s\n", "scalar", "qz", "scalar ns", "batch ns", "speedup", ">=3?");
  for (const char* T : {"float", "double"})
    for (const char* qz : {"2", "0.1", "-0.1", "-0.9"}) {
      const std::string rest = std::string("/") + T + "/qz=" + qz + "/spl=500";
      const auto s = net("sphere-solid-angle", rest), b = net("sphere-solid-angle", rest, "/batch");
      const auto r = ratio(s, b);
      std::printf("%-7s %-5s %10s %10s %8s %7s\n", T, qz, fmt(s ? std::optional(*s * 1e9) : std::nullopt).c_str(),
                  fmt(b ? std::optional(*b * 1e9) : std::nullopt).c_str(), fmt(r).c_str(),
                  std::string(T) == "float" && r ? (*r >= 3 ? "yes" : "NO") : "");
    }
  print_setup_table(t, net, ratio);
  return 0;
}
