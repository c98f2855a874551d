// Every worst-case search for 30 s (label "slow"): each must find a finite worst case.
#include <gtest/gtest.h>

#include <cmath>

#include "warpcheck/validation/searches.h"

using namespace warpcheck::validation;

namespace {
std::vector<std::string> search_names() {
  std::vector<std::string> v;
  for (const auto& s : all_searches()) v.push_back(s.name);
  return v;
}
std::string gtest_name(const testing::TestParamInfo<std::string>& i) {
  std::string s = i.param;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}
}  // namespace

class EverySearchLong : public testing::TestWithParam<std::string> {};

TEST_P(EverySearchLong, FindsAFiniteWorstCaseInThirtySeconds) {
  const Search s = *find_search(GetParam());
  SearchRecord r;
  r.search = s.name;
  RunOptions o;
  o.seconds = 30;
  run_search(s, r, o);
  ASSERT_FALSE(r.best_x.empty()) << "no valid point found";
  EXPECT_TRUE(std::isfinite(r.best_f)) << r.best_f;
  EXPECT_EQ(s.objective(r.best_x), r.best_f);
  std::printf("%s: worst %.4Le after %lld evaluations, %llu chains\n", s.name.c_str(), r.best_f, r.evaluations,
              (unsigned long long)r.chains);
}

INSTANTIATE_TEST_SUITE_P(Searches, EverySearchLong, testing::ValuesIn(search_names()), gtest_name);
