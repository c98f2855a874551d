// fuzz/checks/sphere.h: sphere lights. The decoder and the inside-the-light reference, shared with the projected
// cap's and the SPTD's checks (projected_cap.h; sptd.h's joint phase-function / sphere-light sampling), and the
// checks of the solid-angle (Shirley 1996 Sec. 3.2.2) and visible-cap area samplers (lib/warpcheck/sphere.h).
// Degeneracies of decode_sphere: shading point on or just off the surface, very far away (d / r up to 2^120),
// radius zero / negative / subnormal, normal perpendicular to the direction to the centre or putting the cone
// exactly tangent to the horizon, NaN / Inf anywhere.
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

enum class SphereKernel { kSolidAngle, kVisibleArea };

// One input, one kernel: its samples (direction inside the sphere, pdf(direction) consistent with the sample's
// pdf) and its density at an arbitrary unit direction (finite, >= 0, zero outside the light and for invalid
// geometry; the decoded vector is normalised in T first, the pdf's contract).
template <class T> void check_sphere(FuzzedDataProvider& in, SphereKernel kernel) {
  const bool solid_angle = kernel == SphereKernel::kSolidAngle;
  const char* name = solid_angle ? SphereSolidAngle<T>::name : SphereVisibleArea<T>::name;
  const SphereLightGeometry<T> g = decode_sphere<T>(in);
  const bool finite_input = all_finite(g.light.center) && all_finite(g.shading.position) &&
                            all_finite(g.shading.normal) && std::isfinite(g.light.radius);
  const SphereReference ref = sphere_reference(g);
  const L kappa = ref.kappa, r_ref = ref.r, tol = ref.tol;
  const SphereView<T> view = make_sphere_view(g);
  auto pdf = [&](const Vec3<T>& w) {
    return solid_angle ? pdf_sphere_solid_angle(g, w) : pdf_sphere_visible_area(g, w);
  };
  const int samples = in.ConsumeIntegralInRange<int>(1, 3);
  for (int k = 0; k < samples; ++k) {
    const Vec2<T> u = unit_square<T>(in);
    const DirectionSample<T> s = solid_angle ? sample_sphere_solid_angle(g, u) : sample_sphere_visible_area(g, u);
    const std::string geo = describe(g, u, name);
    check_sample_shape(s, geo);
    if (!finite_input) WARPCHECK_FUZZ_REQUIRE(!s.valid(), "a sample from non-finite input", geo);
    if (!s.valid()) continue;
    WARPCHECK_FUZZ_REQUIRE(view.valid(), "a sample although the view is invalid", geo);
    L d, miss;
    const L margin = sphere_margin(g, s.direction, &d, &miss);
    WARPCHECK_FUZZ_REQUIRE(margin >= -tol, "direction outside the sphere",
                           geo << "direction " << show(s.direction) << " margin " << margin << " tol " << tol << "\n");
    if (solid_angle) {
      // Same view, same formula: the constant density must agree to rounding.
      check_pdf_consistency<T>(s.pdf, pdf(s.direction), 4 * eps<T>(), margin, tol, geo);
    } else {
      // pdf = dist^2 / (cos_light 2 pi r^2 (1 - r/d)) with cos_light = sqrt(1 - q^2), q = (d/r) sin(theta).
      // An angular error delta moves cos_light by (d/r) delta / cos_light relative to itself; the error
      // delta_d = eps_T kappa d of d moves (1 - r/d) and dist (>= d - r) by at most delta_d / (d - r)
      // relative. Hence rel = 3 tol (1 + (d/r) / cos_l^2) + 3 kTolUlps eps_T kappa d / (d - r).
      const L q = std::min(L(1), miss / r_ref);
      const L cos_l2 = (1 - q) * (1 + q);
      const L rel = cos_l2 > 0 && d > r_ref
                        ? 3 * tol * (1 + (d / r_ref) / cos_l2) + 3 * L(kTolUlps) * eps<T>() * kappa * d / (d - r_ref)
                        : L(1);
      check_pdf_consistency<T>(s.pdf, pdf(s.direction), rel, margin, tol, geo);
    }
  }
  // Near the direction to the centre; an invalid view's frame is not set, and then near the z axis.
  const Vec3<T> axis = view.valid() ? view.frame.z : Vec3<T>(T(0), T(0), T(1));
  const Vec3<T> w = safe_normalized(in.ConsumeBool() ? vec3<T>(in) : near(in, axis));
  const T p = pdf(w);
  const std::string geo = describe(g, Vec2<T>(Vec2<T>::Zero()), name) + "pdf at w " + show(w) + "\n";
  WARPCHECK_FUZZ_REQUIRE(std::isfinite(p) && p >= T(0), "pdf not finite and >= 0", geo << "pdf " << p << "\n");
  if (!view.valid()) WARPCHECK_FUZZ_REQUIRE(p == T(0), "pdf > 0 for invalid geometry", geo);
  const L wn = w.template cast<L>().norm();
  if (view.valid() && wn > 0 && std::isfinite(wn)) {
    L d, miss;
    const L margin = sphere_margin(g, w, &d, &miss);
    if (margin < -tol)
      WARPCHECK_FUZZ_REQUIRE(p == T(0), "pdf > 0 outside the sphere",
                             geo << "margin " << margin << " tol " << tol << " pdf " << p << "\n");
  }
}

}  // namespace warpcheck::fuzz
