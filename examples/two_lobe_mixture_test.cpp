// A mixture of two lobes chosen by a third uniform number, as a BSDF with a diffuse and a glossy lobe samples:
// with probability 0.3 cosine-weighted over the upper hemisphere, else uniform in a cone of 0.4 rad around an axis
// tilted 0.5 rad from the normal. Every direction is above the horizon: the grid's domain is the hemisphere.
#include <gtest/gtest.h>
#include <cmath>
#include <span>
#include "warpcheck/validation/battery.h"
using namespace warpcheck::validation;
using V = Vec3<double>;

struct TwoLobes {
  double p_diffuse = 0.3, cos_max = std::cos(0.4);
  V axis = V(std::sin(0.5), 0, std::cos(0.5));
  double cone_pdf(const V& w) const {  // accepts directions that rounding put just outside the cone
    return w.dot(axis) >= cos_max - support_slack<double>() ? 1 / (2 * kPi<double> * (1 - cos_max)) : 0;
  }
  double pdf(const V& w) const {
    return p_diffuse * std::max(0.0, w.z()) / kPi<double> + (1 - p_diffuse) * cone_pdf(w);
  }
  Sample sample(std::span<const double> u) const {
    const bool diffuse = u[2] < p_diffuse;
    const double c = diffuse ? std::sqrt(1 - u[0]) : 1 - u[0] * (1 - cos_max), s = std::sqrt(1 - c * c);
    const Frame<double> f = Frame<double>::from_z(diffuse ? V(0, 0, 1) : axis);
    const double phi = 2 * kPi<double> * u[1];
    const V w = s * std::cos(phi) * f.x + s * std::sin(phi) * f.y + c * f.z;
    return {w.cast<Real>(), pdf(w), true};
  }
};

TEST(TwoLobes, PassesTheBatteryWithTheLobeChosenByAThirdNumber) {
  const TwoLobes bsdf;
  SamplerUnderTest s;
  s.kernel = "two-lobes", s.scalar = "double", s.config = "0.3 diffuse";
  s.uniforms = 3;
  s.sample_u = [&](std::span<const double> u) { return bsdf.sample(u); };
  s.pdf = [&](const Vec3L& w) { return Real(bsdf.pdf(w.cast<double>())); };
  s.bounding_cap = hemisphere(Vec3L(0, 0, 1));
  s.boundary_caps = {Cap<Real>{bsdf.axis.cast<Real>(), 1 - Real(bsdf.cos_max)}};  // the cone's edge
  BatteryOptions options;
  options.samples = 1'000'000;
  const auto results = validate(s, options);
  EXPECT_TRUE(all_passed(results)) << format_table(results);
}
