// Specification of `warpcheck validate` as a process: with --json FILE --resume, a run killed with SIGKILL keeps the
// cases it finished in FILE, bit for bit (the power figures come with the completed run), and the same command with
// --resume runs only the others; a file from other --samples is refused. Its progress on stderr when stderr is not a
// terminal.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <regex>
#include <sstream>
#include <thread>

#include "cli_process.h"
#include "warpcheck/validation/results.h"

using namespace warpcheck::validation;
using namespace warpcheck::test;
namespace fs = std::filesystem;

namespace {

// The file of a running CLI, once it parses (the CLI replaces it atomically, so it always does once it exists).
std::optional<BatteryRun> peek(const fs::path& p) {
  const std::string text = read_all(p);
  if (text.empty()) return std::nullopt;
  return parse_battery_json(text);
}

}  // namespace

TEST(ValidateCli, AKilledRunResumedWithTheSameCommandKeepsWhatItFinishedAndRunsOnlyTheRest) {
  ASSERT_TRUE(fs::exists(warpcheck_cli())) << "build the warpcheck executable";
  const fs::path dir = fs::temp_directory_path() / ("warpcheck-resume-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path json = dir / "results.json";
  // Two cases, sphere-solid-angle double far and tiny, each a few seconds of quadrature.
  const std::vector<std::string> command = {
      "validate", "--kernel",   "sphere-solid-angle", "--scalar", "double",    "--config", "far",
      "--config", "tiny",       "--samples",          "2000",     "--threads", "1",        "--quiet",
      "--json",   json.string()};

  // Kill the run as soon as its file holds the first case.
  const pid_t pid = start(command, dir, "killed");
  ASSERT_GT(pid, 0);
  std::optional<BatteryRun> first;
  for (auto t0 = std::chrono::steady_clock::now(); std::chrono::steady_clock::now() - t0 < std::chrono::minutes(5);) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if ((first = peek(json)) && !first->results.empty()) break;
  }
  ::kill(pid, SIGKILL);
  EXPECT_EQ(exit_status(pid), 128 + SIGKILL);
  first = peek(json);
  ASSERT_TRUE(first && !first->results.empty()) << read_all(dir / "killed.err");
  ASSERT_EQ(first->complete, false) << "the run finished before it was killed";
  EXPECT_TRUE(first->power.empty()) << "a checkpoint carries no power figures; the completed run does";
  for (const TestResult& r : first->results) ASSERT_EQ(r.config, "far");

  std::vector<std::string> resume = command;
  resume.push_back("--resume");
  ASSERT_EQ(exit_status(start(resume, dir, "resumed")), 0) << read_all(dir / "resumed.err");
  EXPECT_NE(read_all(dir / "resumed.err").find("1 cases done, 1 to run"), std::string::npos);
  const BatteryRun done = parse_battery_json(read_all(json));
  EXPECT_EQ(done.complete, true);
  EXPECT_EQ(done.power.size(), 2u);  // one per case
  // The finished case's results as they were, then the other case's, each once.
  ASSERT_GT(done.results.size(), first->results.size());
  for (std::size_t i = 0; i < done.results.size(); ++i) {
    const TestResult& r = done.results[i];
    EXPECT_EQ(r.config, i < first->results.size() ? "far" : "tiny") << i;
    if (i >= first->results.size()) continue;
    const TestResult& a = first->results[i];
    EXPECT_EQ(a.test, r.test);
    EXPECT_EQ(a.statistic, r.statistic) << r.test;
    EXPECT_EQ(a.p_value, r.p_value) << r.test;
    EXPECT_EQ(a.detail, r.detail) << r.test;
    EXPECT_EQ(a.expected, r.expected) << r.test;
    EXPECT_EQ(a.observed, r.observed) << r.test;
  }
  EXPECT_EQ(done.results.size(), 2 * first->results.size());

  // Other --samples: refused with the usage status, the file untouched.
  const std::string before = read_all(json);
  std::vector<std::string> other = resume;
  other[std::find(other.begin(), other.end(), "2000") - other.begin()] = "3000";
  EXPECT_EQ(exit_status(start(other, dir, "refused")), 2);
  EXPECT_NE(read_all(dir / "refused.err").find("--samples 2000"), std::string::npos) << read_all(dir / "refused.err");
  EXPECT_EQ(read_all(json), before);
  fs::remove_all(dir);
}

// Progress on stderr when it is not a terminal: one line per finished case, in order, with the cases done of the
// total, the elapsed time and (but after the last case) the time left; nothing with --quiet. The below-horizon
// cases have no sample and no quadrature: three cases in well under a second.
TEST(ValidateCli, ProgressIsOneLinePerFinishedCaseWithTheTimeLeftAndNothingWhenQuiet) {
  ASSERT_TRUE(fs::exists(warpcheck_cli())) << "build the warpcheck executable";
  const fs::path dir = fs::temp_directory_path() / ("warpcheck-progress-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::vector<std::string> command = {"validate",  "--kernel", "sphere-solid-angle", "--config", "below-horizon",
                                            "--samples", "1000"};
  ASSERT_EQ(exit_status(start(command, dir, "plain")), 0) << read_all(dir / "plain.err");
  const std::string err = read_all(dir / "plain.err");
  const std::regex line(R"(\[([123])/3\] sphere-solid-angle / (float|double|long double) / below-horizon done in )"
                        R"([0-9.]+ (s|min [0-9]+ s); elapsed [^,]+ s(, about .* left)?)");
  std::istringstream lines(err);
  std::string l;
  int k = 0;
  while (std::getline(lines, l)) {
    std::smatch m;
    ASSERT_TRUE(std::regex_match(l, m, line)) << l;
    EXPECT_EQ(m[1].str(), std::to_string(++k));
    EXPECT_EQ(m[4].matched, k < 3) << l;  // the time left, but after the last case
  }
  EXPECT_EQ(k, 3) << err;
  std::vector<std::string> quiet = command;
  quiet.push_back("--quiet");
  ASSERT_EQ(exit_status(start(quiet, dir, "quiet")), 0);
  EXPECT_EQ(read_all(dir / "quiet.err"), "");
  fs::remove_all(dir);
}
