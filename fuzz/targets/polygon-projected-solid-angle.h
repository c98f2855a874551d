// fuzz/targets/polygon-projected-solid-angle.h: fuzz_polygon-projected-solid-angle_{float,double}, polygon lights by
// projected solid angle, Peters 2021 Sec. 3, with 0 to 4 tangent-line iterations (the catalogue's configuration has 2).
// Samples lie in the polygon clipped to the shading horizon. The byte after the geometry chose the biased variant when
// one target checked both: it is read and ignored, so that the stored inputs decode as they did.
#pragma once

#include "checks/polygon.h"
#include "warpcheck/polygon_projected.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<PolygonProjectedSolidAngle> {
  template <class T> static void check(FuzzedDataProvider& in) {
    const PolygonLightGeometry<T> g = decode_polygon_geometry<T>(in);
    (void)in.ConsumeIntegralInRange<int>(0, 3);
    const int iterations = in.ConsumeIntegralInRange<int>(0, 4);
    const PolygonProjectedView<T> v = make_polygon_projected_view<T, false>(g);
    check_polygon_kernel<T>(
        in, g, PolygonProjectedSolidAngle<T>::name, true, PolygonDensity::kCosine,
        [&](const Vec2<T>& u) { return sample_polygon_projected_solid_angle<T, false>(v, u, iterations); },
        [&](const Vec3<T>& w) { return pdf_polygon_projected_solid_angle(g, w); });
  }
};

}  // namespace warpcheck::fuzz
