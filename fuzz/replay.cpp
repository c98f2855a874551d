// fuzz/replay.cpp: the replay driver (plain main(), builds with g++, no libFuzzer). Runs inputs through the
// same FuzzTarget checks as the libFuzzer targets:
//   warpcheck_fuzz_replay TARGET PATH... [--optional PATH...]
//   e.g. warpcheck_fuzz_replay fuzz_sphere-solid-angle_double data/fuzz/fuzz_sphere-solid-angle_double/corpus
//   warpcheck_fuzz_replay --list                                    (the targets, one a line)
// A PATH is a file or a directory (walked recursively; files ending in .triage are skipped). An input F with
// a triage file F.triage whose first word is "known" (a documented limit of a float kernel or a finding in a
// published baseline, not fixed on purpose) is replayed and its outcome printed but not asserted; every other
// input must pass every invariant, and one triaged "open" fails whatever its outcome here (a sanitizer finding
// does not reproduce without the sanitizers). A missing PATH is an error (a target without its corpus must not
// pass vacuously, nor may one whose paths hold no input at all); paths after --optional may be missing (a target
// without findings has no regressions/). Exit status: 0 when every asserted input passes; 1 otherwise. ctest runs
// one "fuzz_replay.TARGET" test per target over data/fuzz/TARGET/{corpus,regressions} (label fast).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "target_table.h"

namespace fs = std::filesystem;
using warpcheck::fuzz::TargetCheck;

static std::string triage_status(const fs::path& input) {
  std::ifstream f(input.string() + ".triage");
  std::string word;
  if (f >> word) {
    if (!word.empty() && word.back() == ':') word.pop_back();
    return word;
  }
  return "";
}

int main(int argc, char** argv) {
  const auto all = warpcheck::fuzz::fuzz_targets();
  if (argc == 2 && std::string(argv[1]) == "--list") {
    for (const auto& [name, _] : all) std::printf("%s\n", name.c_str());
    return 0;
  }
  if (argc < 3 || all.find(argv[1]) == all.end()) {
    std::fprintf(stderr, "usage: %s TARGET PATH... [--optional PATH...]\ntargets:", argv[0]);
    for (const auto& [name, _] : all) std::fprintf(stderr, " %s", name.c_str());
    std::fprintf(stderr, "\n");
    return 2;
  }
  const TargetCheck& check = all.at(argv[1]);
  std::vector<fs::path> inputs;
  bool missing = false, optional = false;
  for (int i = 2; i < argc; ++i) {
    if (std::string(argv[i]) == "--optional") {
      optional = true;
      continue;
    }
    const fs::path p(argv[i]);
    if (fs::is_regular_file(p)) {
      inputs.push_back(p);
    } else if (fs::is_directory(p)) {
      for (const auto& e : fs::recursive_directory_iterator(p))
        if (e.is_regular_file() && e.path().extension() != ".triage") inputs.push_back(e.path());
    } else if (!optional) {
      std::fprintf(stderr, "missing: %s\n", argv[i]);
      missing = true;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  int failures = 0, known = 0, known_violating = 0;
  for (const auto& path : inputs) {
    std::ifstream f(path, std::ios::binary);
    const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    FuzzedDataProvider in(bytes.data(), bytes.size());
    const std::string status = triage_status(path);
    const bool is_known = status == "known";
    known += is_known;
    // An open finding fails even when it does not reproduce here: a sanitizer report (UBSan, ASan) needs the
    // libFuzzer build to show, and must not pass the default run silently.
    if (status == "open") {
      ++failures;
      std::printf("FAIL (open finding, see %s.triage): %s\n", path.c_str(), path.c_str());
    }
    try {
      check(in);
    } catch (const warpcheck::fuzz::InvariantViolation& e) {
      if (is_known) {
        ++known_violating;
        std::printf("known (not asserted): %s\n%s", path.c_str(), e.what());
      } else {
        ++failures;
        std::printf("FAIL: %s\n%s", path.c_str(), e.what());
      }
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s: %zu inputs replayed in %.3f s, %d failing, %d known (%d of them still violating)\n", argv[1],
              inputs.size(), seconds, failures, known, known_violating);
  // A target whose corpus holds no input would pass vacuously: that is a failure too.
  if (inputs.empty()) std::fprintf(stderr, "no input to replay for %s\n", argv[1]);
  return failures == 0 && !missing && !inputs.empty() ? 0 : 1;
}
