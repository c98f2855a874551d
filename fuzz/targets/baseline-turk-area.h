// fuzz/targets/baseline-turk-area.h: fuzz_baseline-turk-area_{float,double}, the baseline Turk 1992 (uniform area
// sampling, density per solid angle), as published. Its findings are recorded (triage "known"), not fixed.
#pragma once

#include "checks/polygon.h"
#include "warpcheck/polygon_solid_angle.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<BaselineTurkArea> {
  template <class T> static void check(FuzzedDataProvider& in) {
    const PolygonLightGeometry<T> g = decode_polygon_geometry<T>(in);
    const TurkAreaView<T> v = make_turk_area_view(g);
    check_polygon_kernel<T>(
        in, g, BaselineTurkArea<T>::name, false, PolygonDensity::kArea,
        [&](const Vec2<T>& u) { return sample_turk_area(v, u); },
        [&](const Vec3<T>& w) { return pdf_turk_area(g, w); });
  }
};

}  // namespace warpcheck::fuzz
