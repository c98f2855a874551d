#include <gtest/gtest.h>
#include <cmath>
#include "warpcheck/validation/battery.h"
using namespace warpcheck::validation;  // also names warpcheck's Cap, Vec3 and kPi

// A renderer's own sampler: uniform directions in a cone of half-angle 0.3 rad around +z.
struct MyConeSampler {
  double cos_max = std::cos(0.3), density = 1 / (2 * kPi<double> * (1 - cos_max));
  Sample sample(double u0, double u1) const {
    const double c = 1 - u0 * (1 - cos_max), s = std::sqrt(1 - c * c), phi = 2 * kPi<double> * u1;
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
  s.bounding_cap = Cap<Real>{Vec3L(0, 0, 1), 1 - my.cos_max};  // contains every sample: the chi2 grid's cap
  BatteryOptions options;
  options.samples = 1'000'000;
  const auto results = validate(s, options);  // chi2, 2 KS, pdf integral, pdf/Jacobian; alpha 0.01, Holm
  EXPECT_TRUE(all_passed(results)) << format_table(results);
}
