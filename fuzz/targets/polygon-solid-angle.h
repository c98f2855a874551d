// fuzz/targets/polygon-solid-angle.h: fuzz_polygon-solid-angle_{float,double}, polygon lights by solid angle,
// Peters 2021 Sec. 5, the whole polygon; the checks are fuzz/checks/polygon.h's.
#pragma once

#include "checks/polygon.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<PolygonSolidAngle> {
  template <class T> static void check(FuzzedDataProvider& in) { check_polygon_solid_angle<T, false>(in); }
};

}  // namespace warpcheck::fuzz
