// fuzz/targets/polygon-solid-angle-clipped.h: fuzz_polygon-solid-angle-clipped_{float,double}, polygon lights by solid
// angle, Peters 2021 Sec. 5, clipped to the shading horizon; the checks are fuzz/checks/polygon.h's.
#pragma once

#include "checks/polygon.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<PolygonSolidAngleClipped> {
  template <class T> static void check(FuzzedDataProvider& in) { check_polygon_solid_angle<T, true>(in); }
};

}  // namespace warpcheck::fuzz
