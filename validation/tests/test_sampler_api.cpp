// The parts of SamplerUnderTest that renderers' samplers need beyond a warp of two numbers: a weight checked against
// eval / pdf, more than two uniform numbers, a domain that is not a tight cap; and the table and defaults a user meets.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "warpcheck/validation/battery.h"

using namespace warpcheck::validation;

namespace {

// Uniform in a cone of half-angle 0.3 rad around +z, with f = 2 pdf (weight 2) made wrong by a relative `error` where
// u0 < `wrong_fraction`, i.e. on that fraction of the support.
SamplerUnderTest cone(Real error = 0, double wrong_fraction = 0) {
  const Real cos_max = std::cos(Real(0.3)), density = 1 / (kTwoPi<Real> * (1 - cos_max));
  SamplerUnderTest s;
  s.kernel = "test-cone", s.scalar = "long double", s.config = "0.3 rad";
  s.sample = [=](double u0, double u1) {
    const Real c = 1 - u0 * (1 - cos_max), r = std::sqrt(1 - c * c), phi = kTwoPi<Real> * u1;
    return Sample{Vec3L(r * std::cos(phi), r * std::sin(phi), c), density, true,
                  u0 < wrong_fraction ? 2 + 2 * error : 2};
  };
  s.pdf = [=](const Vec3L& w) { return w.z() >= cos_max ? density : 0; };
  s.eval = [=](const Vec3L& w) { return 2 * (w.z() >= cos_max ? density : 0); };
  s.bounding_cap = Cap<Real>{Vec3L(0, 0, 1), 1 - cos_max};
  return s;
}

BatteryOptions quick() {
  BatteryOptions o;
  o.samples = 200'000;
  return o;
}

const TestResult& find(const std::vector<TestResult>& r, const std::string& test) {
  for (const auto& x : r)
    if (x.test == test) return x;
  throw std::logic_error("no result " + test);
}

}  // namespace

TEST(SamplerApi, WeightEqualToEvalOverPdfPasses) {
  const auto r = validate(cone(), quick());
  EXPECT_TRUE(all_passed(r)) << format_table(r);
  EXPECT_EQ(find(r, "weight").statistic, 0);
}

TEST(SamplerApi, WeightOffByOneThousandthOnATenthOfTheSupportIsRejected) {
  const auto r = validate(cone(1e-3L, 0.1), quick());
  EXPECT_FALSE(find(r, "weight").passed) << format_table(r);
  EXPECT_NEAR(find(r, "weight").statistic, 1e-3, 1e-9);
  for (const auto& x : r) {
    if (x.test != "weight") {
      EXPECT_TRUE(x.passed) << x.test;  // the direction, pdf and warp are right
    }
  }
}

TEST(SamplerApi, SamplesWithoutAWeightFailWhenEvalIsGiven) {
  SamplerUnderTest s = cone();
  const auto sample = s.sample;
  s.sample = [sample](double u0, double u1) {
    Sample x = sample(u0, u1);
    x.weight.reset();
    return x;
  };
  EXPECT_FALSE(find(validate(s, quick()), "weight").passed);
}

TEST(SamplerApi, MoreThanTwoUniformsNeedSampleU) {
  SamplerUnderTest s = cone();
  s.uniforms = 3;
  EXPECT_THROW(run_battery(s, quick()), std::invalid_argument);
  s.uniforms = 1;
  EXPECT_THROW(run_battery(s, quick()), std::invalid_argument);
}

TEST(SamplerApi, SampleUReceivesAllItsUniformNumbers) {
  // The cone again, its azimuth from the fourth number: passes only if u[3] is uniform and independent of u[0].
  SamplerUnderTest s = cone();
  const auto sample = s.sample;
  s.sample = nullptr;
  s.uniforms = 4;
  s.sample_u = [sample](std::span<const double> u) { return u.size() == 4 ? sample(u[0], u[3]) : Sample{}; };
  const auto r = validate(s, quick());
  EXPECT_TRUE(all_passed(r)) << format_table(r);
}

TEST(SamplerApi, SamplesOutsideTheDeclaredHemisphereFailChi2WithTheirCount) {
  // Cosine-weighted over the upper hemisphere, but every 100th sample mirrored below the horizon.
  SamplerUnderTest s;
  s.kernel = "test-cosine", s.scalar = "double", s.config = "leaky";
  s.sample = [](double u0, double u1) {
    const Real c = std::sqrt(1 - Real(u0)), r = std::sqrt(Real(u0)), phi = kTwoPi<Real> * u1;
    const Real z = std::fmod(u1 * 1000, 10) < 0.1 ? -c : c;
    return Sample{Vec3L(r * std::cos(phi), r * std::sin(phi), z), c / kPi<Real>, true};
  };
  s.pdf = [](const Vec3L& w) { return std::max<Real>(0, w.z()) / kPi<Real>; };
  s.bounding_cap = hemisphere(Vec3L(0, 0, 1));
  const auto r = validate(s, quick());
  const TestResult& chi2 = find(r, "chi2");
  EXPECT_FALSE(chi2.passed);
  EXPECT_NE(chi2.detail.find("outside"), std::string::npos) << chi2.detail;
}

TEST(SamplerApi, HemisphereAndWholeSphereAreCapsOfOneAndTwo) {
  EXPECT_EQ(hemisphere(Vec3L(0, 0, 2)).one_minus_cos, 1);
  EXPECT_EQ(hemisphere(Vec3L(0, 0, 2)).axis, Vec3L(0, 0, 1));
  EXPECT_EQ(whole_sphere().one_minus_cos, 2);
}

TEST(SamplerApi, SupportSlackIs64EpsilonsOfTheScalarType) {
  EXPECT_EQ(support_slack<float>(), 64 * Real(FLT_EPSILON));
  EXPECT_EQ(support_slack<double>(), 64 * Real(DBL_EPSILON));
}

TEST(SamplerApi, BatteryRunsOnOneThreadUnlessAsked) { EXPECT_EQ(BatteryOptions{}.threads, 1); }

TEST(FormatTable, ColumnsStayAlignedWhenANameIsLong) {
  const auto row = [](std::string config) {
    TestResult r;
    r.kernel = std::string("k"), r.scalar = std::string("double"), r.config = std::move(config);
    r.test = std::string("chi2");
    return r;
  };
  const std::string t = format_table({row("short"), row(std::string(60, 'c'))});
  // Every line has its test column ("test" or "chi2") at the same offset.
  std::size_t offset = std::string::npos;
  for (std::size_t begin = 0, end; (end = t.find('\n', begin)) != std::string::npos; begin = end + 1) {
    const std::string line = t.substr(begin, end - begin);
    const std::size_t at = line.find(begin == 0 ? "test" : "chi2");
    if (offset == std::string::npos) offset = at;
    EXPECT_EQ(at, offset) << t;
  }
}
