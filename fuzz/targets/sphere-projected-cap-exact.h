// fuzz/targets/sphere-projected-cap-exact.h: fuzz_sphere-projected-cap-exact_{float,double}, a sphere light by
// projected solid angle, Peters & Dachsbacher 2019 with the exact inverse of the cut-disk area; the checks are
// fuzz/checks/projected_cap.h's.
#pragma once

#include "checks/projected_cap.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<SphereProjectedCapExact> {
  template <class T> static void check(FuzzedDataProvider& in, const Mutation& mutate = {}) {
    check_projected_cap<SphereProjectedCapExact<T>>(in, mutate);
  }
};

}  // namespace warpcheck::fuzz
