// warpcheck/validation/shards.h: a battery run split into shards and merged back.
//
// Shard I of K of a run holds the cases c of the run's case list (the registry's selection, in registry order)
// with c mod K == I. Every case is run with the run's seed, whatever its shard, so the union of the K shards has
// the statistics and p-values of the unsharded run bit for bit. The verdicts of statistical tests depend on the
// whole run (the correction counts all its tests): a shard's verdicts are provisional, merge_shards recomputes
// them over the union.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "warpcheck/validation/registry.h"
#include "warpcheck/validation/results.h"

namespace warpcheck::validation {

// The cases c of `all` with c mod count == index, in their order.
std::vector<const Case*> shard_cases(const std::vector<const Case*>& all, std::uint64_t index, std::uint64_t count);

// A digest of a case list's names and order (FNV-1a 64 of "kernel\tscalar\tconfig\n" per case, 16 hex digits):
// shards of one run carry the same one.
std::string case_list_digest(const std::vector<const Case*>& cases);

// What shard I of K of the run over `all` holds.
ShardOf shard_of(const std::vector<const Case*>& all, std::uint64_t index, std::uint64_t count);

struct ShardFile {
  std::string path;  // named in errors
  BatteryRun run;
};

// The unsharded run's results from its K shards: the cases in the run's order, the statistical tests' verdicts
// recomputed with the run's correction over all of them, complete and without shard. Throws std::runtime_error
// naming the files when a file is not a shard or is incomplete, when two files hold the same shard or case, when
// a shard is missing, or when the files differ in alpha, correction, samples, seed, shard count or case list.
BatteryRun merge_shards(const std::vector<ShardFile>& shards);

// True when the JSON text is a battery results file (a top-level object with "results"), false for any other
// JSON (e.g. a worst-case search record). Throws std::runtime_error when it is not JSON.
bool is_battery_results(const std::string& text);

}  // namespace warpcheck::validation
