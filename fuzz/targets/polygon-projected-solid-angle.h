// fuzz/targets/polygon-projected-solid-angle.h: fuzz_polygon-projected-solid-angle_{float,double}, polygon lights by
// projected solid angle, Peters 2021 Sec. 3; the checks are fuzz/checks/polygon.h's.
#pragma once

#include "checks/polygon.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<PolygonProjectedSolidAngle> {
  template <class T> static void check(FuzzedDataProvider& in) { check_polygon_projected<T, false>(in); }
};

}  // namespace warpcheck::fuzz
