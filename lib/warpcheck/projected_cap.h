// warpcheck/projected_cap.h: sphere lights sampled by projected solid angle (Peters & Dachsbacher 2019,
// "Sampling Projected Spherical Caps in Real Time", HPG 2019; "the paper" below).
//
// Local frame (Alg. 1): z = n, x horizontal towards the centre. The cap's boundary projects to an ellipse (centre
// (c_x, 0), half-axes |r_x|, r_y); the projected cap is cut into pieces, each a cut unit disk (Alg. 5) mapped
// affinely (Alg. 2-3) or by Alg. 4's warp. With h = n.w_d and r_y = r / |d|: Case 1 h >= r_y, Case 2 0 <= h < r_y,
// Case 3 -r_y < h < 0, Case 4 (no sample) h <= -r_y. pdf is per solid angle (the paper's density times n.w).
//
// Beyond the paper (docs/derivations/projected-cap.md): Alg. 5's argument is the area left of d_x, a in [0, pi];
// Alg. 1-4's quantities are taken without cancellation; the quintic is rescaled, so the warp is injective, and its
// exact density is reported. CutDiskInverse::kExact uses the exact inverse instead.
#pragma once

#include <algorithm>
#include <array>
#include <boost/math/tools/roots.hpp>
#include <cstdint>
#include <vector>

#include "warpcheck/core.h"
#include "warpcheck/sphere.h"

namespace warpcheck {

enum class CutDiskInverse { kQuintic, kExact };

// ---- Cut unit disks (Sec. 3.6) ----

// Area of the unit disk right of x = cos(theta), theta in [0, pi/2]: C = theta - sin cos = (phi - sin phi) / 2,
// phi = 2 theta; by its Taylor series for phi < 1, where the difference cancels.
template <class T> T cut_disk_area_from_angle(T theta) {
  const T phi = T(2) * theta;
  if (phi < T(1)) {
    // (phi - sin phi) / 2 = sum_{k>=1} (-1)^(k+1) phi^(2k+1) / (2 (2k+1)!); 12 terms reach 1e-25 relative.
    const T p2 = phi * phi;
    T term = phi * p2 / T(6), sum = T(0);
    for (int k = 1; k <= 12; ++k) {
      sum += term;
      term *= -p2 / T((2 * k + 2) * (2 * k + 3));
    }
    return sum / T(2);
  }
  return (phi - sine(phi)) / T(2);
}

// The area of the unit disk left of x (pi/2 + A(x), Sec. 3.3), given x and its half-height hh = sqrt(1 - x^2).
template <class T> T unit_disk_area_left_of(T x, T hh) {
  const T theta = std::atan2(std::max(hh, T(0)), std::abs(x));  // angle of |x| = cos(theta)
  const T right_of_abs = cut_disk_area_from_angle(theta);
  return x >= T(0) ? kPi<T> - right_of_abs : right_of_abs;
}

// A point's abscissa in the unit disk and its half-height sqrt(1 - x^2), without cancellation.
template <class T> struct CutDiskX {
  T x = T(0);
  T half_height = T(1);
  T inv_density = T(1);       // 1 / density per unit disk area for a uniform left-area (1: exact inverse)
  T one_minus_abs_x = T(-1);  // 1 - |x| where known without cancellation (quintic: q), else -1
  T half_height2 = T(-1);     // half_height^2 (quintic), else -1
  T density() const { return T(1) / inv_density; }
};

// Exact inverse of the left-area: C(theta) = target in [0, pi/2] by safeguarded Newton (C' = 2 sin^2 theta).
template <class T> T solve_cut_disk_angle(T target) {
  if (!(target > T(0))) return T(0);
  if (target >= kPi<T> / T(2)) return kPi<T> / T(2);
  // From the small-angle asymptote C ~ 2 theta^3 / 3; in long double from the double root, 53 of the 62 bits
  // asked for, which leaves Newton two steps instead of five or six (an x87 sine costs three double ones).
  T guess = std::min(std::cbrt(T(1.5) * target), kPi<T> / T(2));
  if constexpr (std::is_same_v<T, long double>) {
    const double root = solve_cut_disk_angle(double(target));
    if (root > 0) guess = root;
  }
  std::uintmax_t iterations = 60;
  return boost::math::tools::newton_raphson_iterate(
      [target](T th) {
        const T s = sine(th);
        return std::make_pair(cut_disk_area_from_angle(th) - target, T(2) * s * s);
      },
      guess, T(0), kPi<T> / T(2), std::numeric_limits<T>::digits - 2, iterations);
}

// ---- The quintic of Alg. 5, as published and as the sampler uses it ----
//
// Alg. 5 is |d_x| = 1 - q(e), q(e) = g(pi/2 - e) e^(2/3), e = pi/2 - |A|; as published q(pi/2) = 1.0000463 (a fold at
// A = 0). The sampler evaluates it at e' = kappa e, kappa = e0 / (pi/2), q(e0) = 1 (e0 by Newton in long double).
template <class T> constexpr T kQuinticE0 = T(1.57070406662117638809L);
template <class T> constexpr T kQuinticKappa = kQuinticE0<T> / (kPi<T> / T(2));

// The quintic g of Alg. 5 (Horner) and its derivative.
template <class T> T quintic_g(T s) {
  return (
      ((((T(-0.0079908617) * s + T(0.0238255409)) * s - T(0.0283903598)) * s + T(0.0198450184)) * s - T(0.0574433620)) *
          s +
      T(0.7400712465));
}
template <class T> T quintic_g_prime(T s) {
  return ((((T(5) * T(-0.0079908617) * s + T(4) * T(0.0238255409)) * s - T(3) * T(0.0283903598)) * s +
           T(2) * T(0.0198450184)) *
              s -
          T(0.0574433620));
}

// Alg. 5 exactly as published: d_x for the left-area a in [0, pi] (the paper's A = a - pi/2).
template <class T> T paper_quintic_x(T left_area) {
  const T a = std::clamp(left_area, T(0), kPi<T>);
  const T e = std::min(a, kPi<T> - a);
  const T m = T(1) - quintic_g(kPi<T> / T(2) - e) * cube_root(e * e);
  return a >= kPi<T> / T(2) ? m : -m;
}

// Inverse of the quintic warp's density per unit of its argument e, at s = pi/2 - e with q = g(s) e^(2/3) known:
// 2 ((2/3) g - g' e) sqrt(g) sqrt(2 - q) (derivation: docs/derivations/projected-cap.md).
template <class T> T quintic_inverse_density(T s, T e, T q) {
  const T g = quintic_g(s), gp = quintic_g_prime(s);
  return T(2) * (T(2) / T(3) * g - gp * e) * std::sqrt(g * std::max(T(0), T(2) - q));
}
template <class T> T quintic_density(T s, T e) {
  return T(1) / quintic_inverse_density(s, e, quintic_g(s) * std::cbrt(e * e));
}

// SampleCutUnitDisk (Alg. 5), abscissa only: the point of left-area `left_area` in [0, pi] (exactly for kExact, by
// the rescaled quintic for kQuintic); right_area = pi - left_area without cancellation. Always inlined (GCC 12
// otherwise returns CutDiskX through the stack, on the float sample's critical path).
template <class T, CutDiskInverse M>
[[gnu::always_inline]] inline CutDiskX<T> sample_cut_unit_disk_x(T left_area, T right_area) {
  // std::clamp as min(max(v, lo), hi): the same result, without a branch.
  const T a = std::min(std::max(left_area, T(0)), kPi<T>);
  const bool positive = a >= kPi<T> / T(2);
  // pi/2 - |A| of Alg. 5, the area between the point and the disk's nearer end: min(a, right-area), branch-free.
  const T e = std::min(a, std::min(std::max(right_area, T(0)), kPi<T> / T(2)));
  CutDiskX<T> out;
  if constexpr (M == CutDiskInverse::kQuintic) {
    const T er = kQuinticKappa<T> * e;  // the rescaled argument: er <= e0, so q <= 1 and no fold
    const T s = kPi<T> / T(2) - er;
    // er^(2/3): for float by core.h's division-free root, else cube_root(er^2).
    T er23;
    if constexpr (std::is_same_v<T, float>)
      er23 = cube_root_squared_for_float(er);
    else
      er23 = cube_root(er * er);
    const T q = std::min(T(1), quintic_g(s) * er23);
    const T m = T(1) - q;                         // |d_x|
    out.x = std::copysign(m, a - kPi<T> / T(2));  // -m where a < pi/2 (m >= 0), without a branch
    const T hh2 = q * (T(2) - q);                 // 1 - m^2 = (1 - m)(1 + m)
    out.half_height = std::sqrt(hh2);
    out.inv_density = kQuinticKappa<T> * quintic_inverse_density(s, er, q);  // d er / d a = kappa
    out.one_minus_abs_x = q;
    out.half_height2 = hh2;
  } else {
    const T theta = solve_cut_disk_angle(e);  // C(theta) = e: the area beyond |x| = cos(theta)
    T sin_theta, cos_theta;
    sine_cosine(theta, sin_theta, cos_theta);
    out.x = positive ? cos_theta : -cos_theta;
    out.half_height = sin_theta;
  }
  return out;
}
template <class T, CutDiskInverse M> CutDiskX<T> sample_cut_unit_disk_x(T left_area) {
  return sample_cut_unit_disk_x<T, M>(left_area, kPi<T> - left_area);
}

// The inverse of sample_cut_unit_disk_x (injective): the left-area a whose abscissa is x (half-height hh), with the
// density there.
template <class T> struct CutDiskPreimage {
  T left_area;
  T density;
  T right_area;  // pi - left_area, without cancellation
};
template <class T, CutDiskInverse M> CutDiskPreimage<T> cut_disk_preimage(T x, T hh) {
  if constexpr (M == CutDiskInverse::kExact) {
    return {unit_disk_area_left_of(x, hh), T(1), unit_disk_area_left_of(-x, hh)};
  } else {
    // q = 1 - |x| (from hh where more accurate) = g(pi/2 - t^3) t^2, solved for t = er^(1/3): smooth in t, so Newton
    // converges near the disk's edge where dx/da is infinite.
    const T ax = std::abs(x);
    const T target = std::clamp(ax > T(0.5) ? hh * hh / (T(1) + ax) : T(1) - ax, T(0), T(1));
    const T t_max = std::cbrt(kQuinticE0<T>);
    const T guess = std::min(std::sqrt(target / quintic_g(kPi<T> / T(2))), t_max);
    std::uintmax_t iterations = 60;
    const T t = boost::math::tools::newton_raphson_iterate(
        [target](T t) {
          const T t3 = t * t * t, s = kPi<T> / T(2) - t3;
          const T g = quintic_g(s), gp = quintic_g_prime(s);
          return std::make_pair(g * t * t - target, t * (T(2) * g - T(3) * t3 * gp));
        },
        guess, T(0), t_max, std::numeric_limits<T>::digits - 2, iterations);
    const T er = t * t * t, e = er / kQuinticKappa<T>;
    return {x >= T(0) ? kPi<T> - e : e, quintic_density(kPi<T> / T(2) - er, er) / kQuinticKappa<T>,
            x >= T(0) ? e : kPi<T> - e};
  }
}

// ---- ComputeGeometry (Alg. 1) and the per-light precomputation (Sec. 3.7) ----

namespace projected_cap_detail {
// A piece of a view: its u0 range and left-area map a = beta u0 (alpha = 0) or alpha (1 - u0) (alpha = -beta);
// Alg. 2-4's maps, ending with the quintic where it reaches the cuts (docs/derivations/projected-cap.md).
template <class T> struct Piece {
  int kind;
  T u_lo, u_hi, alpha, beta;
  T right_hi = T(0);  // pieces with alpha = 0: the right-area pi - a at u_hi, without cancellation
};
}  // namespace projected_cap_detail

template <class T> struct ProjectedCapView {
  NoSample reason = NoSample::kNone;
  int which_case = 4;    // 1: entirely above, 2: mostly above, 3: mostly below (Sec. 3.2)
  SphereView<T> sphere;  // validation, distance, the cap (shared with the sphere kernels)
  Vec3<T> x = Vec3<T>::Zero(), y = Vec3<T>::Zero(), z = Vec3<T>::Zero();  // local frame (Alg. 1)
  T h = T(0), w_dx = T(0);                                                // n.w_d and the horizontal length of w_d
  T r_x = T(0), r_y = T(0), r_z = T(0), c_x = T(0), c_z = T(0), t_x = T(0), t_y = T(0), v = T(0);
  // Pieces: ellipse (Cases 1-2, u0 in [0, tau)), mirrored disk (Case 2, u0 in [tau, 1]), lune (Case 3).
  T area_e = T(0), area_e_unit = T(0), area_d = T(0), total = T(0), tau = T(0);
  // The left-areas at which the rescaled quintic reaches the cuts: X(quintic_area_e_unit) = X_t, X(quintic_area_d) =
  // -t_x; and pi minus the ellipse's two, without cancellation.
  T quintic_area_e_unit = T(0), quintic_area_d = T(0);
  T right_e_unit = T(0), quintic_right_e_unit = T(0);
  // Case 3: k = (c_z + r_z) / t_y, c_z + r_z, r_z - c_z. Cases 1-2: c_z - r_z = (h^2 - r_y^2) / (h v + w_dx r_y).
  T k = T(0), top = T(0), rz_minus_cz = T(0), cz_minus_rz = T(0);
  // Case 3: m of s_y^2 = (t_y + m d_z) / (t_y + d_z), 1 - m and 1 - k^2 (each >= 0).
  T sy_m = T(0), sy_one_minus_m = T(0), one_minus_k2 = T(0);
  // 1 - c_x = (h^2 + w_dx^2 r_y^2) / (1 + w_dx v), for the inverse of the ellipse piece.
  T one_minus_cx = T(0);
  // float only: the quintic sampler's pieces, formed once per light (double: per sample measured faster).
  std::array<projected_cap_detail::Piece<T>, 2> quintic_pieces{};
  int quintic_piece_count = 0;

  bool valid() const { return reason == NoSample::kNone; }
  Vec3<T> to_world(const Vec3<T>& w) const { return w.x() * x + w.y() * y + w.z() * z; }
  Vec3<T> to_local(const Vec3<T>& w) const { return Vec3<T>(w.dot(x), w.dot(y), w.dot(z)); }
  // The normaliser of Cases 1-2 (A_E + A_D, the projected solid angle); Case 3 has none (non-uniform density).
  T projected_solid_angle_if_uniform() const { return which_case <= 2 ? total : T(0); }
};

namespace projected_cap_detail {

// Scale invariance (ours): Alg. 1 reads only d / |d| and r / |d|, d = c - x, so the view is built from x' = 0,
// c' = d 2^-e, r' = r 2^-e with |d'|_inf in [1/2, 1) (exact): every later quantity is of unit scale. r' is capped at 4
// and kept >= denorm_min. Returns e (0: geometry passed on unchanged, for make_sphere_view to reject).
template <class T> int unit_scale_geometry(const SphereLightGeometry<T>& g, SphereLightGeometry<T>& out) {
  out = g;
  const T r = g.light.radius;
  if (!all_finite(g.light.center) || !all_finite(g.shading.position) || !std::isfinite(r) || !(r > T(0))) return 0;
  const Vec3<T> d = g.light.center - g.shading.position;
  if (!all_finite(d)) return 0;  // the difference overflowed
  const T m = max_abs(d);
  if (!(m > T(0))) return 0;  // x at the centre: inside the light
  int e = 0, er = 0;
  std::frexp(m, &e);
  std::frexp(r, &er);  // r < 2^er
  out.shading.position = Vec3<T>::Zero();
  out.light.center = ldexp(d, -e);
  out.light.radius = er - e > 2 ? T(4) : std::max(scale_by_power_of_two(r, -e), std::numeric_limits<T>::denorm_min());
  return e;
}

}  // namespace projected_cap_detail

namespace projected_cap_detail {
template <class T, CutDiskInverse M> int pieces(const ProjectedCapView<T>& p, std::array<Piece<T>, 2>& out);

// Alg. 1's frame: z = n, x from w_d's horizontal part n x (w_d x n), horizontal to rounding even for a light overhead
// (replaced only when exactly 0: a threshold would differ between precisions); h = n.w_d, w_dx its length.
template <class T> void local_frame(ProjectedCapView<T>& p) {
  const SphereView<T>& s = p.sphere;
  const Vec3<T> wd = s.frame.z;
  p.z = s.normal;
  const T h_raw = p.z.dot(wd);
  const Vec3<T> horizontal = p.z.cross(Vec3<T>(wd.cross(p.z)));
  p.h = std::clamp(h_raw, T(-1), T(1));
  p.w_dx = stable_norm(horizontal);
  // Scaled to [1/2, 1) by a power of two first (exact), so that a subnormal horizontal part gives a unit x.
  if (p.w_dx > T(0)) {
    int ex = 0;
    std::frexp(max_abs(horizontal), &ex);
    const Vec3<T> scaled = ldexp(horizontal, -ex);
    p.x = scaled / stable_norm(scaled);
  } else {
    p.x = Frame<T>::from_z(p.z).x;  // overhead: any horizontal x
  }
  p.y = p.z.cross(p.x);
}

// Case 1 (Alg. 3): the whole ellipse; t_x >= 1 is never needed.
template <class T> void case1_geometry(ProjectedCapView<T>& p) {
  p.which_case = 1;
  p.area_e_unit = kPi<T>;
  p.area_e = p.r_x * p.r_y * kPi<T>;
  p.total = p.area_e;
  p.tau = T(1);
}

// Case 2 (Alg. 2), chord2 = r_y^2 - h^2 > 0: A_E' = pi - C(theta_E), X_t = cos(theta_E) = v h / (r_y w_dx).
template <class T> void case2_geometry(ProjectedCapView<T>& p, T chord2) {
  const T h = p.h, ry = p.r_y, v = p.v;
  p.which_case = 2;
  p.right_e_unit = cut_disk_area_from_angle(std::atan2(std::sqrt(chord2), v * h));
  p.area_e_unit = kPi<T> - p.right_e_unit;
  const CutDiskPreimage<T> qe =
      cut_disk_preimage<T, CutDiskInverse::kQuintic>(v * h / (ry * p.w_dx), std::sqrt(chord2) / (ry * p.w_dx));
  p.quintic_area_e_unit = qe.left_area;
  p.quintic_right_e_unit = qe.right_area;
  p.area_e = p.r_x * p.r_y * p.area_e_unit;
  p.total = p.area_e + p.area_d;
  // Both areas can underflow to 0: tau only for a positive total, which the caller tests.
  p.tau = p.total > T(0) ? p.area_e / p.total : T(0);
}

// Case 3 (Alg. 4): the lune; chord2 = r_y^2 - h^2 > 0, h < 0.
template <class T> void case3_geometry(ProjectedCapView<T>& p, T chord2) {
  const T h = p.h, ry = p.r_y, v = p.v;
  p.which_case = 3;
  p.rz_minus_cz = p.w_dx * ry - h * v;
  p.top = chord2 / p.rz_minus_cz;                    // c_z + r_z
  p.k = std::sqrt(chord2) * p.w_dx / p.rz_minus_cz;  // (c_z + r_z) / t_y
  // 1 - m = -2 h v / (r_z - c_z), 1 - k^2 = q (2 v w_dx r_y / (r_z - c_z) + q (v^2 + w_dx^2)), q = -h / (r_z -
  // c_z): terms >= 0 for h < 0, no square of r_z - c_z (it underflows).
  p.sy_m = p.top / p.rz_minus_cz;
  p.sy_one_minus_m = T(-2) * h * v / p.rz_minus_cz;
  const T q3 = -h / p.rz_minus_cz;
  p.one_minus_k2 = q3 * (T(2) * v * p.w_dx * (ry / p.rz_minus_cz) + q3 * (v * v + p.w_dx * p.w_dx));
  p.total = p.area_d;
  p.tau = T(0);
}
}  // namespace projected_cap_detail

// ComputeGeometry (Alg. 1) and the pieces (Alg. 2-4), once per light.
template <class T> NoSample fill_projected_cap_view(const SphereLightGeometry<T>& g, ProjectedCapView<T>& p) {
  using namespace projected_cap_detail;
  SphereLightGeometry<T> unit;
  const int scale_exponent = unit_scale_geometry(g, unit);
  p.sphere.reason = fill_sphere_view(unit, p.sphere);  // in place, as make_sphere_view would return it
  if (!p.sphere.valid()) return p.sphere.reason;
  p.sphere.distance = scale_by_power_of_two(p.sphere.distance, scale_exponent);  // |c - x| in the caller's units
  local_frame(p);
  p.r_y = std::sqrt(p.sphere.sin2_theta_max);
  p.v = p.sphere.cos_theta_max;
  p.r_x = p.h * p.r_y, p.r_z = p.w_dx * p.r_y, p.c_x = p.w_dx * p.v, p.c_z = p.h * p.v;
  const T h = p.h, ry = p.r_y, v = p.v;
  if (h <= -ry) return NoSample::kBelowHorizon;  // Case 4 (make_sphere_view catches it first)
  // r_y^2 - h^2 = w_dx^2 - v^2, from the smaller operands; at the case boundary both cancel (inherent).
  const T chord2 = ry < v ? (ry - std::abs(h)) * (ry + std::abs(h)) : (p.w_dx - v) * (p.w_dx + v);
  if (h >= T(0)) p.cz_minus_rz = -chord2 / (h * v + p.w_dx * ry);
  p.one_minus_cx = (h * h + p.w_dx * p.w_dx * ry * ry) / (T(1) + p.w_dx * v);
  // Cases 2-3 divide by w_dx (> v >= 0 when h < r_y); w_dx = 0 with h < r_y is h = 1 against r_y = 1: Case 1.
  if (h >= ry || !(p.w_dx > T(0))) {
    case1_geometry(p);
  } else {
    p.t_x = v / p.w_dx;  // w_dx >= v > 0 here
    p.t_y = std::sqrt(chord2) / p.w_dx;
    p.area_d = cut_disk_area_from_angle(std::atan2(std::sqrt(chord2), v));  // pi/2 - A(t_x)
    p.quintic_area_d = cut_disk_preimage<T, CutDiskInverse::kQuintic>(-p.t_x, p.t_y).left_area;
    if (h >= T(0))
      case2_geometry(p, chord2);
    else
      case3_geometry(p, chord2);
  }
  if (!(p.total > T(0)) || !std::isfinite(p.total)) return NoSample::kTooSmall;
  if constexpr (std::is_same_v<T, float>)
    p.quintic_piece_count = pieces<T, CutDiskInverse::kQuintic>(p, p.quintic_pieces);
  return NoSample::kNone;
}

template <class T> ProjectedCapView<T> make_projected_cap_view(const SphereLightGeometry<T>& g) {
  ProjectedCapView<T> p;  // filled in place: no copy of the view on return
  p.reason = fill_projected_cap_view(g, p);
  return p;
}

// ---- The pieces: cut disk <-> local direction ----

namespace projected_cap_detail {

// Case 3 (Alg. 4): s_y = sqrt((t_y + m d_z) / (t_y + d_z)) and 1 - s_y^2 = (1 - m) d_z / (t_y + d_z), both without
// cancellation; the guard is for a lune without width.
template <class T> struct Case3Sy { T s_y, one_minus_sy2; };
template <class T> Case3Sy<T> case3_sy(const ProjectedCapView<T>& p, T d_z) {
  const T den = p.t_y + d_z;
  if (!(den > T(0))) return {T(0), T(0)};
  if constexpr (std::is_same_v<T, float>) {
    // float: two divisions side by side instead of a reciprocal and products after it (a shorter chain)
    return {std::sqrt((p.t_y + p.sy_m * d_z) / den), p.sy_one_minus_m * d_z / den};
  }
  const T inv = T(1) / den;
  const T r = d_z * inv;  // in [0, 1]
  return {std::sqrt(p.t_y * inv + p.sy_m * r), p.sy_one_minus_m * r};
}

// A cut-disk point mapped to a local direction by piece 0 (ellipse), 1 (mirrored disk) or 2 (Case-3 lune), with the
// projected-solid-angle density from the inverse disk density (per unit area and unit u0).
template <class T> struct Local {
  Vec3<T> w;
  T pdf_proj;
  // pdf_proj = pdf_num / pdf_den, for the float sampler's one division w_z pdf_num / pdf_den.
  T pdf_num = T(1), pdf_den = T(0);
  // |w|^2 with the last square root's radicand for that component's square: known one root earlier than w.
  T norm2 = T(1);
};

// The cut-disk point is (d_x, (2 u1 - 1) hh), hh = sqrt(1 - d_x^2). Heights without the cancellation of
// 1 - w_x^2 - w_y^2, by exact identities: d_z = 2 hh sqrt(u1 (1 - u1)) on the disk, and on the ellipse
// 1 - w_x^2 - w_y^2 = (c_z - r_z d_x)^2 + r_y^2 d_z^2 with c_z - r_z d_x = (c_z - r_z) + r_z hh^2 / (1 + d_x) for
// d_x > 0. one_minus_abs_dx, hh2: 1 - |d_x| and hh^2 if the caller has them (else negative).
template <class T> Local<T> disk_to_local(const ProjectedCapView<T>& p, int piece, T dx, T hh, T u1, T inv_disk_density,
                                          T one_minus_abs_dx = T(-1), T hh2 = T(-1)) {
  Local<T> o;
  const T dy = (T(2) * u1 - T(1)) * hh;
  const auto disk_z = [&] { return T(2) * hh * std::sqrt(u1 * (T(1) - u1)); };  // d_z (the ellipse may not need it)
  if (piece == 0) {
    const T wx = p.r_x * dx + p.c_x, wy = p.r_y * dy;
    T low;
    if (one_minus_abs_dx >= T(0)) {
      // (c_z - r_z) + r_z (1 - d_x) or c_z + r_z |d_x|, selected exactly by a 0/1 weight: no branch on d_x's sign.
      const T t = T(dx > T(0));
      const T b = t * p.cz_minus_rz + (T(1) - t) * p.c_z;
      low = b + p.r_z * ((T(1) - t) + (T(2) * t - T(1)) * one_minus_abs_dx);
    } else {
      low = dx > T(0) ? p.cz_minus_rz + p.r_z * (hh * hh / (T(1) + dx)) : p.c_z - p.r_z * dx;
    }
    T rest2;
    if (hh2 >= T(0)) {
      rest2 = (p.r_y * p.r_y) * (T(4) * (u1 * (T(1) - u1))) * hh2;  // (r_y d_z)^2, d_z^2 = 4 hh^2 u1 (1 - u1)
    } else {
      const T rest = p.r_y * disk_z();
      rest2 = rest * rest;
    }
    const T height2 = low * low + rest2;
    o.w = Vec3<T>(wx, wy, std::sqrt(height2));
    o.norm2 = wx * wx + wy * wy + height2;
    o.pdf_den = inv_disk_density * (p.r_x * p.r_y);
    o.pdf_proj = T(1) / o.pdf_den;
  } else if (piece == 1) {
    const T d_z = disk_z();
    o.w = Vec3<T>(-dx, dy, d_z);
    o.norm2 = o.w.squaredNorm();
    o.pdf_den = inv_disk_density;
    o.pdf_proj = T(1) / o.pdf_den;
  } else {
    // w_x^2 = d_x^2 + (1 - s_y^2) d_y^2 + (1 - k^2) d_z^2: a sum of squares, not 1 - w_y^2 - w_z^2.
    const T d_z = disk_z();
    const T w_z = p.k * d_z;
    const Case3Sy<T> sy = case3_sy(p, d_z);
    const T s_y = sy.s_y;
    const T w_y = s_y * dy;
    const T w_x2 = dx * dx + sy.one_minus_sy2 * (dy * dy) + p.one_minus_k2 * (d_z * d_z);
    const T w_x = std::sqrt(w_x2);
    o.w = Vec3<T>(w_x, w_y, w_z);
    o.norm2 = w_x2 + w_y * w_y + w_z * w_z;
    // Alg. 4: p = -t_y^2 / ((c_z + r_z)^2 A_D) w_x / (d_x s_y) = w_x / (k^2 s_y |d_x|) per unit disk density.
    // Where the lune has no width in T (s_y = 0) or d_x = 0 the density is not representable: 0 (no sample).
    const T den = inv_disk_density * (p.k * p.k) * s_y * std::abs(dx);
    o.pdf_num = w_x, o.pdf_den = den;
    o.pdf_proj = den > T(0) ? w_x / den : T(0);
  }
  return o;
}

// Inverse of disk_to_local: the cut-disk point of w and the area factor; false outside the piece's image. The
// ellipse's d_x = ((1 - c_x) - (1 - w_x)) / r_x for w_x > 1/2, 1 - w_x = (w_y^2 + w_z^2) / (1 + w_x); the disk's
// half-height sqrt(d_y^2 + d_z^2): no cancellation.
template <class T>
bool local_to_disk(const ProjectedCapView<T>& p, int piece, const Vec3<T>& w, T& dx, T& dy, T& hh, T& area_factor) {
  if (piece == 0) {
    if (!(p.r_x > T(0))) return false;
    dx = w.x() > T(0.5) ? (p.one_minus_cx - (w.y() * w.y() + w.z() * w.z()) / (T(1) + w.x())) / p.r_x
                        : (w.x() - p.c_x) / p.r_x;
    dy = w.y() / p.r_y;
    area_factor = p.r_x * p.r_y;
    const T rest = (T(1) - std::abs(dx)) * (T(1) + std::abs(dx));
    if (!(rest >= T(0))) return false;
    hh = std::sqrt(rest);
  } else if (piece == 1) {
    dx = -w.x(), dy = w.y();
    area_factor = T(1);
    hh = std::sqrt(dy * dy + w.z() * w.z());
  } else {
    if (!(w.x() > T(0))) return false;
    const T d_z = w.z() / p.k;
    const Case3Sy<T> sy = case3_sy(p, d_z);
    const T s_y = sy.s_y;
    if (!(s_y > T(0)) || !(d_z <= T(1))) return false;
    dy = w.y() / s_y;
    // d_x^2 = w_x^2 - (1 - s_y^2) d_y^2 - (1 - k^2) d_z^2 (disk_to_local's identity): rounding eps w_x^2, inherent.
    const T rest = w.x() * w.x() - sy.one_minus_sy2 * (dy * dy) - p.one_minus_k2 * (d_z * d_z);
    if (!(rest >= T(0))) return false;
    dx = -std::sqrt(rest);
    area_factor = p.k * p.k * s_y * std::abs(dx) / w.x();
    hh = std::sqrt(dy * dy + d_z * d_z);
  }
  return std::abs(dy) <= hh && std::isfinite(area_factor) && area_factor > T(0);
}

// A piece's left-area a = beta u0 (alpha = 0) or alpha (1 - u0), exact where a is small.
template <class T> T piece_left_area(const Piece<T>& pc, T u0) {
  return pc.alpha == T(0) ? pc.beta * u0 : pc.alpha * (T(1) - u0);
}
// pi - a for the same u0: right_hi + beta (u_hi - u0) for alpha = 0 (a near pi), else pi - a (a <= pi/2).
template <class T> T piece_right_area(const Piece<T>& pc, T u0) {
  return pc.alpha == T(0) ? pc.right_hi + pc.beta * (pc.u_hi - u0) : kPi<T> - pc.alpha * (T(1) - u0);
}
template <class T, CutDiskInverse M> int pieces(const ProjectedCapView<T>& p, std::array<Piece<T>, 2>& out) {
  constexpr bool q = M == CutDiskInverse::kQuintic;
  switch (p.which_case) {
    case 1:
      out[0] = {0, T(0), T(1), T(0), kPi<T>, T(0)};
      return 1;
    case 2: {
      int n = 0;
      if (p.area_e > T(0)) {
        const T ae = q ? p.quintic_area_e_unit : p.area_e_unit;
        out[n++] = {0,
                    T(0),
                    p.tau,
                    T(0),
                    q ? ae / p.tau : p.total / (p.r_x * p.r_y),
                    q ? p.quintic_right_e_unit : p.right_e_unit};
      }
      // tau rounds to 1 when A_D < eps A_E / 2: the disk piece has no u0 range then (its share is below rounding).
      if (p.tau < T(1)) {
        const T ad = q ? p.quintic_area_d / (T(1) - p.tau) : p.total;
        out[n++] = {1, p.tau, T(1), ad, -ad};
      }
      return n;
    }
    case 3: {
      const T ad = q ? p.quintic_area_d : p.area_d;
      out[0] = {2, T(0), T(1), ad, -ad};
      return 1;
    }
    default:
      return 0;
  }
}

// Whether a preimage's left-area lies in a piece's range, and else by how much it lies beyond an end of the range
// where the next piece begins (a seam: u0 strictly inside (0, 1)); infinite beyond an end of the warp. A piece
// a = beta u0 ends near pi, so it is compared by right-areas (left-areas lose a tiny neighbour there).
template <class T> T seam_miss(const Piece<T>& pc, const CutDiskPreimage<T>& pre) {
  const T inf = std::numeric_limits<T>::infinity();
  if (pc.alpha == T(0)) {
    const T miss = pc.right_hi - pre.right_area;  // beyond u_hi
    return !(miss > T(0)) ? T(0) : pc.u_hi < T(1) ? miss : inf;
  }
  const T a_at_u_lo = piece_left_area(pc, pc.u_lo), a_at_u_hi = piece_left_area(pc, pc.u_hi);
  const T a_lo = std::min(a_at_u_lo, a_at_u_hi), a_hi = std::max(a_at_u_lo, a_at_u_hi);
  if (pre.left_area < a_lo) return (a_lo == a_at_u_lo ? pc.u_lo > T(0) : pc.u_hi < T(1)) ? a_lo - pre.left_area : inf;
  if (pre.left_area > a_hi) return (a_hi == a_at_u_lo ? pc.u_lo > T(0) : pc.u_hi < T(1)) ? pre.left_area - a_hi : inf;
  return T(0);
}

// Density (per projected solid angle) of local direction w, optionally with its preimage (u0, u1). The pieces
// tile the projected cap: at most one reaches w, except on a seam (the first is taken). A direction on a seam can
// miss both pieces' ranges by the rounding of its left-areas (measured up to 1.5 eps pi in float): if it lies in the
// light's cap and within 8 eps pi of a seam, the piece whose seam it misses least. (Farther, the other piece's
// left-area is its mirror image's: a direction on the ellipse's edge that the ellipse refuses by rounding would
// get the disk piece's preimage and density of another direction.)
template <class T, CutDiskInverse M> T pdf_local(const ProjectedCapView<T>& p, const Vec3<T>& w, Vec2<T>* u = nullptr) {
  std::array<Piece<T>, 2> ps{};
  const int n = pieces<T, M>(p, ps);
  int best = -1;
  T best_miss = std::numeric_limits<T>::infinity(), dy = 0, hh = 0, area = 0;
  CutDiskPreimage<T> pre{};
  for (int i = 0; i < n && best_miss > T(0); ++i) {
    T dx_i, dy_i, hh_i, area_i;
    if (!local_to_disk(p, ps[i].kind, w, dx_i, dy_i, hh_i, area_i)) continue;
    const CutDiskPreimage<T> pre_i = cut_disk_preimage<T, M>(dx_i, hh_i);
    const T miss = seam_miss(ps[i], pre_i);
    if (!(miss < best_miss)) continue;
    best = i, best_miss = miss, pre = pre_i, dy = dy_i, hh = hh_i, area = area_i;
  }
  if (best < 0) return T(0);
  // The light's cap in the local frame, whose x axis is the light centre's horizontal direction.
  if (best_miss > T(0) && (best_miss > T(8) * std::numeric_limits<T>::epsilon() * kPi<T> ||
                           !Cap<T>{Vec3<T>(p.w_dx, T(0), p.h), p.sphere.one_minus_cos_max}.contains(w)))
    return T(0);
  const Piece<T>& pc = ps[best];
  if (u) {
    (*u)[0] =
        std::clamp(pc.alpha == T(0) ? pre.left_area / pc.beta : T(1) - pre.left_area / pc.alpha, pc.u_lo, pc.u_hi);
    (*u)[1] = hh > T(0) ? std::clamp((dy / hh + T(1)) / T(2), T(0), T(1)) : T(0.5);
  }
  // |beta| area underflows to 0 for a piece whose left-area scale is subnormal: density not representable, 0.
  const T den = std::abs(pc.beta) * area;
  return den > T(0) ? pre.density / den : T(0);
}

}  // namespace projected_cap_detail

// ---- SampleProjectedSphericalCap (Alg. 6), per-sample part ----

template <class T, CutDiskInverse M = CutDiskInverse::kQuintic>
DirectionSample<T> sample_projected_spherical_cap(const ProjectedCapView<T>& p, const Vec2<T>& u) {
  using namespace projected_cap_detail;
  if (!p.valid()) return DirectionSample<T>::none(p.reason);
  if (!std::isfinite(u[0]) || !std::isfinite(u[1])) return DirectionSample<T>::none(NoSample::kNonFinite);
  const T u0 = std::min(std::max(u[0], T(0)), T(1)), u1 = std::min(std::max(u[1], T(0)), T(1));  // clamps
  // float with the quintic: the view's pieces, 1 - d_x from the cut disk, one division, one Newton renormalisation.
  constexpr bool fast = std::is_same_v<T, float> && M == CutDiskInverse::kQuintic;
  std::array<Piece<T>, 2> formed{};
  const std::array<Piece<T>, 2>& ps = fast ? p.quintic_pieces : formed;
  int n = p.quintic_piece_count;
  if constexpr (!fast) n = pieces<T, M>(p, formed);
  int i = 0;
  while (i + 1 < n && u0 >= ps[i].u_hi) ++i;  // Alg. 2's threshold xi_0 < A_E / (A_E + A_D)
  const Piece<T>& pc = ps[i];
  const CutDiskX<T> d = sample_cut_unit_disk_x<T, M>(piece_left_area(pc, u0), piece_right_area(pc, u0));  // Alg. 5
  const Local<T> loc = disk_to_local(p, pc.kind, d.x, d.half_height, u1, d.inv_density * std::abs(pc.beta),
                                     fast ? d.one_minus_abs_x : T(-1), fast ? d.half_height2 : T(-1));
  T pdf;
  if constexpr (fast) {
    if (!(loc.pdf_den > T(0))) return DirectionSample<T>::none(NoSample::kOnSilhouette);
    pdf = loc.pdf_num * loc.w.z() / loc.pdf_den;
  } else {
    pdf = loc.pdf_proj * loc.w.z();
  }
  if (!(pdf > T(0)) || !std::isfinite(pdf)) return DirectionSample<T>::none(NoSample::kOnSilhouette);
  DirectionSample<T> s;
  if constexpr (fast)
    s.direction = p.to_world(loc.w) * near_unit_renormalization_factor(loc.norm2);
  else
    s.direction = renormalized(p.to_world(loc.w));
  s.pdf = pdf;
  return s;
}

template <class T, CutDiskInverse M = CutDiskInverse::kQuintic>
DirectionSample<T> sample_projected_spherical_cap(const SphereLightGeometry<T>& g, const Vec2<T>& u) {
  return sample_projected_spherical_cap<T, M>(make_projected_cap_view(g), u);
}

// Density per solid angle of world direction w (the exact density of the implemented warp).
template <class T, CutDiskInverse M = CutDiskInverse::kQuintic>
T pdf_projected_spherical_cap(const ProjectedCapView<T>& p, const Vec3<T>& w) {
  if (!p.valid() || !all_finite(w)) return T(0);
  const Vec3<T> wl = p.to_local(w.normalized());
  if (!(wl.z() > T(0))) return T(0);
  const T pdf = projected_cap_detail::pdf_local<T, M>(p, wl) * wl.z();
  return std::isfinite(pdf) ? pdf : T(0);
}

template <class T, CutDiskInverse M = CutDiskInverse::kQuintic>
T pdf_projected_spherical_cap(const SphereLightGeometry<T>& g, const Vec3<T>& w) {
  return pdf_projected_spherical_cap<T, M>(make_projected_cap_view(g), w);
}

// Inverse map: the (u0, u1) that the warp with inverse M maps to w; false outside the support. (kExact on the quintic
// warp's samples measures the quintic's error in primary sample space.)
template <class T, CutDiskInverse M = CutDiskInverse::kQuintic>
bool invert_projected_spherical_cap(const ProjectedCapView<T>& p, const Vec3<T>& w, Vec2<T>& u) {
  if (!p.valid() || !all_finite(w)) return false;
  const Vec3<T> wl = p.to_local(w.normalized());
  if (!(wl.z() >= T(0))) return false;
  return projected_cap_detail::pdf_local<T, M>(p, wl, &u) > T(0);
}

// ---- Case 1 by polar coordinates (Sec. 3.4), an option: the paper's discontinuous alternative ----

// When the cap is entirely above the horizon (Case 1), the projected cap is the ellipse, sampled uniformly by the
// polar map of the unit disk, r = sqrt(u0), phi = 2 pi u1, scaled to the ellipse; Cases 2-3 by the quintic sampler.
// The warp jumps where the light reaches the horizon (Sec. 3.4 prefers the continuous map for stratification).
// Heights as disk_to_local's: 1 - w_x^2 - w_y^2 = (c_z - r_z d_x)^2 + r_y^2 (1 - r^2), with, for d_x > 0,
// 1 - d_x = (1 - u0) / (1 + r) + 2 r sin^2(phi / 2), both terms >= 0: no cancellation.
template <class T>
DirectionSample<T> sample_projected_spherical_cap_polar(const ProjectedCapView<T>& p, const Vec2<T>& u) {
  if (!p.valid() || p.which_case != 1) return sample_projected_spherical_cap<T>(p, u);
  if (!std::isfinite(u[0]) || !std::isfinite(u[1])) return DirectionSample<T>::none(NoSample::kNonFinite);
  const T u0 = std::min(std::max(u[0], T(0)), T(1)), u1 = std::min(std::max(u[1], T(0)), T(1));
  const T r = std::sqrt(u0), phi = kTwoPi<T> * u1;
  const T dx = r * std::cos(phi), dy = r * std::sin(phi);
  T low;
  if (dx > T(0)) {
    const T half = std::sin(phi / T(2));
    low = p.cz_minus_rz + p.r_z * ((T(1) - u0) / (T(1) + r) + T(2) * r * (half * half));
  } else {
    low = p.c_z - p.r_z * dx;
  }
  const T w_z = std::sqrt(low * low + (p.r_y * p.r_y) * (T(1) - u0));
  const T pdf = w_z / p.area_e;
  if (!(pdf > T(0)) || !std::isfinite(pdf)) return DirectionSample<T>::none(NoSample::kOnSilhouette);
  DirectionSample<T> s;
  s.direction = renormalized(p.to_world(Vec3<T>(p.r_x * dx + p.c_x, p.r_y * dy, w_z)));
  s.pdf = pdf;
  return s;
}

namespace projected_cap_detail {
// Case 1 of the polar option: the local direction of w and its point d on the unit disk (local_to_disk's test and
// its d_x without cancellation); false off the ellipse or at or below the horizon.
template <class T> bool polar_case1_disk(const ProjectedCapView<T>& p, const Vec3<T>& w, Vec3<T>& wl, T& dx, T& dy) {
  if (!all_finite(w)) return false;
  wl = p.to_local(w.normalized());
  T hh, area;
  return wl.z() > T(0) && local_to_disk(p, 0, wl, dx, dy, hh, area);
}
}  // namespace projected_cap_detail

// Its density per solid angle: w_z / A_E on the ellipse in Case 1, else the quintic sampler's.
template <class T> T pdf_projected_spherical_cap_polar(const ProjectedCapView<T>& p, const Vec3<T>& w) {
  if (!p.valid() || p.which_case != 1) return pdf_projected_spherical_cap<T>(p, w);
  Vec3<T> wl;
  T dx, dy;
  if (!projected_cap_detail::polar_case1_disk(p, w, wl, dx, dy)) return T(0);
  const T pdf = wl.z() / p.area_e;
  return std::isfinite(pdf) ? pdf : T(0);
}

// Its inverse: in Case 1 u0 = |d|^2, u1 = atan2(d_y, d_x) / 2 pi in [0, 1); else the quintic sampler's.
template <class T>
bool invert_projected_spherical_cap_polar(const ProjectedCapView<T>& p, const Vec3<T>& w, Vec2<T>& u) {
  if (!p.valid() || p.which_case != 1) return invert_projected_spherical_cap<T>(p, w, u);
  Vec3<T> wl;
  T dx, dy;
  if (!projected_cap_detail::polar_case1_disk(p, w, wl, dx, dy)) return false;
  const T phi = std::atan2(dy, dx);
  u[0] = std::min(T(1), dx * dx + dy * dy);
  u[1] = phi >= T(0) ? phi / kTwoPi<T> : std::min(std::nextafter(T(1), T(0)), T(1) + phi / kTwoPi<T>);
  const T pdf = wl.z() / p.area_e;
  return std::isfinite(pdf) && pdf > T(0);
}

// The light's cap widened by 64 eps_T radians: the pieces tile it exactly, and the battery's quadrature must see the
// support reach the cap's edge.
template <class T> Cap<T> projected_cap_bounding_cap(const ProjectedCapView<T>& p) {
  Cap<T> c = p.sphere.cap();
  const T delta = T(64) * std::numeric_limits<T>::epsilon();  // radians
  const T omc = c.one_minus_cos;
  // 1 - cos(theta + delta) = omc + sin(theta) delta + cos(theta) delta^2 / 2 (cos <= 1 bounds the last term).
  c.one_minus_cos = std::min(T(2), omc + std::sqrt(omc * (T(2) - omc)) * delta + delta * delta / T(2));
  return c;
}

// ---- Catalogue traits (warpcheck/catalogue.h) ----------------------------------------------------------------

// M = kQuintic is the paper's sampler (Alg. 5's quintic); kExact inverts A(X) exactly.
template <class T, CutDiskInverse M> struct SphereProjectedCapKernel {
  static constexpr CutDiskInverse inverse = M;
  static constexpr bool kQuintic = M == CutDiskInverse::kQuintic;
  static constexpr const char* name = kQuintic ? "sphere-projected-cap" : "sphere-projected-cap-exact";
  static constexpr const char* description =
      kQuintic ? "projected solid angle, Peters & Dachsbacher 2019 with the quintic"
               : "projected solid angle, Peters & Dachsbacher 2019 with the exact inverse";
  using Scalar = T;
  using Geometry = SphereLightGeometry<T>;
  using View = ProjectedCapView<T>;
  static View view(const Geometry& g) { return make_projected_cap_view(g); }
  static DirectionSample<T> sample(const View& v, const Vec2<T>& u) {
    return sample_projected_spherical_cap<T, M>(v, u);
  }
  static T pdf(const View& v, const Vec3<T>& w) { return pdf_projected_spherical_cap<T, M>(v, w); }
  static bool invert(const View& v, const Vec3<T>& w, Vec2<T>& u) {
    return invert_projected_spherical_cap<T, M>(v, w, u);
  }
  static Cap<T> bounding_cap(const Geometry& g) {
    const View v = make_projected_cap_view(g);
    return v.valid() ? projected_cap_bounding_cap(v) : make_sphere_view(g).cap();
  }
  // The horizon, where the cut cap ends and the density's cosine reaches 0; for the quintic in Case 2 also the
  // mirrored disk's kink (kinks_u0) at d_x = 0, which is local w_x = 0.
  static std::vector<Vec3<T>> boundary_planes(const Geometry& g) {
    std::vector<Vec3<T>> planes{g.shading.normal.normalized()};
    if constexpr (kQuintic) {
      const View v = make_projected_cap_view(g);
      if (v.valid() && v.which_case == 2) planes.push_back(v.x);
    }
    return planes;
  }
  // Small circles where the quintic's density kinks (kinks_u0): on the ellipse piece of Cases 1-2 at d_x = 0 (local
  // w_x = c_x), and in Case 2 on the seam between the pieces (local w_x = t_x, where the disk piece begins).
  static std::vector<Cap<T>> boundary_caps(const Geometry& g) {
    std::vector<Cap<T>> caps;
    if constexpr (kQuintic) {
      const View v = make_projected_cap_view(g);
      if (!v.valid() || v.which_case > 2) return caps;
      if (v.r_x > T(0)) caps.push_back(Cap<T>{v.x, v.one_minus_cx});
      if (v.which_case == 2) caps.push_back(Cap<T>{v.x, (v.w_dx - v.v) / v.w_dx});  // 1 - t_x, t_x = v / w_dx
    }
    return caps;
  }
  // A_E + A_D: the projected solid angle in Cases 1-2 (Case 3's density is not uniform in the disk).
  static T normaliser(const View& v) { return v.total; }
  // Case 2's threshold tau (the warp passes from the ellipse to the disk: continuous, its derivative jumps) and,
  // for the quintic, the u0 where a piece's left-area passes pi/2 (its density factor depends on min(a, pi - a)).
  static std::vector<T> kinks_u0(const Geometry& g) {
    std::vector<T> kinks;
    const View v = make_projected_cap_view(g);
    if (!v.valid()) return kinks;
    if (v.which_case == 2) kinks.push_back(v.tau);
    if constexpr (kQuintic) {
      std::array<projected_cap_detail::Piece<T>, 2> ps;
      const int n = projected_cap_detail::pieces<T, M>(v, ps);
      for (int i = 0; i < n; ++i) {
        const T u = (kPi<T> / T(2) - ps[i].alpha) / ps[i].beta;
        if (u > ps[i].u_lo && u < ps[i].u_hi) kinks.push_back(u);
      }
    }
    std::sort(kinks.begin(), kinks.end());
    return kinks;
  }
};
template <class T> using SphereProjectedCap = SphereProjectedCapKernel<T, CutDiskInverse::kQuintic>;
template <class T> using SphereProjectedCapExact = SphereProjectedCapKernel<T, CutDiskInverse::kExact>;

// The quintic sampler with Case 1 by polar coordinates (sample_projected_spherical_cap_polar).
template <class T> struct SphereProjectedCapPolar : SphereProjectedCap<T> {
  using View = ProjectedCapView<T>;
  static constexpr const char* name = "sphere-projected-cap-polar";
  static constexpr const char* description =
      "projected solid angle, Peters & Dachsbacher 2019, Case 1 by polar coordinates (Sec. 3.4)";
  static DirectionSample<T> sample(const View& v, const Vec2<T>& u) {
    return sample_projected_spherical_cap_polar(v, u);
  }
  static T pdf(const View& v, const Vec3<T>& w) { return pdf_projected_spherical_cap_polar(v, w); }
  static bool invert(const View& v, const Vec3<T>& w, Vec2<T>& u) {
    return invert_projected_spherical_cap_polar(v, w, u);
  }
  // Case 1: none (the polar map is smooth for u0 > 0, and u1's seam is periodic); Cases 2-3: the quintic's.
  static std::vector<T> kinks_u0(const SphereLightGeometry<T>& g) {
    const View v = make_projected_cap_view(g);
    return v.valid() && v.which_case == 1 ? std::vector<T>{} : SphereProjectedCap<T>::kinks_u0(g);
  }
};

}  // namespace warpcheck
