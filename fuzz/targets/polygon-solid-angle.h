// fuzz/targets/polygon-solid-angle.h: fuzz_polygon-solid-angle_{float,double}, polygon lights by solid angle, Peters
// 2021 Sec. 5, the whole polygon. The byte after the geometry chose whether to clip when one target checked both: it
// is read and ignored, so that the stored inputs decode as they did.
#pragma once

#include "checks/polygon.h"
#include "warpcheck/polygon_solid_angle.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<PolygonSolidAngle> {
  template <class T> static void check(FuzzedDataProvider& in) {
    const PolygonLightGeometry<T> g = decode_polygon_geometry<T>(in);
    (void)in.ConsumeBool();
    const PolygonSolidAngleView<T> v = make_polygon_solid_angle_view(g, false);
    check_polygon_kernel<T>(
        in, g, PolygonSolidAngle<T>::name, false, PolygonDensity::kConstant,
        [&](const Vec2<T>& u) { return sample_polygon_solid_angle(v, u); },
        [&](const Vec3<T>& w) { return pdf_polygon_solid_angle(g, w, false); });
  }
};

}  // namespace warpcheck::fuzz
