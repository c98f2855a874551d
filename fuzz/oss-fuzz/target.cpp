// One libFuzzer target, chosen by macros: WARPCHECK_FUZZ_TARGET_HEADER (its header as a string literal,
// "targets/sphere-solid-angle.h"), WARPCHECK_FUZZ_KERNEL (the kernel's catalogue name, "sphere-solid-angle"),
// WARPCHECK_FUZZ_TRAIT (its trait's C++ name, SphereSolidAngle) and WARPCHECK_FUZZ_SCALAR (float or double).
// fuzz/oss-fuzz/build.sh compiles this file once per target; the static_assert of WARPCHECK_FUZZ_ASSERT_NAMED
// rejects a trait that is not the kernel's.
#include WARPCHECK_FUZZ_TARGET_HEADER
#include "entry.h"

WARPCHECK_FUZZ_ASSERT_NAMED(WARPCHECK_FUZZ_KERNEL, WARPCHECK_FUZZ_TRAIT);
WARPCHECK_FUZZ_ENTRY(warpcheck::fuzz::FuzzTarget<warpcheck::WARPCHECK_FUZZ_TRAIT>::check<WARPCHECK_FUZZ_SCALAR>)
