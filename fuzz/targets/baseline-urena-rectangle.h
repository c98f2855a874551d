// fuzz/targets/baseline-urena-rectangle.h: fuzz_baseline-urena-rectangle_{float,double}, the baseline Urena et al. 2013
// (spherical rectangles), as published. Inputs lean to rectangles. Its findings are recorded (triage "known"), not
// fixed.
#pragma once

#include "checks/polygon.h"
#include "warpcheck/spherical_rectangle.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<BaselineUrenaRectangle> {
  template <class T> static void check(FuzzedDataProvider& in) {
    const bool rectangle_bias = in.ConsumeIntegralInRange<int>(0, 7) != 0;
    const PolygonLightGeometry<T> g = decode_polygon_geometry<T>(in, rectangle_bias);
    const SphericalRectangleView<T> v = make_spherical_rectangle_view(g);
    check_polygon_kernel<T>(
        in, g, BaselineUrenaRectangle<T>::name, false, PolygonDensity::kConstant,
        [&](const Vec2<T>& u) { return sample_spherical_rectangle(v, u); },
        [&](const Vec3<T>& w) { return pdf_spherical_rectangle(g, w); });
  }
};

}  // namespace warpcheck::fuzz
