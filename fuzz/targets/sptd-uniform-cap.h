// fuzz/targets/sptd-uniform-cap.h: fuzz_sptd-uniform-cap_{float,double}, a uniform spherical pivot transformed
// distribution over a cap, Dupuy et al. 2017, including the pivot phase function and its joint sampling with a sphere
// light; the checks are fuzz/checks/sptd.h's.
#pragma once

#include "checks/sptd.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<SptdUniformCap> {
  template <class T> static void check(FuzzedDataProvider& in, const Mutation& mutate = {}) {
    check_sptd<T, SptdBase::kUniform>(in, mutate);
  }
};

}  // namespace warpcheck::fuzz
