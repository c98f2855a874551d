// fuzz/checks/projected_cap.h: sphere lights sampled by projected solid angle, Peters & Dachsbacher 2019
// (lib/warpcheck/projected_cap.h), with the paper's quintic (Alg. 5, CutDiskInverse::kQuintic) and with the exact
// inverse of the cut-disk area (kExact). The geometry comes from decode_sphere (sphere.h), whose normal is
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
//  - Cases 1-2: the view's normaliser A_E + A_D equals the cap's projected solid angle (cap.h's quadrature,
//    no part of the paper's path), so a density off by a constant factor cannot hide in both sample and pdf;
//  - pdf at an arbitrary direction: finite, >= 0, 0 for invalid geometry, below the horizon and outside the
//    cap by more than tol.
#pragma once

#include "cap.h"
#include "sphere.h"
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

// The margins of a direction (> 0 inside): against the light's cap (the samples' and the support's boundary, for
// both inverses) and the height above the horizon; and their tolerances.
struct ProjectedCapMargins {
  L light, height;
};
template <class T> struct ProjectedCapTolerances {
  const ProjectedCapReference& ref;
  int which_case;                     // the view's case (Sec. 3.2)
  L e = 0;                            // kTolUlps eps_T
  Vec3<L> frame_x = Vec3<L>::Zero();  // the kernel's local frame (Alg. 1: z = n, x = the horizontal direction to the
                                      // centre), in long double
  ProjectedCapTolerances(const ProjectedCapReference& r, int c) : ref(r), which_case(c), e(L(kTolUlps) * eps<T>()) {
    const Vec3<L> h = ref.wd - ref.n.dot(ref.wd) * ref.n;
    frame_x = h.norm() > 0 ? Vec3<L>(h.normalized()) : Frame<L>::from_z(ref.n).x;
  }
  ProjectedCapMargins margins(const Vec3<T>& w) const {
    const Vec3<L> wl = w.template cast<L>().normalized();
    return {ref.theta_max - angle_between(ref.wd, wl), ref.n.dot(wl)};
  }
  // The cap margin's tolerance beyond the cone's own (sphere_reference): the conditioning of the paper's
  // parameterisation. A sample is a point (w_x, w_y) of the projected disk (Alg. 1), computed in T with absolute
  // errors of a few eps, lifted to w_z = sqrt(1 - w_x^2 - w_y^2) (Case 3's lune lifts w_x from w_y and w_z). An
  // error e <= 11 eps of w_x^2 + w_y^2 moves the lifted component by e / (2 w_z), and by at most sqrt(e) at the rim:
  // an angular error along the meridian that does not shrink with the light. Hence e / max(l, sqrt(e)), l the
  // lifted component of the sample (long double, exact frame).
  L lift_tol(const Vec3<T>& w) const {
    const Vec3<L> wl = w.template cast<L>().normalized();
    L lifted = ref.n.dot(wl);
    if (which_case == 3) {
      const Vec3<L> horizontal = ref.wd - ref.n.dot(ref.wd) * ref.n;
      const L hn = horizontal.norm();
      if (hn > 0) lifted = std::min(lifted, std::abs(horizontal.dot(wl)) / hn);
    }
    return e / std::max(std::abs(lifted), std::sqrt(e));
  }
  // The probe radius of the pdf comparison: how far from the sampler's point the density is evaluated. (1) The
  // sample is the lift of a disk point, off by lift_tol. (2) pdf() reads the direction's local coordinates (a few
  // eps) and inverts the pieces from them (w_x, w_y for the ellipse and the disk, w_y, w_z for Case 3's lune); an
  // absolute error eps in the coordinate w_c is a direction moved by eps / sqrt(1 - w_c^2). Hence lift_tol + e (1 +
  // max_c 1 / max(sqrt(1 - w_c^2), sqrt(e))) over the coordinates read.
  L probe_radius(const Vec3<T>& w) const {
    const Vec3<L> v = w.template cast<L>().normalized();
    const Vec3<L> wl(v.dot(frame_x), v.dot(ref.n.cross(frame_x)), v.dot(ref.n));
    L coordinate = 0;
    for (int c = which_case == 3 ? 1 : 0; c < (which_case == 3 ? 3 : 2); ++c)
      coordinate =
          std::max(coordinate, 1 / std::max(std::sqrt(std::max(L(0), (1 - wl[c]) * (1 + wl[c]))), std::sqrt(e)));
    return lift_tol(w) + e * (1 + coordinate);
  }
};

// One decoded input: the geometry, the view both inverses share, and the references.
template <class T> struct ProjectedCapCase {
  SphereLightGeometry<T> g;
  bool finite_input = false;
  ProjectedCapView<T> view;
  ProjectedCapReference ref;
  SphereReference sref;
};
template <class T> ProjectedCapCase<T> decode_projected_cap_case(FuzzedDataProvider& in) {
  ProjectedCapCase<T> c;
  c.g = decode_projected_cap<T>(in);
  c.finite_input = all_finite(c.g.light.center) && all_finite(c.g.shading.position) && all_finite(c.g.shading.normal) &&
                   std::isfinite(c.g.light.radius);
  c.view = make_projected_cap_view(c.g);
  c.ref = projected_cap_reference(c.g);
  // kappa without common.h's subnormal allowance: the kernel's only arithmetic on the coordinates is d = c - x,
  // whose rounding is at most eps_T |c - x| / 2 per component (exact where the difference is subnormal), covered by
  // kappa's (|c|_inf + |x|_inf) / d >= 1; then it scales d and r by an exact power of two to |d|_inf in [1/2, 1)
  // (unit_scale_geometry, lib/warpcheck/projected_cap.h), so every later intermediate is of unit scale. With the
  // allowance a light of subnormal size would have a tolerance of radians, and the cap check could not fail there.
  c.sref = sphere_reference(c.g, L(0));
  return c;
}

// Cases 1-2: the view's normaliser A_E + A_D is the projected solid angle P(t, theta_max) of the cap (cap.h's
// quadrature, no part of the paper's path), so a density off by a constant factor cannot hide in both sample and
// pdf. Its conditioning: the kernel knows theta_max to tan(theta_max) eps kappa (d's relative rounding) and the
// angle t to eps kappa (the direction to the centre); dP/dtheta_max = sin(theta_max) I(theta_max) (the ring
// integrand at the boundary) and |dP/dt| <= the cap's solid angle 2 pi (1 - cos) (rotating the cap by dt changes
// n.w by at most dt on it). Hence, with the quadrature's own error estimate,
//   rel = kTolUlps eps kappa (tan(theta) sin(theta) I(theta) + 2 pi (1 - cos theta)) / P + 16 eps + 16 err / P.
template <class K>
void check_projected_cap_normaliser(const ProjectedCapCase<typename K::Scalar>& c, const Mutation& mutate) {
  using T = typename K::Scalar;
  const ProjectedCapView<T>& view = c.view;
  const ProjectedCapReference& ref = c.ref;
  if (!(view.valid() && ref.defined && view.which_case <= 2)) return;
  const Quadrature q = reference_cap_projected_solid_angle(ref.t, ref.theta_max);
  const L th = ref.theta_max;
  const L sens =
      std::tan(th) * std::sin(th) * ring_cosine_integral(th, ref.t) + kTwoPi<L> * 2 * std::pow(std::sin(th / 2), 2);
  const L rel =
      q.value > 0 ? (L(kTolUlps) * eps<T>() * c.sref.kappa * sens + 16 * q.error) / q.value + 16 * eps<T>() : L(1);
  const std::string geo =
      describe(c.g, Vec2<T>(Vec2<T>::Zero()), K::name) + "view, case " + std::to_string(view.which_case) + "\n";
  const L total = L(mutate.normaliser(view.total));
  if (rel < L(0.5))
    WARPCHECK_FUZZ_REQUIRE(std::abs(total / q.value - 1) <= rel, "A_E + A_D differs from the projected solid angle",
                           geo << "A_E + A_D " << total << " reference " << q.value << " (quadrature error " << q.error
                               << ") ratio - 1 " << (total / q.value - 1) << " allowed " << rel << "\n");
}

// The random numbers one inverse's check takes: 1 to 3 points u, and an arbitrary unit direction w (raw, or near
// the direction to the centre; an invalid view's frame is not set, and then near the z axis).
template <class T> struct ProjectedCapDraws {
  int samples = 0;
  Vec2<T> u[3];
  Vec3<T> w;
};
template <class T>
ProjectedCapDraws<T> decode_projected_cap_draws(FuzzedDataProvider& in, const ProjectedCapView<T>& view) {
  ProjectedCapDraws<T> d;
  d.samples = in.ConsumeIntegralInRange<int>(1, 3);
  for (int k = 0; k < d.samples; ++k) d.u[k] = unit_square<T>(in);
  const Vec3<T> axis = view.valid() ? view.sphere.frame.z : Vec3<T>(T(0), T(0), T(1));
  d.w = safe_normalized(in.ConsumeBool() ? vec3<T>(in) : near(in, axis));
  return d;
}

// One inverse's samples and densities (header comment's invariants). The pdf comparison is probed
// (check_pdf_consistency_probed): the warp's pieces and the quintic's fold make the density piecewise smooth.
template <class K> void check_projected_cap_kernel(const ProjectedCapCase<typename K::Scalar>& c,
                                                   const ProjectedCapDraws<typename K::Scalar>& draws,
                                                   const Mutation& mutate) {
  using T = typename K::Scalar;
  const char* name = K::name;
  const ProjectedCapView<T>& view = c.view;
  const ProjectedCapTolerances<T> tols(c.ref, view.which_case);
  const L e = tols.e;
  auto pdf = [&](const Vec3<T>& w) { return mutate.pdf(K::pdf(view, w)); };
  for (int k = 0; k < draws.samples; ++k) {
    const Vec2<T> u = draws.u[k];
    const DirectionSample<T> s = mutate.sample(K::sample(view, u));
    const std::string geo = describe(c.g, u, name) + "case " + std::to_string(view.which_case) + "\n";
    check_sample_shape(s, geo);
    if (!c.finite_input) WARPCHECK_FUZZ_REQUIRE(!s.valid(), "a sample from non-finite input", geo);
    if (!s.valid()) continue;
    WARPCHECK_FUZZ_REQUIRE(view.valid(), "a sample although the view is invalid", geo);
    if (!c.ref.defined) continue;  // x inside the light in long double but not in T: no reference cap
    const ProjectedCapMargins m = tols.margins(s.direction);
    WARPCHECK_FUZZ_REQUIRE(m.height >= -e, "direction below the horizon",
                           geo << "direction " << show(s.direction) << " n.w " << m.height << "\n");
    const L tol = c.sref.tol + tols.lift_tol(s.direction);
    WARPCHECK_FUZZ_REQUIRE(m.light >= -tol, "direction outside the cap",
                           geo << "direction " << show(s.direction) << " margin " << m.light << " tol " << tol
                               << " theta_max " << c.ref.theta_max << "\n");
    check_pdf_consistency_probed<T>(s.pdf, s.direction, pdf, tols.probe_radius(s.direction), 16 * eps<T>(),
                                    std::min(m.light, m.height), tol, geo);
  }
  const Vec3<T> w = draws.w;
  const T p = pdf(w);
  const std::string geo = describe(c.g, Vec2<T>(Vec2<T>::Zero()), name) + "pdf at w " + show(w) + "\n";
  WARPCHECK_FUZZ_REQUIRE(std::isfinite(p) && p >= T(0), "pdf not finite and >= 0", geo << "pdf " << p << "\n");
  if (!view.valid()) WARPCHECK_FUZZ_REQUIRE(p == T(0), "pdf > 0 for invalid geometry", geo << "pdf " << p << "\n");
  if (view.valid() && c.ref.defined && !w.isZero()) {
    const ProjectedCapMargins m = tols.margins(w);
    const L tol = c.sref.tol + tols.lift_tol(w);
    if (m.light < -tol || m.height < -e)
      WARPCHECK_FUZZ_REQUIRE(
          p == T(0), "pdf > 0 outside the cap or below the horizon",
          geo << "pdf " << p << " margin " << m.light << " tol " << tol << " n.w " << m.height << "\n");
  }
}

// The target of one inverse: the view's normaliser, then the inverse's samples and densities. An input holds the
// draws of the quintic, then those of the exact inverse (one target checked both before they were split, and the
// stored inputs decode as they did); each target checks its own.
// K is one of the projected-cap kernel traits; sphere-projected-cap-polar (the quintic's inverse) decodes as the
// quintic's target (its corpus seeded from that one's).
template <class K> void check_projected_cap(FuzzedDataProvider& in, const Mutation& mutate = {}) {
  using T = typename K::Scalar;
  const ProjectedCapCase<T> c = decode_projected_cap_case<T>(in);
  check_projected_cap_normaliser<K>(c, mutate);
  ProjectedCapDraws<T> draws = decode_projected_cap_draws(in, c.view);
  if (K::inverse == CutDiskInverse::kExact) draws = decode_projected_cap_draws(in, c.view);
  check_projected_cap_kernel<K>(c, draws, mutate);
}

}  // namespace warpcheck::fuzz
