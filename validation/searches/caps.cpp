// Worst-case searches for spherical caps (searches.h): the projected-spherical-cap sampler of Peters &
// Dachsbacher 2019 and the cap invariance of spherical pivot transforms (Dupuy, Heitz & Belcour 2017).
//
//  projected-cap-quintic       Peters & Dachsbacher 2019 Sec. 3.6: max over A in [0, pi/2] of |X(A) - X_quintic(A)|,
//                              X the exact inverse of A(X) = X sqrt(1 - X^2) + asin X; the paper: 4.6e-5.
//  projected-cap-case3-ratio   Sec. 3.5: p(u) / p(u') divided by the paper's bound on max p / min p,
//                              (c_x - r_x) / t_x sqrt((t_x - (c_x + r_x)) / -r_x), for Case-3 caps; must stay
//                              <= 1. Evaluated with the exact cut-disk inverse (CutDiskInverse::kExact): the bound
//                              is about Alg. 4's warp, and the quintic's own density factor (up to ~1.5e-4
//                              away from 1, see projected_cap.h) is not part of it.
//  sptd-cap-invariance         Dupuy et al. 2017 Eqs. 6-7: a point on the boundary of a cap C must map onto the
//                              boundary of the image cap g(C); the angle (rad) by which g(w) misses it.
#include <cmath>

#include "searches/objective.h"
#include "warpcheck/projected_cap.h"
#include "warpcheck/sptd.h"
#include "warpcheck/validation/searches.h"

namespace warpcheck::validation {

namespace {

constexpr L kPiL = std::numbers::pi_v<L>;

L angle_between(const Vec3<L>& a, const Vec3<L>& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

Search quintic_search() {
  Search s;
  s.name = "projected-cap-quintic";
  s.description =
      "Peters & Dachsbacher 2019 Sec. 3.6 (Alg. 5): |X(A) - X_quintic(A)| over A in [0, pi/2], X the exact "
      "inverse of A(X) = X sqrt(1 - X^2) + asin X (Boost.Math Newton), long double";
  s.paper = "Peters & Dachsbacher 2019 Sec. 3.6: 4.6e-5 (quintic)";
  s.parameters = {{"A", 0, kPiL / 2, "offset area A of Alg. 5 (left-area pi/2 + A)"}};
  s.objective = [](std::span<const L> p) -> L {
    const L left = kPiL / 2 + p[0];
    const L xq = paper_quintic_x<L>(left);  // the published fit, not the sampler's rescaled form
    const L xe = sample_cut_unit_disk_x<L, CutDiskInverse::kExact>(left).x;
    const L e = std::abs(xq - xe);
    return std::isfinite(e) ? e : kInf;
  };
  return s;
}

Search case3_search() {
  Search s;
  s.name = "projected-cap-case3-ratio";
  s.description =
      "Peters & Dachsbacher 2019 Sec. 3.5 (Alg. 4): p(u) / p(u') / bound, p the density per projected solid "
      "angle of the Case-3 warp (exact cut-disk inverse), bound = (c_x - r_x) / t_x sqrt((t_x - (c_x + r_x)) "
      "/ -r_x); must stay <= 1";
  s.paper = "Peters & Dachsbacher 2019 Sec. 3.5: max p / min p <= bound (proved in their supplement)";
  s.parameters = {
      {"log10_distance_over_radius", std::log10(1.0001L), 3, "log10(d / r), unit radius"},
      {"depth", 0, 1, "h = -depth * r / d: the centre's height below the horizon as a fraction of sin(theta_max)"},
      {"u0", 0, 1, "first sample, first coordinate"},
      {"u1", 0, 1, "first sample, second coordinate"},
      {"v0", 0, 1, "second sample, first coordinate"},
      {"v1", 0, 1, "second sample, second coordinate"}};
  s.objective = [](std::span<const L> p) -> L {
    const L d = std::pow(L(10), p[0]), h = -p[1] / d;
    SphereLightGeometry<L> g{ShadingPoint<L>{Vec3<L>::Zero(), Vec3<L>(0, 0, 1)},
                             SphereLight<L>{d * Vec3<L>(std::sqrt((1 - h) * (1 + h)), 0, h), 1}};
    const ProjectedCapView<L> v = make_projected_cap_view(g);
    if (!v.valid() || v.which_case != 3) return kNaN;
    auto proj_pdf = [&](L a, L b) -> L {
      const DirectionSample<L> smp = sample_projected_spherical_cap<L, CutDiskInverse::kExact>(v, Vec2<L>(a, b));
      if (!smp.valid()) return kNaN;
      const L z = v.to_local(smp.direction).z();
      return z > 0 ? smp.pdf / z : kNaN;
    };
    const L p1 = proj_pdf(p[2], p[3]), p2 = proj_pdf(p[4], p[5]);
    if (std::isnan(p1) || std::isnan(p2)) return kNaN;
    // The bound's (t_x - (c_x + r_x)) / -r_x cancels catastrophically as h -> 0- (to 0 at depth 3e-21). Exact
    // algebra with Alg. 1's t_x = v / w_dx, c_x = w_dx v, r_x = h r_y, w_dx^2 + h^2 = 1: t_x - c_x = v h^2 / w_dx,
    // so the quotient is 1 + v |h| / (w_dx r_y).
    const L bound = (v.c_x - v.r_x) / v.t_x * std::sqrt(1 + v.v * std::abs(v.h) / (v.w_dx * v.r_y));
    const L r = p1 / p2 / bound;
    return std::isfinite(r) ? r : kInf;
  };
  return s;
}

Search sptd_invariance_search() {
  Search s;
  s.name = "sptd-cap-invariance";
  s.description =
      "Dupuy, Heitz & Belcour 2017 Eqs. 2, 6-7: angle (rad) between g(w) and the boundary of g(C) for w on "
      "the boundary of C, long double";
  s.paper = "Dupuy et al. 2017: exact (the pivot transform maps caps to caps)";
  s.parameters = {{"pivot_radius", 0, 0.99L, "|r_p|"},
                  {"pivot_polar", 0, kPiL, "polar angle of r_p (rad)"},
                  {"pivot_azimuth", -kPiL, kPiL, "azimuth of r_p (rad)"},
                  {"cap_polar", 0, kPiL, "polar angle of the cap axis (rad)"},
                  {"cap_azimuth", -kPiL, kPiL, "azimuth of the cap axis (rad)"},
                  {"cap_half_angle", 1e-3L, kPiL - 1e-3L, "half-angle of C (rad)"},
                  {"boundary_angle", -kPiL, kPiL, "position of w on the boundary of C (rad)"}};
  s.objective = [](std::span<const L> p) -> L {
    auto dir = [](L polar, L az) {
      return Vec3<L>(std::sin(polar) * std::cos(az), std::sin(polar) * std::sin(az), std::cos(polar));
    };
    const Vec3<L> rp = p[0] * dir(p[1], p[2]);
    const Vec3<L> axis = dir(p[3], p[4]);
    const L alpha = p[5];
    const Cap<L> c{axis, 2 * std::sin(alpha / 2) * std::sin(alpha / 2)};  // 1 - cos without cancellation
    const Frame<L> f = Frame<L>::from_z(axis);
    const Vec3<L> w = std::cos(alpha) * axis + std::sin(alpha) * (std::cos(p[6]) * f.x + std::sin(p[6]) * f.y);
    const Cap<L> image = pivot_transform_cap(c, rp);
    const Vec3<L> gw = pivot_transform(w, rp);
    if (!all_finite(gw) || !all_finite(image.axis) || !std::isfinite(image.one_minus_cos)) return kInf;
    const L image_alpha = 2 * std::asin(std::sqrt(std::clamp(image.one_minus_cos / 2, L(0), L(1))));
    return std::abs(angle_between(gw.normalized(), image.axis.normalized()) - image_alpha);
  };
  return s;
}

}  // namespace

void append_cap_searches(std::vector<Search>& v) {
  v.push_back(quintic_search());
  v.push_back(case3_search());
  v.push_back(sptd_invariance_search());
}

}  // namespace warpcheck::validation
