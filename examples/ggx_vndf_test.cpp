// A BSDF sampler with a weight and an eval: GGX reflection by sampling the visible normals (Heitz 2018, "Sampling
// the GGX Distribution of Visible Normals", listing 1), roughness 0.5, seen from 1 rad off the normal. Reflected
// directions reach below the horizon (where f, and so the weight, is zero): the grid's domain is the whole sphere,
// and the pdf drops to zero on the small circle wi.z = -wo.z, where the half vector meets the horizon.
#include <gtest/gtest.h>
#include <algorithm>
#include <cmath>
#include "warpcheck/validation/battery.h"
using namespace warpcheck::validation;
using V = Vec3<double>;

struct GgxVndf {
  double a = 0.5;
  V wo = V(std::sin(1.0), 0, std::cos(1.0));
  double lambda(const V& w) const { return (std::sqrt(1 + a * a * (1 / (w.z() * w.z()) - 1)) - 1) / 2; }
  double d(const V& h) const {
    const double t = (h.x() * h.x() + h.y() * h.y()) / (a * a) + h.z() * h.z();
    return 1 / (kPi<double> * a * a * t * t);
  }
  V half(const V& wi) const { return (wo + wi).normalized(); }
  double pdf(const V& wi) const { return half(wi).z() > 0 ? d(half(wi)) / (4 * wo.z() * (1 + lambda(wo))) : 0; }
  double eval(const V& wi) const {  // f cos: D G2 / (4 wo.z), G2 height-correlated Smith
    return wi.z() > 0 ? d(half(wi)) / (4 * wo.z() * (1 + lambda(wo) + lambda(wi))) : 0;
  }
  Sample sample(double u0, double u1) const {
    const V v = V(a * wo.x(), a * wo.y(), wo.z()).normalized();
    const V t1 = v.z() < 1 ? V(-v.y(), v.x(), 0).normalized() : V(1, 0, 0), t2 = v.cross(t1);
    const double r = std::sqrt(u0), phi = 2 * kPi<double> * u1, s = (1 + v.z()) / 2;
    const double p1 = r * std::cos(phi), p2 = (1 - s) * std::sqrt(1 - p1 * p1) + s * r * std::sin(phi);
    const V n = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1 - p1 * p1 - p2 * p2)) * v;
    const V h = V(a * n.x(), a * n.y(), std::max(0.0, n.z())).normalized(), wi = 2 * wo.dot(h) * h - wo;
    const double weight = wi.z() > 0 ? (1 + lambda(wo)) / (1 + lambda(wo) + lambda(wi)) : 0;  // G2 / G1
    return {wi.cast<Real>(), pdf(wi), true, weight};
  }
};

TEST(GgxVndf, PassesTheBatteryWithItsWeightEqualToEvalOverPdf) {
  const GgxVndf bsdf;
  SamplerUnderTest s;
  s.kernel = "ggx-vndf", s.scalar = "double", s.config = "alpha 0.5, 1 rad";
  s.sample = [&](double u0, double u1) { return bsdf.sample(u0, u1); };
  s.pdf = [&](const Vec3L& w) { return Real(bsdf.pdf(w.cast<double>())); };
  s.eval = [&](const Vec3L& w) { return Real(bsdf.eval(w.cast<double>())); };
  s.bounding_cap = whole_sphere();
  s.boundary_caps = {Cap<Real>{Vec3L(0, 0, 1), 1 + Real(bsdf.wo.z())}};  // the pdf's jump to zero
  BatteryOptions options;
  options.samples = 1'000'000;
  const auto results = validate(s, options);
  EXPECT_TRUE(all_passed(results)) << format_table(results);
}
