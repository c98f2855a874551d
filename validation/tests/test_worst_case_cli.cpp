// Specification of `warpcheck worst-case` as a process: killed with SIGKILL and restarted with the same
// command, it loses no best-so-far and continues; bad arguments exit with status 2.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "warpcheck/validation/searches.h"

using namespace warpcheck::validation;
namespace fs = std::filesystem;

namespace {

// The CLI sits in the build root (PROJECT_BINARY_DIR), the test executable in build/validation/.
fs::path cli_path() {
  const fs::path self = fs::read_symlink("/proc/self/exe").parent_path();
  for (const fs::path& p : {self / ".." / "warpcheck", self / "warpcheck"})
    if (fs::exists(p)) return fs::canonical(p);
  return {};
}

pid_t spawn(const std::vector<std::string>& args, const fs::path& log, const fs::path& out = "/dev/null") {
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    if (std::FILE* f = std::freopen(log.c_str(), "w", stderr)) (void)f;
    if (std::FILE* f = std::freopen(out.c_str(), "w", stdout)) (void)f;
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

int wait_status(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

struct TempDir {
  fs::path path;
  TempDir() {
    char tmpl[] = "/tmp/warpcheck-worst-XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() { fs::remove_all(path); }
};

}  // namespace

TEST(WorstCaseCli, ASigkilledRunRestartedWithTheSameCommandLosesNoBestAndContinues) {
  const fs::path cli = cli_path();
  ASSERT_FALSE(cli.empty()) << "warpcheck executable not found next to the test binary (build it)";
  TempDir dir;
  const fs::path ckpt = dir.path / "ckpt.json", out = dir.path / "out.json";
  const std::vector<std::string> cmd = {
      cli.string(),  "worst-case",         "--search", "polygon-backward-k1", "--seconds", "5",      "--checkpoint",
      ckpt.string(), "--checkpoint-every", "0.3",      "--progress",          "0",         "--json", out.string()};
  const pid_t first = spawn(cmd, dir.path / "first.log");
  // Wait for a checkpoint with some chains in it, then kill without warning.
  const auto t0 = std::chrono::steady_clock::now();
  SearchRecord before;
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (fs::exists(ckpt)) {
      before = record_from_json(slurp(ckpt));
      if (before.chains > 0 && before.seconds >= 1.5) break;
    }
    ASSERT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(20)) << "no checkpoint written";
  }
  ASSERT_EQ(kill(first, SIGKILL), 0);
  EXPECT_EQ(wait_status(first), 128 + SIGKILL);
  EXPECT_FALSE(fs::exists(out));                               // it really died before finishing
  const SearchRecord at_kill = record_from_json(slurp(ckpt));  // the file is whole: written atomically
  EXPECT_GE(at_kill.chains, before.chains);

  const auto t1 = std::chrono::steady_clock::now();
  EXPECT_EQ(wait_status(spawn(cmd, dir.path / "second.log")), 0) << slurp(dir.path / "second.log");
  const double second_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  const SearchRecord after = record_from_json(slurp(out));
  EXPECT_NE(slurp(dir.path / "second.log").find("resuming from"), std::string::npos);
  EXPECT_GE(after.best_f, at_kill.best_f);  // no best-so-far lost
  ASSERT_FALSE(at_kill.history.empty());
  ASSERT_GE(after.history.size(), at_kill.history.size());  // and its history continues the killed run's
  for (std::size_t i = 0; i < at_kill.history.size(); ++i)
    EXPECT_EQ(after.history[i].best_f, at_kill.history[i].best_f);
  EXPECT_GT(after.chains, at_kill.chains);          // and it went on
  EXPECT_GE(after.next_local, at_kill.next_local);  // with chains it had not done
  EXPECT_GT(after.evaluations, at_kill.evaluations);
  EXPECT_GE(after.seconds, 5.0);
  EXPECT_LT(second_wall, 5.0 - at_kill.seconds + 2.0);  // it used the remaining budget, not a fresh one
}

TEST(WorstCaseCli, BadArgumentsExitWithStatusTwo) {
  const fs::path cli = cli_path();
  ASSERT_FALSE(cli.empty());
  TempDir dir;
  for (const std::vector<std::string>& bad : {std::vector<std::string>{"worst-case"},
                                              {"worst-case", "--search", "no-such-search"},
                                              {"worst-case", "--search", "polygon-backward-k0", "--shard", "3/3"},
                                              {"worst-case", "--search", "polygon-backward-k0", "--seconds", "-1"},
                                              {"worst-case", "--search", "polygon-backward-k0", "--threads", "x"},
                                              {"worst-case", "--frobnicate"},
                                              {"merge"}}) {
    std::vector<std::string> args = {cli.string()};
    args.insert(args.end(), bad.begin(), bad.end());
    EXPECT_EQ(wait_status(spawn(args, dir.path / "log")), 2) << bad.back();
    EXPECT_FALSE(slurp(dir.path / "log").empty()) << "no message for " << bad.back();
  }
}

TEST(WorstCaseCli, EvaluatePrintsTheObjectiveAtARecordedInput) {
  const fs::path cli = cli_path();
  ASSERT_FALSE(cli.empty());
  TempDir dir;
  const fs::path rec = fs::path(WARPCHECK_SOURCE_DIR) / "data" / "worst-cases" / "projected-cap-quintic.json";
  const SearchRecord r = record_from_json(slurp(rec));
  EXPECT_EQ(
      wait_status(spawn({cli.string(), "worst-case", "--search", "projected-cap-quintic", "--evaluate", rec.string()},
                        dir.path / "log", dir.path / "out")),
      0)
      << slurp(dir.path / "log");
  char expected[64];
  std::snprintf(expected, sizeof expected, ": %.6Le\n", r.best_f);
  EXPECT_NE(slurp(dir.path / "out").find(expected), std::string::npos) << slurp(dir.path / "out") << " vs " << expected;
  // An input of a search with other parameters is a usage error.
  EXPECT_EQ(
      wait_status(spawn({cli.string(), "worst-case", "--search", "polygon-backward-k0", "--evaluate", rec.string()},
                        dir.path / "log")),
      2);
}

// --evaluate with --json re-records an input with the current kernels: a record whose error was tampered with
// (halved) comes back with the true error at the same input, the rest of the record kept.
TEST(WorstCaseCli, EvaluateWithJsonRewritesTheRecordWithTheCurrentError) {
  const fs::path cli = cli_path();
  ASSERT_FALSE(cli.empty());
  TempDir dir;
  const fs::path rec = fs::path(WARPCHECK_SOURCE_DIR) / "data" / "worst-cases" / "projected-cap-quintic.json";
  SearchRecord r = record_from_json(slurp(rec));
  const long double truth = r.best_f;
  r.best_f /= 2;
  if (!r.history.empty()) r.history.back().best_f /= 2;
  {
    std::ofstream f(dir.path / "tampered.json");
    f << to_json(r);
  }
  ASSERT_EQ(wait_status(spawn({cli.string(), "worst-case", "--search", "projected-cap-quintic", "--evaluate",
                               (dir.path / "tampered.json").string(), "--json", (dir.path / "fresh.json").string()},
                              dir.path / "log", dir.path / "out")),
            0)
      << slurp(dir.path / "log");
  const SearchRecord f = record_from_json(slurp(dir.path / "fresh.json"));
  EXPECT_EQ(f.best_f, truth);
  ASSERT_FALSE(f.history.empty());
  EXPECT_EQ(f.history.back().best_f, truth);
  EXPECT_EQ(f.best_x, r.best_x);
  EXPECT_EQ(f.evaluations, r.evaluations);
  EXPECT_NE(f.command.find("--evaluate"), std::string::npos);
}
