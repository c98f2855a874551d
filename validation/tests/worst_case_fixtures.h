// The recorded worst cases, data/worst-cases/*.json, as the tests that replay them read them.
#pragma once

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "warpcheck/validation/searches.h"

namespace warpcheck::validation {

inline std::filesystem::path worst_case_dir() {
  return std::filesystem::path(WARPCHECK_SOURCE_DIR) / "data" / "worst-cases";
}

// The records' file names ("<search>.json"), sorted.
inline std::vector<std::string> recorded_worst_case_files() {
  std::vector<std::string> v;
  if (std::filesystem::exists(worst_case_dir()))
    for (const auto& e : std::filesystem::directory_iterator(worst_case_dir()))
      if (e.path().extension() == ".json") v.push_back(e.path().filename().string());
  std::sort(v.begin(), v.end());
  return v;
}

// The record in file `name` of worst_case_dir(); throws std::runtime_error when it is missing or malformed.
inline SearchRecord read_recorded_worst_case(const std::string& name) {
  std::ifstream f(worst_case_dir() / name);
  if (!f) throw std::runtime_error("cannot read " + (worst_case_dir() / name).string());
  std::ostringstream text;
  text << f.rdbuf();
  return record_from_json(text.str());
}

}  // namespace warpcheck::validation
