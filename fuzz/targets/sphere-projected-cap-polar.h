// fuzz/targets/sphere-projected-cap-polar.h: fuzz_sphere-projected-cap-polar_{float,double}, a sphere light by
// projected solid angle, Peters & Dachsbacher 2019 with Case 1 by polar coordinates (Sec. 3.4); the checks are
// fuzz/checks/projected_cap.h's.
#pragma once

#include "checks/projected_cap.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<SphereProjectedCapPolar> {
  template <class T> static void check(FuzzedDataProvider& in, const Mutation& mutate = {}) {
    check_projected_cap<SphereProjectedCapPolar<T>>(in, mutate);
  }
};

}  // namespace warpcheck::fuzz
