// fuzz/targets/polygon-projected-solid-angle-biased.h: fuzz_polygon-projected-solid-angle-biased_{float,double},
// polygon lights by projected solid angle, the biased variant of Peters 2021 Sec. 6.4; the checks are
// fuzz/checks/polygon.h's.
#pragma once

#include "checks/polygon.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<PolygonProjectedSolidAngleBiased> {
  template <class T> static void check(FuzzedDataProvider& in) { check_polygon_projected<T, true>(in); }
};

}  // namespace warpcheck::fuzz
