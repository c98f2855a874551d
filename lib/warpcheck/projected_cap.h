// warpcheck/projected_cap.h: sphere lights sampled by projected solid angle (Peters & Dachsbacher 2019,
// "Sampling Projected Spherical Caps in Real Time", HPG 2019; "the paper" below).
//
// Local frame (Alg. 1): z = n, x = horizontal direction towards the centre, y = z x x. The cap's boundary circle
// projects to an ellipse in the xy-plane with centre (c_x, 0), half-axes |r_x|, r_y; the projected cap P is
// cut into pieces that are each a cut unit disk (Alg. 5) mapped affinely (Cases 1-2, Alg. 2-3) or by the
// Case-3 warp (Alg. 4) onto P. Cases, by the height h = n.w_d of the unit direction w_d to the centre and
// r_y = sin(theta_max) = r / |d|:
//   Case 1 h >= r_y (entirely above), Case 2 0 <= h < r_y, Case 3 -r_y < h < 0, Case 4 h <= -r_y (no sample).
//
// Conventions the paper leaves implicit, derived here (the supplement is not available):
//  * SampleCutUnitDisk's argument. Alg. 5 states an "offset area A in [-pi/2, pi/2]", but Alg. 2-4 pass areas
//    in [0, pi] (pi xi_0 in Alg. 3, A_E' up to pi in Alg. 2). The only reading under which Alg. 2 is continuous
//    at its threshold (the ellipse piece ends at x = t_x where the mirrored disk piece begins) is that the
//    argument is the area LEFT of d_x, a in [0, pi], and Alg. 5's A is a - pi/2. We implement that.
//  * Numerically stable forms (no cancellation near the case boundaries), all exact algebra on Alg. 1:
//      t_x = v / w_dx, t_y = sqrt((r_y - |h|)(r_y + |h|)) / w_dx         (from t_y^2 = 1 - t_x^2, v^2 = 1 - r_y^2)
//      X_t = (t_x - c_x) / r_x = v h / (r_y w_dx), sqrt(1 - X_t^2) = sqrt(r_y^2 - h^2) / (r_y w_dx)
//      c_z + r_z = (r_y^2 - h^2) / (w_dx r_y - h v)                       (Case 3: h < 0, no cancellation)
//      s_y^2 = r_y^2 (c_z + r_z)(r_z - c_z + w_z) / (t_y r_z^2 (t_y + d_z))  (Alg. 4's s_y with the common factor
//              (t_y - d_z) cancelled: no 0/0 at the top of the lune, no clamping needed there)
//            = (t_y + m d_z) / (t_y + d_z),  m = (c_z + r_z) / (r_z - c_z)
//              (using (c_z + r_z)(r_z - c_z) = r_y^2 - h^2 = t_y^2 w_dx^2 and r_z = w_dx r_y), so that
//      1 - s_y^2 = (1 - m) d_z / (t_y + d_z),  1 - m = -2 h v / (r_z - c_z) >= 0,
//      1 - k^2 = 1 - (r_y^2 - h^2) w_dx^2 / (r_z - c_z)^2 = -h (2 v w_dx r_y - h (v^2 + w_dx^2)) / (r_z - c_z)^2 >= 0
//              (Case 3, h < 0; k = (c_z + r_z) / t_y), and Case 3's lift, d on the unit sphere and w = (w_x, s_y d_y, k
//              d_z):
//      w_x^2 = 1 - w_y^2 - w_z^2 = d_x^2 + (1 - s_y^2) d_y^2 + (1 - k^2) d_z^2,
//    a sum of non-negative terms where 1 - w_y^2 - w_z^2 cancels for a sample near the lune's flat side (w_x ~ 0,
//    e.g. a cap of 90 deg - 0.02 deg with its centre on the horizon, fuzz_projected_cap_double 71f5a077). The
//    identities are ours (not in the paper); at h = 0 they give the identity warp the paper notes (Sec. 3.5).
//    and areas of cut disks from angles: the unit disk's area right of x = cos(theta) is
//      C(theta) = theta - sin(theta) cos(theta) = (2 theta - sin 2 theta) / 2,
//    evaluated by its Taylor series for small theta (it is ~ 2 theta^3 / 3; the difference form cancels).
//  * The quintic (Alg. 5) is not an exact inverse of A(X), so the warp it defines is not exactly uniform. Its
//    density is known in closed form: with q(s) = g(s) (pi/2 - s)^(2/3) and e = pi/2 - s, the cut disk point
//    has density (per unit disk area, per unit left-area) 1 / (X'(a) 2 sqrt(1 - X^2)) =
//      1 / (2 ((2/3) g - g' e) sqrt(g) sqrt(2 - q))
//    instead of 1. As published it is also not monotone at a = pi/2 and its pieces' ends miss the cuts; our
//    sampler rescales its argument and matches its ranges to the cuts (see "The quintic of Alg. 5" below), so
//    the warp is injective and the pieces tile the projected cap. We report the TRUE density of the
//    implemented warp (quintic factor included). CutDiskInverse::kExact replaces the quintic by the exact
//    inverse of A(X) (Boost.Math Newton iteration), for which the paper's densities hold exactly (Cases 1-2
//    uniform).
//  * pdf is per solid angle: the paper's density p w.r.t. projected solid angle times cos = n.w.
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

// ---- Cut unit disks (Sec. 3.6) ----------------------------------------------------------------------------

// Area of the unit disk right of x = cos(theta), theta in [0, pi/2]: C = theta - sin cos = (phi - sin phi) / 2,
// phi = 2 theta. Hand-rolled series for phi < 1 because the difference cancels (no library has x - sin x).
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
  return (phi - std::sin(phi)) / T(2);
}

// The area of the unit disk left of x, pi/2 + A(x) with A of Sec. 3.3, given x and its half-height
// hh = sqrt(1 - x^2) (both known accurately by the caller): pi - C(theta) for x = cos(theta) >= 0.
template <class T> T unit_disk_area_left_of(T x, T hh) {
  const T theta = std::atan2(std::max(hh, T(0)), std::abs(x));  // angle of |x| = cos(theta)
  const T right_of_abs = cut_disk_area_from_angle(theta);
  return x >= T(0) ? kPi<T> - right_of_abs : right_of_abs;
}

// A point's abscissa in the unit disk with its half-height sqrt(1 - x^2), computed without cancellation.
template <class T> struct CutDiskX {
  T x = T(0);
  T half_height = T(1);
  T inv_density = T(1);       // 1 / density of x per unit disk area when the left-area is uniform (1 for the exact
                              // inverse); kept inverted so that a sample's pdf costs one division
  T one_minus_abs_x = T(-1);  // 1 - |x| where known without cancellation (quintic: q); -1 (unknown) otherwise
  T half_height2 = T(-1);     // half_height^2 (before its square root; quintic), else -1
  T density() const { return T(1) / inv_density; }
};

// Exact inverse of the left-area: solves C(theta) = target (target in [0, pi/2]) for theta in [0, pi/2] by
// Boost.Math's safeguarded Newton iteration (C' = 2 sin^2 theta).
template <class T> T solve_cut_disk_angle(T target) {
  if (!(target > T(0))) return T(0);
  if (target >= kPi<T> / T(2)) return kPi<T> / T(2);
  // Start from the small-angle asymptote C ~ 2 theta^3 / 3, clamped into the bracket.
  const T guess = std::min(std::cbrt(T(1.5) * target), kPi<T> / T(2));
  std::uintmax_t iterations = 60;
  return boost::math::tools::newton_raphson_iterate(
      [target](T th) {
        const T s = std::sin(th);
        return std::make_pair(cut_disk_area_from_angle(th) - target, T(2) * s * s);
      },
      guess, T(0), kPi<T> / T(2), std::numeric_limits<T>::digits - 2, iterations);
}

// ---- The quintic of Alg. 5, as published and as the sampler uses it ------------------------------------------
//
// In terms of e = pi/2 - |A| (the area between the point and the nearer end of the disk), Alg. 5 is
//   |d_x| = 1 - q(e),   q(e) = g(pi/2 - e) e^(2/3),   sign(d_x) = sign(A).
// Its constants give q(pi/2) = g(0) (pi/2)^(2/3) = 1.0000463 instead of 1: at A = 0 the published warp jumps
// from d_x = +4.63e-5 (A -> 0-) to -4.63e-5 (A -> 0+), so a strip |d_x| < 4.63e-5 is reached twice (a fold of
// the warp in u0), and a piece whose left-area range ends at the exact area of its cut (A_D, A_E' of Alg. 2-4)
// ends up to ~1e-4 of the cut's width before or beyond the cut, because the quintic's abscissa there differs
// from the exact one by up to 4.6e-5. Measured with the published form and the exact density of the warp
// (warpcheck validate, double, 1e7 samples, 2026-12-01): the Case-3 estimator E[cos/pdf; hit] was 1.1e-4 low
// (a sliver at the top of the lune never sampled), the Case-2 pieces overlapped at their seam, and the battery's
// quadrature could not resolve the fold's thin strip of double density (pdf-integral 1.5e-6 low in Case 1,
// although the density integrates to 1 - 1.0e-11 with the strip as a breakpoint).
//
// Our sampler therefore keeps the paper's g and evaluates Alg. 5 at a rescaled argument (our change, not in the
// paper): e' = kappa e with kappa = e0 / (pi/2), where q(e0) = 1, so the two halves meet at d_x = 0 (no fold);
// and each piece's left-area range ends where the quintic's abscissa is exactly the piece's cut (solved once per
// light, `quintic_left_area`), so the pieces tile the projected cap exactly. The warp is then continuous and
// injective, the density (reported exactly, see the header comment) is unchanged up to the factor kappa, and the
// paper's Alg. 2-4 and 6 are otherwise as published. The paper's fit itself (its 4.6e-5) is measured on
// `paper_quintic_x`, untouched; the rescaled fit's own error is measured by ProjectedCapQuintic.
// RescaledFitErrorAgainstTheExactInverse.
//
// e0 solves g(pi/2 - e) e^(2/3) = 1 (Newton in long double; the test ProjectedCapQuintic.
// RescaledHalvesMeetAtTheCentre recomputes it).
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

// Inverse of the density factor of the quintic per unit of its own argument e, at s = pi/2 - e with
// q = g(s) e^(2/3) already known (derived above: the strip at x has area 2 sqrt(1 - x^2) |dx/de|, and
// dx/de = (2/3) g e^(-1/3) - g' e^(2/3)): 2 ((2/3) g - g' e) sqrt(g) sqrt(2 - q) (the e^(-1/3) cancels against
// sqrt(1 - x^2) = sqrt(q (2 - q)) = e^(1/3) sqrt(g (2 - q))).
template <class T> T quintic_inverse_density(T s, T e, T q) {
  const T g = quintic_g(s), gp = quintic_g_prime(s);
  return T(2) * (T(2) / T(3) * g - gp * e) * std::sqrt(g * std::max(T(0), T(2) - q));
}
template <class T> T quintic_density(T s, T e) {
  return T(1) / quintic_inverse_density(s, e, quintic_g(s) * std::cbrt(e * e));
}

// SampleCutUnitDisk (Alg. 5), abscissa only: the point whose left-area is `left_area` in [0, pi] (exactly for
// kExact; for kQuintic the rescaled quintic above, whose density per unit left-area is 1 / (kappa times the
// inverse factor of quintic_inverse_density)).
// right_area = pi - left_area, computed by the caller without cancellation (pi - a loses the digits of a small
// right-area: absolute error eps pi, 1.7e-4 relative for float at u0 = 1 - 3.6e-5 in Case 1).
// Always inlined: GCC 12 kept it out of line (20% of the float sample's time on main under perf, q_z = -0.1),
// returning CutDiskX through the stack; inlined, the float q_z = -0.1 sample took 44.3 ns instead of 50.8 with the
// other float changes of issue 9 (warpcheck_bench, one run each).
template <class T, CutDiskInverse M>
[[gnu::always_inline]] inline CutDiskX<T> sample_cut_unit_disk_x(T left_area, T right_area) {
  // std::min(std::max(v, lo), hi) is std::clamp(v, lo, hi) for lo <= hi (same comparisons, same operand returned;
  // NaN and -0 included), written so that it compiles to minss/maxss instead of branches on random data.
  const T a = std::min(std::max(left_area, T(0)), kPi<T>);
  const bool positive = a >= kPi<T> / T(2);
  // pi/2 - |A| of Alg. 5: the area between the point and the nearer end of the disk: the right-area (clamped to
  // pi/2) where a >= pi/2, else a; the smaller of the two in either case, taken without a branch (u0 is random,
  // so a branch on `positive` is mispredicted for half of the samples).
  const T e = std::min(a, std::min(std::max(right_area, T(0)), kPi<T> / T(2)));
  CutDiskX<T> out;
  if constexpr (M == CutDiskInverse::kQuintic) {
    const T er = kQuinticKappa<T> * e;  // the rescaled argument: er <= e0, so q <= 1 and no fold
    const T s = kPi<T> / T(2) - er;
    // er^(2/3): for float by the division-free root of core.h (issue 9: the Halley steps' divisions of cube_root were
    // on the sample's critical path), else cube_root(er^2).
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
    out.x = positive ? std::cos(theta) : -std::cos(theta);
    out.half_height = std::sin(theta);
  }
  return out;
}
template <class T, CutDiskInverse M> CutDiskX<T> sample_cut_unit_disk_x(T left_area) {
  return sample_cut_unit_disk_x<T, M>(left_area, kPi<T> - left_area);
}

// The left-area a in [0, pi] whose cut-disk abscissa is x (half-height hh = sqrt(1 - x^2), passed for accuracy
// near the disk's edge), with the density there; the inverse of sample_cut_unit_disk_x. One preimage: both
// warps are injective (the rescaled quintic has no fold).
template <class T> struct CutDiskPreimage {
  T left_area;
  T density;
  T right_area;  // pi - left_area, without cancellation
};
template <class T, CutDiskInverse M> CutDiskPreimage<T> cut_disk_preimage(T x, T hh) {
  if constexpr (M == CutDiskInverse::kExact) {
    return {unit_disk_area_left_of(x, hh), T(1), unit_disk_area_left_of(-x, hh)};
  } else {
    // q = 1 - |x|, from hh when that is more accurate; solve q = g(pi/2 - t^3) t^2 for t = er^(1/3) (smooth in
    // t, so Newton converges near the disk's edge where dx/da is infinite), t in [0, e0^(1/3)].
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

// ---- ComputeGeometry (Alg. 1) and the per-light precomputation (Sec. 3.7) ----------------------------------

namespace projected_cap_detail {
// The pieces of a view, with their u0 ranges and left-area maps a = alpha + beta u0. With the exact inverse these
// are Alg. 2-4's: ellipse a = u0 (A_E + A_D) / A_E * A_E' = u0 A_E' / tau, disk a = (1 - u0) A_D / (1 - tau)
// (= total (1 - u0)), lune a = (1 - u0) A_D. With the quintic the same maps end at the left-areas where the
// quintic reaches the cuts (quintic_area_*), so that the pieces meet exactly; tau is the same.
template <class T> struct Piece {
  int kind;
  T u_lo, u_hi, alpha, beta;
  T right_hi = T(0);  // pieces with alpha = 0: the right-area pi - a at u_hi, without cancellation
};
}  // namespace projected_cap_detail

template <class T> struct ProjectedCapView {
  NoSample reason = NoSample::kNone;
  int which_case = 4;       // 1: entirely above, 2: mostly above, 3: mostly below (Sec. 3.2)
  SphereView<T> sphere;     // validation, distance, the cap (shared with the sphere kernels)
  Vec3<T> x, y, z;          // local frame (Alg. 1)
  T h = T(0), w_dx = T(0);  // n.w_d and the horizontal length of w_d
  T r_x = T(0), r_y = T(0), r_z = T(0), c_x = T(0), c_z = T(0), t_x = T(0), t_y = T(0), v = T(0);
  // Pieces: ellipse (Cases 1-2, u0 in [0, tau)), mirrored disk (Case 2, u0 in [tau, 1]), lune (Case 3).
  T area_e = T(0), area_e_unit = T(0), area_d = T(0), total = T(0), tau = T(0);
  // The left-areas at which the rescaled quintic reaches the cuts exactly (Cases 2-3; see "The quintic of
  // Alg. 5" above): X(quintic_area_e_unit) = X_t for the ellipse, X(quintic_area_d) = -t_x for the disk.
  T quintic_area_e_unit = T(0), quintic_area_d = T(0);
  // pi - area_e_unit and pi - quintic_area_e_unit, without cancellation (the ellipse piece's right-areas at tau).
  T right_e_unit = T(0), quintic_right_e_unit = T(0);
  // Case 3: z scale k = (c_z + r_z) / t_y, c_z + r_z and r_z - c_z. Cases 1-2: c_z - r_z, the height of the
  // ellipse's point d_x = 1 (lowest point of the cap's boundary), = (h^2 - r_y^2) / (h v + w_dx r_y).
  T k = T(0), top = T(0), rz_minus_cz = T(0), cz_minus_rz = T(0);
  // Case 3: s_y^2 = (t_y + m d_z) / (t_y + d_z) with m = (c_z + r_z) / (r_z - c_z), its 1 - m, and 1 - k^2
  // (header comment; each >= 0, so the lune's w_x is a sum of squares).
  T sy_m = T(0), sy_one_minus_m = T(0), one_minus_k2 = T(0);
  // 1 - c_x = 1 - w_dx v = (h^2 + w_dx^2 r_y^2) / (1 + w_dx v), for the inverse of the ellipse piece.
  T one_minus_cx = T(0);
  // float: the quintic sampler's pieces (projected_cap_detail::pieces<T, kQuintic>), formed once per light (Sec.
  // 3.7's split) instead of per sample (Case 2's maps divide by tau and 1 - tau): float q_z = 0.1 at 500 samples per
  // light 40.4 -> 35.2 ns. Not for double and long double: there it cost 20-35 ns per light at 1 sample per light
  // (double, warpcheck_bench, q_z = 2: 204 -> 224 ns, -0.1: 346 -> 379 ns; cause not found), so they form them per
  // sample as before.
  std::array<projected_cap_detail::Piece<T>, 2> quintic_pieces{};
  int quintic_piece_count = 0;

  bool valid() const { return reason == NoSample::kNone; }
  Vec3<T> to_world(const Vec3<T>& w) const { return w.x() * x + w.y() * y + w.z() * z; }
  Vec3<T> to_local(const Vec3<T>& w) const { return Vec3<T>(w.dot(x), w.dot(y), w.dot(z)); }
  // The normaliser of Cases 1-2 (A_E + A_D, the projected solid angle); Case 3 has none (non-uniform density).
  T projected_solid_angle_if_uniform() const { return which_case <= 2 ? total : T(0); }
};

namespace projected_cap_detail {

// Scale invariance (our change, not in the paper). Alg. 1 reads the light only through w_d = d / |d| and
// r_y = r / |d|, d = c - x, which do not change when d and r are multiplied by the same power of two; that product
// is exact (barring underflow). make_sphere_view forms |d|, d / |d| and r / |d| in T, which is accurate for d in
// T's normal range but not for subnormal coordinates, where every intermediate carries an absolute rounding of
// denorm_min / 2: d = (1, 3, -1) denorm_min has |d| = sqrt(11) denorm_min, rounded to 3 denorm_min, so w_d came
// out of length 1.106 and r_y = 2/3 instead of 0.603 (fuzz_projected_cap_double 07252d59, 8df1478e, issue 7).
// The view is therefore built from x' = 0, c' = d 2^-e and r' = r 2^-e with |d|_inf in [1/2, 1): every later
// quantity (|d'|, r' / |d'|, squares) is of unit scale, whatever the coordinates' magnitude (subnormal, or ~1e209
// where |d|^2 overflows). d itself is formed in T from the inputs, as before: its rounding is the input's
// conditioning (exact when the difference is subnormal). r' is capped at 4 (> |d'| <= sqrt(3): x inside the light
// either way, no overflow) and at least denorm_min (r' / |d'| then squares to 0: kTooSmall, as unscaled).
// Returns the exponent e (0 where the geometry is passed on unchanged for make_sphere_view to reject).
template <class T> int unit_scale_geometry(const SphereLightGeometry<T>& g, SphereLightGeometry<T>& out) {
  out = g;
  const T r = g.light.radius;
  if (!all_finite(g.light.center) || !all_finite(g.shading.position) || !std::isfinite(r) || !(r > T(0))) return 0;
  const Vec3<T> d = g.light.center - g.shading.position;
  if (!all_finite(d)) return 0;  // the difference overflowed
  const T m = d.cwiseAbs().maxCoeff();
  if (!(m > T(0))) return 0;  // x at the centre: inside the light
  int e = 0, er = 0;
  std::frexp(m, &e);
  std::frexp(r, &er);  // r < 2^er
  out.shading.position = Vec3<T>::Zero();
  out.light.center = ldexp(d, -e);
  out.light.radius = er - e > 2 ? T(4) : std::max(std::ldexp(r, -e), std::numeric_limits<T>::denorm_min());
  return e;
}

}  // namespace projected_cap_detail

namespace projected_cap_detail {
template <class T, CutDiskInverse M> int pieces(const ProjectedCapView<T>& p, std::array<Piece<T>, 2>& out);
}  // namespace projected_cap_detail

template <class T> ProjectedCapView<T> make_projected_cap_view(const SphereLightGeometry<T>& g) {
  ProjectedCapView<T> p;
  SphereLightGeometry<T> unit;
  const int scale_exponent = projected_cap_detail::unit_scale_geometry(g, unit);
  p.sphere = make_sphere_view(unit);
  if (!p.sphere.valid()) return p.reason = p.sphere.reason, p;
  p.sphere.distance = std::ldexp(p.sphere.distance, scale_exponent);  // |c - x| in the caller's units
  const SphereView<T>& s = p.sphere;
  const Vec3<T> wd = s.frame.z;
  p.z = s.normal;
  // The horizontal part of w_d, n x (w_d x n) (= w_d - (n.w_d) n for unit n). For a light (nearly) overhead the
  // true horizontal part can be far below eps. One Gram-Schmidt pass (or subtracting the clamped height, when the
  // rounded w_d has n.w_d = 1 + ulp) leaves a rounding residue ~eps along n that outweighs it, turning x towards
  // n (found by the worst-case search precision-sphere-projected-cap-double-angle: long double x came out
  // (-0.225, 0, 0.974) for an overhead light, 0.65 rad between the double and long double samples). A second
  // pass is not enough when the light is overhead to rounding (w_d x n ~ eps): the first residue is then noise,
  // and the second pass leaves ~eps of it in any direction, along n too (found by fuzz_projected_cap_double,
  // issue 7: x parallel to n, y = 0, a sample at n.w = -1 for a cap of 90 deg overhead). An outer cross product
  // with n is orthogonal to n up to eps of its own length whatever the inner one holds, so x is horizontal to
  // rounding even where its direction is noise, and as accurate as w_d's horizontal components (absolute eps in
  // each component of w_d x n; exact for an axis-aligned normal). No threshold below which x is replaced: a
  // threshold depends on eps_T, so float/double and long double would choose different x's between their
  // thresholds, which is the same O(1) rotation of the samples this fixes; x is replaced only when the
  // horizontal part is exactly 0.
  const T h_raw = p.z.dot(wd);
  const Vec3<T> horizontal = p.z.cross(Vec3<T>(wd.cross(p.z)));
  p.h = std::clamp(h_raw, T(-1), T(1));
  p.w_dx = horizontal.stableNorm();
  // x from the horizontal part scaled to [1/2, 1) by a power of two: exact, so x is bit for bit horizontal / w_dx
  // for a normal horizontal part. A subnormal one carries few significant bits: (t, t, 0) with t = denorm_min has
  // the rounded norm t, and x came out (1, 1, 0), of length sqrt 2 (found by fuzz_projected_cap_double 613804bc:
  // a light overhead to 1e-318, w_d and n with subnormal horizontal components, sampled 0.11 rad outside its
  // cap, issue 7).
  if (p.w_dx > T(0)) {
    int ex = 0;
    std::frexp(horizontal.cwiseAbs().maxCoeff(), &ex);
    const Vec3<T> scaled = ldexp(horizontal, -ex);
    p.x = scaled / scaled.stableNorm();
  } else {
    p.x = Frame<T>::from_z(p.z).x;  // overhead: any horizontal x
  }
  p.y = p.z.cross(p.x);
  p.r_y = std::sqrt(s.sin2_theta_max);
  p.v = s.cos_theta_max;
  p.r_x = p.h * p.r_y, p.r_z = p.w_dx * p.r_y, p.c_x = p.w_dx * p.v, p.c_z = p.h * p.v;
  const T h = p.h, ry = p.r_y, v = p.v;
  if (h <= -ry) return p.reason = NoSample::kBelowHorizon, p;  // Case 4 (make_sphere_view catches it first)
  // r_y^2 - h^2 = w_dx^2 - v^2 (h^2 + w_dx^2 = r_y^2 + v^2 = 1), each form from the smaller operands: for a large
  // cap (r_y ~ 1) seen overhead (h ~ 1), r_y - h would cancel through r_y's rounding (1.4e-5 in float pdfs of
  // near-touching, ProjectedCapFloat test); near the case boundary r_y = |h| both cancel (inherent).
  const T chord2 = ry < v ? (ry - std::abs(h)) * (ry + std::abs(h)) : (p.w_dx - v) * (p.w_dx + v);
  if (h >= T(0)) p.cz_minus_rz = -chord2 / (h * v + p.w_dx * ry);
  p.one_minus_cx = (h * h + p.w_dx * p.w_dx * ry * ry) / (T(1) + p.w_dx * v);
  // Cases 2-3 divide by w_dx (w_dx > v >= 0 when h < r_y). With w_dx = 0 the rounded w_d is n (up to the
  // rounding of the cross product), so h < r_y can only be the rounding of h = 1 against r_y = 1: an overhead
  // light touching the horizon, Case 1 (found by fuzz_projected_cap_float with r_y = 1 in float, UBSan's
  // float-divide-by-zero in t_x = v / w_dx once x came from the cross product, issue 7).
  if (h >= ry || !(p.w_dx > T(0))) {
    // Case 1 (Alg. 3): the whole ellipse; t_x >= 1 is never needed.
    p.which_case = 1;
    p.area_e_unit = kPi<T>;
    p.area_e = p.r_x * p.r_y * kPi<T>;
    p.total = p.area_e;
    p.tau = T(1);
  } else {
    // chord2 = r_y^2 - h^2 > 0 (above)
    p.t_x = v / p.w_dx;  // w_dx >= v > 0 here
    p.t_y = std::sqrt(chord2) / p.w_dx;
    p.area_d = cut_disk_area_from_angle(std::atan2(std::sqrt(chord2), v));  // pi/2 - A(t_x)
    p.quintic_area_d = cut_disk_preimage<T, CutDiskInverse::kQuintic>(-p.t_x, p.t_y).left_area;
    if (h >= T(0)) {
      // Case 2 (Alg. 2). A_E' = pi/2 + A(X_t) = pi - C(theta_E), X_t = cos(theta_E) = v h / (r_y w_dx).
      p.which_case = 2;
      p.right_e_unit = cut_disk_area_from_angle(std::atan2(std::sqrt(chord2), v * h));
      p.area_e_unit = kPi<T> - p.right_e_unit;
      // X_t and its half-height sqrt(1 - X_t^2) (header comment).
      const CutDiskPreimage<T> qe =
          cut_disk_preimage<T, CutDiskInverse::kQuintic>(v * h / (ry * p.w_dx), std::sqrt(chord2) / (ry * p.w_dx));
      p.quintic_area_e_unit = qe.left_area;
      p.quintic_right_e_unit = qe.right_area;
      p.area_e = p.r_x * p.r_y * p.area_e_unit;
      p.total = p.area_e + p.area_d;
      // Both areas can underflow to 0 (r_y = 7.5e-155, r_x = 0): tau only for a positive total, which is tested
      // below (found by fuzz_projected_cap_double under UBSan's float-divide-by-zero, issue 7).
      p.tau = p.total > T(0) ? p.area_e / p.total : T(0);
    } else {
      // Case 3 (Alg. 4).
      p.which_case = 3;
      p.rz_minus_cz = p.w_dx * ry - h * v;
      p.top = chord2 / p.rz_minus_cz;                    // c_z + r_z
      p.k = std::sqrt(chord2) * p.w_dx / p.rz_minus_cz;  // (c_z + r_z) / t_y
      // Header comment (Case 3 without cancellation): m = (c_z + r_z) / (r_z - c_z), 1 - m = -2 h v / (r_z - c_z),
      // 1 - k^2 = q (2 v w_dx r_y / (r_z - c_z) - h (v^2 + w_dx^2) / (r_z - c_z)) with q = -h / (r_z - c_z); all
      // terms >= 0 for h < 0, and no square of r_z - c_z (which underflows for r_y ~ 1e-154).
      p.sy_m = p.top / p.rz_minus_cz;
      p.sy_one_minus_m = T(-2) * h * v / p.rz_minus_cz;
      const T q3 = -h / p.rz_minus_cz;
      p.one_minus_k2 = q3 * (T(2) * v * p.w_dx * (ry / p.rz_minus_cz) + q3 * (v * v + p.w_dx * p.w_dx));
      p.total = p.area_d;
      p.tau = T(0);
    }
  }
  if (!(p.total > T(0)) || !std::isfinite(p.total)) return p.reason = NoSample::kTooSmall, p;
  if constexpr (std::is_same_v<T, float>)
    p.quintic_piece_count = projected_cap_detail::pieces<T, CutDiskInverse::kQuintic>(p, p.quintic_pieces);
  return p;
}

// ---- The pieces: cut disk <-> local direction --------------------------------------------------------------

namespace projected_cap_detail {

// Case 3 (Alg. 4): s_y at d_z, s_y^2 = (t_y + m d_z) / (t_y + d_z), and 1 - s_y^2 = (1 - m) d_z / (t_y + d_z), both
// without cancellation (header comment). t_y + d_z >= t_y >= sqrt(denorm_min) wherever Case 3 has an area (r_y^2 -
// h^2 > 0), so its reciprocal is finite; the guard keeps a lune without width from dividing by zero (found by
// fuzz_projected_cap_double under UBSan's float-divide-by-zero, issue 7).
template <class T> struct Case3Sy { T s_y, one_minus_sy2; };
template <class T> Case3Sy<T> case3_sy(const ProjectedCapView<T>& p, T d_z) {
  const T den = p.t_y + d_z;
  if (!(den > T(0))) return {T(0), T(0)};
  if constexpr (std::is_same_v<T, float>) {
    // float (issue 9): two divisions side by side instead of a reciprocal and products after it (shorter chain)
    return {std::sqrt((p.t_y + p.sy_m * d_z) / den), p.sy_one_minus_m * d_z / den};
  }
  const T inv = T(1) / den;
  const T r = d_z * inv;  // in [0, 1]
  return {std::sqrt(p.t_y * inv + p.sy_m * r), p.sy_one_minus_m * r};
}

// Piece geometry: 0 ellipse, 1 mirrored disk, 2 Case-3 lune. Maps a cut-disk point to a local direction and
// gives the projected-solid-angle density from the INVERSE disk density (per unit area and unit u0), with one
// division.
template <class T> struct Local {
  Vec3<T> w;
  T pdf_proj;
  // pdf_proj = pdf_num / pdf_den before its rounding (pdf_den > 0 wherever pdf_proj > 0), for the float sampler's
  // one division w_z pdf_num / pdf_den.
  T pdf_num = T(1), pdf_den = T(0);
  // |w|^2 with the radicand of w's last square root in place of that component's square: known one square root
  // earlier than w (the float sampler renormalises with it); equal to |w|^2 up to the root's rounding.
  T norm2 = T(1);
};

// The cut-disk point is (d_x, d_y) with d_y = (2 u1 - 1) hh and hh = sqrt(1 - d_x^2) as Alg. 5 returns it.
// Heights are computed without the cancellation of 1 - w_x^2 - w_y^2 (absolute error eps, so relative error
// eps / w_z^2 near the horizon: 1.5e-4 in float pdfs at the rim of case tangent-horizon, and for a tiny light
// straddling the horizon, w_x ~ 1 - 1e-6, no significant digit of w_z at all), by exact identities:
//  * unit disk: 1 - d_x^2 - d_y^2 = hh^2 (1 - (2 u1 - 1)^2) = 4 hh^2 u1 (1 - u1), so d_z = 2 hh sqrt(u1 (1 - u1));
//  * ellipse (w_x = r_x d_x + c_x, w_y = r_y d_y; h^2 + w_dx^2 = v^2 + r_y^2 = 1):
//      1 - w_x^2 - w_y^2 = (c_z - r_z d_x)^2 + r_y^2 (1 - d_x^2 - d_y^2),
//    a sum of squares, where c_z - r_z d_x = (c_z - r_z) + r_z hh^2 / (1 + d_x) for d_x > 0 (c_z - r_z from the
//    view, without cancellation) and c_z + r_z |d_x| otherwise. The identity is ours (not in the paper).
// one_minus_abs_dx: 1 - |d_x| if the caller has it without cancellation, else negative (then hh^2 / (1 + d_x) is
// used for d_x > 0); hh2: hh^2 if the caller has it before hh (then the ellipse's height does not wait for hh),
// else negative.
template <class T> Local<T> disk_to_local(const ProjectedCapView<T>& p, int piece, T dx, T hh, T u1, T inv_disk_density,
                                          T one_minus_abs_dx = T(-1), T hh2 = T(-1)) {
  Local<T> o;
  const T dy = (T(2) * u1 - T(1)) * hh;
  const auto disk_z = [&] { return T(2) * hh * std::sqrt(u1 * (T(1) - u1)); };  // d_z (the ellipse may not need it)
  if (piece == 0) {
    const T wx = p.r_x * dx + p.c_x, wy = p.r_y * dy;
    T low;
    if (one_minus_abs_dx >= T(0)) {
      // c_z - r_z + r_z (1 - d_x) for d_x > 0, c_z + r_z |d_x| otherwise, with |d_x| = 1 - (1 - |d_x|) rounded as
      // the cut disk rounds it: both as b + r_z v, b and v selected by a 0/1 weight t (exact: v = (1 - t) + (2 t - 1)
      // (1 - |d_x|) is 1 - |d_x| or 1 - (1 - |d_x|)), without a branch on the random sign of d_x (the compiler kept
      // one for a plain ?:) and with the selection of b done before 1 - |d_x| is known.
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
    // 1 - w_y^2 - w_z^2 = d_x^2 + (1 - s_y^2) d_y^2 + (1 - k^2) d_z^2 on the unit sphere: a sum of squares (header
    // comment), where 1 - w_y^2 - w_z^2 lost eps / w_x^2 of w_x's digits (a Case-3 sample pdf 2e-9 off at
    // w_x = 3.5e-4, fuzz_projected_cap_double 71f5a077; 2e-5 at w_x = 1.5e-6, 8b269b33; issue 7).
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
    // Where the lune has no width in T (s_y = 0) or d_x = 0 the density is not representable: 0, which the
    // sampler turns into "no sample" (it divided by zero, fuzz_projected_cap_double under UBSan, issue 7).
    const T den = inv_disk_density * (p.k * p.k) * s_y * std::abs(dx);
    o.pdf_num = w_x, o.pdf_den = den;
    o.pdf_proj = den > T(0) ? w_x / den : T(0);
  }
  return o;
}

// Inverse of disk_to_local: the cut-disk point (d_x, d_y) of a local direction w, and the area factor
// (projected area per disk area); false when w is not in the piece's image of the unit disk.
// Like disk_to_local, without cancellation where the direction's own digits allow it: for w_x > 1/2 the ellipse's
// d_x = (w_x - c_x) / r_x is written ((1 - c_x) - (1 - w_x)) / r_x with 1 - w_x = (w_y^2 + w_z^2) / (1 + w_x)
// and 1 - c_x from the view (a light of angular radius 2e-3 has r_x ~ 1e-6 near the horizon, below float's
// resolution of w_x ~ 1), and the unit disk's half-height at d_x is sqrt(d_y^2 + d_z^2) (= sqrt(1 - d_x^2) on
// the unit sphere, without the cancellation of 1 - d_x^2 when |d_x| ~ 1).
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
    // d_x^2 = 1 - d_y^2 - d_z^2 = w_x^2 - (1 - s_y^2) d_y^2 - (1 - k^2) d_z^2 for a unit w (disk_to_local's identity):
    // rounding eps w_x^2 instead of eps, i.e. within the inherent 2 eps w_x of w_x's own digits (d_x ~ w_x near
    // the lune's flat side, where the warp is near the identity).
    const T rest = w.x() * w.x() - sy.one_minus_sy2 * (dy * dy) - p.one_minus_k2 * (d_z * d_z);
    if (!(rest >= T(0))) return false;
    dx = -std::sqrt(rest);
    area_factor = p.k * p.k * s_y * std::abs(dx) / w.x();
    hh = std::sqrt(dy * dy + d_z * d_z);
  }
  return std::abs(dy) <= hh && std::isfinite(area_factor) && area_factor > T(0);
}

// The pieces of a view: see Piece (declared before ProjectedCapView, which stores the quintic's pieces).
// Every piece's map is a = beta u0 (alpha = 0) or a = alpha (1 - u0) (alpha = -beta); the second is evaluated in
// that form: 1 - u0 is exact for u0 >= 1/2, where a is small, and alpha + beta u0 cancels there (relative error
// eps / (1 - u0) in a: 1.7e-3 in float at u0 = 1 - 3.6e-5, which moved float samples near the disk's edge and
// put their pdfs 3e-4 off the long double ones; ProjectedCapFloat test).
template <class T> T piece_left_area(const Piece<T>& pc, T u0) {
  return pc.alpha == T(0) ? pc.beta * u0 : pc.alpha * (T(1) - u0);
}
// pi - a for the same u0: for alpha = 0, right_hi + beta (u_hi - u0) (u_hi - u0 exact near u_hi, where a is
// near pi); otherwise a <= pi/2 and pi - a does not cancel.
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
      // tau rounds to 1 when A_D < eps A_E / 2: the disk piece then has no u0 range (and 1 / (1 - tau) is a
      // division by zero, found by fuzz_projected_cap_double under UBSan, issue 7); its share of the
      // normaliser is below rounding. area_e > 0 there, so the ellipse piece exists.
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

// Density (per projected solid angle) of local direction w.
// Optionally returns the first preimage (u0, u1).
// The pieces tile the projected cap, so at most one reaches w, except on the seam (measure zero) where the
// first one is taken.
template <class T, CutDiskInverse M> T pdf_local(const ProjectedCapView<T>& p, const Vec3<T>& w, Vec2<T>* u = nullptr) {
  std::array<Piece<T>, 2> ps{};
  const int n = pieces<T, M>(p, ps);
  for (int i = 0; i < n; ++i) {
    const Piece<T>& pc = ps[i];
    T dx, dy, hh, area;
    if (!local_to_disk(p, pc.kind, w, dx, dy, hh, area)) continue;
    const CutDiskPreimage<T> pre = cut_disk_preimage<T, M>(dx, hh);
    // A piece a = beta u0 (alpha = 0) covers left-areas [0, beta u_hi], i.e. right-areas >= right_hi; compared as
    // right-areas, because its end is near pi, where left-areas lose the cut: a Case-2 disk piece of area 6.4e-16
    // lies within one ulp of pi (4.4e-16) in left-area, so the ellipse piece claimed all of it and pdf() returned
    // the ellipse's density there (sample pdf 0.55 x pdf(direction), tau = 1 - 2^-53 for a share of 2.0e-16;
    // confirming campaign of issue 7, 2026-12-02). The other pieces (a = alpha (1 - u0) <= pi/2) keep left-areas.
    if (pc.alpha == T(0)) {
      if (pre.right_area < pc.right_hi) continue;
    } else {
      const T a_lo = std::min(piece_left_area(pc, pc.u_lo), piece_left_area(pc, pc.u_hi));
      const T a_hi = std::max(piece_left_area(pc, pc.u_lo), piece_left_area(pc, pc.u_hi));
      if (pre.left_area < a_lo || pre.left_area > a_hi) continue;
    }
    if (u) {
      (*u)[0] =
          std::clamp(pc.alpha == T(0) ? pre.left_area / pc.beta : T(1) - pre.left_area / pc.alpha, pc.u_lo, pc.u_hi);
      (*u)[1] = hh > T(0) ? std::clamp((dy / hh + T(1)) / T(2), T(0), T(1)) : T(0.5);
    }
    // |beta| area underflows to 0 for a piece whose left-area scale is subnormal (a float lune piece with
    // alpha = 9e-44, fuzz_projected_cap_float aad9b177, issue 9's float path moved a grazing sample into it): the
    // density there is not representable. 0, which the callers made of the infinite quotient before, without the
    // division by zero.
    const T den = std::abs(pc.beta) * area;
    return den > T(0) ? pre.density / den : T(0);
  }
  return T(0);
}

}  // namespace projected_cap_detail

// ---- SampleProjectedSphericalCap (Alg. 6), per-sample part ----------------------------------------------------

template <class T, CutDiskInverse M = CutDiskInverse::kQuintic>
DirectionSample<T> sample_projected_spherical_cap(const ProjectedCapView<T>& p, const Vec2<T>& u) {
  using namespace projected_cap_detail;
  if (!p.valid()) return DirectionSample<T>::none(p.reason);
  if (!std::isfinite(u[0]) || !std::isfinite(u[1])) return DirectionSample<T>::none(NoSample::kNonFinite);
  const T u0 = std::min(std::max(u[0], T(0)), T(1)), u1 = std::min(std::max(u[1], T(0)), T(1));  // clamps
  // float with the quintic (issue 9's speed target): the pieces stored in the view (see quintic_pieces), and below
  // 1 - d_x = q from the cut disk (no division), the pdf by one division instead of two, and the renormalisation of
  // a direction that is unit to rounding by one Newton step (core.h). Double and long double keep the earlier path
  // (disk_to_local's defaults -1: 1 - d_x and hh^2 unknown).
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

// Inverse map: the primary sample (u0, u1) that the warp with inverse M maps to w. False outside the support. With M =
// kExact applied to samples of the quintic warp, u0 measures the quintic's error in primary sample space.
template <class T, CutDiskInverse M = CutDiskInverse::kQuintic>
bool invert_projected_spherical_cap(const ProjectedCapView<T>& p, const Vec3<T>& w, Vec2<T>& u) {
  if (!p.valid() || !all_finite(w)) return false;
  const Vec3<T> wl = p.to_local(w.normalized());
  if (!(wl.z() >= T(0))) return false;
  return projected_cap_detail::pdf_local<T, M>(p, wl, &u) > T(0);
}

// A cap containing every direction the sampler returns: the light's cap, its angular radius widened by 64 eps_T
// for rounding. The pieces tile the light's projection exactly (also with the quintic: its ranges end at the
// cuts), so no more is needed; and no more is wanted: the battery's quadrature over this cap must see the support
// reach the cap's edge (an earlier 2% widening of 1 - cos left the Case-3 sliver's support a thin band inside the
// cap, which the quadrature missed: pdf-integral 2.75e-4 low on case3-sliver, double).
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
  static constexpr bool kQuintic = M == CutDiskInverse::kQuintic;
  static constexpr const char* name = kQuintic ? "sphere-projected-cap" : "sphere-projected-cap-exact";
  static constexpr const char* description = kQuintic
                                                 ? "projected solid angle, Peters & Dachsbacher 2019 (quintic)"
                                                 : "projected solid angle, Peters & Dachsbacher 2019 (exact inverse)";
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

}  // namespace warpcheck
