// fuzz/targets/polygon-solid-angle-clipped.h: fuzz_polygon-solid-angle-clipped_{float,double}, polygon lights by solid
// angle, Peters 2021 Sec. 5, clipped to the shading horizon. The byte after the geometry chose whether to clip when one
// target checked both: it is read and ignored, so that the stored inputs decode as they did.
#pragma once

#include "checks/polygon.h"
#include "warpcheck/polygon_solid_angle.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<PolygonSolidAngleClipped> {
  template <class T> static void check(FuzzedDataProvider& in) {
    const PolygonLightGeometry<T> g = decode_polygon_geometry<T>(in);
    (void)in.ConsumeBool();
    const PolygonSolidAngleView<T> v = make_polygon_solid_angle_view(g, true);
    check_polygon_kernel<T>(
        in, g, PolygonSolidAngleClipped<T>::name, true, PolygonDensity::kConstant,
        [&](const Vec2<T>& u) { return sample_polygon_solid_angle(v, u); },
        [&](const Vec3<T>& w) { return pdf_polygon_solid_angle(g, w, true); });
  }
};

}  // namespace warpcheck::fuzz
