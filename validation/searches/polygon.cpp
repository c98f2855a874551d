// Worst-case searches of Peters 2021's decentral inversion (searches.h): the backward error after k iterations.
#include <cmath>
#include <numbers>
#include <optional>
#include <span>
#include <string>

#include "searches/objective.h"
#include "warpcheck/polygon_error_analysis.h"
#include "warpcheck/polygon_projected.h"
#include "warpcheck/validation/searches.h"

namespace warpcheck::validation {

namespace {

// ---- Peters 2021 Sec. 3.6: backward error of the decentral inversion -------------------------------------
//
// The paper's 6-D space (rotational symmetry removed): inner and outer ellipse, sector, target area. We give
// each ellipse by its great circle's unit normal n = (sin t cos a, sin t sin a, cos t), tilt t in [0, pi/2]
// (pi/2 is the zenith case, which our homogeneous ellipses handle), i.e. u = n_xy / n_z of the paper, so the
// box covers every ellipse. The sector runs from s0 = (1, 0) counterclockwise over the given angle, the target
// is A = xi * (sector area). Constraints (as in the paper): sector <= 179.999 deg, area >= min_area, and the
// inner ellipse inside the outer one across the sector (else the case is no polygon's). With a_l = n_l,xy . w,
// "inside" is n_o,z^2 a_i^2 >= n_i,z^2 a_o^2, i.e. f1 f2 >= 0 with the linear forms
// f1,2 = (n_o,z n_i,xy -+ n_i,z n_o,xy) . w. On an arc below 180 degrees a linear form has at most one zero,
// so it keeps its sign iff it does at both ends: we check f1 and f2 at s0, s1 and their product at the middle.
// And each edge's own half of its ellipse: an edge's points q in the upper hemisphere satisfy
// n_xy . q_xy = -n_z q_z, so n_xy . w has one sign over every direction w that reaches the edge; the sector,
// bounded by the rays through the polygon's vertices, lies within the edge's azimuth range, so n_l,xy . w must
// not change sign across it (same test at s0 and s1). Without this constraint the search finds its worst cases
// (7.8e-2 after two iterations) in sectors containing the direction where the outer edge's great circle meets the
// horizon, i.e. the tip of its ellipse: no polygon has such a sector.
std::vector<SearchParameter> sector_parameters() {
  constexpr L max_tilt = std::numbers::pi_v<L> / 2;
  return {{"inner_tilt", 0, max_tilt, "inner edge normal: angle from the zenith (rad)"},
          {"inner_azimuth", -std::numbers::pi_v<L>, std::numbers::pi_v<L>, "inner edge normal: azimuth (rad)"},
          {"outer_tilt", 0, max_tilt, "outer edge normal: angle from the zenith (rad)"},
          {"outer_azimuth", -std::numbers::pi_v<L>, std::numbers::pi_v<L>, "outer edge normal: azimuth (rad)"},
          {"sector_deg", 0, 179.999L, "sector opening angle from s0 = (1, 0), counterclockwise (degrees)"},
          {"xi", 0, 1, "target area A = xi * sector area"}};
}

std::optional<RandomSectorCase<L>> sector_case(std::span<const L> p, L min_area) {
  auto normal = [](L tilt, L az) {
    return EdgeEllipse<L>{Vec2<L>(std::sin(tilt) * std::cos(az), std::sin(tilt) * std::sin(az)), std::cos(tilt)};
  };
  ProjectedSector<L> s;
  s.decentral = true;
  s.inner = normal(p[0], p[1]);
  s.outer = normal(p[2], p[3]);
  const L angle = p[4] * kDeg;
  s.s0 = Vec2<L>(1, 0);
  s.s1 = Vec2<L>(std::cos(angle), std::sin(angle));
  const Vec2<L> mid(std::cos(angle / 2), std::sin(angle / 2));
  const Vec2<L> d1 = s.outer.nz * s.inner.nxy - s.inner.nz * s.outer.nxy;
  const Vec2<L> d2 = s.outer.nz * s.inner.nxy + s.inner.nz * s.outer.nxy;
  // A form that vanishes at s0 or s1 up to rounding does not change sign: the first and last sectors of every
  // decentral polygon end where the inner and outer ellipse meet (f1 = 0 there, computed as -1e-20 in about half
  // of them; test PolygonBackwardSearch.EverySectorOfARealPolygonIsAPointOfTheSearchAndNoOtherIs).
  auto changes_sign = [&](const Vec2<L>& f) {
    const L a = f.dot(s.s0), b = f.dot(s.s1), tol = 64 * std::numeric_limits<L>::epsilon() * f.norm();
    return std::abs(a) > tol && std::abs(b) > tol && a * b < 0;
  };
  if (changes_sign(d1) || changes_sign(d2) || d1.dot(mid) * d2.dot(mid) < 0) return std::nullopt;
  if (changes_sign(s.inner.nxy) || changes_sign(s.outer.nxy)) return std::nullopt;
  // The sector's area exactly as make_polygon_projected_view computes it.
  const L cross = kahan_cross2(s.s0, s.s1);
  const L sine = cross > 0 ? cross : L(0);
  s.area = std::max(L(0), area_between_ellipses<L>(s, s.s0, s.s1, sine));
  if (!(s.area >= min_area)) return std::nullopt;
  return RandomSectorCase<L>{s, p[5] * s.area};
}

Search polygon_backward_search(int k, L min_area, const char* name, const char* paper) {
  Search s;
  s.name = name;
  s.description =
      "Peters 2021 Sec. 3.6: backward error |A_delta| / sector area (Eq. 7) of the decentral inversion after " +
      std::to_string(k) + " iteration(s), long double; sectors <= 179.999 deg, area >= " +
      (min_area >= 1e-3L ? std::string("1e-2") : std::string("1e-7"));
  s.paper = paper;
  s.parameters = sector_parameters();
  s.objective = [k, min_area](std::span<const L> p) -> L {
    const auto c = sector_case(p, min_area);
    if (!c) return kNaN;
    const L e = decentral_backward_error(*c, k);
    return std::isfinite(e) ? e : kInf;
  };
  return s;
}

// No separate search for the biased variant (Sec. 6.4) per sector: its initialisation sees the target only
// through xi = A / A_sector, which the approximate atan2 leaves unchanged, so its per-sector backward error is
// exactly that of polygon-backward-k0 (data/polygon/claims.json shows identical statistics).

}  // namespace

void append_polygon_searches(std::vector<Search>& v) {
  v.push_back(polygon_backward_search(0, 1e-2L, "polygon-backward-k0", "Peters 2021 Sec. 3.6: 0.27 (no iteration)"));
  v.push_back(polygon_backward_search(1, 1e-2L, "polygon-backward-k1", "not published"));
  v.push_back(polygon_backward_search(2, 1e-2L, "polygon-backward-k2",
                                      "Peters 2021 Sec. 3.6: 1.8e-5 (two iterations, area >= 1e-2)"));
  v.push_back(polygon_backward_search(3, 1e-2L, "polygon-backward-k3",
                                      "not published (Sec. 3.6: a third iteration for double-precision renderers)"));
  v.push_back(polygon_backward_search(2, 1e-7L, "polygon-backward-k2-area1e-7",
                                      "Peters 2021 Sec. 3.6: 6.6e-5 (two iterations, area >= 1e-7)"));
}

}  // namespace warpcheck::validation
