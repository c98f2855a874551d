// For the examples compiled with a deliberate bug (examples/CMakeLists.txt): whether the battery's test `test` failed.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "warpcheck/validation/results.h"

inline bool fails(const std::vector<warpcheck::validation::TestResult>& results, const std::string& test) {
  return std::any_of(results.begin(), results.end(),
                     [&](const warpcheck::validation::TestResult& r) { return r.test == test && !r.passed; });
}
