#pragma once
#include <stdexcept>
#include <string>
#include <vector>

#include "warpcheck/validation/registry.h"

namespace warpcheck::cli {

// Bad arguments: main prints the message and exits with status 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Command {
  const char* name;
  const char* summary;
  int (*main)(const std::vector<std::string>& args);
};

int list_main(const std::vector<std::string>& args);
int validate_main(const std::vector<std::string>& args);
int worst_case_main(const std::vector<std::string>& args);
int merge_main(const std::vector<std::string>& args);
int report_main(const std::vector<std::string>& args);
int promote_main(const std::vector<std::string>& args);
int plan_main(const std::vector<std::string>& args);

// `warpcheck merge` of battery shards (validate.cpp): files and their texts; the merged run to json or stdout.
int merge_battery(const std::vector<std::string>& files, const std::vector<std::string>& texts,
                  const std::string& json);

// Argument helpers shared by the subcommands.
std::uint64_t parse_u64(const std::string& flag, const std::string& value, std::uint64_t min, std::uint64_t max);
double parse_double(const std::string& flag, const std::string& value, double min, double max);
// --shard I/N into index I and count N (N >= 1, I < N).
void parse_shard(const std::string& value, std::uint64_t& index, std::uint64_t& count);
// The cases a command runs on: --kernel, --config and --scalar globs, and the random geometries (validate.cpp).
struct Selection {
  std::vector<std::string> kernels, configs, scalars;
  validation::RandomGeometries random;
};
// Consumes "--flag value" pairs; returns false if args[i] is not one of the selection flags.
bool take_selection(const std::vector<std::string>& args, std::size_t& i, Selection& sel);
// The registry's cases the selection matches; UsageError when none does.
std::vector<const validation::Case*> select_cases(const validation::Registry& reg, const Selection& sel);
// Writes text to path atomically (temporary file in the same directory, then rename).
void write_file_atomically(const std::string& path, const std::string& text);

}  // namespace warpcheck::cli
