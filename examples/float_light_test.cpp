// A float light sampler, validated against its own long double instantiation as the reference warp of the
// Jacobian check: a sphere light that subtends a cone of half-angle 0.3 rad around +z, sampled uniformly in it.
#include <gtest/gtest.h>
#include <cmath>
#include "warpcheck/validation/battery.h"
using namespace warpcheck::validation;

template <class T> struct ConeLight {
  T one_minus_cos = 2 * std::sin(T(0.15)) * std::sin(T(0.15)), cos_max = 1 - one_minus_cos;
  T density = 1 / (2 * kPi<T> * one_minus_cos);
  Sample sample(T u0, T u1) const {
    const T c = 1 - u0 * one_minus_cos, s = std::sqrt((1 - c) * (1 + c)), phi = 2 * kPi<T> * u1;
    return {Vec3<T>(s * std::cos(phi), s * std::sin(phi), c).template cast<Real>(), density, true};
  }
  // Rounding in T may put a direction up to support_slack<T>() radians beyond the edge: the pdf accepts it.
  T pdf(const Vec3<T>& w) const { return w.z() >= cos_max - support_slack<T>() ? density : 0; }
};

TEST(FloatConeLight, PassesTheBatteryAgainstItsLongDoubleReference) {
  const ConeLight<float> light;
  const ConeLight<long double> reference;
  SamplerUnderTest s;
  s.kernel = "float-cone-light", s.scalar = "float", s.config = "0.3 rad";  // scalar: the slack and u's rounding
  s.sample = [&](double u0, double u1) { return light.sample(to_unit<float>(u0), to_unit<float>(u1)); };
  s.pdf = [&](const Vec3L& w) { return Real(light.pdf(w.cast<float>())); };
  s.reference_sample = [&](Real u0, Real u1) { return reference.sample(u0, u1); };
  s.bounding_cap = Cap<Real>{Vec3L(0, 0, 1), reference.one_minus_cos};
  s.tolerance = 1e-6L;
  BatteryOptions options;
  options.samples = 1'000'000;
  const auto results = validate(s, options);
  EXPECT_TRUE(all_passed(results)) << format_table(results);
}
