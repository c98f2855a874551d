// Specification of the results file (results.h): every double reads back bit for bit, the layout is the one the
// report and the stored battery files use, each stored file reads, and malformed files are rejected by name.
#include <gtest/gtest.h>

#include <bit>
#include <boost/json.hpp>
#include <cfloat>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "warpcheck/validation/battery.h"
#include "warpcheck/validation/results.h"

namespace warpcheck::validation {
namespace {

std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

TestResult chi2_result(double statistic, double p, std::vector<double> expected) {
  TestResult r;
  r.kernel = "k", r.scalar = "double", r.config = "c", r.test = "chi2";
  r.statistic = statistic, r.p_value = p, r.detail = "dof 3";
  if (expected.empty()) return r;
  r.map_rows = 1, r.map_cols = int(expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) r.observed.push_back(double(1000 + i));
  r.expected = std::move(expected);
  return r;
}

TestResult deterministic_result(double statistic) {
  TestResult r;
  r.kernel = "k \"quoted\"\n", r.scalar = "long double", r.config = "c\\d", r.test = "pdf-integral";
  r.statistic = statistic, r.passed = true, r.detail = "tab\there, control \x01";
  return r;
}

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

void expect_same_bits(const TestResult& a, const TestResult& b) {
  EXPECT_EQ(a.kernel, b.kernel);
  EXPECT_EQ(a.scalar, b.scalar);
  EXPECT_EQ(a.config, b.config);
  EXPECT_EQ(a.test, b.test);
  EXPECT_EQ(bits(a.statistic), bits(b.statistic)) << a.statistic << " read back as " << b.statistic;
  ASSERT_EQ(a.p_value.has_value(), b.p_value.has_value());
  if (a.p_value) {
    EXPECT_EQ(bits(*a.p_value), bits(*b.p_value)) << *a.p_value << " read back as " << *b.p_value;
  }
  EXPECT_EQ(a.passed, b.passed);
  EXPECT_EQ(a.detail, b.detail);
  EXPECT_EQ(a.known_limitation, b.known_limitation);
  EXPECT_EQ(a.map_rows, b.map_rows);
  EXPECT_EQ(a.map_cols, b.map_cols);
  EXPECT_EQ(a.observed, b.observed);
  ASSERT_EQ(a.expected.size(), b.expected.size());
  for (std::size_t i = 0; i < a.expected.size(); ++i) EXPECT_EQ(bits(a.expected[i]), bits(b.expected[i]));
}

TEST(ResultsJson, EveryDoubleReadsBackBitForBit) {
  // Random bit patterns over the whole range, values in [0, 1) like p-values, and the edge cases.
  std::mt19937_64 g(5);
  std::vector<double> values = {0.0,
                                -0.0,
                                1.0,
                                0.01,
                                5e-324,
                                DBL_MIN,
                                DBL_MAX,
                                -1e-9,
                                1e22,
                                9.5e18,
                                1.8446744073709552e19,
                                1.3927926388013963e-143};
  while (values.size() < 20000) {
    const double x = std::bit_cast<double>(g());
    if (std::isfinite(x)) values.push_back(x);
    values.push_back(double(g() >> 11) * 0x1.0p-53);
  }
  BatteryRun run;
  run.alpha = values[100], run.samples = ~0ULL, run.seed = 1ULL << 63;
  for (std::size_t i = 0; i + 1 < values.size(); i += 2)
    run.results.push_back(chi2_result(values[i], values[i + 1], {}));
  run.results.back().map_rows = 1;
  run.results.back().map_cols = int(values.size());
  run.results.back().observed.assign(values.size(), 7);
  run.results.back().expected = values;
  run.results.push_back(deterministic_result(std::numeric_limits<double>::infinity()));
  run.results.push_back(deterministic_result(-std::numeric_limits<double>::infinity()));
  run.results.back().known_limitation = "documented";
  const std::string text = to_json(run);
  const BatteryRun back = parse_battery_json(text);
  EXPECT_EQ(bits(back.alpha), bits(run.alpha));
  EXPECT_EQ(back.samples, run.samples);
  EXPECT_EQ(back.seed, run.seed);
  ASSERT_EQ(back.results.size(), run.results.size());
  for (std::size_t i = 0; i < run.results.size(); ++i) expect_same_bits(run.results[i], back.results[i]);
  EXPECT_EQ(to_json(back), text);
}

// A long run's checkpoints keep the text of the results written so far: after more results arrive and the
// correction over the run flips an earlier result's verdict, the text equals a fresh write.
TEST(ResultsJson, ACheckpointWithKeptTextsEqualsAFreshWriteAfterTheCorrectionChanges) {
  BatteryRun run;
  run.results = {chi2_result(3.5, 0.004, {1.5, 2.5}), deterministic_result(1e-9)};
  ResultTexts texts;
  apply_correction(run.results, run.alpha, run.correction);  // m = 1: 0.004 <= 0.01 rejects
  EXPECT_EQ(to_json(run, &texts), to_json(run));
  ASSERT_FALSE(run.results[0].passed);
  run.results.push_back(chi2_result(1.0, 0.5, {}));
  run.results.push_back(chi2_result(2.0, 0.3, {4.25}));
  apply_correction(run.results, run.alpha, run.correction);  // m = 3: 0.004 > 0.01 / 3 passes
  ASSERT_TRUE(run.results[0].passed);
  EXPECT_EQ(to_json(run, &texts), to_json(run));
  EXPECT_EQ(texts.parts.size(), run.results.size());
}

TEST(ResultsJson, ReadsNumbersExactlyWhereBoostJsonParseDoesNot) {
  // Boost.JSON 1.81's own conversion misreads this 17-digit double by two ulps; the results reader does not.
  const double x = 1.3927926388013963e-143;
  const std::string text =
      "{\"alpha\":0.01,\"correction\":\"holm\",\"statistical_tests\":0,\"results\":[{\"kernel\":"
      "\"k\",\"scalar\":\"double\",\"config\":\"c\",\"test\":\"t\",\"statistic\":"
      "1.3927926388013963e-143,\"p_value\":null,\"passed\":true}]}";
  EXPECT_NE(boost::json::parse(text).at("results").at(0).at("statistic").as_double(), x);
  EXPECT_EQ(parse_battery_json(text).results.at(0).statistic, x);
}

TEST(ResultsJson, KeepsTheLayoutOfTheReportAndTheStoredFiles) {
  BatteryRun run;
  run.alpha = 0.01, run.correction = Correction::kSidak, run.samples = 20000, run.seed = 1, run.complete = false;
  run.results = {chi2_result(3.5, 0.5, {1e3, 2.5e3}), deterministic_result(1e-17)};
  run.results[1].statistic = std::numeric_limits<double>::quiet_NaN();
  run.results.push_back(deterministic_result(std::numeric_limits<double>::infinity()));
  EXPECT_EQ(to_json(run),
            "{\"alpha\":0.01,\"correction\":\"sidak\",\"statistical_tests\":1,\"samples\":20000,\"seed\":1,"
            "\"complete\":false,\"results\":[\n"
            "{\"kernel\":\"k\",\"scalar\":\"double\",\"config\":\"c\",\"test\":\"chi2\",\"statistic\":3.5,"
            "\"p_value\":0.5,\"passed\":false,\"detail\":\"dof 3\",\"map\":{\"rows\":1,\"cols\":2,"
            "\"observed\":[1000,1001],\"expected\":[1000,2500]}},\n"
            "{\"kernel\":\"k \\\"quoted\\\"\\n\",\"scalar\":\"long double\",\"config\":\"c\\\\d\","
            "\"test\":\"pdf-integral\",\"statistic\":null,\"p_value\":null,\"passed\":true,"
            "\"detail\":\"tab\\there, control \\u0001\"},\n"
            "{\"kernel\":\"k \\\"quoted\\\"\\n\",\"scalar\":\"long double\",\"config\":\"c\\\\d\","
            "\"test\":\"pdf-integral\",\"statistic\":1e999,\"p_value\":null,\"passed\":true,"
            "\"detail\":\"tab\\there, control \\u0001\"}\n"
            "]}\n");
  // Without the CLI's members, and a known limitation where there is one.
  BatteryRun bare;
  bare.results = {deterministic_result(0.25)};
  bare.results[0].known_limitation = "float";
  EXPECT_EQ(to_json(bare),
            "{\"alpha\":0.01,\"correction\":\"holm\",\"statistical_tests\":0,\"results\":[\n"
            "{\"kernel\":\"k \\\"quoted\\\"\\n\",\"scalar\":\"long double\",\"config\":\"c\\\\d\","
            "\"test\":\"pdf-integral\",\"statistic\":0.25,\"p_value\":null,\"passed\":true,"
            "\"detail\":\"tab\\there, control \\u0001\",\"known_limitation\":\"float\"}\n"
            "]}\n");
}

TEST(ResultsJson, ReadsEveryStoredBatteryFile) {
  const std::filesystem::path data = std::filesystem::path(WARPCHECK_SOURCE_DIR) / "data";
  for (const char* file : {"polygon/battery-double.json", "polygon/battery-float.json",
                           "projected-cap/battery-float.json", "sptd/battery-ltc-sptd.json"}) {
    SCOPED_TRACE(file);
    const std::string text = slurp(data / file);
    ASSERT_FALSE(text.empty());
    const BatteryRun run = parse_battery_json(text);
    EXPECT_EQ(run.complete, true);
    EXPECT_EQ(run.samples, 10'000'000u);
    ASSERT_FALSE(run.results.empty());
    std::size_t maps = 0;
    for (const TestResult& r : run.results) maps += r.map_rows > 0;
    EXPECT_GT(maps, 0u);
    // What it holds survives the codec: the values, and the text once written.
    const BatteryRun again = parse_battery_json(to_json(run));
    ASSERT_EQ(again.results.size(), run.results.size());
    for (std::size_t i = 0; i < run.results.size(); ++i) expect_same_bits(run.results[i], again.results[i]);
    // Numbers agree with the file's text read by strtod (the stored files hold %.17g, exact for every double).
    const auto pos = text.find("\"statistic\":") + 12;
    EXPECT_EQ(run.results[0].statistic, std::strtod(text.c_str() + pos, nullptr));
  }
}

TEST(ResultsJson, RejectsMalformedFilesNamingTheMember) {
  auto message = [](const std::string& text) {
    try {
      parse_battery_json(text);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string head = R"({"alpha":0.01,"correction":"holm","statistical_tests":1,"results":[)";
  const std::string chi2 = R"({"kernel":"k","scalar":"double","config":"c","test":"chi2","statistic":1,)"
                           R"("p_value":0.5,"passed":true)";
  EXPECT_NE(message("{}").find("missing \"alpha\""), std::string::npos);
  EXPECT_NE(message("not json").find("not valid JSON"), std::string::npos);
  EXPECT_NE(message(head + chi2 + "}]} trailing").find("not valid JSON"), std::string::npos);
  EXPECT_NE(message(head + R"({"kernel":"k"}]})").find("results[0]: missing \"scalar\""), std::string::npos);
  EXPECT_NE(message(head + chi2 + R"(,"map":{"rows":2,"cols":2,"observed":[1,2,3],"expected":[1,2,3,4]}}]})")
                .find("results[0].map: rows x cols"),
            std::string::npos);
  EXPECT_NE(
      message(R"({"alpha":0.01,"correction":"bonferroni","statistical_tests":0,"results":[]})").find("\"bonferroni\""),
      std::string::npos);
  // The same results, well formed, are accepted: infinity as 1e999 and a null statistic.
  const BatteryRun run = parse_battery_json(head + chi2 +
                                            R"(},{"kernel":"k","scalar":"double","config":"c",)"
                                            R"("test":"battery","statistic":null,"p_value":null,)"
                                            R"("passed":false},{"kernel":"k","scalar":"double",)"
                                            R"("config":"c","test":"pdf-integral","statistic":1e999,)"
                                            R"("p_value":null,"passed":false}]})");
  ASSERT_EQ(run.results.size(), 3u);
  EXPECT_TRUE(std::isnan(run.results[1].statistic));
  EXPECT_TRUE(std::isinf(run.results[2].statistic));
}

}  // namespace
}  // namespace warpcheck::validation
