// Specification of the worst-case searches (validation/.../searches.h): every search finds a finite worst case
// in 2 s, chains are reproducible from (seed, chain index), records survive JSON exactly, resumed runs
// continue, merging takes the worst of the shards.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <set>

#include "warpcheck/polygon_error_analysis.h"
#include "warpcheck/validation/searches.h"

using namespace warpcheck::validation;

namespace {

std::vector<std::string> search_names() {
  std::vector<std::string> v;
  for (const auto& s : all_searches()) v.push_back(s.name);
  return v;
}

SearchRecord fresh(const std::string& name, std::uint64_t seed = 1, std::uint64_t shard = 0, std::uint64_t shards = 1) {
  SearchRecord r;
  r.search = name, r.seed = seed, r.shard_index = shard, r.shard_count = shards;
  return r;
}

std::string gtest_name(const testing::TestParamInfo<std::string>& i) {
  std::string s = i.param;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

}  // namespace

class EverySearch : public testing::TestWithParam<std::string> {};

TEST_P(EverySearch, FindsAFiniteWorstCaseInsideItsBoxInTwoSeconds) {
  const Search s = *find_search(GetParam());
  SearchRecord r = fresh(s.name);
  RunOptions o;
  o.seconds = 2;
  run_search(s, r, o);
  ASSERT_FALSE(r.best_x.empty()) << "no valid point found";
  EXPECT_TRUE(std::isfinite(r.best_f)) << r.best_f;
  EXPECT_GE(r.best_f, 0);
  ASSERT_EQ(r.best_x.size(), s.parameters.size());
  for (std::size_t i = 0; i < r.best_x.size(); ++i) {
    EXPECT_GE(r.best_x[i], s.parameters[i].lo) << s.parameters[i].name;
    EXPECT_LE(r.best_x[i], s.parameters[i].hi) << s.parameters[i].name;
  }
  // The reported worst case is what the objective gives at the reported input.
  EXPECT_EQ(s.objective(r.best_x), r.best_f);
  EXPECT_GT(r.chains, 0u);
  // The history records every improvement, in order, and ends at the reported worst case.
  ASSERT_FALSE(r.history.empty());
  EXPECT_EQ(r.history.back().best_f, r.best_f);
  EXPECT_EQ(r.history.back().chain, r.best_chain);
  for (std::size_t i = 1; i < r.history.size(); ++i) {
    EXPECT_GT(r.history[i].best_f, r.history[i - 1].best_f);
    EXPECT_GE(r.history[i].evaluations, r.history[i - 1].evaluations);
  }
  std::printf("%s: worst %.4Le after %lld evaluations\n", s.name.c_str(), r.best_f, r.evaluations);
}

INSTANTIATE_TEST_SUITE_P(Searches, EverySearch, testing::ValuesIn(search_names()), gtest_name);

TEST(Searches, NamesAreUniqueAndEveryParameterHasABoxAndAMeaning) {
  const auto all = all_searches();
  std::set<std::string> names;
  for (const auto& s : all) {
    EXPECT_TRUE(names.insert(s.name).second) << s.name;
    EXPECT_FALSE(s.description.empty()) << s.name;
    for (const auto& p : s.parameters) {
      EXPECT_LT(p.lo, p.hi) << s.name << " " << p.name;
      EXPECT_FALSE(p.meaning.empty()) << s.name << " " << p.name;
    }
  }
  for (const char* required :
       {"polygon-backward-k0", "polygon-backward-k1", "polygon-backward-k2", "polygon-backward-k2-area1e-7",
        "projected-cap-quintic", "projected-cap-case3-ratio", "sptd-cap-invariance",
        "precision-sphere-solid-angle-float-angle", "precision-polygon-projected-solid-angle-double-backward",
        "pdf-warp-sphere-visible-area"})
    EXPECT_TRUE(names.count(required)) << required;
}

TEST(Searches, TheWorstCaseIsReproducedByRerunningItsChainFromSeedAndIndex) {
  const Search s = *find_search("polygon-backward-k1");
  SearchRecord r = fresh(s.name, 42, 1, 3);  // shard 1 of 3: global chains 1, 4, 7, ...
  RunOptions o;
  o.seconds = 0.5;
  run_search(s, r, o);
  ASSERT_FALSE(r.best_x.empty());
  EXPECT_EQ(r.best_chain % 3, 1u);
  const ChainResult<long double> again = run_chain(s.objective, s.bounds(), s.options(), 42, r.best_chain);
  EXPECT_EQ(again.f, r.best_f);
  EXPECT_EQ(again.x, r.best_x);
}

TEST(Searches, TwoThreadsCompleteEveryChainBelowTheWatermark) {
  const Search s = *find_search("polygon-backward-k0");
  SearchRecord r = fresh(s.name);
  RunOptions o;
  o.seconds = 0.5;
  o.threads = 2;
  run_search(s, r, o);
  EXPECT_EQ(r.chains, r.next_local + r.done_above.size());
  for (auto j : r.done_above) EXPECT_GT(j, r.next_local);
}

TEST(Searches, ARecordSurvivesJsonExactly) {
  const Search s = *find_search("polygon-backward-k2");
  SearchRecord r = fresh(s.name, 7, 2, 5);
  r.best_x = {0.1L, 1.0L / 3, -2.5L, 1e-30L, 179.999L, std::nextafter(1.0L, 0.0L)};
  r.best_f = 1.0L / 7;
  r.best_chain = 12, r.evaluations = 123456789012LL, r.chains = 99, r.next_local = 90;
  r.done_above = {91, 95};
  r.seconds = 12.5, r.target_seconds = 60, r.kernel_version = "v-test", r.command = "warpcheck worst-case ...";
  r.history = {{0.25, 1000, 3, 1.0L / 9, 1, 2}, {11.5, 123456789000LL, 98, 1.0L / 7, 12, 2}};
  const SearchRecord back = record_from_json(to_json(r, &s));
  ASSERT_EQ(back.history.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back.history[i].seconds, r.history[i].seconds);
    EXPECT_EQ(back.history[i].evaluations, r.history[i].evaluations);
    EXPECT_EQ(back.history[i].chains, r.history[i].chains);
    EXPECT_EQ(back.history[i].best_f, r.history[i].best_f);
    EXPECT_EQ(back.history[i].chain, r.history[i].chain);
    EXPECT_EQ(back.history[i].shard_index, r.history[i].shard_index);
  }
  EXPECT_EQ(back.search, r.search);
  EXPECT_EQ(back.best_x, r.best_x);
  EXPECT_EQ(back.best_f, r.best_f);
  EXPECT_EQ(back.seed, r.seed);
  EXPECT_EQ(back.shard_index, r.shard_index);
  EXPECT_EQ(back.shard_count, r.shard_count);
  EXPECT_EQ(back.best_chain, r.best_chain);
  EXPECT_EQ(back.evaluations, r.evaluations);
  EXPECT_EQ(back.chains, r.chains);
  EXPECT_EQ(back.next_local, r.next_local);
  EXPECT_EQ(back.done_above, r.done_above);
  EXPECT_EQ(back.seconds, r.seconds);
  EXPECT_EQ(back.kernel_version, r.kernel_version);
  EXPECT_THROW(record_from_json("{\"search\": 3}"), std::runtime_error);
  EXPECT_THROW(record_from_json("not json"), std::runtime_error);
}

TEST(Searches, AResumedRunContinuesWithNewChainsAndKeepsItsBest) {
  const Search s = *find_search("polygon-backward-k0");
  SearchRecord r = fresh(s.name);
  RunOptions o;
  o.seconds = 0.4;
  run_search(s, r, o);
  const SearchRecord first = record_from_json(to_json(r, &s));  // as if from a checkpoint file
  SearchRecord resumed = first;
  o.seconds = 0.8;  // the budget counts over resumes
  run_search(s, resumed, o);
  EXPECT_GT(resumed.chains, first.chains);
  EXPECT_GE(resumed.next_local, first.next_local);
  EXPECT_GT(resumed.evaluations, first.evaluations);
  EXPECT_GE(resumed.best_f, first.best_f);
  EXPECT_GE(resumed.seconds, 0.8);
  EXPECT_LT(resumed.seconds, 0.8 + 0.5);  // it ran about the remaining 0.4 s, not another 0.8 s
}

TEST(Searches, MergingShardsTakesTheWorstAndSumsTheWork) {
  const Search s = *find_search("polygon-backward-k0");
  std::vector<SearchRecord> shards;
  for (std::uint64_t i = 0; i < 3; ++i) {
    shards.push_back(fresh(s.name, 5, i, 3));
    RunOptions o;
    o.seconds = 0.2;
    run_search(s, shards.back(), o);
  }
  const SearchRecord m = merge_records(shards);
  long double worst = 0;
  long long evaluations = 0;
  for (const auto& r : shards) worst = std::max(worst, r.best_f), evaluations += r.evaluations;
  EXPECT_EQ(m.best_f, worst);
  EXPECT_EQ(m.evaluations, evaluations);
  EXPECT_EQ(s.objective(m.best_x), m.best_f);
  // The merged history improves monotonically and ends at the merged worst case.
  ASSERT_FALSE(m.history.empty());
  EXPECT_EQ(m.history.back().best_f, m.best_f);
  for (std::size_t i = 1; i < m.history.size(); ++i) {
    EXPECT_GT(m.history[i].best_f, m.history[i - 1].best_f);
    EXPECT_GE(m.history[i].seconds, m.history[i - 1].seconds);
  }
  SearchRecord other = fresh("polygon-backward-k1");
  EXPECT_THROW(merge_records({shards[0], other}), std::runtime_error);
}

// The polygon-backward searches cover exactly the sectors real polygons have (Peters 2021 Sec. 3.6 searches
// "test cases" of inner/outer ellipse, sector and target): every sector of random decentral triangles, rotated so
// that s0 = (1, 0) and written in the search's parameters, is a valid point with the kernel's own backward error;
// and a sector containing the direction where the outer edge's great circle meets the horizon (the worst case the
// search reaches without its edge-half constraint, 7.8e-2) is not a valid point.
TEST(PolygonBackwardSearch, EverySectorOfARealPolygonIsAPointOfTheSearchAndNoOtherIs) {
  using L = long double;
  const Search s = *find_search("polygon-backward-k2");
  std::mt19937_64 rng(7);
  int checked = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const warpcheck::RandomSectorCase<L> c = warpcheck::random_decentral_case<L>(rng, 1e-2L);
    const auto& sec = c.sector;
    const L rot = std::atan2(sec.s0.y(), sec.s0.x());
    const warpcheck::Vec2<L> s0 = sec.s0 / sec.s0.norm(), s1 = sec.s1 / sec.s1.norm();
    const L angle = std::atan2(s0.x() * s1.y() - s0.y() * s1.x(), s0.dot(s1));
    std::vector<L> p;
    for (const auto* e : {&sec.inner, &sec.outer}) {
      const L sign = e->nz < 0 ? -1 : 1;  // the ellipse of n and -n is the same: the search has n_z >= 0
      const L nx = sign * e->nxy.x(), ny = sign * e->nxy.y(), nz = sign * e->nz;
      p.push_back(std::atan2(std::hypot(nx, ny), nz));
      p.push_back(std::remainder(std::atan2(ny, nx) - rot, 2 * std::numbers::pi_v<L>));
    }
    p.push_back(angle * 180 / std::numbers::pi_v<L>);
    p.push_back(c.target / sec.area);
    if (!(p[4] <= 179.999L)) continue;
    const L e = s.objective(p);
    ASSERT_FALSE(std::isnan(e)) << "a real polygon's sector is outside the search, trial " << trial;
    EXPECT_NEAR(e, warpcheck::decentral_backward_error(c, 2), 1e-12L + 1e-6L * e) << trial;
    ++checked;
  }
  EXPECT_GT(checked, 1900);
  // That worst case, to 17 digits: its error is 7.8e-2 without the constraint, which makes it NaN.
  const std::vector<L> old{1.5707963267948966L,   -1.5720280146623582L, 1.5644003505118398L,
                           -0.80375905809977888L, 179.91251265643641L,  0.2705798324036342L};
  EXPECT_TRUE(std::isnan(s.objective(old)));
}
