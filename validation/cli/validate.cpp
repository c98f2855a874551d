// warpcheck list / warpcheck validate.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>

#include "commands.h"
#include "warpcheck/validation/battery.h"
#include "warpcheck/validation/negative_controls.h"
#include "warpcheck/validation/power.h"
#include "warpcheck/validation/registry.h"
#include "warpcheck/validation/shards.h"

namespace warpcheck::cli {

using namespace warpcheck::validation;

std::uint64_t parse_u64(const std::string& flag, const std::string& value, std::uint64_t min, std::uint64_t max) {
  std::size_t used = 0;
  unsigned long long v = 0;
  try {
    if (value.empty() || value[0] == '-') throw std::invalid_argument("negative");
    v = std::stoull(value, &used);
  } catch (const std::exception&) {
    throw UsageError(flag + " needs a non-negative integer, got '" + value + "'");
  }
  if (used != value.size()) throw UsageError(flag + " needs an integer, got '" + value + "'");
  if (v < min || v > max)
    throw UsageError(flag + " must be in [" + std::to_string(min) + ", " + std::to_string(max) + "], got " + value);
  return v;
}

double parse_double(const std::string& flag, const std::string& value, double min, double max) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(value, &used);
  } catch (const std::exception&) {
    throw UsageError(flag + " needs a number, got '" + value + "'");
  }
  if (used != value.size() || !(v >= min && v <= max))
    throw UsageError(flag + " must be a number in [" + std::to_string(min) + ", " + std::to_string(max) + "], got '" +
                     value + "'");
  return v;
}

void parse_shard(const std::string& v, std::uint64_t& index, std::uint64_t& count) {
  const auto slash = v.find('/');
  if (slash == std::string::npos) throw UsageError("--shard needs I/N, e.g. 3/8, got '" + v + "'");
  count = parse_u64("--shard N", v.substr(slash + 1), 1, UINT32_MAX);
  index = parse_u64("--shard I", v.substr(0, slash), 0, count - 1);
}

void write_file_atomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw std::runtime_error("cannot write " + tmp);
    f << text;
    f.flush();
    if (!f) throw std::runtime_error("cannot write " + tmp);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot rename " + tmp + " to " + path);
  }
}

namespace {

const char* kListHelp =
    "usage: warpcheck list [--kernel GLOB]... [--config GLOB]... [--random N] [--random-seed S]\n"
    "Lists every registered (kernel, scalar, configuration) with a one-line description of the geometry.\n";

const char* kValidateHelp =
    "usage: warpcheck validate [--kernel GLOB]... [--config GLOB]... [--scalar GLOB]... [--samples N]\n"
    "                          [--seed S] [--alpha A] [--correction holm|sidak] [--threads N] [--json FILE]\n"
    "                          [--quiet] [--negative-controls] [--resume] [--shard I/N] [--random N]\n"
    "                          [--random-seed S]\n"
    "\n"
    "Runs the battery (chi2, chi2-rings, chi2-columns, chi2-coarse, ks-radial, ks-azimuth, pdf-integral,\n"
    "pdf-consistency, normalization:*, and round-trip where a kernel has an inverse) on every selected kernel\n"
    "and configuration and prints a table: kernel, scalar, config, test, statistic, p-value, verdict. Globs\n"
    "use '*' and '?'; a repeated option matches any of its globs.\n"
    "\n"
    "  --kernel GLOB     kernels to run (default: all; see 'warpcheck list')\n"
    "  --config GLOB     configurations to run (default: all)\n"
    "  --scalar GLOB     scalar types: float, double, 'long double' (default: all)\n"
    "  --random N        also N random geometries per kernel family (double and long double), drawn by the\n"
    "                    fuzz targets' decoders and named random-s<S>-<index>; --config random-s<S>-<index>\n"
    "                    alone replays one (default 0)\n"
    "  --random-seed S   seed of the random geometries (default 1)\n"
    "  --samples N       samples per kernel and configuration (default 10000000, at least 1000)\n"
    "  --seed S          seed of every random stream (default 1); the same seed gives the same results\n"
    "  --alpha A         family-wise significance level of the whole run (default 0.01)\n"
    "  --correction C    holm (default) or sidak, across all statistical tests of the run\n"
    "  --threads N       worker threads (default: all cores)\n"
    "  --json FILE       also write {\"alpha\",\"correction\",\"results\":[...]}; rewritten atomically after each\n"
    "                    case with \"complete\": false, so a killed run keeps what it finished (the\n"
    "                    \"power\" figures are written when the run completes)\n"
    "  --quiet           no progress on stderr (see below)\n"
    "  --resume          with --json: keep the cases already in FILE (from a killed run with the same --samples\n"
    "                    and --seed) and run only the others; the correction is recomputed over all of them\n"
    "  --shard I/N       run only the cases c with c mod N == I of the selection's case list (in 'warpcheck list'\n"
    "                    order), each with the same seed as in the whole run; the JSON file records the shard.\n"
    "                    'warpcheck merge' combines the N shards' files into the whole run's, bit for bit, and\n"
    "                    recomputes the correction over all of them: a shard's verdicts and exit status count\n"
    "                    only its own tests\n"
    "  --negative-controls  run the deliberately broken samplers instead of the registered kernels (each\n"
    "                    must FAIL; the exit status is then 1 when the battery works)\n"
    "\n"
    "Progress goes to stderr: the cases done of the total, the elapsed time and the time left, estimated as the\n"
    "mean time of the cases done so far times the cases left (a rough guide: cases differ in cost). On a terminal\n"
    "it is one line rewritten in place that also names the running case and its phase; otherwise one line per\n"
    "finished case.\n"
    "\n"
    "Exit status: 0 when every test passes (documented known limitations excepted), 1 when any fails, 2 on\n"
    "bad arguments.\n";

}  // namespace

bool take_selection(const std::vector<std::string>& a, std::size_t& i, Selection& sel) {
  const std::string& f = a[i];
  if (f != "--kernel" && f != "--config" && f != "--scalar" && f != "--random" && f != "--random-seed") return false;
  if (i + 1 >= a.size()) throw UsageError(f + " needs a value");
  if (f == "--random") return sel.random.count = int(parse_u64(f, a[++i], 0, 100000)), true;
  if (f == "--random-seed") return sel.random.seed = parse_u64(f, a[++i], 0, ~0ULL), true;
  if (f == "--config") sel.random.names.push_back(a[i + 1]);  // random-s<S>-<index>: that geometry
  auto& dst = f == "--kernel" ? sel.kernels : f == "--config" ? sel.configs : sel.scalars;
  dst.push_back(a[++i]);
  return true;
}

std::vector<const Case*> select_cases(const Registry& reg, const Selection& sel) {
  std::vector<const Case*> out;
  for (const Case* c : reg.select(sel.kernels, sel.configs)) {
    bool ok = sel.scalars.empty();
    for (const auto& g : sel.scalars) ok = ok || glob_match(g, c->scalar);
    if (ok) out.push_back(c);
  }
  if (out.empty()) throw UsageError("no kernel/configuration matches the selection (see 'warpcheck list')");
  return out;
}

int list_main(const std::vector<std::string>& a) {
  Selection sel;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i] == "--help" || a[i] == "-h") {
      std::fputs(kListHelp, stdout);
      return 0;
    }
    if (!take_selection(a, i, sel)) throw UsageError("unknown option '" + a[i] + "'");
  }
  const Registry reg = default_registry(sel.random);
  for (const Case* c : select_cases(reg, sel)) {
    std::printf("%-38s %-11s %-26s %s%s%s\n", c->kernel.c_str(), c->scalar.c_str(), c->config.c_str(),
                c->description.c_str(), c->known_limitation.empty() ? "" : "  [known limitation: ",
                c->known_limitation.empty() ? "" : (c->known_limitation + "]").c_str());
  }
  return 0;
}

namespace {

// The command's battery options: every core unless --threads (the library's default is one thread).
BatteryOptions every_core() {
  BatteryOptions o;
  o.threads = 0;
  return o;
}

struct ValidateArgs {
  Selection sel;
  BatteryOptions opt = every_core();
  double alpha = 0.01;
  Correction corr = Correction::kHolm;
  std::string json;
  bool quiet = false, negative = false, resume = false;
  std::uint64_t shard_index = 0, shard_count = 0;  // shard_count 0: not sharded
};

// Parses validate's arguments into v; false when --help was printed instead.
bool parse_validate_args(const std::vector<std::string>& a, ValidateArgs& v) {
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string& f = a[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= a.size()) throw UsageError(f + " needs a value");
      return a[++i];
    };
    if (f == "--help" || f == "-h") {
      std::fputs(kValidateHelp, stdout);
      return false;
    } else if (take_selection(a, i, v.sel)) {
    } else if (f == "--samples") {
      v.opt.samples = parse_u64(f, value(), 1000, 1ULL << 34);
    } else if (f == "--seed") {
      v.opt.seed = parse_u64(f, value(), 0, ~0ULL);
    } else if (f == "--alpha") {
      v.alpha = parse_double(f, value(), 1e-12, 0.5);
    } else if (f == "--correction") {
      const std::string& c = value();
      if (c != "holm" && c != "sidak") throw UsageError("--correction must be holm or sidak, got '" + c + "'");
      v.corr = c == "holm" ? Correction::kHolm : Correction::kSidak;
    } else if (f == "--threads") {
      v.opt.threads = int(parse_u64(f, value(), 1, 1024));
    } else if (f == "--json") {
      v.json = value();
      if (v.json.empty()) throw UsageError("--json needs a file name");
    } else if (f == "--quiet") {
      v.quiet = true;
    } else if (f == "--negative-controls") {
      v.negative = true;
    } else if (f == "--resume") {
      v.resume = true;
    } else if (f == "--shard") {
      parse_shard(value(), v.shard_index, v.shard_count);
    } else {
      throw UsageError("unknown option '" + f + "'");
    }
  }
  if (v.resume && v.json.empty()) throw UsageError("--resume needs --json FILE (the file of the run to resume)");
  return true;
}

bool same_case(const TestResult& r, const Case& c) {
  return r.kernel == c.kernel && r.scalar == c.scalar && r.config == c.config;
}

// The results of an earlier run (the --json file of a killed or finished run) to continue from; removes their
// cases from `cases`. The file must come from the same --samples and --seed: mixing sample counts would make
// the run's verdicts meaningless; and from the same shard of the same case list. Known limitations are the current
// registry's policy, not the earlier run's: the results of selected cases are re-tagged.
std::vector<TestResult> results_to_resume(const ValidateArgs& v, const std::optional<ShardOf>& run_shard,
                                          std::vector<const Case*>& cases) {
  std::ifstream in(v.json);
  std::stringstream text;
  if (in) text << in.rdbuf();
  if (text.str().empty()) return {};  // nothing to resume: start afresh
  BatteryRun earlier;
  try {
    earlier = parse_battery_json(text.str());
  } catch (const std::runtime_error& e) {
    throw UsageError("cannot resume: '" + v.json + "' is not a warpcheck validate --json file (" + e.what() + ")");
  }
  if (earlier.samples.value_or(0) != v.opt.samples || earlier.seed.value_or(0) != v.opt.seed)
    throw UsageError("cannot resume: '" + v.json + "' was written with --samples " +
                     std::to_string(earlier.samples.value_or(0)) + " --seed " +
                     std::to_string(earlier.seed.value_or(0)) + "; give the same values");
  if (earlier.shard != run_shard)
    throw UsageError("cannot resume: '" + v.json + "' holds " +
                     (earlier.shard ? "shard " + std::to_string(earlier.shard->index) + "/" +
                                          std::to_string(earlier.shard->count) + " of a run"
                                    : std::string("no shard")) +
                     (run_shard ? ", not shard " + std::to_string(v.shard_index) + "/" + std::to_string(v.shard_count) +
                                      " of this selection"
                                : ", not this unsharded run"));
  for (TestResult& r : earlier.results)
    for (const Case* c : cases)
      if (same_case(r, *c)) r.known_limitation = c->known_limitation;
  const std::size_t before = cases.size();
  std::erase_if(cases, [&](const Case* c) {
    return std::any_of(earlier.results.begin(), earlier.results.end(),
                       [&](const TestResult& r) { return same_case(r, *c); });
  });
  std::fprintf(stderr, "resuming %s: %zu cases done, %zu to run\n", v.json.c_str(), before - cases.size(),
               cases.size());
  return std::move(earlier.results);
}

// The battery and the case's extras on one case, tagged with its known limitation; a battery that throws gives
// one result "battery" with the error and no statistic.
std::vector<TestResult> run_case(const Case& c, const BatteryOptions& opt) {
  std::vector<TestResult> r;
  try {
    r = run_battery(c.make(), opt);
    if (c.extras) {
      auto extra = c.extras(opt);
      r.insert(r.end(), extra.begin(), extra.end());
    }
  } catch (const std::exception& e) {
    TestResult err;
    err.kernel = c.kernel, err.scalar = c.scalar, err.config = c.config, err.test = "battery";
    err.statistic = std::numeric_limits<double>::quiet_NaN();
    err.detail = std::string("error: ") + e.what();
    r.push_back(err);
  }
  for (auto& x : r) x.known_limitation = c.known_limitation;
  return r;
}

// "42 s", "12 min 05 s", "2 h 03 min" (tenths below 10 s).
std::string format_duration(double secs) {
  char buf[64];
  if (secs < 10)
    std::snprintf(buf, sizeof buf, "%.1f s", secs);
  else if (secs < 60)
    std::snprintf(buf, sizeof buf, "%.0f s", secs);
  else if (secs < 3600)
    std::snprintf(buf, sizeof buf, "%d min %02d s", int(secs) / 60, int(secs) % 60);
  else
    std::snprintf(buf, sizeof buf, "%d h %02d min", int(secs) / 3600, int(secs) % 3600 / 60);
  return buf;
}

// Progress of a run on stderr (kValidateHelp says what it shows): on a terminal one line rewritten in place with
// the running case and its phase, otherwise one line per finished case; nothing when quiet.
class Progress {
 public:
  Progress(std::size_t total, bool quiet) : total_(total), quiet_(quiet), tty_(::isatty(2)) {}

  // BatteryOptions::progress while the case `label` runs: the live line on a terminal, nothing otherwise.
  std::function<void(const std::string&, double)> during(const std::string& label) {
    if (quiet_ || !tty_) return {};
    live(label + ": starting");
    return [this, label](const std::string& phase, double frac) {
      char pct[16];
      std::snprintf(pct, sizeof pct, " %3.0f%%", 100 * frac);
      live(label + ": " + phase + pct);
    };
  }

  void finished(const std::string& label, double case_secs) {
    ++done_;
    if (quiet_) return;
    if (tty_) return live(label + ": done in " + format_duration(case_secs));
    std::fprintf(stderr, "[%zu/%zu] %s done in %s; %s\n", done_, total_, label.c_str(),
                 format_duration(case_secs).c_str(), times().c_str());
  }

  void end() const {
    if (!quiet_ && tty_ && total_ > 0) std::fprintf(stderr, "\n");
  }

 private:
  // "elapsed 1 min 12 s, about 3 min 10 s left", from the mean time of the cases done.
  std::string times() const {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::string t = "elapsed " + format_duration(elapsed);
    if (done_ > 0 && done_ < total_) t += ", about " + format_duration(elapsed / done_ * (total_ - done_)) + " left";
    return t;
  }

  // The terminal's line: cases done, times, then what runs (the rest of the line erased).
  void live(const std::string& what) const {
    std::fprintf(stderr, "\r[%zu/%zu done, %s] %s\x1b[K", done_, total_, times().c_str(), what.c_str());
    std::fflush(stderr);
  }

  std::size_t total_, done_ = 0;
  bool quiet_, tty_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// The command that replays each failing random or promoted case alone, with the run's sample count and seed.
void print_replays(const BatteryRun& run) {
  std::vector<std::string> printed;
  for (const TestResult& r : run.results) {
    if (!r.failed() || (r.config.rfind("random-", 0) != 0 && r.config.rfind("promoted-", 0) != 0)) continue;
    const std::string cmd = "warpcheck validate --kernel " + r.kernel + " --scalar '" + r.scalar + "' --config " +
                            r.config + " --samples " + std::to_string(run.samples.value_or(0)) + " --seed " +
                            std::to_string(run.seed.value_or(0));
    if (std::find(printed.begin(), printed.end(), cmd) != printed.end()) continue;
    printed.push_back(cmd);
    std::printf("replay %s / %s / %s: %s\n", r.kernel.c_str(), r.scalar.c_str(), r.config.c_str(), cmd.c_str());
  }
}

void print_summary(const BatteryRun& run, std::size_t cases, double secs) {
  std::fputs(format_table(run.results).c_str(), stdout);
  print_replays(run);
  std::size_t failed = 0, known = 0;
  for (const auto& r : run.results) {
    failed += r.failed();
    known += !r.passed && !r.known_limitation.empty();
  }
  std::printf("\n%zu tests on %zu cases in %.1f s; alpha %g, %s correction over %zu statistical tests; %zu failed%s\n",
              run.results.size(), cases, secs, run.alpha, to_string(run.correction), run.statistical_tests(), failed,
              known ? (", " + std::to_string(known) + " known-limitation failures").c_str() : "");
  if (run.shard)
    std::printf(
        "shard %llu/%llu of a run of %llu cases: the correction counts this shard's tests only; "
        "'warpcheck merge' of all shards gives the run's verdicts\n",
        static_cast<unsigned long long>(run.shard->index), static_cast<unsigned long long>(run.shard->count),
        static_cast<unsigned long long>(run.shard->cases));
}

}  // namespace

int validate_main(const std::vector<std::string>& a) {
  ValidateArgs v;
  if (!parse_validate_args(a, v)) return 0;
  const Registry reg = v.negative ? negative_control_registry() : default_registry(v.sel.random);
  std::vector<const Case*> cases = select_cases(reg, v.sel);
  BatteryRun run;
  run.alpha = v.alpha, run.correction = v.corr, run.samples = v.opt.samples, run.seed = v.opt.seed;
  if (v.shard_count > 0) {
    run.shard = shard_of(cases, v.shard_index, v.shard_count);
    cases = shard_cases(cases, v.shard_index, v.shard_count);
  }
  if (v.resume) run.results = results_to_resume(v, run.shard, cases);
  if (!v.json.empty()) {  // fail on an unwritable path now, not after an hour of work
    std::ofstream probe(v.json, std::ios::app);
    if (!probe) throw UsageError("cannot write --json file '" + v.json + "'");
  }
  const auto start = std::chrono::steady_clock::now();
  Progress progress(cases.size(), v.quiet);
  ResultTexts texts;  // the checkpoints' text of the results so far
  for (const Case* c : cases) {
    const std::string label = c->kernel + " / " + c->scalar + " / " + c->config;
    v.opt.progress = progress.during(label);
    const auto case_start = std::chrono::steady_clock::now();
    const std::vector<TestResult> r = run_case(*c, v.opt);
    progress.finished(label, std::chrono::duration<double>(std::chrono::steady_clock::now() - case_start).count());
    run.results.insert(run.results.end(), r.begin(), r.end());
    // So far, judged together, and marked incomplete: a killed run keeps what it finished. The power figures wait
    // for the completed run: they depend on its final level, and computing them for every case after each case
    // would make the checkpoints quadratic in the run's length (0.15 s each at the registry's 4635 results).
    if (!v.json.empty()) {
      BatteryRun partial = run;
      apply_correction(partial.results, run.alpha, run.correction);
      partial.complete = false;
      write_file_atomically(v.json, to_json(partial, &texts));
    }
  }
  progress.end();
  apply_correction(run.results, run.alpha, run.correction);
  run.power = run_power(run);
  run.complete = true;
  print_summary(run, cases.size(), std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  if (!v.json.empty()) write_file_atomically(v.json, to_json(run, &texts));
  return all_passed(run.results) ? 0 : 1;
}

int merge_battery(const std::vector<std::string>& files, const std::vector<std::string>& texts,
                  const std::string& json) {
  std::vector<ShardFile> shards;
  for (std::size_t i = 0; i < files.size(); ++i) try {
      shards.push_back({files[i], parse_battery_json(texts[i])});
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(files[i] + ": " + e.what());
    }
  BatteryRun run = merge_shards(shards);
  run.power = run_power(run);  // at the union's corrected level, as the unsharded run computes them
  std::size_t failed = 0;
  for (const TestResult& r : run.results) failed += r.failed();
  const std::string text = to_json(run);
  if (json.empty())
    std::fputs(text.c_str(), stdout);
  else
    write_file_atomically(json, text);
  std::fprintf(stderr, "merged %zu shards: %zu tests; alpha %g, %s correction over %zu statistical tests; %zu failed\n",
               files.size(), run.results.size(), run.alpha, to_string(run.correction), run.statistical_tests(), failed);
  return 0;
}

}  // namespace warpcheck::cli
