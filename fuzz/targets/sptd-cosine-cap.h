// fuzz/targets/sptd-cosine-cap.h: fuzz_sptd-cosine-cap_{float,double}, a clamped-cosine spherical pivot transformed
// distribution over a cap, Dupuy et al. 2017; the checks are fuzz/checks/sptd.h's.
#pragma once

#include "checks/sptd.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<SptdCosineCap> {
  template <class T> static void check(FuzzedDataProvider& in, const Mutation& mutate = {}) {
    check_sptd<T, SptdBase::kClampedCosine>(in, mutate);
  }
};

}  // namespace warpcheck::fuzz
