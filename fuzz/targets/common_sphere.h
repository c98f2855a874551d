// fuzz/targets/common_sphere.h: decoding and the inside-the-light reference shared by the families whose light
// is a sphere (sphere.h, projected_cap.h, sptd.h's joint phase-function / sphere-light sampling). Not a family
// (files named common*.h are helpers). Degeneracies of decode_sphere: shading point on or just off the surface,
// very far away (d / r up to 2^120), radius zero / negative / subnormal, normal perpendicular to the direction
// to the centre or putting the cone exactly tangent to the horizon, NaN / Inf anywhere.
#pragma once

#include "common.h"
#include "warpcheck/sphere.h"

namespace warpcheck::fuzz {

template <class T> SphereLightGeometry<T> decode_sphere(FuzzedDataProvider& in) {
  SphereLightGeometry<T> g;
  const T scale = scalar<T>(in);
  const T s = std::isfinite(scale) && scale != T(0) ? std::abs(scale) : T(1);
  g.light.center = vec3<T>(in, s);
  g.light.radius = in.ConsumeBool() ? std::abs(scalar<T>(in, s)) : scalar<T>(in, s);
  const T r = g.light.radius;
  const Vec3<T> dir = safe_normalized(vec3<T>(in));
  const Vec3<T> unit_dir = dir.isZero() ? Vec3<T>(T(0), T(0), T(1)) : dir;
  switch (in.ConsumeIntegralInRange<int>(0, 4)) {
    case 0:
      g.shading.position = vec3<T>(in, s);
      break;
    case 1:
      g.shading.position = g.light.center + unit_dir * (r * (T(1) + tiny<T>(in, T(1))));
      break;  // on the surface
    case 2:
      g.shading.position = g.light.center + unit_dir * (r * std::ldexp(T(1), in.ConsumeIntegralInRange<int>(0, 120)));
      break;
    default:
      g.shading.position = g.light.center + vec3<T>(in, std::isfinite(r) && r != T(0) ? std::abs(r) : T(1));
      break;
  }
  const Vec3<T> to_c = g.light.center - g.shading.position;
  switch (in.ConsumeIntegralInRange<int>(0, 4)) {
    case 0:
      g.shading.normal = vec3<T>(in);
      break;
    case 1:
      g.shading.normal = perpendicular(in, to_c);
      break;
    case 2: {  // the cone exactly tangent to the horizon (from above or below): n.axis = -+ sin(theta_max)
      const T d = to_c.norm();
      const T sn = d > T(0) ? r / d : T(0);
      const T sign = in.ConsumeBool() ? T(1) : T(-1);
      g.shading.normal =
          safe_normalized(to_c) * (sign * sn) + perpendicular(in, to_c) * std::sqrt(std::max(T(0), T(1) - sn * sn));
      break;
    }
    default: {
      const T along = scalar<T>(in);
      g.shading.normal = near(in, Vec3<T>(to_c * along));
      break;
    }
  }
  return g;
}

template <class T> std::string describe(const SphereLightGeometry<T>& g, const Vec2<T>& u, const char* kernel) {
  std::ostringstream os;
  os.precision(std::numeric_limits<T>::max_digits10);
  os << kernel << " <" << (sizeof(T) == 4 ? "float" : "double") << ">: center " << show(g.light.center) << " radius "
     << g.light.radius << " x " << show(g.shading.position) << " n " << show(g.shading.normal) << " u (" << u[0] << ", "
     << u[1] << ")\n";
  return os.str();
}

// Reference: the ray's miss distance from the centre over d (the angular margin, > 0 inside) in long double.
template <class T> L sphere_margin(const SphereLightGeometry<T>& g, const Vec3<T>& w, L* d_out, L* miss_out) {
  const Vec3<L> to_c = g.light.center.template cast<L>() - g.shading.position.template cast<L>();
  const Vec3<L> wl = w.template cast<L>().normalized();
  const L d = to_c.norm(), r = L(g.light.radius);
  const L miss = to_c.cross(wl).norm();
  *d_out = d, *miss_out = miss;
  if (to_c.dot(wl) <= 0) return -1;  // pointing away: outside by a right angle or more
  return (r - miss) / d;
}

// The cone's reference numbers in long double from the exact inputs, and its angular tolerance (common.h's
// header): the kernels know d only to delta_d = eps_T kappa d. That moves the cone's boundary
// theta_max = asin(r/d) by (r/d)(delta_d/d) / cos(theta_max) <= eps_T kappa / cos(theta_max): unbounded for a
// point on the surface. Hence tol = kTolUlps eps_T kappa (1 + 1 / cos(theta_max)).
struct SphereReference {
  L kappa, d, r, cos_max, tol;
};
// subnormal_ulps: kappa_of's.
template <class T>
SphereReference sphere_reference(const SphereLightGeometry<T>& g, L subnormal_ulps = kSubnormalUlps) {
  SphereReference s;
  const Vec3<T> c = g.light.center;
  s.kappa = kappa_of<T>(&c, 1, g.shading.position, subnormal_ulps);
  s.d = (c.template cast<L>() - g.shading.position.template cast<L>()).norm(), s.r = L(g.light.radius);
  s.cos_max = s.d > s.r && s.r > 0 ? std::sqrt((s.d - s.r) * (s.d + s.r)) / s.d : L(0);
  s.tol = L(kTolUlps) * eps<T>() * s.kappa * (1 + (s.cos_max > 0 ? 1 / s.cos_max : L(0)));
  return s;
}

}  // namespace warpcheck::fuzz
