// Specification of sharded battery runs: `warpcheck validate --shard I/N` runs the cases c with c mod N == I,
// `warpcheck merge` puts the N shards' files together into the unsharded run's file, bit for bit, with the
// correction recomputed over all tests (merge_shards, shards.h), and refuses shards that are not the N disjoint,
// finished parts of one run, naming the files. `warpcheck merge` of worst-case search files works as before.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "cli_process.h"
#include "warpcheck/validation/battery.h"
#include "warpcheck/validation/results.h"
#include "warpcheck/validation/searches.h"
#include "warpcheck/validation/shards.h"

using namespace warpcheck::validation;
using namespace warpcheck::test;
namespace fs = std::filesystem;

namespace {

// Runs the CLI with args to completion, stdout and stderr to dir/name.{out,err}; returns its exit status.
int run(const std::vector<std::string>& args, const fs::path& dir, const std::string& name) {
  const pid_t pid = start(args, dir, name);
  return pid > 0 ? exit_status(pid) : -1;
}

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& more) {
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

// Eight cases of sphere-solid-angle at 10^4 samples (two below the horizon, with deterministic tests only), in
// 3 shards of 3, 3 and 2 cases: a run of a few seconds.
const std::vector<std::string> kRun = {"validate",    "--kernel",  "sphere-solid-angle",
                                       "--config",    "near",      "--config",
                                       "grazing",     "--config",  "below-horizon",
                                       "--scalar",    "double",    "--scalar",
                                       "long double", "--config",  "partly-below-horizon",
                                       "--samples",   "10000",     "--seed",
                                       "7",           "--threads", "2",
                                       "--quiet"};

class ShardMerge : public ::testing::Test {
 protected:
  // The unsharded run, its three shards and their merge, made once for the suite.
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("warpcheck-shards-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    whole_status_ = run(with(kRun, {"--json", path("whole.json")}), dir_, "whole");
    for (int i = 0; i < 3; ++i) {
      const std::string s = "shard" + std::to_string(i);
      shard_status_[i] = run(with(kRun, {"--shard", std::to_string(i) + "/3", "--json", path(s + ".json")}), dir_, s);
    }
    merge_status_ =
        run({"merge", path("shard2.json"), path("shard0.json"), path("shard1.json"), "--json", path("merged.json")},
            dir_, "merge");
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static std::string path(const std::string& name) { return (dir_ / name).string(); }
  static BatteryRun load(const std::string& name) { return parse_battery_json(read_all(dir_ / name)); }
  // `warpcheck merge` of the files; its exit status, stderr in err.
  static int merge(const std::vector<std::string>& names, std::string& err) {
    std::vector<std::string> args = {"merge"};
    for (const auto& n : names) args.push_back(path(n));
    const int status = run(with(args, {"--json", path("refused.json")}), dir_, "refused");
    err = read_all(dir_ / "refused.err");
    return status;
  }
  static void write(const std::string& name, const BatteryRun& r) { std::ofstream(dir_ / name) << to_json(r); }

  static inline fs::path dir_;
  static inline int whole_status_ = -1, shard_status_[3] = {-1, -1, -1}, merge_status_ = -1;
};

}  // namespace

TEST_F(ShardMerge, EachShardRunsTheCasesWhoseIndexModNIsItsOwn) {
  ASSERT_TRUE(fs::exists(warpcheck_cli())) << "build the warpcheck executable";
  ASSERT_EQ(whole_status_, 0) << read_all(dir_ / "whole.err");
  const BatteryRun whole = load("whole.json");
  std::vector<std::string> order;  // the whole run's cases, in its order
  for (const TestResult& r : whole.results) {
    const std::string c = r.scalar + "/" + r.config;
    if (order.empty() || order.back() != c) order.push_back(c);
  }
  ASSERT_EQ(order.size(), 8u);
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(shard_status_[i], 0) << read_all(dir_ / ("shard" + std::to_string(i) + ".err"));
    const BatteryRun s = load("shard" + std::to_string(i) + ".json");
    ASSERT_TRUE(s.shard);
    EXPECT_EQ(s.shard->index, std::uint64_t(i));
    EXPECT_EQ(s.shard->count, 3u);
    EXPECT_EQ(s.shard->cases, 8u);
    std::vector<std::string> cases;
    for (const TestResult& r : s.results)
      if (cases.empty() || cases.back() != r.scalar + "/" + r.config) cases.push_back(r.scalar + "/" + r.config);
    std::vector<std::string> expected;
    for (std::size_t c = i; c < order.size(); c += 3) expected.push_back(order[c]);
    EXPECT_EQ(cases, expected) << "shard " << i;
  }
}

TEST_F(ShardMerge, TheMergedShardsAreTheUnshardedRunsFileBitForBit) {
  ASSERT_EQ(merge_status_, 0) << read_all(dir_ / "merge.err");
  const BatteryRun whole = load("whole.json"), merged = load("merged.json");
  ASSERT_EQ(merged.results.size(), whole.results.size());
  EXPECT_GT(whole.statistical_tests(), 10u);
  for (std::size_t i = 0; i < whole.results.size(); ++i) {
    const TestResult &a = whole.results[i], &b = merged.results[i];
    EXPECT_EQ(a.scalar + a.config + a.test, b.scalar + b.config + b.test) << i;
    EXPECT_EQ(std::memcmp(&a.statistic, &b.statistic, sizeof(double)), 0) << a.test;
    EXPECT_EQ(a.p_value, b.p_value) << a.test;
    EXPECT_EQ(a.passed, b.passed) << a.test;
    EXPECT_EQ(a.observed, b.observed) << a.test;
  }
  EXPECT_FALSE(merged.shard);
  EXPECT_EQ(merged.complete, true);
  EXPECT_EQ(read_all(dir_ / "merged.json"), read_all(dir_ / "whole.json"));
}

TEST_F(ShardMerge, TheReportReadsTheMergedFile) {
  ASSERT_EQ(merge_status_, 0) << read_all(dir_ / "merge.err");
  ASSERT_EQ(
      run({"report", "--from", path("merged.json"), "--out", path("html"), "--data", path("no-data")}, dir_, "report"),
      0)
      << read_all(dir_ / "report.err");
  EXPECT_NE(read_all(dir_ / "report.out").find("results, 0 failed"), std::string::npos)
      << read_all(dir_ / "report.out");
  EXPECT_TRUE(fs::exists(dir_ / "html" / "index.html"));
}

TEST_F(ShardMerge, TwoFilesOfTheSameShardAreRefusedAsOverlappingNamingBoth) {
  fs::copy_file(dir_ / "shard1.json", dir_ / "shard1-again.json", fs::copy_options::overwrite_existing);
  std::string err;
  EXPECT_EQ(merge({"shard0.json", "shard1.json", "shard1-again.json", "shard2.json"}, err), 1);
  EXPECT_NE(err.find("overlap"), std::string::npos) << err;
  EXPECT_NE(err.find(path("shard1.json")), std::string::npos) << err;
  EXPECT_NE(err.find(path("shard1-again.json")), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir_ / "refused.json"));
}

TEST_F(ShardMerge, AMissingShardIsRefusedNamingIt) {
  std::string err;
  EXPECT_EQ(merge({"shard0.json", "shard2.json"}, err), 1);
  EXPECT_NE(err.find("shard 1/3 missing"), std::string::npos) << err;
}

TEST_F(ShardMerge, AShardThatDidNotFinishIsRefusedNamingIt) {
  BatteryRun killed = load("shard1.json");
  killed.complete = false;
  killed.results.resize(3);  // as the checkpoint of a killed run: its first case only
  write("shard1-killed.json", killed);
  std::string err;
  EXPECT_EQ(merge({"shard0.json", "shard1-killed.json", "shard2.json"}, err), 1);
  EXPECT_NE(err.find(path("shard1-killed.json") + " (shard 1/3) is incomplete"), std::string::npos) << err;
}

TEST_F(ShardMerge, AShardMissingACaseOrHoldingAnotherShardsCaseIsRefusedNamingIt) {
  BatteryRun short_of_one = load("shard0.json"), one_too_many = load("shard1.json");
  const TestResult first = short_of_one.results.front();
  std::erase_if(short_of_one.results,
                [&](const TestResult& r) { return r.scalar == first.scalar && r.config == first.config; });
  write("shard0-short.json", short_of_one);
  std::string err;
  EXPECT_EQ(merge({"shard0-short.json", "shard1.json", "shard2.json"}, err), 1);
  EXPECT_NE(err.find(path("shard0-short.json") + " (shard 0/3) holds 2 cases, not the 3 of its shard"),
            std::string::npos)
      << err;

  // Shard 1 with shard 0's first case in place of its own first case: the same number of cases.
  const BatteryRun zero = load("shard0.json");
  std::vector<TestResult> swapped;
  for (const TestResult& r : zero.results)
    if (r.scalar == zero.results.front().scalar && r.config == zero.results.front().config) swapped.push_back(r);
  for (const TestResult& r : one_too_many.results)
    if (!(r.scalar == one_too_many.results.front().scalar && r.config == one_too_many.results.front().config))
      swapped.push_back(r);
  one_too_many.results = swapped;
  write("shard1-overlapping.json", one_too_many);
  EXPECT_EQ(merge({"shard0.json", "shard1-overlapping.json", "shard2.json"}, err), 1);
  EXPECT_NE(err.find("overlap: both hold"), std::string::npos) << err;
  EXPECT_NE(err.find(path("shard0.json")), std::string::npos) << err;
  EXPECT_NE(err.find(path("shard1-overlapping.json")), std::string::npos) << err;
}

TEST_F(ShardMerge, ShardsOfDifferentRunsAreRefusedNamingTheFilesAndWhatDiffers) {
  std::string err;
  for (const char* what : {"samples", "seed", "alpha", "correction", "case list"}) {
    BatteryRun other = load("shard2.json");
    const std::string w = what;
    if (w == "samples") other.samples = 20000;
    if (w == "seed") other.seed = 8;
    if (w == "alpha") other.alpha = 0.05;
    if (w == "correction") other.correction = Correction::kSidak;
    if (w == "case list") other.shard->case_list = "0123456789abcdef";
    write("shard2-other.json", other);
    EXPECT_EQ(merge({"shard0.json", "shard1.json", "shard2-other.json"}, err), 1) << what;
    EXPECT_NE(err.find(path("shard0.json") + " and " + path("shard2-other.json") + " differ in " + w),
              std::string::npos)
        << err;
  }
  // The unsharded run's file is no shard.
  EXPECT_EQ(merge({"whole.json"}, err), 1);
  EXPECT_NE(err.find(path("whole.json") + " is not a shard"), std::string::npos) << err;
}

TEST_F(ShardMerge, ResumingAShardFromAnotherShardsFileIsRefused) {
  fs::copy_file(dir_ / "shard0.json", dir_ / "resume.json", fs::copy_options::overwrite_existing);
  EXPECT_EQ(run(with(kRun, {"--shard", "1/3", "--json", path("resume.json"), "--resume"}), dir_, "resume"), 2);
  EXPECT_NE(read_all(dir_ / "resume.err").find("holds shard 0/3"), std::string::npos) << read_all(dir_ / "resume.err");
  EXPECT_EQ(read_all(dir_ / "resume.json"), read_all(dir_ / "shard0.json"));
}

// The negative controls at 10^5 samples fail a chi2, a KS test (p 3e-4, rejected by Holm at alpha / 12) and
// pdf-consistency; split over two shards and merged, every verdict is the unsharded run's.
TEST(ShardMergeNegativeControls, MergedShardsFailExactlyAsTheUnshardedRunWithTheSameHolmDecisions) {
  const fs::path dir = fs::temp_directory_path() / ("warpcheck-shards-nc-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::vector<std::string> command = {"validate", "--negative-controls", "--samples", "100000", "--threads", "2",
                                            "--quiet"};
  ASSERT_EQ(run(with(command, {"--json", (dir / "whole.json").string()}), dir, "whole"), 1)
      << read_all(dir / "whole.err");
  for (const char* s : {"0", "1"})
    ASSERT_EQ(
        run(with(command, {"--shard", std::string(s) + "/2", "--json", (dir / (std::string(s) + ".json")).string()}),
            dir, s),
        1);
  ASSERT_EQ(run({"merge", (dir / "0.json").string(), (dir / "1.json").string(), "--json", (dir / "m.json").string()},
                dir, "merge"),
            0)
      << read_all(dir / "merge.err");
  const BatteryRun whole = parse_battery_json(read_all(dir / "whole.json"));
  const BatteryRun merged = parse_battery_json(read_all(dir / "m.json"));
  ASSERT_EQ(merged.results.size(), whole.results.size());
  std::size_t failed = 0, failed_by_holm = 0;
  for (std::size_t i = 0; i < whole.results.size(); ++i) {
    const TestResult &a = whole.results[i], &b = merged.results[i];
    EXPECT_EQ(a.kernel + a.test, b.kernel + b.test);
    EXPECT_EQ(a.p_value, b.p_value) << a.kernel << " " << a.test;
    EXPECT_EQ(a.passed, b.passed) << a.kernel << " " << a.test;
    failed += !a.passed;
    failed_by_holm += !a.passed && a.p_value && *a.p_value > 0;
  }
  EXPECT_GE(failed, 4u);
  EXPECT_GE(failed_by_holm, 1u);  // a decision at Holm's threshold, not only p = 0
  EXPECT_EQ(read_all(dir / "m.json"), read_all(dir / "whole.json"));
  fs::remove_all(dir);
}

namespace {

TestResult stat_result(const std::string& config, double p) {
  TestResult r;
  r.kernel = "k", r.scalar = "double", r.config = config, r.test = "ks-radial";
  r.statistic = 1 - p, r.p_value = p;
  return r;
}

// A shard file of a run over cases "a", "b", "c", "d" (one statistical test each) with the given p-values.
ShardFile shard_file(std::uint64_t index, const std::vector<std::pair<std::string, double>>& cases, Correction c) {
  ShardFile f{"shard" + std::to_string(index), {}};
  f.run.alpha = 0.01, f.run.correction = c, f.run.samples = 1000, f.run.seed = 1, f.run.complete = true;
  f.run.shard = ShardOf{index, 2, 4, "fedcba9876543210"};
  for (const auto& [config, p] : cases) f.run.results.push_back(stat_result(config, p));
  apply_correction(f.run.results, f.run.alpha, f.run.correction);
  return f;
}

}  // namespace

// Holm over a shard of two tests rejects p = 0.004 (alpha / 2 = 0.005); over the run's four it does not
// (0.004 > alpha / 4): the merge decides as the run, not as the shard. Likewise Sidak's threshold.
TEST(MergeShards, RecomputesTheCorrectionOverTheUnionNeverTakingAShardsVerdict) {
  for (Correction c : {Correction::kHolm, Correction::kSidak}) {
    const ShardFile s0 = shard_file(0, {{"a", 0.004}, {"c", 0.5}}, c);
    const ShardFile s1 = shard_file(1, {{"b", 0.6}, {"d", 0.7}}, c);
    ASSERT_FALSE(s0.run.results[0].passed) << to_string(c);
    const BatteryRun merged = merge_shards({s1, s0});
    ASSERT_EQ(merged.results.size(), 4u);
    EXPECT_EQ(merged.results[0].config + merged.results[1].config + merged.results[2].config + merged.results[3].config,
              "abcd");
    std::vector<TestResult> expected = merged.results;
    apply_correction(expected, 0.01, c);
    EXPECT_TRUE(merged.results[0].passed) << to_string(c);
    for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(merged.results[i].passed, expected[i].passed);
    EXPECT_FALSE(merged.shard);
  }
}

TEST(MergeShards, AShardOfAFourCaseRunWithTooFewCasesIsRefusedNamingIt) {
  const ShardFile s0 = shard_file(0, {{"a", 0.5}, {"c", 0.5}}, Correction::kHolm);
  const ShardFile s1 = shard_file(1, {{"b", 0.5}}, Correction::kHolm);
  try {
    merge_shards({s0, s1});
    FAIL() << "merged a shard that lacks a case";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("shard1 (shard 1/2) holds 1 cases, not the 2"), std::string::npos) << e.what();
  }
}

// The dispatch by content leaves the merge of worst-case search shards as it was: the best of the shards.
TEST(MergeCli, WorstCaseSearchShardsStillMergeToTheBestOfThem) {
  ASSERT_TRUE(fs::exists(warpcheck_cli())) << "build the warpcheck executable";
  const fs::path dir = fs::temp_directory_path() / ("warpcheck-merge-search-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string search = all_searches().front().name;
  for (const char* s : {"0", "1"})
    ASSERT_EQ(run({"worst-case", "--search", search, "--seconds", "0.5", "--progress", "0", "--shard",
                   std::string(s) + "/2", "--json", (dir / (std::string(s) + ".json")).string()},
                  dir, s),
              0)
        << read_all(dir / (std::string(s) + ".err"));
  ASSERT_EQ(run({"merge", (dir / "0.json").string(), (dir / "1.json").string(), "--json", (dir / "m.json").string()},
                dir, "merge"),
            0)
      << read_all(dir / "merge.err");
  const SearchRecord a = record_from_json(read_all(dir / "0.json")), b = record_from_json(read_all(dir / "1.json"));
  const SearchRecord m = record_from_json(read_all(dir / "m.json"));
  EXPECT_EQ(m.best_f, std::max(a.best_f, b.best_f));
  EXPECT_EQ(m.chains, a.chains + b.chains);
  // A battery file and a search file together: refused, naming both.
  std::ofstream(dir / "battery.json") << to_json(BatteryRun{});
  EXPECT_EQ(run({"merge", (dir / "battery.json").string(), (dir / "0.json").string()}, dir, "mixed"), 1);
  EXPECT_NE(read_all(dir / "mixed.err").find("merge files of one kind"), std::string::npos);
  fs::remove_all(dir);
}
