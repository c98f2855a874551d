// Sharded battery runs (shards.h): which cases a shard holds, and the merge of shards into the run.
#include "warpcheck/validation/shards.h"

#include <boost/json.hpp>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <tuple>

#include "warpcheck/validation/battery.h"

namespace warpcheck::validation {

std::vector<const Case*> shard_cases(const std::vector<const Case*>& all, std::uint64_t index, std::uint64_t count) {
  std::vector<const Case*> out;
  for (std::size_t c = index; c < all.size(); c += count) out.push_back(all[c]);
  return out;
}

std::string case_list_digest(const std::vector<const Case*>& cases) {
  std::uint64_t h = 14695981039346656037ull;  // FNV-1a 64, offset basis and prime
  auto add = [&h](const std::string& s, char end) {
    for (unsigned char ch : s) h = (h ^ ch) * 1099511628211ull;
    h = (h ^ static_cast<unsigned char>(end)) * 1099511628211ull;
  };
  for (const Case* c : cases) add(c->kernel, '\t'), add(c->scalar, '\t'), add(c->config, '\n');
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

ShardOf shard_of(const std::vector<const Case*>& all, std::uint64_t index, std::uint64_t count) {
  return ShardOf{index, count, all.size(), case_list_digest(all)};
}

namespace {

using CaseKey = std::tuple<std::string, std::string, std::string>;
CaseKey key_of(const TestResult& r) { return {r.kernel, r.scalar, r.config}; }
std::string label(const CaseKey& k) { return std::get<0>(k) + " / " + std::get<1>(k) + " / " + std::get<2>(k); }
std::string shard_name(const ShardFile& f) {
  return f.path + " (shard " + std::to_string(f.run.shard->index) + "/" + std::to_string(f.run.shard->count) + ")";
}

// A run's results grouped by case (the battery writes a case's results together).
std::vector<std::vector<TestResult>> cases_of(const BatteryRun& run) {
  std::vector<std::vector<TestResult>> out;
  for (const TestResult& r : run.results) {
    if (out.empty() || key_of(out.back().front()) != key_of(r)) out.emplace_back();
    out.back().push_back(r);
  }
  return out;
}

// The run-wide members of f agree with those of the first shard, and f is a complete shard.
void check_compatible(const ShardFile& first, const ShardFile& f) {
  if (!f.run.shard) throw std::runtime_error(f.path + " is not a shard (written without --shard)");
  if (f.run.shard->index >= f.run.shard->count) throw std::runtime_error(f.path + ": shard index not below count");
  if (f.run.complete != true)
    throw std::runtime_error(shard_name(f) + " is incomplete (its run did not finish): resume it with --resume");
  const BatteryRun &a = first.run, &b = f.run;
  const char* differs = a.alpha != b.alpha                         ? "alpha"
                        : a.correction != b.correction             ? "correction"
                        : a.samples != b.samples                   ? "samples"
                        : a.seed != b.seed                         ? "seed"
                        : a.shard->count != b.shard->count         ? "shard count"
                        : a.shard->cases != b.shard->cases         ? "number of cases"
                        : a.shard->case_list != b.shard->case_list ? "case list"
                                                                   : nullptr;
  if (differs)
    throw std::runtime_error(first.path + " and " + f.path + " differ in " + differs + ": not shards of one run");
}

}  // namespace

BatteryRun merge_shards(const std::vector<ShardFile>& shards) {
  if (shards.empty()) throw std::runtime_error("no shards to merge");
  for (const ShardFile& f : shards) check_compatible(shards.front(), f);
  const ShardOf& of = *shards.front().run.shard;
  std::vector<const ShardFile*> by_index(of.count, nullptr);
  for (const ShardFile& f : shards) {
    const ShardFile*& slot = by_index[f.run.shard->index];
    if (slot) throw std::runtime_error(shard_name(*slot) + " and " + shard_name(f) + " overlap: the same shard");
    slot = &f;
  }
  std::string missing;
  for (std::uint64_t i = 0; i < of.count; ++i)
    if (!by_index[i]) missing += (missing.empty() ? "" : ", ") + std::to_string(i) + "/" + std::to_string(of.count);
  if (!missing.empty()) throw std::runtime_error("shard " + missing + " missing: the shards are incomplete");

  std::vector<std::vector<std::vector<TestResult>>> groups(of.count);
  std::map<CaseKey, const ShardFile*> seen;
  for (std::uint64_t i = 0; i < of.count; ++i) {
    groups[i] = cases_of(by_index[i]->run);
    const std::uint64_t expected = of.cases > i ? (of.cases - 1 - i) / of.count + 1 : 0;
    if (groups[i].size() != expected)
      throw std::runtime_error(shard_name(*by_index[i]) + " holds " + std::to_string(groups[i].size()) +
                               " cases, not the " + std::to_string(expected) + " of its shard");
    for (const auto& g : groups[i]) {
      const auto [it, fresh] = seen.emplace(key_of(g.front()), by_index[i]);
      if (!fresh)
        throw std::runtime_error(shard_name(*it->second) + " and " + shard_name(*by_index[i]) + " overlap: both hold " +
                                 label(key_of(g.front())));
    }
  }

  BatteryRun run = shards.front().run;
  run.shard.reset();
  run.results.clear();
  for (std::uint64_t c = 0; c < of.cases; ++c)  // case c of the run is case c / K of shard c mod K
    for (const TestResult& r : groups[c % of.count][c / of.count]) run.results.push_back(r);
  apply_correction(run.results, run.alpha, run.correction);
  return run;
}

bool is_battery_results(const std::string& text) {
  boost::json::error_code ec;
  const boost::json::value v = boost::json::parse(text, ec);
  if (ec) throw std::runtime_error("not valid JSON (" + ec.message() + ")");
  return v.is_object() && v.get_object().contains("results");
}

}  // namespace warpcheck::validation
