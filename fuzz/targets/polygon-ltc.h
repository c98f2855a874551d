// fuzz/targets/polygon-ltc.h: fuzz_polygon-ltc_{float,double}, polygon lights by a linearly transformed cosine, Peters
// 2021 Sec. 4.1; the checks are fuzz/checks/ltc.h's.
#pragma once

#include "checks/ltc.h"

namespace warpcheck::fuzz {

template <> struct FuzzTarget<PolygonLtc> {
  template <class T> static void check(FuzzedDataProvider& in, const Mutation& mutate = {}) {
    check_ltc<T>(in, mutate);
  }
};

}  // namespace warpcheck::fuzz
