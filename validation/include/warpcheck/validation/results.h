// warpcheck/validation/results.h: a battery run's results and their JSON file.
//
// One TestResult per (kernel, scalar, config, test); a BatteryRun holds a run's results with the significance
// level and correction that judged them. `warpcheck validate --json` writes a BatteryRun with to_json,
// `--resume` and `warpcheck report` read it back with parse_battery_json. The file:
//
//   {"alpha":0.01,"correction":"holm","statistical_tests":m,"samples":N,"seed":S,"complete":true,
//    "shard":{"index":I,"count":K,"cases":C,"case_list":"<16 hex digits>"} (only for a shard),"results":[
//   {"kernel":..,"scalar":..,"config":..,"test":..,"statistic":x,"p_value":p|null,"passed":b,"detail":..,
//    "known_limitation":.. (only when set), "map":{"rows":R,"cols":A,"observed":[..],"expected":[..]} (chi2)},
//   ...
//   ],"power":[
//   {"kernel":..,"scalar":..,"config":..,"samples":N,"level":a,"target":0.9,
//    "figures":[{"alternative":"region","eps":e|null,"test":..},...]},
//   ...
//   ]}
//
// one result (and one case's power) per line; "power" is absent when there is none. samples, seed, complete and shard
// are present when set; statistical_tests is written for other readers and recomputed from the results on reading.
// Numbers are written in the shortest form that reads back to the same double and are read exactly, so a file
// round-trips bit for bit; a NaN statistic is null,
// +-infinity is +-1e999 (JSON has no infinity; parsers read 1e999 as infinity).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace warpcheck::validation {

enum class Correction { kSidak, kHolm };
const char* to_string(Correction c);

struct TestResult {
  std::string kernel, scalar, config, test;
  double statistic = 0;           // chi2 / KS D / relative error; NaN when there is none (the battery threw)
  std::optional<double> p_value;  // null for deterministic tests
  bool passed = false;            // for statistical tests: set by apply_correction
  std::string detail;             // human-readable: dof, pooled bins, tolerance, worst point, ...
  std::string known_limitation;   // non-empty: a documented expected failure; it does not fail a run
  // chi2 only: the grid over the bounding cap, row-major [radial][azimuth] (radial row r covers
  // t = (1 - cos theta)/(1 - cos theta_max) in [r/R, (r+1)/R), column a covers phi in [2 pi a/A, 2 pi (a+1)/A)),
  // observed counts and expected counts (n * bin mass) before pooling; empty for other tests.
  int map_rows = 0, map_cols = 0;
  std::vector<double> observed, expected;

  // Failed and not a documented limitation: this fails the run.
  bool failed() const { return !passed && known_limitation.empty(); }
};

// The part of a run a shard file holds (`warpcheck validate --shard I/K`): the cases c with c mod K == I of the
// run's case list of C cases, identified by a digest of its names (shards.h) so that shards of different
// selections are not merged.
struct ShardOf {
  std::uint64_t index = 0, count = 1, cases = 0;
  std::string case_list;
  bool operator==(const ShardOf&) const = default;
};

// The smallest relative density error of one standard alternative (power.h) that the battery rejects with
// probability `target` at a run's sample count and first-step corrected level: eps, and the test that reaches it.
// eps is +infinity when no test sees the alternative and NaN when the alternative is not defined for the case
// (a wedge without mass).
struct PowerFigure {
  std::string alternative, test;
  double eps = 0;
};
// The power figures of one case of a run, computed from its chi2 result's expected counts.
struct CasePower {
  std::string kernel, scalar, config;
  std::uint64_t samples = 0;
  double level = 0, target = 0.9;  // the per-test significance level and the probability of rejection
  std::vector<PowerFigure> figures;
};

struct BatteryRun {
  double alpha = 0.01;  // family-wise significance level of the run
  Correction correction = Correction::kHolm;
  std::optional<std::uint64_t> samples, seed;  // the CLI's --samples and --seed
  std::optional<bool> complete;                // false while the CLI is still running (or was killed)
  std::optional<ShardOf> shard;                // set when the run is one shard of a larger run
  std::vector<TestResult> results;
  std::vector<CasePower> power;  // one per case with a chi2 map; power.h's run_power fills it

  // The number of results with a p-value: the m of the correction.
  std::size_t statistical_tests() const;
};

// The JSON text of results before and after their "passed" member (the one member the correction over a run may
// change), kept between the checkpoints of a long run so that each one writes only its new results.
struct ResultTexts {
  std::vector<std::pair<std::string, std::string>> parts;  // by index into BatteryRun::results
};

// With `texts`, the results already in it are not written again (they must be the run's first results, unchanged
// but for "passed"), and the new ones are added.
std::string to_json(const BatteryRun& run, ResultTexts* texts = nullptr);
// Reads what to_json writes. Throws std::runtime_error naming the first missing or mistyped member.
BatteryRun parse_battery_json(const std::string& text);

}  // namespace warpcheck::validation
