// fuzz/targets/sphere.h: sphere lights, solid-angle (Shirley 1996 Sec. 3.2.2) and visible-cap area sampling
// (lib/warpcheck/sphere.h). The geometry comes from decode_sphere (common_sphere.h, shared with projected_cap.h
// and sptd.h).
#pragma once

#include "common_sphere.h"

namespace warpcheck::fuzz {

template <class T> void check_sphere(FuzzedDataProvider& in) {
  const SphereLightGeometry<T> g = decode_sphere<T>(in);
  const bool finite_input = all_finite(g.light.center) && all_finite(g.shading.position) &&
                            all_finite(g.shading.normal) && std::isfinite(g.light.radius);
  const SphereReference ref = sphere_reference(g);
  const L kappa = ref.kappa, r_ref = ref.r, tol = ref.tol;
  const SphereView<T> view = make_sphere_view(g);
  const int samples = in.ConsumeIntegralInRange<int>(1, 3);
  for (int k = 0; k < samples; ++k) {
    const Vec2<T> u = unit_square<T>(in);
    for (int kernel = 0; kernel < 2; ++kernel) {
      const char* name = kernel == 0 ? "sphere_solid_angle" : "sphere_visible_area";
      const DirectionSample<T> s = kernel == 0 ? sample_sphere_solid_angle(g, u) : sample_sphere_visible_area(g, u);
      const std::string geo = describe(g, u, name);
      check_sample_shape(s, geo);
      if (!finite_input) WARPCHECK_FUZZ_REQUIRE(!s.valid(), "a sample from non-finite input", geo);
      if (!s.valid()) continue;
      WARPCHECK_FUZZ_REQUIRE(view.valid(), "a sample although the view is invalid", geo);
      L d, miss;
      const L margin = sphere_margin(g, s.direction, &d, &miss);
      WARPCHECK_FUZZ_REQUIRE(
          margin >= -tol, "direction outside the sphere",
          geo << "direction " << show(s.direction) << " margin " << margin << " tol " << tol << "\n");
      if (kernel == 0) {
        // Same view, same formula: the constant density must agree to rounding.
        check_pdf_consistency<T>(s.pdf, pdf_sphere_solid_angle(g, s.direction), 4 * eps<T>(), margin, tol, geo);
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
        check_pdf_consistency<T>(s.pdf, pdf_sphere_visible_area(g, s.direction), rel, margin, tol, geo);
      }
    }
  }
  // The densities at an arbitrary direction: finite, >= 0, zero outside the light and for invalid geometry.
  // Directions are unit vectors (the pdf's contract), so the decoded vector is normalised in T first.
  // Near the direction to the centre; an invalid view's frame is not set, and then near the z axis.
  const Vec3<T> axis = view.valid() ? view.frame.z : Vec3<T>(T(0), T(0), T(1));
  const Vec3<T> w = safe_normalized(in.ConsumeBool() ? vec3<T>(in) : near(in, axis));
  const T p0 = pdf_sphere_solid_angle(g, w), p1 = pdf_sphere_visible_area(g, w);
  const std::string geo = describe(g, Vec2<T>(Vec2<T>::Zero()), "sphere pdf") + "w " + show(w) + "\n";
  WARPCHECK_FUZZ_REQUIRE(std::isfinite(p0) && p0 >= T(0) && std::isfinite(p1) && p1 >= T(0), "pdf not finite and >= 0",
                         geo << "pdfs " << p0 << " " << p1 << "\n");
  if (!view.valid()) WARPCHECK_FUZZ_REQUIRE(p0 == T(0) && p1 == T(0), "pdf > 0 for invalid geometry", geo);
  const L wn = w.template cast<L>().norm();
  if (view.valid() && wn > 0 && std::isfinite(wn)) {
    L d, miss;
    const L margin = sphere_margin(g, w, &d, &miss);
    if (margin < -tol)
      WARPCHECK_FUZZ_REQUIRE(p0 == T(0) && p1 == T(0), "pdf > 0 outside the sphere",
                             geo << "margin " << margin << " tol " << tol << " pdfs " << p0 << " " << p1 << "\n");
  }
}

}  // namespace warpcheck::fuzz
