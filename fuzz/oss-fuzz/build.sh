#!/bin/bash -eu
# Builds every fuzz target (fuzz/targets/<kernel>.h, fuzz_<kernel>_{float,double}) in the OSS-Fuzz layout, with
# the environment OSS-Fuzz and ClusterFuzzLite give a project's build.sh:
#   CXX, CXXFLAGS        compiler and flags (clang, the sanitizer and -fsanitize=fuzzer-no-link for libFuzzer)
#   LIB_FUZZING_ENGINE   the engine to link (-fsanitize=fuzzer for libFuzzer)
#   OUT                  where the binaries go; beside each, <target>_seed_corpus.zip (data/fuzz/<target>/corpus)
#                        and <target>.dict (data/fuzz/<target>/dict)
#   SRC                  not read: the source tree is the one this script is in
# Optional: WARPCHECK_FUZZ_JOBS compiles at once (default: nproc), EIGEN_INCLUDE (default /usr/include/eigen3),
# WARPCHECK_FUZZ_KERNELS the kernels to build (space-separated names of fuzz/targets/*.h; default: all).
# Needs Eigen 3.4 and Boost headers, zip. The targets are header-only: each is fuzz/oss-fuzz/target.cpp compiled
# with the kernel, trait and scalar as macros; the trait's name is the kernel's in CamelCase (as fuzz/CMakeLists.txt
# derives it), and a static_assert in the source rejects a wrong one. Stored findings (regressions/) are not
# part of the seed corpus: the replay test runs them.
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
jobs=${WARPCHECK_FUZZ_JOBS:-$(nproc)}
eigen=${EIGEN_INCLUDE:-/usr/include/eigen3}
mkdir -p "$OUT"

# One target: compile, link, corpus and dictionary. $1 kernel, $2 scalar.
build_target() {
  local kernel=$1 scalar=$2
  local target=fuzz_${kernel}_${scalar} trait
  trait=$(sed -E 's/(^|-)([a-z0-9])/\U\2/g' <<<"$kernel")
  local obj
  obj=$(mktemp --suffix=.o)
  # shellcheck disable=SC2086 # CXXFLAGS and LIB_FUZZING_ENGINE are lists of flags
  $CXX $CXXFLAGS -std=c++20 -I"$root/fuzz" -I"$root/lib" -I"$eigen" \
    "-DWARPCHECK_FUZZ_TARGET_HEADER=\"targets/$kernel.h\"" "-DWARPCHECK_FUZZ_KERNEL=\"$kernel\"" \
    "-DWARPCHECK_FUZZ_TRAIT=$trait" "-DWARPCHECK_FUZZ_SCALAR=$scalar" -c "$root/fuzz/oss-fuzz/target.cpp" -o "$obj"
  # shellcheck disable=SC2086
  $CXX $CXXFLAGS "$obj" $LIB_FUZZING_ENGINE -o "$OUT/$target"
  rm -f "$obj"
  local data=$root/data/fuzz/$target
  rm -f "$OUT/${target}_seed_corpus.zip"
  if [ -d "$data/corpus" ] && [ -n "$(ls -A "$data/corpus")" ]; then
    (cd "$data/corpus" && zip -q -r "$OUT/${target}_seed_corpus.zip" .)
  fi
  if [ -f "$data/dict" ]; then cp "$data/dict" "$OUT/$target.dict"; fi
  echo "built $target"
}
export -f build_target
export root eigen CXX CXXFLAGS LIB_FUZZING_ENGINE OUT

kernels=${WARPCHECK_FUZZ_KERNELS:-$(basename -s .h "$root"/fuzz/targets/*.h)}
for kernel in $kernels; do
  [ -f "$root/fuzz/targets/$kernel.h" ] || { echo "build.sh: no fuzz target fuzz/targets/$kernel.h" >&2; exit 2; }
done
for kernel in $kernels; do
  printf '%s float\n%s double\n' "$kernel" "$kernel"
done | xargs -P "$jobs" -L 1 bash -euc 'build_target "$0" "$1"'
