// The README's "Validate your own sampler" example, compiled and run exactly as printed there (the code between
// the markers is copied into README.md; ReadmeExample.IsTheCodeInTheReadme checks they are the same text).
// README-EXAMPLE-BEGIN
#include <gtest/gtest.h>
#include <cmath>
#include <numbers>
#include "warpcheck/validation/battery.h"
using namespace warpcheck::validation;

// A renderer's own sampler: uniform directions in a cone of half-angle 0.3 rad around +z.
struct MyConeSampler {
  double cos_max = std::cos(0.3), density = 1 / (2 * std::numbers::pi * (1 - cos_max));
  Sample sample(double u0, double u1) const {
    const double c = 1 - u0 * (1 - cos_max), s = std::sqrt(1 - c * c), phi = 2 * std::numbers::pi * u1;
    return {Vec3L(s * std::cos(phi), s * std::sin(phi), c), density, true};
  }
  double pdf(const Vec3L& w) const { return w.z() >= cos_max ? density : 0; }
};

TEST(MyConeSampler, PassesTheWarpcheckBattery) {
  MyConeSampler my;
  SamplerUnderTest s;
  s.kernel = "my-cone", s.config = "0.3 rad";
  s.sample = [&](double u0, double u1) { return my.sample(u0, u1); };
  s.pdf = [&](const Vec3L& w) { return Real(my.pdf(w)); };
  s.bounding_cap = {Vec3L(0, 0, 1), Real(1 - my.cos_max)};  // contains every sample: the chi2 grid's cap
  BatteryOptions options;
  options.samples = 1'000'000;
  const auto results = validate(s, options);  // chi2, 2 KS, pdf integral, pdf/Jacobian; alpha 0.01, Holm
  EXPECT_TRUE(all_passed(results)) << format_table(results);
}
// README-EXAMPLE-END

#include <fstream>
#include <sstream>
#include <string>

namespace {
std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace

TEST(ReadmeExample, IsTheCodeInTheReadme) {
  const std::string self = slurp(WARPCHECK_SOURCE_DIR "/validation/tests/test_readme_example.cpp");
  const std::string readme = slurp(WARPCHECK_SOURCE_DIR "/README.md");
  const std::string begin = "// README-EXAMPLE-BEGIN\n", end = "// README-EXAMPLE-END";
  const auto b = self.find(begin) + begin.size(), e = self.find(end);
  ASSERT_NE(self.find(begin), std::string::npos);
  const std::string example = self.substr(b, e - b);
  EXPECT_NE(readme.find("```cpp\n" + example + "```"), std::string::npos)
      << "README.md must contain, in a ```cpp block, exactly the example between the markers of this file";
  int lines = 0;
  for (char c : example) lines += c == '\n';
  EXPECT_LE(lines, 30) << "the issue asks for at most 30 lines";
}
