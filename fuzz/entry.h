// fuzz/entry.h: the libFuzzer entry point of one target. CMake generates one source per target that includes the
// target header and this file and says WARPCHECK_FUZZ_ENTRY(warpcheck::fuzz::FuzzTarget<warpcheck::Trait>::check<T>).
//
// An InvariantViolation is printed and turned into abort(), which libFuzzer reports as a crash with the
// input saved. With -DWARPCHECK_FUZZ_TRAP_FP=ON, FE_INVALID traps (SIGFPE at the instruction that makes the
// NaN; the decoder then never produces NaN/Inf input, whose comparisons would raise FE_INVALID themselves).
#pragma once

#include <cfenv>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#define WARPCHECK_FUZZ_ENTRY(check)                                                   \
  extern "C" int LLVMFuzzerInitialize(int*, char***) {                                \
    WARPCHECK_FUZZ_ENABLE_TRAPS();                                                    \
    return 0;                                                                         \
  }                                                                                   \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { \
    FuzzedDataProvider in(data, size);                                                \
    try {                                                                             \
      check(in);                                                                      \
    } catch (const ::warpcheck::fuzz::InvariantViolation& e) {                        \
      std::fputs(e.what(), stderr);                                                   \
      std::fflush(stderr);                                                            \
      std::abort();                                                                   \
    }                                                                                 \
    return 0;                                                                         \
  }

#ifdef WARPCHECK_FUZZ_TRAP_FP
#define WARPCHECK_FUZZ_ENABLE_TRAPS() feenableexcept(FE_INVALID)
#else
#define WARPCHECK_FUZZ_ENABLE_TRAPS() ((void)0)
#endif
