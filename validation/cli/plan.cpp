// `warpcheck plan`: how many samples the battery needs to detect a given relative density error of a standard
// alternative (power.h) with probability 0.9, per case, from the case's bin masses by the battery's quadrature.
#include <cstdio>
#include <string>
#include <vector>

#include "commands.h"
#include "warpcheck/validation/power.h"

namespace warpcheck::cli {

using namespace warpcheck::validation;

namespace {

const char* kPlanHelp =
    "usage: warpcheck plan [--kernel GLOB]... [--config GLOB]... [--scalar GLOB]... [--error EPS]\n"
    "                      [--alternative region|tilt|wedge|all] [--alpha A] [--correction holm|sidak]\n"
    "                      [--tests M] [--threads N]\n"
    "\n"
    "For each selected case, the smallest sample count at which the battery rejects a sampler whose density is\n"
    "wrong by the relative error EPS (default 0.001) with probability 0.9:\n"
    "  region  the innermost 10% of the mass (in t = (1 - cos theta) / (1 - cos theta_max)) too dense by EPS\n"
    "  tilt    a smooth radial tilt whose largest relative error is EPS\n"
    "  wedge   the first column of the chi-square grid (1/32 of the azimuth) too dense by EPS\n"
    "The statistical tests are judged at the first-step level of the correction over M tests (default 6, the\n"
    "tests of one case; give a whole run's count to plan for it). The figures come from the non-central\n"
    "chi-square and the KS asymptotics on the case's expected counts (docs/derivations/power.md), and name the test "
    "that\n"
    "reaches the error first.\n";

struct PlanArgs {
  Selection sel;
  double eps = 1e-3, alpha = 0.01;
  Correction corr = Correction::kHolm;
  std::size_t tests = 6;
  std::vector<Alternative> alternatives = {Alternative::kRegion};
  BatteryOptions opt;
};

bool parse_plan_args(const std::vector<std::string>& a, PlanArgs& p) {
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string& f = a[i];
    if (f == "--help" || f == "-h") return std::fputs(kPlanHelp, stdout), false;
    if (take_selection(a, i, p.sel)) continue;
    if (i + 1 >= a.size()) throw UsageError(f + " needs a value (or is unknown)");
    const std::string v = a[++i];
    if (f == "--error") {
      p.eps = parse_double(f, v, 1e-9, 1);
    } else if (f == "--alpha") {
      p.alpha = parse_double(f, v, 1e-12, 0.5);
    } else if (f == "--correction") {
      if (v != "holm" && v != "sidak") throw UsageError("--correction must be holm or sidak, got '" + v + "'");
      p.corr = v == "holm" ? Correction::kHolm : Correction::kSidak;
    } else if (f == "--tests") {
      p.tests = std::size_t(parse_u64(f, v, 1, 1ULL << 32));
    } else if (f == "--threads") {
      p.opt.threads = int(parse_u64(f, v, 0, 4096));
    } else if (f == "--alternative") {
      p.alternatives.clear();
      for (Alternative x : kAlternatives)
        if (v == "all" || v == to_string(x)) p.alternatives.push_back(x);
      if (p.alternatives.empty()) throw UsageError("--alternative must be region, tilt, wedge or all, got '" + v + "'");
    } else {
      throw UsageError("unknown option '" + f + "'");
    }
  }
  return true;
}

}  // namespace

int plan_main(const std::vector<std::string>& a) {
  PlanArgs p;
  if (!parse_plan_args(a, p)) return 0;
  const Registry reg = default_registry();
  const std::vector<const Case*> cases = select_cases(reg, p.sel);
  const double level = first_step_level(p.alpha, p.corr, p.tests);
  std::printf("%-38s %-11s %-24s %-11s %10s %14s  %s\n", "kernel", "scalar", "config", "alternative", "error",
              "samples", "first test to reach it");
  for (const Case* c : cases) {
    const SamplerUnderTest s = c->make();
    if (s.expect_no_sample) continue;
    const GridMasses g = grid_masses(s, p.opt);
    for (Alternative alt : p.alternatives) {
      const std::uint64_t n = samples_needed(g, alt, p.eps, p.alpha, p.corr, p.tests);
      std::string test = "-";  // the most powerful test at n
      double best = p.eps;
      if (n > 0)
        for (const TestPower& t : test_power(g, alt, n, level))
          if (t.eps <= best) test = t.test, best = t.eps;
      std::printf("%-38s %-11s %-24s %-11s %10.3g %14s  %s\n", c->kernel.c_str(), c->scalar.c_str(), c->config.c_str(),
                  to_string(alt), p.eps, n > 0 ? std::to_string(n).c_str() : "never", test.c_str());
    }
  }
  return 0;
}

}  // namespace warpcheck::cli
