// warpcheck/validation/searches.h: worst-case error searches.
//
// A Search is an error measure maximised by the multi-start Nelder-Mead of nelder_mead.h over a documented box
// of parameters (every parameter has a name, bounds and a meaning; `warpcheck worst-case --list` prints them).
// The objective is a pure function of the parameters, evaluated in long double; NaN marks a point that violates
// the search's constraints (the optimizer ranks it below every number), +Inf a kernel that failed outright
// (declined a valid input or returned a non-finite value where the reference did not) -- a real finding.
//
// A run is split into chains (nelder_mead.h: run_chain), each a pure function of (seed, chain index); shard
// I of N runs the chain indices j N + I, j = 0, 1, ..., so shards with the same seed are disjoint and any
// scheduler can run them. SearchRecord is both the checkpoint and the result: it knows which chains are
// done, so a resumed run continues with the next ones and never loses its best-so-far.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "warpcheck/validation/nelder_mead.h"

namespace warpcheck::validation {

struct SearchParameter {
  std::string name;
  long double lo = 0, hi = 1;
  std::string meaning;
};

struct Search {
  std::string name;         // e.g. "polygon-backward-k2"
  std::string description;  // what is maximised, where, under which constraints
  std::string paper;        // the paper's figure to compare with, or empty
  std::vector<SearchParameter> parameters;
  std::function<long double(std::span<const long double>)> objective;
  int local_iterations = 100;  // Nelder-Mead iterations per local run (Peters 2021 Sec. 3.6 uses 100)
  // True where the objective calls a point "unresolved" (NaN) by comparing finite differences of the long
  // double warp with steps h and 2h. Whether a point next to a kink passes that test depends on the last bits
  // of the x87 transcendental instructions behind long double atan2/exp/log, which differ between CPUs: the
  // same kernel and the same recorded input can give 2.0e-9 on one CPU and NaN on another.
  // The replay (test_worst_case_replay.cpp) therefore reports such a record's NaN instead of failing on it.
  bool resolution_depends_on_cpu = false;

  Bounds<long double> bounds() const;
  MultiStartOptions<long double> options() const;
};

// Every search, in a fixed order (rebuilt on each call; no global state).
std::vector<Search> all_searches();
std::optional<Search> find_search(const std::string& name);

// One improvement of the best-so-far: when it happened (seconds and evaluations of the run that found it,
// counted over resumes), the new best and the global chain that found it.
struct HistoryPoint {
  double seconds = 0;
  long long evaluations = 0;
  std::uint64_t chains = 0;  // chains completed, including this one
  long double best_f = std::numeric_limits<long double>::quiet_NaN();
  std::uint64_t chain = 0;
  std::uint64_t shard_index = 0;  // the shard that found it (merged records mix shards)
};

// The state of a (sharded, resumable) run; also the format of checkpoints, results and data/worst-cases/.
struct SearchRecord {
  std::string search;
  std::uint64_t seed = 1;
  std::uint64_t shard_index = 0, shard_count = 1;
  std::vector<long double> best_x;  // empty until some chain found a valid point
  long double best_f = std::numeric_limits<long double>::quiet_NaN();
  std::uint64_t best_chain = 0;           // global chain index that found best_x
  long long evaluations = 0;              // objective evaluations spent (over all resumes)
  std::uint64_t chains = 0;               // chains completed
  std::uint64_t next_local = 0;           // every local chain index below this is done
  std::vector<std::uint64_t> done_above;  // completed local indices >= next_local (out of order, threads)
  double seconds = 0;                     // wall-clock seconds spent (over all resumes)
  double target_seconds = 0;              // the budget the run was started with
  std::string kernel_version;             // `git describe --always --dirty` of the tree that ran it
  std::string command;                    // the command line that produced it
  std::vector<std::string> merged_from;   // for merged records: the files they came from
  std::vector<HistoryPoint> history;      // every improvement of best_f, in order (the last one is best_f)

  std::uint64_t global_chain(std::uint64_t local) const { return local * shard_count + shard_index; }
};

// JSON (Boost.JSON). Long doubles are stored exactly as hexadecimal strings ("%La") beside a decimal copy
// for people; reading uses the hexadecimal one.
std::string to_json(const SearchRecord& r, const Search* s = nullptr);
SearchRecord record_from_json(const std::string& text);  // throws std::runtime_error on malformed input

struct RunOptions {
  double seconds = 10;  // total budget, counted over resumes (SearchRecord::seconds)
  int threads = 1;
  double tick_seconds = 1;  // how often `tick` is called (from the calling thread)
  std::function<void(const SearchRecord& snapshot, double evaluations_per_second)> tick;
  const std::atomic<bool>* stop = nullptr;  // set asynchronously (e.g. by SIGINT) to end the run early
};

// Runs chains until the budget is spent, updating `state` in place (which may come from a checkpoint).
// The chain in flight when time runs out is finished; `tick` receives consistent snapshots.
void run_search(const Search& s, SearchRecord& state, const RunOptions& o);

// Combines records of one search (shards, resumed runs): the best of the bests, summed evaluations, chains
// and seconds. The merged history is every record's history ordered by its own seconds (as if the shards had
// run side by side), keeping the points that improve on all earlier ones; their seconds, evaluations and
// chains are those of the shard that found them. Throws std::runtime_error if the records belong to
// different searches.
SearchRecord merge_records(const std::vector<SearchRecord>& records);

// Search families defined in other files of validation/searches (called by all_searches()).
void append_polygon_searches(std::vector<Search>& v);  // polygon.cpp: Peters 2021 backward errors
void append_kernel_searches(std::vector<Search>& v);   // kernels.cpp: precision and pdf vs warp
void append_cap_searches(std::vector<Search>& v);      // caps.cpp: projected caps, SPTD caps

// `git describe --always --dirty` of the source tree, or "unknown" without git.
std::string source_version();

std::string hex(long double v);              // "%La"
long double from_hex(const std::string& s);  // strtold; throws on garbage

}  // namespace warpcheck::validation
