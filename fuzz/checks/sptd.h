// fuzz/checks/sptd.h: spherical pivot transformed distributions over a cap, Dupuy, Heitz & Belcour 2017
// (lib/warpcheck/sptd.h): sample the original distribution (uniform, or the clamped cosine) over the image cap
// g(C) and pivot back (Sec. 4.2, Fig. 5). Three ways in, as the header exposes them: a general SPTD over a cap
// (uniform or clamped-cosine base), the pivot phase function over a cap (pivot_phase_geometry, Sec. 6.2, with
// g_p from the paper's fit to Henyey-Greenstein, Eqs. 27-28, or raw), and the joint pivot-phase-function and
// sphere-light sampling (pivot_phase_sphere_light_geometry, Fig. 17: the cap is the light's cone, the sphere from
// sphere.h's decoder). Degeneracies: |r_p| = 1 - 2^-k up to and beyond rounding to 1, raw pivots (|r_p| >= 1:
// no pivot), caps containing the pivot direction, with their boundary through it (tangent), opposite to it, the
// whole sphere and 2 - tiny, tiny caps, 1 - cos <= 0, NaN / Inf anywhere.
// The target of sptd-uniform-cap takes all three ways in, that of sptd-cosine-cap the general cap (decode_sptd).
//
// The kernel's sample pdf IS its pdf(direction) (sample_sptd_cap calls pdf_sptd_cap), so comparing the two would
// be a test that cannot fail. Instead both are compared with an independent long double reference of the
// normalised density, D(w) = D_std(g(w)) (k / |w - r_p|^2)^2 / integral_C D (Eqs. 4, 8, 10):
//  - g by Eq. 2 verbatim (pivot_transform_point; the kernel samples with the anti-inversion form);
//  - the image cap g(C) from the inversion's distance formula (sptd_reference; the kernel uses Eqs. 6-7, a bisector
//    and differences of the images), oriented by points of known side (+-p, +-w_c) tested on C itself;
//  - integral_C D = integral over g(C) of D_std: |g(C)| / 4 pi for the uniform base, and for the clamped cosine the
//    projected solid angle of g(C) over pi by cap.h's quadrature (the kernel: its own closed-form areas).
//
// Invariants beyond common.h's (shape, non-finite input): input the reference finds invalid (no pivot, 1 - cos <= 0,
// zero axes) gives no sample; a sample lies inside C (angular margin, long double); its pdf and pdf at an arbitrary
// direction agree with the reference D; pdf is 0 outside C by more than tol.
//
// Tolerances (derivations). e = kTolUlps eps_T, r = |r_p|, k = 1 - r^2, rho = |w - r_p|.
//  * g in T: g = r_p + (k / rho^2)(r_p - w) with k relative error eps / (1 - r) (from 1 - |r_p|), i.e. an angular
//    error of ~eps (1 + (k / rho)(1 + 1 / (1 - r))) <= eps (1 + 2 / rho) since k / (1 - r) = 1 + r <= 2.
//  * The image cap in T: its boundary points' images are off by eps (1 + 2 / dist) (dist = the distance from r_p
//    to the boundary of C, attained in the plane of w_c and r_p, where the kernel takes its boundary points), and C
//    itself is known to an angle delta_C (e for a decoded cap; the light's cone tolerance, sphere.h, for the
//    joint sampler), which g magnifies by at most k / dist^2 on the boundary (Eq. 4: g stretches lengths at p by
//    k / |p - r_p|^2). delta_img = e (kappa_C k / dist^2 + 1 + 2 / dist), kappa_C = delta_C / e.
//  * The sampler's point w_i in g(C): uniform cap sampling, a few eps; the clamped cosine lifts a point of the
//    projected disk, e / max(z_i, sqrt(e)) as in projected_cap.h (z_i = n.w_i).
//  * The margin of w = g(w_i) in C: g maps image distances near w_i to world distances by m_i = k / |w_i - r_p|^2,
//    tol = m_i (delta_img + e (1 + rim_i)) + e (1 + 2 / |w_i - r_p|).
//  * The density, relative: the Jacobian (k / rho^2)^2 from k (2 eps / (1 - r)) and rho (8 eps / rho); the cosine
//    base's n.g(w) from g's angular error over n.g(w); the normaliser: the uniform one is (1 - cos psi_img) / 2,
//    moved by sin(psi_img) delta_img, the cosine one is the projected area P_img, moved by at most its boundary
//    length 2 pi sin(psi_img) times delta_img (a finer bound: sptd_reference), plus the resolution of the kernel's
//    disk coordinates (e per unit of abscissa, times the region's height); the quadrature's own error estimate. (The
//    reference's own rounding has the same form with eps_L, which is at most eps_double / 2048.)
#pragma once

#include "cap.h"
#include "sphere.h"
#include "warpcheck/sptd.h"

namespace warpcheck::fuzz {

template <class T> Vec3<T> unit_or_z(const Vec3<T>& v) {
  const Vec3<T> u = safe_normalized(v);
  return u.isZero() ? Vec3<T>(T(0), T(0), T(1)) : u;
}

// A pivot, leaning to |r_p| close to 1 (1 - 2^-k up to beyond T's rounding) and to invalid ones.
template <class T> Vec3<T> decode_pivot(FuzzedDataProvider& in) {
  const int digits = std::numeric_limits<T>::digits;
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0:
      return vec3<T>(in);  // raw: often |r_p| >= 1 (no pivot)
    case 1: {
      const Vec3<T> dir = unit_or_z(vec3<T>(in));
      return dir * (T(1) - std::ldexp(T(1), -in.ConsumeIntegralInRange<int>(1, digits + 2)));
    }
    case 2: {
      const Vec3<T> dir = unit_or_z(vec3<T>(in));
      return dir * (T(2) * unit_random<T>(in) - T(1));
    }
    default: {
      const Vec3<T> dir = unit_or_z(vec3<T>(in));
      return dir * scalar<T>(in);
    }
  }
}

// A cap, leaning to the pivot's direction p: containing it, with its boundary through it (tangent), opposite.
template <class T> Cap<T> decode_sptd_cap(FuzzedDataProvider& in, const Vec3<T>& p) {
  Cap<T> c;
  switch (in.ConsumeIntegralInRange<int>(0, 4)) {
    case 0:
      c.one_minus_cos = T(2);
      break;  // the whole sphere
    case 1:
      c.one_minus_cos = std::ldexp(T(1), -in.ConsumeIntegralInRange<int>(1, std::numeric_limits<T>::digits + 40));
      break;
    case 2:
      c.one_minus_cos = T(2) - std::ldexp(T(2), -in.ConsumeIntegralInRange<int>(1, std::numeric_limits<T>::digits + 2));
      break;
    case 3:
      c.one_minus_cos = scalar<T>(in);
      break;  // negative, zero, > 2, NaN, ...
    default:
      c.one_minus_cos = T(2) * unit_random<T>(in);
      break;
  }
  const Vec3<T> pu = unit_or_z(p);
  const T omc = std::clamp(c.one_minus_cos, T(0), T(2));
  const T psi = std::isfinite(omc) ? T(2) * std::asin(std::sqrt(omc / T(2))) : T(0);
  switch (in.ConsumeIntegralInRange<int>(0, 4)) {
    case 0:
      c.axis = vec3<T>(in);
      break;  // raw (possibly zero or unnormalised)
    case 1:
      c.axis = near(in, pu);
      break;   // around the pivot direction
    case 2: {  // the boundary through the pivot direction, just off
      const T a = psi + tiny<T>(in, T(1));
      c.axis = std::cos(a) * pu + std::sin(a) * perpendicular(in, pu);
      break;
    }
    case 3:
      c.axis = near(in, Vec3<T>(-pu));
      break;  // opposite
    default:
      c.axis = unit_or_z(vec3<T>(in));
      break;
  }
  return c;
}

template <class T>
std::string describe(const SptdCapGeometry<T>& g, const Vec2<T>& u, const char* kernel, const char* way) {
  std::ostringstream os;
  os.precision(std::numeric_limits<T>::max_digits10);
  os << kernel << " <" << (sizeof(T) == 4 ? "float" : "double") << ">: " << way << ", pivot " << show(g.sptd.pivot)
     << " base " << (g.sptd.base == SptdBase::kUniform ? "uniform" : "cosine") << " n " << show(g.sptd.base_axis)
     << " cap axis " << show(g.cap.axis) << " 1-cos " << g.cap.one_minus_cos << " u (" << u[0] << ", " << u[1] << ")\n";
  return os.str();
}

// The independent reference (header comment), from the exact inputs in long double.
struct SptdReference {
  bool invalid = false;  // input the kernel must reject: no pivot beyond rounding, 1 - cos <= 0, zero axes, NaN
  bool defined = false;  // a reference exists (valid and not within rounding of invalid)
  bool oriented = true;  // which of the two caps bounded by the image circle is g(C) is decided beyond rounding (else
                         // the densities, whose normaliser depends on it, are not compared)
  bool uniform = true;
  Vec3<L> rp = Vec3<L>::Zero(), axis = Vec3<L>::Zero(), n = Vec3<L>::Zero(), img_axis = Vec3<L>::Zero();
  L r = 0, k = 0, omc = 0, psi = 0, img_omc = 0, img_psi = 0;
  L dist = 0;       // from r_p to the boundary of C
  L norm = 0;       // integral_C D = integral_{g(C)} D_std
  L norm_rel = 0;   // its relative tolerance (header comment)
  L delta_img = 0;  // the image cap's angular tolerance
  bool whole = false;

  Vec3<L> g(const Vec3<L>& w) const { return pivot_transform_point<L>(w, rp).normalized(); }
  L jacobian(const Vec3<L>& w) const {
    const L j = k / (w - rp).squaredNorm();
    return j * j;
  }
  L density(const Vec3<L>& w) const {
    if (!whole && angle_between(w, axis) > psi) return 0;
    const L base = uniform ? L(1) / (4 * kPi<L>) : std::max(L(0), g(w).dot(n)) / kPi<L>;
    return base * jacobian(w) / norm;
  }
};

// The unit vector orthogonal to a in the plane of a and r_p (two Gram-Schmidt passes; any orthogonal one when r_p
// is parallel to a up to rounding).
inline Vec3<L> sptd_in_plane(const SptdReference& r, const Vec3<L>& a) {
  Vec3<L> t = r.rp - r.rp.dot(a) * a;
  t -= t.dot(a) * a;
  const L tn = t.norm();
  return tn > 64 * std::numeric_limits<L>::epsilon() * r.r ? Vec3<L>(t / tn) : Frame<L>::from_z(a).x;
}

// The circle bounding g(C), as the smaller of the two caps it bounds: axis and half-angle psi_s <= pi/2, from C's
// boundary points p+- = cos(psi) a +- sin(psi) t in the plane of a and r_p (t: in that plane, orthogonal to a).
// g is an inversion about r_p (power k) composed with the point reflection through r_p, so |g(p) - g(q)| =
// k |p - q| / (|p - r_p| |q - r_p|); p+- map to the two ends of a diameter of the image circle (it is symmetric
// about that plane), whose chord is therefore 2 sin(psi_s) = 2 k sin(psi) / (|p+ - r_p| |p- - r_p|), without
// cancellation (differences of the images, as in Eq. 7, lose eps / psi_s relatively for tiny caps). The axis is
// the in-plane direction orthogonal to g(p+) - g(p-) on the side of g(p+) + g(p-).
struct SptdImageCircle {
  bool defined = false;
  Vec3<L> pp, pm, small_axis;
  L psi_s = 0;
};
inline SptdImageCircle sptd_image_circle(const SptdReference& r) {
  SptdImageCircle c;
  const Vec3<L> t = sptd_in_plane(r, r.axis);
  c.pp = std::cos(r.psi) * r.axis + std::sin(r.psi) * t, c.pm = std::cos(r.psi) * r.axis - std::sin(r.psi) * t;
  const Vec3<L> gp = r.g(c.pp), gm = r.g(c.pm);
  const L sin_s = std::min(L(1), r.k * std::sin(r.psi) / ((c.pp - r.rp).norm() * (c.pm - r.rp).norm()));
  const Vec3<L> plane_normal = r.axis.cross(t), chord = gp - gm, sum = gp + gm;
  // The axis from the sum where that is well conditioned (|sum| = 2 cos(psi_s) >= 1), else from the chord.
  c.small_axis = sum.norm() >= 1 ? sum : Vec3<L>(plane_normal.cross(chord));
  if (!(c.small_axis.norm() > 0)) return c;
  c.small_axis.normalize();
  if (c.small_axis.dot(sum) < 0) c.small_axis = -c.small_axis;
  c.psi_s = std::atan2(sin_s, std::max(L(0), c.small_axis.dot(sum) / 2));
  c.defined = true;
  return c;
}

// Whether g(C) is the small cap of the image circle (else its complement), and whether that is decided beyond
// rounding (`oriented`). A world point q whose side of C is known and whose image g(q) is known is tested against
// the small cap: g(C) is that cap iff both tests agree. Candidates: r_p's direction p and -p, which g swaps exactly
// (g(p) = -p), and C's axis +-w_c, whose world margins are psi and pi - psi, with images in long double. The one
// whose smaller margin from the two circles (C's boundary in the world, the image circle) exceeds its error by the
// most decides: the images of points near p are beyond long double's resolution when |r_p| is close to 1, and +-p
// lie on C's boundary when that passes through p. Without a pivot direction (r_p = 0, g(w) = -w) g(C) = -C.
inline bool sptd_image_is_small_cap(const SptdReference& r, const SptdImageCircle& c, bool* oriented) {
  if (!(r.r > 0)) return angle_between(Vec3<L>(-c.small_axis), r.axis) < r.psi;
  const Vec3<L> p = r.rp / r.r;
  // psi_s's error: the chord formula's distances |p+- - r_p| (differences of nearly equal vectors when r_p is close
  // to C's boundary) carry ~eps_L / |p+- - r_p| relatively, and k = (1 - r)(1 + r) ~eps_L / (1 - r) (r = |r_p| is
  // rounded to ~eps_L). A margin smaller than its error says nothing.
  const L eps_l = std::numeric_limits<L>::epsilon();
  const L psi_s_error =
      16 * eps_l *
      (1 + std::tan(std::min(c.psi_s, L(1.5))) * (1 / (c.pp - r.rp).norm() + 1 / (c.pm - r.rp).norm() + 1 / (1 - r.r)));
  struct Candidate {
    Vec3<L> world, image;
    L image_error;  // of the image point's direction
  };
  // g(w) in long double by Eq. 2 verbatim, g = (a d - d x c) / (a^2 + |c|^2), a = w.r_p - 1, d = w - r_p,
  // c = w x r_p; for unit w, a^2 + |c|^2 = rho^2 (rho = |w - r_p|), |a| = (rho^2 + k) / 2 and |c| <= rho, so
  // absolute errors ~eps_L in a, c and d move g by at most ~eps_L (1 + 1 / rho + k / rho^2) each; w's own rounding
  // (eps_L) is stretched by k / rho^2 (Eq. 4). (Eq. 2 does not use k.)
  auto computed = [&](const Vec3<L>& w) {
    const L rho = (w - r.rp).norm();
    return Candidate{w, r.g(w), 16 * eps_l * (1 + 1 / rho + r.k / (rho * rho))};
  };
  const Candidate candidates[] = {
      {p, Vec3<L>(-p), 0}, {Vec3<L>(-p), p, 0}, computed(r.axis), computed(Vec3<L>(-r.axis))};
  auto margin = [&](const Candidate& q) {
    const L image = std::abs(angle_between(q.image, c.small_axis) - c.psi_s) - psi_s_error - q.image_error;
    const L world = std::abs(angle_between(q.world, r.axis) - r.psi) - 16 * eps_l;
    return std::min(image, world);
  };
  const Candidate* best = &candidates[0];
  for (const Candidate& q : candidates)
    if (margin(q) > margin(*best)) best = &q;
  *oriented = margin(*best) > 0;
  const bool q_in_c = angle_between(best->world, r.axis) < r.psi;
  return (angle_between(best->image, c.small_axis) < c.psi_s) == q_in_c;
}

// The normaliser integral_C D = integral_{g(C)} D_std and its relative tolerance. The image radius psi' has two
// error bounds: the absolute delta_img, and a relative one from the chord formula, whose inputs k, sin(psi) and
// |p+- - r_p| the kernel knows to eps / (1 - r), rel_sin_c (e for a decoded cap, whose 1 - cos is exact; e kappa for
// the light's cone) and (e + delta_C) / dist relatively: sin(psi') to rho = e (2 + 1 / (1 - r)) + rel_sin_c +
// 2 (e + delta_C) / dist, psi' to |tan psi'| rho. The uniform normaliser (1 - cos psi') / 2 moves by sin(psi')
// dpsi'; the projected solid angle P by sin(psi') I(psi') dpsi' (cap.h) plus, for the axis's error
// delta_img, at most the cap's solid angle times it (as in projected_cap.h), plus the resolution of the kernel's
// disk coordinates: its abscissae (the ellipse's centre, the cut) carry absolute errors of a few eps, and the
// projected region's area moves by at most its height 2 sin(psi') per unit of abscissa. Returns false where g(C)
// lies below the cosine's horizon (the kernel gives no sample; not asserted here).
template <class T> bool sptd_normaliser(SptdReference& r, L delta_c, L rel_sin_c) {
  const L e = L(kTolUlps) * eps<T>();
  const L rho = e * (2 + 1 / (1 - r.r)) + rel_sin_c + 2 * (e + delta_c) / r.dist;
  const L dpsi = r.whole ? L(0) : std::min(r.delta_img, std::abs(std::tan(r.img_psi)) * rho);
  if (r.uniform) {
    r.norm = r.img_omc / 2;
    r.norm_rel = (r.img_omc > 0 ? std::sin(r.img_psi) * dpsi / r.img_omc : L(1)) + 16 * eps<T>();
    return true;
  }
  const L t_img = angle_between(r.img_axis, r.n);
  const Quadrature q = reference_cap_projected_solid_angle(t_img, r.img_psi);
  if (!(q.value > 0)) return false;
  r.norm = q.value / kPi<L>;
  r.norm_rel = (std::sin(r.img_psi) * ring_cosine_integral(r.img_psi, t_img) * dpsi +
                kTwoPi<L> * r.img_omc * r.delta_img + 2 * e * std::sin(r.img_psi) + 16 * q.error) /
                   q.value +
               16 * eps<T>();
  return true;
}

// The reference for one input (header comment). delta_c: C's angular tolerance; rel_sin_c: the relative tolerance
// of sin(psi); exact_cap: C from the exact inputs where the kernel builds it (the light's cone), else the decoded cap.
template <class T>
SptdReference sptd_reference(const SptdCapGeometry<T>& geo, L delta_c, L rel_sin_c, const Cap<L>* exact_cap = nullptr) {
  SptdReference r;
  const L e = L(kTolUlps) * eps<T>();
  r.uniform = geo.sptd.base == SptdBase::kUniform;
  const bool finite = all_finite(geo.sptd.pivot) && all_finite(geo.cap.axis) && std::isfinite(geo.cap.one_minus_cos) &&
                      all_finite(geo.sptd.base_axis);
  if (!finite) return r.invalid = true, r;
  r.rp = geo.sptd.pivot.template cast<L>();
  r.r = r.rp.norm();
  r.k = (1 - r.r) * (1 + r.r);
  const Vec3<L> a = exact_cap ? exact_cap->axis : Vec3<L>(geo.cap.axis.template cast<L>());
  r.omc = exact_cap ? exact_cap->one_minus_cos : L(geo.cap.one_minus_cos);
  const Vec3<L> nb = geo.sptd.base_axis.template cast<L>();
  // Invalid beyond rounding: |r_p|^2 >= 1 + 4 eps (the kernel tests |r_p|^2 < 1 in T), 1 - cos < 0 or = 0, axes of
  // zero length (the kernel also rejects subnormal lengths: between those the outcome is not asserted).
  if (r.rp.squaredNorm() >= 1 + 4 * eps<T>() || r.omc < 0 || (!exact_cap && r.omc == 0) || a.norm() == 0 ||
      (!r.uniform && nb.norm() == 0))
    return r.invalid = true, r;
  if (!(r.k > 0) || !(r.omc > 0) || !(a.norm() > L(std::numeric_limits<T>::min())) ||
      (!r.uniform && !(nb.norm() > L(std::numeric_limits<T>::min()))))
    return r;
  r.axis = a.normalized();
  r.n = r.uniform ? Vec3<L>(0, 0, 1) : Vec3<L>(nb.normalized());
  r.whole = r.omc >= 2;
  r.psi = half_angle_of(std::min(r.omc, L(2)));
  {  // distance from r_p to the boundary circle of C: the nearest boundary point lies in the plane of w_c and r_p
    const Vec3<L> t = sptd_in_plane(r, r.axis);
    const Vec3<L> b = std::cos(r.psi) * r.axis + std::sin(r.psi) * t;
    r.dist = r.whole ? L(2) : (b - r.rp).norm();
  }
  if (r.whole) {
    r.img_axis = r.axis, r.img_omc = 2, r.img_psi = kPi<L>;
    r.delta_img = 0;
  } else {
    const SptdImageCircle c = sptd_image_circle(r);
    if (!c.defined) return r;
    const bool small = sptd_image_is_small_cap(r, c, &r.oriented);
    r.img_axis = small ? c.small_axis : Vec3<L>(-c.small_axis);
    r.img_psi = small ? c.psi_s : kPi<L> - c.psi_s;
    r.img_omc = 2 * std::pow(std::sin(r.img_psi / 2), 2);
    r.delta_img = (delta_c / e) * r.k / (r.dist * r.dist) + 1 + 2 / r.dist;
    r.delta_img *= e;
  }
  if (!sptd_normaliser<T>(r, delta_c, rel_sin_c)) return r;
  r.defined = std::isfinite(r.norm) && r.norm > 0;
  return r;
}

template <class T> void check_sptd_kernel(FuzzedDataProvider& in, const SptdCapGeometry<T>& geo,
                                          const SptdReference& ref, const char* name, const char* way,
                                          const Mutation& mutate) {
  const SptdCapView<T> view = make_sptd_cap_view(geo);
  const L e = L(kTolUlps) * eps<T>();
  const bool finite_input = all_finite(geo.sptd.pivot) && all_finite(geo.cap.axis) &&
                            std::isfinite(geo.cap.one_minus_cos) && all_finite(geo.sptd.base_axis);
  // The tolerances at a direction w (header comment).
  struct At {
    L margin, tol, rel, expected;
  };
  auto at = [&](const Vec3<T>& w) {
    const Vec3<L> wl = w.template cast<L>().normalized();
    const Vec3<L> wi = ref.g(wl);
    const L rho = (wl - ref.rp).norm(), rho_i = (wi - ref.rp).norm();
    const L m_i = ref.k / (rho_i * rho_i);
    const L zi = wi.dot(ref.n);
    const L rim = ref.uniform ? L(0) : 1 / std::max(std::abs(zi), std::sqrt(e));
    At a;
    a.margin = ref.whole ? L(kPi<L>) : ref.psi - angle_between(wl, ref.axis);
    a.tol = m_i * (ref.delta_img + e * (1 + rim)) + e * (1 + 2 / rho_i);
    a.rel = e * (1 + 1 / (1 - ref.r) + 1 / rho) + ref.norm_rel;
    if (!ref.uniform) a.rel += zi > 0 ? e * (1 + 2 / rho) / zi : L(1);
    a.expected = ref.density(wl);
    return a;
  };
  const int samples = in.ConsumeIntegralInRange<int>(1, 3);
  for (int k = 0; k < samples; ++k) {
    const Vec2<T> u = unit_square<T>(in);
    const DirectionSample<T> s = mutate.sample(sample_sptd_cap(view, u));
    const std::string geometry = describe(geo, u, name, way);
    check_sample_shape(s, geometry);
    if (!finite_input) WARPCHECK_FUZZ_REQUIRE(!s.valid(), "a sample from non-finite input", geometry);
    if (!s.valid()) continue;
    WARPCHECK_FUZZ_REQUIRE(!ref.invalid, "a sample from input without a valid pivot, cap or axis", geometry);
    if (!ref.defined) continue;
    const At a = at(s.direction);
    WARPCHECK_FUZZ_REQUIRE(
        a.margin >= -a.tol, "direction outside the cap",
        geometry << "direction " << show(s.direction) << " margin " << a.margin << " tol " << a.tol << "\n");
    if (ref.oriented && a.expected > 0 && a.rel < L(0.5))
      WARPCHECK_FUZZ_REQUIRE(
          std::abs(L(s.pdf) / a.expected - 1) <= a.rel, "sample pdf differs from the reference density",
          geometry << "direction " << show(s.direction) << " pdf " << s.pdf << " reference " << a.expected
                   << " ratio - 1 " << (L(s.pdf) / a.expected - 1) << " allowed " << a.rel << "\n");
  }
  // pdf at an arbitrary unit direction (or one near the cap's axis): finite, >= 0, 0 for invalid input and outside,
  // and the reference density where both are positive.
  const Vec3<T> w = safe_normalized(in.ConsumeBool() ? vec3<T>(in) : near(in, geo.cap.axis));
  const T p = mutate.pdf(pdf_sptd_cap(view, w));
  const std::string geometry = describe(geo, Vec2<T>(Vec2<T>::Zero()), name, way) + "pdf at w " + show(w) + "\n";
  WARPCHECK_FUZZ_REQUIRE(std::isfinite(p) && p >= T(0), "pdf not finite and >= 0", geometry << "pdf " << p << "\n");
  if (ref.invalid || !view.valid())
    WARPCHECK_FUZZ_REQUIRE(p == T(0), "pdf > 0 for invalid input", geometry << "pdf " << p << "\n");
  if (!ref.defined || !view.valid() || w.isZero()) return;
  const At a = at(w);
  if (a.margin < -a.tol)
    WARPCHECK_FUZZ_REQUIRE(p == T(0), "pdf > 0 outside the cap",
                           geometry << "pdf " << p << " margin " << a.margin << " tol " << a.tol << "\n");
  if (ref.oriented && p > T(0) && a.expected > 0 && a.rel < L(0.5))
    WARPCHECK_FUZZ_REQUIRE(
        std::abs(L(p) / a.expected - 1) <= a.rel, "pdf(direction) differs from the reference density",
        geometry << "pdf " << p << " reference " << a.expected << " ratio - 1 " << (L(p) / a.expected - 1)
                 << " allowed " << a.rel << " margin " << a.margin << "\n");
  if (ref.oriented && p == T(0) && a.expected > 0 && a.rel < L(0.5))
    WARPCHECK_FUZZ_REQUIRE(
        a.margin <= a.tol, "pdf(direction) is 0 inside the cap where the reference density is not",
        geometry << "reference " << a.expected << " margin " << a.margin << " tol " << a.tol << "\n");
}

// One decoded input: the geometry the kernel gets, its reference, and the way in.
template <class T> struct SptdCase {
  SptdCapGeometry<T> geo;
  SptdReference ref;
  const char* way = "";
};

// A general SPTD over a cap with the given base.
template <class T> SptdCase<T> decode_sptd_general(FuzzedDataProvider& in, SptdBase base) {
  SptdCase<T> c;
  SptdCapGeometry<T>& geo = c.geo;
  geo.sptd.pivot = decode_pivot<T>(in);
  geo.sptd.base = base;
  geo.cap = decode_sptd_cap<T>(in, geo.sptd.pivot);
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0:
      geo.sptd.base_axis = vec3<T>(in);
      break;
    case 1:
      geo.sptd.base_axis = near(in, unit_or_z(geo.sptd.pivot));
      break;
    case 2:
      geo.sptd.base_axis = perpendicular(in, Vec3<T>(geo.cap.axis));
      break;  // g(C) near the horizon
    default:
      geo.sptd.base_axis = geo.cap.axis;
      break;
  }
  c.ref = sptd_reference(geo, L(kTolUlps) * eps<T>(), L(kTolUlps) * eps<T>());
  c.way = "cap";
  return c;
}

// The pivot phase function over a cap (Sec. 6.2): a uniform SPTD.
template <class T> SptdCase<T> decode_sptd_phase(FuzzedDataProvider& in) {
  SptdCase<T> c;
  const Vec3<T> wo = in.ConsumeBool() ? unit_or_z(vec3<T>(in)) : vec3<T>(in);
  T gp;
  if (in.ConsumeBool())
    gp = hg_to_pivot(T(2) * unit_random<T>(in) - T(1));  // Eqs. 27-28
  else {
    const T sign = in.ConsumeBool() ? T(1) : T(-1);
    gp = sign * (T(1) - std::ldexp(T(1), -in.ConsumeIntegralInRange<int>(1, std::numeric_limits<T>::digits + 2)));
  }
  c.geo = pivot_phase_geometry(wo, gp, decode_sptd_cap<T>(in, Vec3<T>(gp * wo)));
  c.ref = sptd_reference(c.geo, L(kTolUlps) * eps<T>(), L(kTolUlps) * eps<T>());
  c.way = "phase function";
  return c;
}

// The joint pivot phase function and sphere light (Fig. 17): a uniform SPTD whose cap is the light's cone. The cone
// in long double from the exact sphere inputs; its angular tolerance is the sphere kernels' (the cap the kernel
// builds is make_sphere_view's, in T).
template <class T> SptdCase<T> decode_sptd_phase_sphere(FuzzedDataProvider& in) {
  SptdCase<T> c;
  const SphereLightGeometry<T> light = decode_sphere<T>(in);
  const Vec3<T> wo = unit_or_z(vec3<T>(in));
  const T gp = hg_to_pivot(T(2) * unit_random<T>(in) - T(1));
  c.geo = pivot_phase_sphere_light_geometry(wo, gp, light);
  c.way = "phase function and sphere light";
  const SphereReference sref = sphere_reference(light);
  const Vec3<L> to_c = light.light.center.template cast<L>() - light.shading.position.template cast<L>();
  if (!(sref.d > sref.r && sref.r > 0 && std::isfinite(sref.d))) {
    c.ref.invalid =
        !(all_finite(light.light.center) && all_finite(light.shading.position) && std::isfinite(light.light.radius)) ||
        sref.r <= 0 || sref.d < sref.r * (1 - 4 * eps<T>());
  } else {
    const L s2 = (sref.r / sref.d) * (sref.r / sref.d);
    const Cap<L> cone{Vec3<L>(to_c / sref.d), s2 / (1 + sref.cos_max)};
    c.ref = sptd_reference(c.geo, sref.tol, L(kTolUlps) * eps<T>() * sref.kappa, &cone);
  }
  return c;
}

// The first byte picks the way in: 0 and 1 a general SPTD over a cap, 2 the pivot phase function, 3 its joint
// sampling with a sphere light (the last two uniform). The cosine kernel's target takes every value as a general
// cap. (When one target checked both bases, 0 and 1 chose the uniform and the cosine base; the stored inputs of
// each base decode to the same geometry in its kernel's target.)
template <class T> SptdCase<T> decode_sptd(FuzzedDataProvider& in, SptdBase base) {
  const int mode = in.ConsumeIntegralInRange<int>(0, 3);
  if (base == SptdBase::kClampedCosine || mode <= 1) return decode_sptd_general<T>(in, base);
  return mode == 2 ? decode_sptd_phase<T>(in) : decode_sptd_phase_sphere<T>(in);
}

template <class T, SptdBase B> void check_sptd(FuzzedDataProvider& in, const Mutation& mutate = {}) {
  const SptdCase<T> c = decode_sptd<T>(in, B);
  check_sptd_kernel<T>(in, c.geo, c.ref, SptdCapKernel<T, B>::name, c.way, mutate);
}

}  // namespace warpcheck::fuzz
