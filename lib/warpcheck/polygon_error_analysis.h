// warpcheck/polygon_error_analysis.h: the empirical error analysis of Peters 2021 Sec. 3.6 and 6.4, as
// functions the tests and tools/polygon_claims.cpp share.
//
// Backward error (Sec. 3.6): |A_delta| (Eq. 7) over the sector's area, the perturbation of xi_0 that explains the
// inverted azimuth's error. Random decentral cases (ours; the paper's distribution is not stated): triangles with
// vertex directions uniform on the upper hemisphere, a sector uniformly, A = xi A_sector; like the paper, sectors
// over 179.999 degrees or of area below `min_area` (the paper: 1e-2) are discarded.
#pragma once

#include <random>

#include "warpcheck/polygon_projected.h"

namespace warpcheck {

template <class T> Vec3<T> uniform_upper_hemisphere(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(0, 1);
  const T z = T(U(rng)), phi = kTwoPi<T> * T(U(rng));
  const T r = std::sqrt(std::max(T(0), T(1) - z * z));
  return Vec3<T>(r * std::cos(phi), r * std::sin(phi), z);
}

template <class T> struct RandomSectorCase {
  ProjectedSector<T> sector;
  T target = 0;
};

template <class T> RandomSectorCase<T> random_decentral_case(std::mt19937_64& rng, T min_area) {
  std::uniform_real_distribution<double> U(0, 1);
  for (;;) {
    PolygonLightGeometry<T> g;
    g.light = PolygonLight<T>{uniform_upper_hemisphere<T>(rng), uniform_upper_hemisphere<T>(rng),
                              uniform_upper_hemisphere<T>(rng)};
    const auto v = make_polygon_projected_view<T>(g);
    if (!v.valid() || v.central || v.sector_count == 0) continue;
    const ProjectedSector<T>& s = v.sectors[std::min<int>(int(U(rng) * v.sector_count), v.sector_count - 1)];
    const T angle = std::atan2(kahan_cross2(s.s0, s.s1), s.s0.dot(s.s1));
    if (!(s.area >= min_area) || angle > T(179.999L) * kPi<T> / T(180)) continue;
    return {s, T(U(rng)) * s.area};
  }
}

// Backward error of the decentral inversion with `iterations` iterations (exact arctangents).
template <class T> T decentral_backward_error(const RandomSectorCase<T>& c, int iterations) {
  const Vec2<T> w = invert_decentral_sector<T, false>(c.sector, c.target, iterations);
  return std::abs(decentral_residual<T, false>(c.sector, c.target, w)) / c.sector.area;
}

// The biased variant (Sec. 6.4) on the same case: the initialisation computed with the approximate atan2
// (which enters through the sector area that scales the quads), judged by the exact Eq. 7.
template <class T> T decentral_backward_error_biased(const RandomSectorCase<T>& c) {
  ProjectedSector<T> approx = c.sector;
  const T cross = kahan_cross2(approx.s0, approx.s1);
  approx.area = area_between_ellipses<T, true>(approx, approx.s0, approx.s1, cross);
  const T target = c.target / c.sector.area * approx.area;  // the same xi within the sector
  const Vec2<T> w = invert_decentral_sector<T, true>(approx, target, 0);
  return std::abs(decentral_residual<T, false>(c.sector, c.target, w)) / c.sector.area;
}

// The exact azimuthal distribution function of a view: the projected solid angle between the first sector
// boundary and the ray through w_xy (local, flipped frame), divided by A_Sigma. Used to measure the biased
// variant's error as a backward error in xi_0 over the whole polygon.
template <class T> T projected_azimuth_cdf(const PolygonProjectedView<T>& v, const Vec2<T>& w) {
  T acc = 0;
  for (int k = 0; k < v.sector_count; ++k) {
    const ProjectedSector<T>& s = v.sectors[k];
    const T c0 = kahan_cross2(s.s0, w), c1 = kahan_cross2(w, s.s1);
    const Vec2<T> half = s.s0 / s.s0.norm() + s.s1 / s.s1.norm();
    if (c0 >= T(0) && c1 >= T(0) && half.dot(w) >= T(0)) {
      const T part = s.decentral ? decentral_area_to<T>(s, w) : ellipse_sector_area<T>(s.outer, s.s0, w, c0);
      return (acc + std::clamp(part, T(0), s.area)) / v.projected_solid_angle;
    }
    acc += s.area;
  }
  return acc / v.projected_solid_angle;
}

}  // namespace warpcheck
