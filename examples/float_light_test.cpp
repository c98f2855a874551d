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
  // The edge tested exactly: c = 1 - u0 (1 - cos_max) >= cos_max in any rounding, so every sample passes it.
  T pdf(const Vec3<T>& w) const { return w.z() >= cos_max ? density : 0; }
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
  // Float's edge cos_max = 1 - one_minus_cos is rounded by up to 3e-8 (half an ulp of 0.955), 6.7e-7 of the cone's
  // 1 - cos = 0.0447, and its density by a few 1e-7 more: pdf-integral measures 1.2e-6.
  s.tolerance = 2e-6L;
  BatteryOptions options;
  options.samples = 1'000'000;
  const auto results = validate(s, options);
  EXPECT_TRUE(all_passed(results)) << format_table(results);
}
