// fuzz/targets/sphere-projected-cap.h: fuzz_sphere-projected-cap_{float,double}, a sphere light by projected solid
// angle, Peters & Dachsbacher 2019 with the paper's quintic (Alg. 5); the checks are fuzz/checks/projected_cap.h's.
#pragma once

#include "checks/projected_cap.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<SphereProjectedCap> {
  template <class T> static void check(FuzzedDataProvider& in, const Mutation& mutate = {}) {
    check_projected_cap<SphereProjectedCap<T>>(in, mutate);
  }
};

}  // namespace warpcheck::fuzz
