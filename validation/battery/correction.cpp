// The family-wise correction across a run's statistical tests, and the run's verdict (battery.h).
#include <algorithm>
#include <cmath>

#include "warpcheck/validation/battery.h"

namespace warpcheck::validation {

std::size_t apply_correction(std::vector<TestResult>& results, double alpha, Correction c) {
  std::vector<TestResult*> stat;
  for (auto& r : results)
    if (r.p_value) stat.push_back(&r);
  const std::size_t m = stat.size();
  if (m == 0) return 0;
  if (c == Correction::kSidak) {
    const double threshold = -std::expm1(std::log1p(-alpha) / double(m));  // 1 - (1 - alpha)^(1/m)
    for (auto* r : stat) r->passed = *r->p_value > threshold;
  } else {
    std::stable_sort(stat.begin(), stat.end(), [](auto* a, auto* b) { return *a->p_value < *b->p_value; });
    bool rejecting = true;
    for (std::size_t i = 0; i < m; ++i) {
      rejecting = rejecting && *stat[i]->p_value <= alpha / double(m - i);
      stat[i]->passed = !rejecting;
    }
  }
  return m;
}

bool all_passed(const std::vector<TestResult>& results) {
  return std::none_of(results.begin(), results.end(), [](const TestResult& r) { return r.failed(); });
}

}  // namespace warpcheck::validation
