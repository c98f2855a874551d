// fuzz/targets/projected_cap.h: sphere lights sampled by projected solid angle, Peters & Dachsbacher 2019
// (lib/warpcheck/projected_cap.h), with the paper's quintic (Alg. 5, CutDiskInverse::kQuintic) and with the exact
// inverse of the cut-disk area (kExact). The geometry comes from decode_sphere (common_sphere.h), whose normal is
// then re-aimed, leaning to the cases' boundaries (Sec. 3.2, h = n.w_d, r_y = sin(theta_max)): the cap tangent to
// the horizon from above (h = r_y, Case 1/2) or below (h = -r_y: Case 3 slivers and Case 4), the centre on the
// horizon (h = 0, Case 2/3), any depth in Cases 2-3, an overhead light (w_d = n up to a tiny offset).
//
// Invariants beyond common.h's (shape, non-finite input):
//  - a sample lies above the horizon (it is a lifted point of the projected disk) and inside the light's cap, for
//    the quintic as for the exact inverse: the quintic's piece ranges end at the cuts, so its pieces tile the
//    projected cap (projected_cap_bounding_cap is the light's cap widened by 64 eps_T for rounding, header of
//    lib/warpcheck/projected_cap.h); the cap is computed here in long double from the exact inputs;
//  - the sample's pdf agrees with pdf(direction) (check_pdf_consistency_probed: the warp's pieces and the
//    quintic's fold make the density piecewise smooth);
//  - Cases 1-2: the view's normaliser A_E + A_D equals the cap's projected solid angle (common_cap.h's quadrature,
//    no part of the paper's path), so a density off by a constant factor cannot hide in both sample and pdf;
//  - pdf at an arbitrary direction: finite, >= 0, 0 for invalid geometry, below the horizon and outside the
//    cap by more than tol.
#pragma once

#include "common_cap.h"
#include "common_sphere.h"
#include "warpcheck/projected_cap.h"

namespace warpcheck::fuzz {

template <class T> SphereLightGeometry<T> decode_projected_cap(FuzzedDataProvider& in) {
  SphereLightGeometry<T> g = decode_sphere<T>(in);
  const Vec3<T> to_c = g.light.center - g.shading.position;
  const Vec3<T> wd = safe_normalized(to_c);
  const int mode = in.ConsumeIntegralInRange<int>(0, 6);
  if (mode == 0 || wd.isZero()) return g;  // decode_sphere's normal
  const Vec3<T> side = perpendicular(in, wd);
  if (mode == 5) {  // overhead, up to a tiny offset: w_dx ~ 0 (the frame's x axis is undetermined)
    g.shading.normal = wd + side * tiny<T>(in, T(1));
    return g;
  }
  const T d = to_c.norm();
  const T ry = std::isfinite(d) && d > T(0) ? std::abs(g.light.radius) / d : T(0);
  T h = 0;
  switch (mode) {
    case 1:
      h = ry * (T(1) + tiny<T>(in, T(1)));
      break;  // tangent from above, just off (Case 1/2)
    case 2:
      h = -ry * (T(1) + tiny<T>(in, T(1)));
      break;  // tangent from below: Case 3 slivers, Case 4
    case 3:
      h = tiny<T>(in, T(1));
      break;  // centre on the horizon, just off (Case 2/3)
    case 4:
      h = ry * (T(2) * unit_random<T>(in) - T(1));
      break;  // Cases 2-3 at any depth
    default:
      h = T(2) * unit_random<T>(in) - T(1);
      break;  // any elevation
  }
  if (!std::isfinite(h)) return g;
  h = std::clamp(h, T(-1), T(1));
  g.shading.normal = wd * h + side * std::sqrt(std::max(T(0), (T(1) - h) * (T(1) + h)));
  return g;
}

// The reference geometry of the cap in long double from the exact inputs: unit normal, unit direction to the
// centre and theta_max.
struct ProjectedCapReference {
  bool defined = false;  // d > r > 0 and a normal of nonzero length
  Vec3<L> n = Vec3<L>::Zero(), wd = Vec3<L>::Zero();
  L theta_max = 0, t = 0;  // t: angle between n and w_d
};
template <class T> ProjectedCapReference projected_cap_reference(const SphereLightGeometry<T>& g) {
  ProjectedCapReference r;
  const Vec3<L> nl = g.shading.normal.template cast<L>(),
                to_c = g.light.center.template cast<L>() - g.shading.position.template cast<L>();
  const L d = to_c.norm(), rad = L(g.light.radius), nn = nl.norm();
  if (!(d > rad && rad > 0 && nn > 0 && std::isfinite(d) && std::isfinite(nn))) return r;
  r.defined = true;
  r.n = nl / nn, r.wd = to_c / d;
  r.theta_max = std::atan2(rad, std::sqrt((d - rad) * (d + rad)));
  r.t = angle_between(r.n, r.wd);
  return r;
}

template <class T, CutDiskInverse M>
void check_projected_cap_kernel(FuzzedDataProvider& in, const SphereLightGeometry<T>& g,
                                const ProjectedCapView<T>& view, const ProjectedCapReference& ref,
                                const SphereReference& sref, bool finite_input, const Mutation& mutate) {
  const bool quintic = M == CutDiskInverse::kQuintic;
  const char* name = quintic ? "projected_cap_quintic" : "projected_cap_exact";
  // Margins of a direction (> 0 inside): against the light's cap (the samples' and the support's boundary, for
  // both inverses) and the height above the horizon.
  struct Margins {
    L light, height;
  };
  auto margins = [&](const Vec3<T>& w) {
    const Vec3<L> wl = w.template cast<L>().normalized();
    const L angle = angle_between(ref.wd, wl);
    return Margins{ref.theta_max - angle, ref.n.dot(wl)};
  };
  // Tolerance of the cap margin: the cone's own (sphere_reference: input rounding of d and of the direction to
  // the centre) plus the conditioning of the paper's parameterisation. A sample is a point (w_x, w_y) of the
  // projected disk (Alg. 1), computed in T with absolute errors of a few eps (|w_x|, |w_y| <= 1; |c_x|, |r_x| <= 1),
  // lifted to w_z = sqrt(1 - w_x^2 - w_y^2) (Case 3's lune lifts w_x from w_y and w_z instead). An error
  // e <= 11 eps of w_x^2 + w_y^2 moves the lifted component by e / (2 w_z), and by at most sqrt(e) at the rim:
  // an angular error that does not shrink with the light, along the meridian, which crosses the cap's boundary
  // wherever that meets the horizon at an angle. With the house's kTolUlps: kTolUlps eps / max(l, sqrt(kTolUlps eps)),
  // l the lifted component of the sample (long double, exact frame).
  const L e = L(kTolUlps) * eps<T>();
  // The kernel's local frame in long double (Alg. 1: z = n, x = the horizontal direction to the centre).
  const Vec3<L> frame_x = [&] {
    const Vec3<L> h = ref.wd - ref.n.dot(ref.wd) * ref.n;
    return h.norm() > 0 ? Vec3<L>(h.normalized()) : Frame<L>::from_z(ref.n).x;
  }();
  auto to_local_l = [&](const Vec3<T>& w) {
    const Vec3<L> v = w.template cast<L>().normalized();
    return Vec3<L>(v.dot(frame_x), v.dot(ref.n.cross(frame_x)), v.dot(ref.n));
  };
  auto lift_tol = [&](const Vec3<T>& w) {
    const Vec3<L> wl = w.template cast<L>().normalized();
    L lifted = ref.n.dot(wl);
    if (view.which_case == 3) {
      const Vec3<L> horizontal = ref.wd - ref.n.dot(ref.wd) * ref.n;
      const L hn = horizontal.norm();
      if (hn > 0) lifted = std::min(lifted, std::abs(horizontal.dot(wl)) / hn);
    }
    return e / std::max(std::abs(lifted), std::sqrt(e));
  };
  const int samples = in.ConsumeIntegralInRange<int>(1, 3);
  for (int k = 0; k < samples; ++k) {
    const Vec2<T> u = unit_square<T>(in);
    const DirectionSample<T> s = mutate.sample(sample_projected_spherical_cap<T, M>(view, u));
    const std::string geo = describe(g, u, name) + "case " + std::to_string(view.which_case) + "\n";
    check_sample_shape(s, geo);
    if (!finite_input) WARPCHECK_FUZZ_REQUIRE(!s.valid(), "a sample from non-finite input", geo);
    if (!s.valid()) continue;
    WARPCHECK_FUZZ_REQUIRE(view.valid(), "a sample although the view is invalid", geo);
    if (!ref.defined) continue;  // x inside the light in long double but not in T: no reference cap
    const Margins m = margins(s.direction);
    WARPCHECK_FUZZ_REQUIRE(m.height >= -e, "direction below the horizon",
                           geo << "direction " << show(s.direction) << " n.w " << m.height << "\n");
    const L tol = sref.tol + lift_tol(s.direction);
    WARPCHECK_FUZZ_REQUIRE(m.light >= -tol, "direction outside the cap",
                           geo << "direction " << show(s.direction) << " margin " << m.light << " tol " << tol
                               << " theta_max " << ref.theta_max << "\n");
    // The probe radius: how far from the sampler's point the density is evaluated. (1) The sample is the lift of
    // a disk point, off by lift_tol. (2) pdf() reads the direction's local coordinates (round trip world -> local:
    // a few eps) and inverts the pieces from them (w_x, w_y for the ellipse and the disk, w_y, w_z for Case 3's
    // lune); an absolute error eps in the coordinate w_c is the error of a direction moved by eps / sqrt(1 - w_c^2)
    // (near the axis of that coordinate, w_c is insensitive to direction and its rounding is what counts: a thin
    // ellipse near the rim reads d_x = (w_x - c_x) / r_x off w_x ~ 1). Hence radius = lift_tol + kTolUlps eps
    // (1 + max_c 1 / max(sqrt(1 - w_c^2), sqrt(kTolUlps eps))) over the coordinates read.
    const Vec3<L> wl = to_local_l(s.direction);
    L coordinate = 0;
    for (int c = view.which_case == 3 ? 1 : 0; c < (view.which_case == 3 ? 3 : 2); ++c)
      coordinate =
          std::max(coordinate, 1 / std::max(std::sqrt(std::max(L(0), (1 - wl[c]) * (1 + wl[c]))), std::sqrt(e)));
    const L radius = lift_tol(s.direction) + e * (1 + coordinate);
    check_pdf_consistency_probed<T>(
        s.pdf, s.direction, [&](const Vec3<T>& w) { return mutate.pdf(pdf_projected_spherical_cap<T, M>(view, w)); },
        radius, 16 * eps<T>(), std::min(m.light, m.height), tol, geo);
  }
  // The density at an arbitrary unit direction.
  // Near the direction to the centre; an invalid view's frame is not set, and then near the z axis.
  const Vec3<T> axis = view.valid() ? view.sphere.frame.z : Vec3<T>(T(0), T(0), T(1));
  const Vec3<T> w = safe_normalized(in.ConsumeBool() ? vec3<T>(in) : near(in, axis));
  const T p = mutate.pdf(pdf_projected_spherical_cap<T, M>(view, w));
  const std::string geo = describe(g, Vec2<T>(Vec2<T>::Zero()), name) + "pdf at w " + show(w) + "\n";
  WARPCHECK_FUZZ_REQUIRE(std::isfinite(p) && p >= T(0), "pdf not finite and >= 0", geo << "pdf " << p << "\n");
  if (!view.valid()) WARPCHECK_FUZZ_REQUIRE(p == T(0), "pdf > 0 for invalid geometry", geo << "pdf " << p << "\n");
  if (view.valid() && ref.defined && !w.isZero()) {
    const Margins m = margins(w);
    const L tol = sref.tol + lift_tol(w);
    if (m.light < -tol || m.height < -e)
      WARPCHECK_FUZZ_REQUIRE(
          p == T(0), "pdf > 0 outside the cap or below the horizon",
          geo << "pdf " << p << " margin " << m.light << " tol " << tol << " n.w " << m.height << "\n");
  }
}

template <class T> void check_projected_cap(FuzzedDataProvider& in, const Mutation& mutate = {}) {
  const SphereLightGeometry<T> g = decode_projected_cap<T>(in);
  const bool finite_input = all_finite(g.light.center) && all_finite(g.shading.position) &&
                            all_finite(g.shading.normal) && std::isfinite(g.light.radius);
  const ProjectedCapView<T> view = make_projected_cap_view(g);
  const ProjectedCapReference ref = projected_cap_reference(g);
  // kappa without common.h's subnormal allowance (kSubnormalUlps min_T per coordinate, for kernels whose
  // intermediates are subnormal when the coordinates are): the kernel's only arithmetic on the coordinates is
  // d = c - x, whose rounding is at most eps_T |c - x| / 2 per component (exact where the difference is subnormal:
  // it is a multiple of denorm_min below 2 min_T), covered by kappa's (|c|_inf + |x|_inf) / d >= 1; then it scales d
  // and r by an exact power of two to |d|_inf in [1/2, 1) (unit_scale_geometry, lib/warpcheck/projected_cap.h), so
  // every later intermediate is of unit scale. With the allowance a light at 1e-323 had tol ~ 700 rad: the cap
  // check could not fail there (issue 7, 07252d59).
  const SphereReference sref = sphere_reference(g, L(0));
  // Cases 1-2: the normaliser is the projected solid angle P(t, theta_max) of the cap. Its conditioning: the
  // kernel knows theta_max to d theta = tan(theta_max) eps kappa (d's relative rounding, sphere_reference) and
  // the angle t to delta t = eps kappa (the direction to the centre). dP/dtheta_max = sin(theta_max) I(theta_max)
  // (the ring integrand at the boundary, common_cap.h) and |dP/dt| <= the cap's solid angle 2 pi (1 - cos)
  // (rotating the cap by dt changes n.w by at most dt on it). Hence, with the house's kTolUlps and the
  // quadrature's own error estimate,
  //   rel = kTolUlps eps kappa (tan(theta) sin(theta) I(theta) + 2 pi (1 - cos theta)) / P + 16 eps + 16 err / P.
  if (view.valid() && ref.defined && view.which_case <= 2) {
    const Quadrature q = reference_cap_projected_solid_angle(ref.t, ref.theta_max);
    const L th = ref.theta_max;
    const L sens =
        std::tan(th) * std::sin(th) * ring_cosine_integral(th, ref.t) + kTwoPi<L> * 2 * std::pow(std::sin(th / 2), 2);
    const L rel =
        q.value > 0 ? (L(kTolUlps) * eps<T>() * sref.kappa * sens + 16 * q.error) / q.value + 16 * eps<T>() : L(1);
    const std::string geo =
        describe(g, Vec2<T>(Vec2<T>::Zero()), "projected_cap view") + "case " + std::to_string(view.which_case) + "\n";
    const L total = L(mutate.normaliser(view.total));
    if (rel < L(0.5))
      WARPCHECK_FUZZ_REQUIRE(std::abs(total / q.value - 1) <= rel, "A_E + A_D differs from the projected solid angle",
                             geo << "A_E + A_D " << total << " reference " << q.value << " (quadrature error "
                                 << q.error << ") ratio - 1 " << (total / q.value - 1) << " allowed " << rel << "\n");
  }
  check_projected_cap_kernel<T, CutDiskInverse::kQuintic>(in, g, view, ref, sref, finite_input, mutate);
  check_projected_cap_kernel<T, CutDiskInverse::kExact>(in, g, view, ref, sref, finite_input, mutate);
}

}  // namespace warpcheck::fuzz
