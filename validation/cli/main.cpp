// warpcheck: the command-line front of the validation suite. Subcommands live in cli/*.cpp and register in
// the table below.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "commands.h"

namespace {

const warpcheck::cli::Command kCommands[] = {
    {"list", "list kernels and their named configurations", warpcheck::cli::list_main},
    {"validate", "run the validation battery", warpcheck::cli::validate_main},
    {"worst-case", "search for the worst-case error of a kernel (resumable, shardable)",
     warpcheck::cli::worst_case_main},
    {"merge", "combine worst-case results, or battery shards, into one file", warpcheck::cli::merge_main},
    {"report", "write the HTML report of a battery run", warpcheck::cli::report_main},
    {"promote", "turn failing random geometries of a results file into registry data", warpcheck::cli::promote_main},
    {"plan", "samples needed to detect a given density error", warpcheck::cli::plan_main},
};

void usage(std::FILE* out) {
  std::fprintf(out, "usage: warpcheck <command> [options]\n\ncommands:\n");
  for (const auto& c : kCommands) std::fprintf(out, "  %-10s %s\n", c.name, c.summary);
  std::fprintf(out, "\n'warpcheck <command> --help' describes a command's options.\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    usage(stderr);
    return 2;
  }
  const std::string cmd = argv[1];
  if (cmd == "--help" || cmd == "-h" || cmd == "help") {
    usage(stdout);
    return 0;
  }
  for (const auto& c : kCommands)
    if (cmd == c.name) {
      try {
        return c.main(std::vector<std::string>(argv + 2, argv + argc));
      } catch (const warpcheck::cli::UsageError& e) {
        std::fprintf(stderr, "warpcheck %s: %s\n(try 'warpcheck %s --help')\n", c.name, e.what(), c.name);
        return 2;
      }
    }
  std::fprintf(stderr, "warpcheck: unknown command '%s'\n", cmd.c_str());
  usage(stderr);
  return 2;
}
