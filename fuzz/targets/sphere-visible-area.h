// fuzz/targets/sphere-visible-area.h: fuzz_sphere-visible-area_{float,double}, uniform in the area of the visible cap
// of a sphere light (lib/warpcheck/sphere.h); the checks are fuzz/checks/sphere.h's.
#pragma once

#include "checks/sphere.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<SphereVisibleArea> {
  template <class T> static void check(FuzzedDataProvider& in) { check_sphere<T>(in, SphereKernel::kVisibleArea); }
};

}  // namespace warpcheck::fuzz
