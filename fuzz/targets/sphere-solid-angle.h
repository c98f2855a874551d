// fuzz/targets/sphere-solid-angle.h: fuzz_sphere-solid-angle_{float,double}, Shirley 1996 Sec. 3.2.2, uniform in the
// solid angle of a sphere light (lib/warpcheck/sphere.h); the checks are fuzz/checks/sphere.h's.
#pragma once

#include "checks/sphere.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<SphereSolidAngle> {
  template <class T> static void check(FuzzedDataProvider& in) { check_sphere<T>(in, SphereKernel::kSolidAngle); }
};

}  // namespace warpcheck::fuzz
