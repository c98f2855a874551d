// fuzz/targets/polygon-projected-solid-angle-biased.h: fuzz_polygon-projected-solid-angle-biased_{float,double},
// polygon lights by projected solid angle, the biased variant of Peters 2021 Sec. 6.4. Samples lie in the polygon
// clipped to the shading horizon. The byte after the geometry chose this variant when one target checked both: it is
// read and ignored, so that the stored inputs decode as they did.
#pragma once

#include "checks/polygon.h"
#include "warpcheck/polygon_projected.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<PolygonProjectedSolidAngleBiased> {
  template <class T> static void check(FuzzedDataProvider& in) {
    const PolygonLightGeometry<T> g = decode_polygon_geometry<T>(in);
    (void)in.ConsumeIntegralInRange<int>(0, 3);
    const PolygonProjectedView<T> v = make_polygon_projected_view<T, true>(g);
    check_polygon_kernel<T>(
        in, g, PolygonProjectedSolidAngleBiased<T>::name, true, PolygonDensity::kCosine,
        [&](const Vec2<T>& u) { return sample_polygon_projected_solid_angle<T, true>(v, u, 0); },
        [&](const Vec3<T>& w) { return pdf_polygon_projected_solid_angle(v, w); });
  }
};

}  // namespace warpcheck::fuzz
