// fuzz/targets/baseline-arvo-triangle.h: fuzz_baseline-arvo-triangle_{float,double}, the baseline Arvo 1995 (spherical
// triangles, as a fan), as published. Its findings are recorded (triage "known"), not fixed.
#pragma once

#include "checks/polygon.h"
#include "warpcheck/polygon_solid_angle.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<BaselineArvoTriangle> {
  template <class T> static void check(FuzzedDataProvider& in) {
    const PolygonLightGeometry<T> g = decode_polygon_geometry<T>(in);
    const ArvoFanView<T> v = make_arvo_fan_view(g);
    check_polygon_kernel<T>(
        in, g, BaselineArvoTriangle<T>::name, false, PolygonDensity::kConstant,
        [&](const Vec2<T>& u) { return sample_arvo_triangle_fan(v, u); },
        [&](const Vec3<T>& w) { return pdf_arvo_triangle_fan(g, w); });
  }
};

}  // namespace warpcheck::fuzz
