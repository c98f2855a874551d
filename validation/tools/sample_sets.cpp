// sample_sets: the report's sample sets, computed and written as JSON for `warpcheck report` to draw.
//
//   build/sample_sets --out FILE [--from RESULTS] [--per-kernel N]
//
// For every kernel of the registry and the negative controls (with --from: every kernel of that results file), up
// to N cases (default 3), one per configuration, the configurations of RESULTS first and then double precision:
// a grid of 17 + 17 lines of 96 points and 1024 best-candidate blue-noise points (seed 1) in primary sample space,
// and the directions the case's sampler maps them to (see sample_sets.h). scripts/battery.sh writes
// reports/sample-sets.json (about 4 MB for the whole registry, so generated beside the report, not committed).
//
// JSON: {"command", "grid_lines", "grid_line_samples", "blue_noise": {"seed", "u": [[u0, u1], ...]},
// "cases": [{"kernel", "scalar", "config", "description", "expect_no_sample", "grid": [...], "blue": [...]}]}
// where each mapped point is [x, y] inside the cap, [x, y, 1] outside it, or null when the sampler declined;
// "grid" holds the points in grid_line_points order. A case that cannot be built has "error" instead.
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "tools/sample_sets.h"
#include "warpcheck/validation/negative_controls.h"
#include "warpcheck/validation/registry.h"
#include "warpcheck/validation/results.h"

using namespace warpcheck::validation;
using namespace warpcheck::validation::sample_sets;

namespace {

// Up to per_kernel cases of each kernel, one per configuration: the run's configurations first, then double.
std::vector<const Case*> chosen_cases(const std::vector<const Case*>& all, const BatteryRun* run, int per_kernel) {
  std::set<std::string> run_kernels;
  std::map<std::string, std::set<std::string>> run_configs;
  if (run)
    for (const TestResult& r : run->results) run_kernels.insert(r.kernel), run_configs[r.kernel].insert(r.config);
  std::vector<std::string> kernels;  // in order of first appearance
  std::map<std::string, std::vector<const Case*>> by_kernel;
  for (const Case* c : all) {
    if (run && !run_kernels.count(c->kernel)) continue;
    if (!by_kernel.count(c->kernel)) kernels.push_back(c->kernel);
    by_kernel[c->kernel].push_back(c);
  }
  std::vector<const Case*> out;
  for (const std::string& k : kernels) {
    std::vector<const Case*>& mine = by_kernel[k];
    auto rank = [&](const Case* c) {
      return (run_configs[k].count(c->config) ? 0 : 2) + (c->scalar == "double" ? 0 : 1);
    };
    std::stable_sort(mine.begin(), mine.end(), [&](const Case* a, const Case* b) { return rank(a) < rank(b); });
    std::set<std::string> taken;
    for (const Case* c : mine)
      if (int(taken.size()) < per_kernel && taken.insert(c->config).second) out.push_back(c);
  }
  return out;
}

const char* kUsage = "usage: sample_sets --out FILE [--from RESULTS] [--per-kernel N]\n";

int usage(const std::string& why) {
  std::fprintf(stderr, "sample_sets: %s\n%s", why.c_str(), kUsage);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out, from, command = "build/sample_sets";
  int per_kernel = 3;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    command += " " + a;
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (i + 1 >= argc) return usage(a + " needs a value");
    const std::string v = argv[++i];
    command += " " + v;
    if (a == "--out") {
      out = v;
    } else if (a == "--from") {
      from = v;
    } else if (a == "--per-kernel") {
      try {
        per_kernel = std::stoi(v);
      } catch (const std::exception&) {
        per_kernel = 0;
      }
      if (per_kernel < 1) return usage("--per-kernel needs a positive integer");
    } else {
      return usage("unknown option '" + a + "'");
    }
  }
  if (out.empty()) return usage("--out FILE is required");
  std::optional<BatteryRun> run;
  if (!from.empty()) {
    std::ifstream in(from);
    if (!in) return usage("cannot read " + from);
    try {
      run = parse_battery_json(std::string(std::istreambuf_iterator<char>(in), {}));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "sample_sets: %s: %s\n", from.c_str(), e.what());
      return 1;
    }
  }
  const Registry registry = default_registry(), controls = negative_control_registry();
  std::vector<const Case*> all;
  for (const auto& c : registry.cases()) all.push_back(&c);
  for (const auto& c : controls.cases()) all.push_back(&c);
  const std::vector<const Case*> cases = chosen_cases(all, run ? &*run : nullptr, per_kernel);
  const std::string j = sample_sets_json(cases, command);
  const std::string tmp = out + ".tmp";
  std::ofstream(tmp) << j;
  if (std::rename(tmp.c_str(), out.c_str()) != 0) {
    std::fprintf(stderr, "sample_sets: cannot write %s\n", out.c_str());
    return 1;
  }
  std::printf("sample_sets: %zu cases written to %s\n", cases.size(), out.c_str());
  return 0;
}
