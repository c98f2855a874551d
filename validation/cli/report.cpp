// warpcheck report: the HTML report of a battery run (the generator is reports/, declared in reports/report.h).
#include <cstdio>

#include "commands.h"
#include "report.h"

namespace warpcheck::cli {

namespace {

const char* kReportHelp =
    "usage: warpcheck report --out DIR [--from RESULTS] [--data DATA_DIR] [--sample-sets FILE]\n"
    "\n"
    "Writes a static, offline HTML site into DIR: index.html (pass/fail matrix of kernels x configurations x\n"
    "tests with p-values, alpha and correction; failing tests listed first; the papers' figures beside ours,\n"
    "worst-case searches, fuzz campaigns, benchmarks, maps over geometry) and one page per kernel (its results,\n"
    "observed / expected / residual maps of each chi2 test as PNG with 32-bit OpenEXR beside them, and sample\n"
    "sets). It draws what its input files hold and computes none of it.\n"
    "\n"
    "  --out DIR       output directory (created if missing)\n"
    "  --from RESULTS  battery results JSON from 'warpcheck validate --json' (default: the source tree's\n"
    "                  reports/results.json, which scripts/battery.sh writes)\n"
    "  --data DIR      data directory with claims, worst cases, fuzz, bench and geometry-map JSON (default: the\n"
    "                  source tree's data/); missing inputs give a section that says how to produce them\n"
    "  --sample-sets FILE  the kernels' sample sets from build/sample_sets (default: the source tree's\n"
    "                  reports/sample-sets.json, which scripts/battery.sh writes)\n"
    "\n"
    "scripts/battery.sh writes its report to reports/html/ (open reports/html/index.html).\n"
    "\n"
    "Exit status: 0 when the report was written, 1 when it could not be (unreadable results), 2 on bad\n"
    "arguments. The exit status does not reflect the tests' verdicts: read the report.\n";

}  // namespace

int report_main(const std::vector<std::string>& a) {
  validation::report::ReportOptions opt;
  opt.results_path = std::string(WARPCHECK_SOURCE_DIR) + "/reports/results.json";
  opt.data_dir = std::string(WARPCHECK_SOURCE_DIR) + "/data";
  opt.sample_sets_path = std::string(WARPCHECK_SOURCE_DIR) + "/reports/sample-sets.json";
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string& f = a[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= a.size() || a[i + 1].empty()) throw UsageError(f + " needs a value");
      return a[++i];
    };
    if (f == "--help" || f == "-h") {
      std::fputs(kReportHelp, stdout);
      return 0;
    } else if (f == "--out") {
      opt.out_dir = value();
    } else if (f == "--from") {
      opt.results_path = value();
    } else if (f == "--data") {
      opt.data_dir = value();
    } else if (f == "--sample-sets") {
      opt.sample_sets_path = value();
    } else {
      throw UsageError("unknown option '" + f + "'");
    }
  }
  if (opt.out_dir.empty()) throw UsageError("--out DIR is required");
  try {
    const auto sum = validation::report::write_report(opt);
    std::printf(
        "report: %zu kernels, %zu results, %zu failed, %zu known-limitation failures; %zu files; open %s/index.html\n",
        sum.kernels, sum.results, sum.failures, sum.known_limitation_failures, sum.files.size(), opt.out_dir.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "warpcheck report: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace warpcheck::cli
