// Deliberately broken samplers; see negative_controls.h.
#include "warpcheck/validation/negative_controls.h"

#include <cmath>

#include "warpcheck/sphere.h"
#include "warpcheck/validation/battery.h"

namespace warpcheck::validation {
namespace {

// The "near" geometry of sphere.cpp.
SphereView<double> near_view() {
  const SphereLightGeometry<double> g{ShadingPoint<double>{Vec3<double>(0, 0, 0), Vec3<double>(0.2, -0.1, 1)},
                                      SphereLight<double>{Vec3<double>(0.3, 0.2, 1.6), 1.0}};
  return make_sphere_view(g);
}

// The correct sampler, with a hook that rewrites (u0, u1) -> t before the cone warp, and a pdf factor of t.
SamplerUnderTest control(const char* name, std::function<double(double, double)> t_of_u,
                         std::function<Real(Real)> pdf_factor) {
  const SphereView<double> v = near_view();
  SamplerUnderTest s;
  s.kernel = std::string("negative-control:") + name;
  s.scalar = "double";
  s.config = "near";
  s.bounding_cap = Cap<Real>{to_long(v.frame.z), Real(v.one_minus_cos_max)};
  const Cap<Real> cap = s.bounding_cap;
  s.sample = [v, t_of_u, pdf_factor, cap](double u0, double u1) {
    const double t = t_of_u(u0, u1);
    Sample x;
    if (t > 1) {  // outside the light: build the direction in the cap's own coordinates
      x.direction = cap_direction(cap, Real(t), kTwoPi<Real> * Real(u1));
      x.pdf = Real(sphere_solid_angle_density(v));
      x.valid = true;
      return x;
    }
    x = to_sample(sample_sphere_solid_angle(v, Vec2<double>(t, u1)));
    x.pdf *= pdf_factor(Real(t));
    return x;
  };
  s.pdf = [v, pdf_factor, cap](const Vec3L& w) {
    const Real p = Real(pdf_sphere_solid_angle(v, Vec3<double>(w.cast<double>())));
    if (p == 0) return p;
    Real t, phi;
    cap_coordinates(cap, w, t, phi);
    return p * pdf_factor(std::min<Real>(t, 1));
  };
  return s;
}

Real one(Real) { return 1; }

}  // namespace

std::vector<SamplerUnderTest> negative_controls() {
  std::vector<SamplerUnderTest> out;
  // Inverse CDF of the density 1.01 on [0, 0.1] and (1 - 0.001 / 0.9) on (0.1, 1].
  out.push_back(control(
      "pdf-1pct-high-on-tenth",
      [](double u0, double) { return u0 < 0.101 ? u0 / 1.01 : 0.1 + (u0 - 0.101) * 0.9 / 0.899; }, one));
  out.push_back(control(
      "wrong-cosine", [](double u0, double) { return std::pow(u0, 1.005); }, one));
  out.push_back(control(
      "outside-now-and-then",
      [](double u0, double u1) {
        const double f = u1 * 1e7 - std::floor(u1 * 1e7);
        return f < 1e-5 ? 1.05 + 0.15 * u0 : u0;
      },
      one));
  out.push_back(control(
      "pdf-disagrees-with-warp", [](double u0, double) { return u0; },
      [](Real t) { return 1 + Real(0.02) * (t - Real(0.5)); }));
  out.push_back(control(
      "pdf-1pct-low-everywhere", [](double u0, double) { return u0; }, [](Real) { return Real(0.99); }));
  return out;
}

Registry negative_control_registry() {
  Registry r;
  for (const SamplerUnderTest& s : negative_controls())
    r.add(Case{s.kernel, s.scalar, s.config, "deliberately broken sampler (must fail)", [s] { return s; }, {}, {}});
  return r;
}

}  // namespace warpcheck::validation
