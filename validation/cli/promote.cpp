// warpcheck promote: a failing random geometry of a results file becomes a promoted configuration, a file under
// data/promoted/ that the registry reads on every run (validation/catalogue/random_geometries.cpp).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "commands.h"
#include "warpcheck/validation/registry.h"
#include "warpcheck/validation/results.h"

namespace warpcheck::cli {

using namespace warpcheck::validation;

namespace {

const char* kPromoteHelp =
    "usage: warpcheck promote RESULTS [--config NAME]... [--out DIR]\n"
    "\n"
    "Writes every failing random geometry of RESULTS (a 'warpcheck validate --random N --json' file) as\n"
    "DIR/<config>-<family>.txt (DIR default: data/promoted of the source tree; one configuration holds one\n"
    "geometry per family). The registry reads those files on every run, as the configuration\n"
    "promoted-<config>-<family> of every kernel of the geometry's family, so that the geometry is checked from then\n"
    "on. The file's '#' lines record the kernels, tests and run that failed; its one other line is the geometry\n"
    "(the result 'geometry' of the case). A file that exists is left alone.\n"
    "\n"
    "  --config NAME     promote only this configuration (repeatable; it need not have failed)\n"
    "  --out DIR         where to write (default: " WARPCHECK_SOURCE_DIR
    "/data/promoted)\n"
    "\n"
    "Exit status: 0 when something was written or there was nothing to promote, 2 on bad arguments.\n";

struct Promotion {
  std::string geometry;               // the text of the case's "geometry" result
  std::vector<std::string> failures;  // "kernel scalar test statistic p"
};

}  // namespace

int promote_main(const std::vector<std::string>& a) {
  std::string from, out = WARPCHECK_SOURCE_DIR "/data/promoted";
  std::vector<std::string> only;
  for (std::size_t i = 0; i < a.size(); ++i) {
    auto value = [&]() -> const std::string& {
      if (i + 1 >= a.size()) throw UsageError(a[i] + " needs a value");
      return a[++i];
    };
    if (a[i] == "--help" || a[i] == "-h") {
      std::fputs(kPromoteHelp, stdout);
      return 0;
    } else if (a[i] == "--config") {
      only.push_back(value());
    } else if (a[i] == "--out") {
      out = value();
    } else if (!a[i].empty() && a[i][0] != '-' && from.empty()) {
      from = a[i];
    } else {
      throw UsageError("unknown option '" + a[i] + "'");
    }
  }
  if (from.empty()) throw UsageError("needs a results file");
  std::ifstream in(from);
  if (!in) throw UsageError("cannot read '" + from + "'");
  std::stringstream text;
  text << in.rdbuf();
  const BatteryRun run = parse_battery_json(text.str());
  // One configuration random-s<S>-<i> holds one geometry per family: the geometry of each case, then the
  // promotions by configuration and family (the geometry text's first word).
  std::map<std::string, std::string> geometry;  // by kernel|scalar|config
  for (const TestResult& r : run.results)
    if (r.test == "geometry") geometry[r.kernel + "|" + r.scalar + "|" + r.config] = r.detail;
  std::map<std::string, Promotion> promote;  // by <config>-<family>
  for (const TestResult& r : run.results) {
    if (r.config.rfind("random-", 0) != 0 || r.test == "geometry") continue;
    const bool chosen = std::find(only.begin(), only.end(), r.config) != only.end();
    if (!(only.empty() ? r.failed() : chosen)) continue;
    const auto g = geometry.find(r.kernel + "|" + r.scalar + "|" + r.config);
    if (g == geometry.end()) {
      std::fprintf(stderr, "promote: %s / %s / %s has no 'geometry' result in %s: skipped\n", r.kernel.c_str(),
                   r.scalar.c_str(), r.config.c_str(), from.c_str());
      continue;
    }
    const std::string family = std::string("-").append(g->second, 0, g->second.find(' '));
    Promotion& p = promote[r.config.ends_with(family) ? r.config : r.config + family];
    p.geometry = g->second;
    p.failures.push_back(r.kernel + " / " + r.scalar + ": " + r.test + " statistic " + std::to_string(r.statistic) +
                         (r.p_value ? std::string(" p ").append(std::to_string(*r.p_value)) : std::string()) +
                         (r.passed ? " (passed)" : " (failed)"));
  }
  std::filesystem::create_directories(out);
  int written = 0;
  for (const auto& [name, p] : promote) {
    const std::string path = out + "/" + name + ".txt";
    if (std::filesystem::exists(path)) {
      std::printf("exists: %s\n", path.c_str());
      continue;
    }
    std::string file = "# " + name + " of a battery run at --samples " + std::to_string(run.samples.value_or(0)) +
                       " --seed " + std::to_string(run.seed.value_or(0)) + "\n";
    for (const std::string& f : p.failures) file += "# " + f + "\n";
    file += p.geometry + "\n";
    write_file_atomically(path, file);
    std::printf("wrote %s (configuration promoted-%s)\n", path.c_str(), name.c_str());
    ++written;
  }
  if (written == 0) std::printf("nothing to promote\n");
  return 0;
}

}  // namespace warpcheck::cli
