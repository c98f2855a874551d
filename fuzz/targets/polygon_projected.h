// fuzz/targets/polygon_projected.h: projected-solid-angle sampling of polygons, Peters 2021 Section 3 (with 0
// to 4 tangent-line iterations; the paper's default is 2) and the biased variant of Section 6.4
// (lib/warpcheck/polygon_projected.h). Samples lie in the polygon clipped to the shading horizon.
#pragma once

#include "common_polygon.h"
#include "warpcheck/polygon_projected.h"

namespace warpcheck::fuzz {

template <class T> void check_polygon_projected(FuzzedDataProvider& in) {
  PolygonLightGeometry<T> g;
  g.light = decode_polygon<T>(in);
  g.shading = decode_polygon_shading<T>(in, g.light);
  const bool biased = in.ConsumeIntegralInRange<int>(0, 3) == 0;
  if (biased) {
    const PolygonProjectedView<T> v = make_polygon_projected_view<T, true>(g);
    check_polygon_kernel<T>(
        in, g, "polygon_projected_biased", true, PolygonDensity::kCosine,
        [&](const Vec2<T>& u) { return sample_polygon_projected_solid_angle<T, true>(v, u, 0); },
        [&](const Vec3<T>& w) { return pdf_polygon_projected_solid_angle(v, w); });
  } else {
    const int iterations = in.ConsumeIntegralInRange<int>(0, 4);
    const PolygonProjectedView<T> v = make_polygon_projected_view<T, false>(g);
    check_polygon_kernel<T>(
        in, g, "polygon_projected", true, PolygonDensity::kCosine,
        [&](const Vec2<T>& u) { return sample_polygon_projected_solid_angle<T, false>(v, u, iterations); },
        [&](const Vec3<T>& w) { return pdf_polygon_projected_solid_angle(g, w); });
  }
}

}  // namespace warpcheck::fuzz
