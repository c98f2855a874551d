#!/bin/bash -eu
# The OSS-Fuzz build as OSS-Fuzz runs it (ctest fuzz_oss_fuzz_build): fuzz/oss-fuzz/build.sh with clang, the
# address sanitizer and libFuzzer's flags as OSS-Fuzz sets them (less its own libc++), into a temporary $OUT;
# then every target of fuzz/targets/ must be there in float and double with its seed corpus and dictionary, and
# each binary runs over its unzipped seed corpus (-runs=0: every input once, no fuzzing) with its dictionary
# loaded, without a crash or sanitizer report.
# CC/CXX are "ccache clang"/"ccache clang++" when ccache is installed (the test builds 28 targets; a cold build
# takes minutes): WARPCHECK_OSSFUZZ_CCACHE=0 builds without it. WARPCHECK_FUZZ_JOBS as in build.sh (default 2).
# Arguments: kernels (names of fuzz/targets/*.h) to build and check instead of all of them.
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
launcher=
if [ "${WARPCHECK_OSSFUZZ_CCACHE:-1}" != 0 ] && command -v ccache >/dev/null; then launcher="ccache "; fi
flags="-O1 -fno-omit-frame-pointer -gline-tables-only -DFUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION"
flags+=" -fsanitize=address -fsanitize-address-use-after-scope -fsanitize=fuzzer-no-link"
export CC="${launcher}clang" CXX="${launcher}clang++" CFLAGS="$flags" CXXFLAGS="$flags"
export LIB_FUZZING_ENGINE=-fsanitize=fuzzer OUT=$tmp/out SRC=$tmp/src WORK=$tmp/work
export WARPCHECK_FUZZ_JOBS=${WARPCHECK_FUZZ_JOBS:-2}
kernels=${*:-$(basename -s .h "$root"/fuzz/targets/*.h)}
export WARPCHECK_FUZZ_KERNELS=$kernels
mkdir -p "$SRC" "$WORK"
start=$(date +%s)
"$root/fuzz/oss-fuzz/build.sh" >"$tmp/build.log" 2>&1 || { cat "$tmp/build.log"; exit 1; }
echo "build.sh: $(($(date +%s) - start)) s"

fail=0
count=0
for kernel in $kernels; do
  for scalar in float double; do
    target=fuzz_${kernel}_${scalar}
    count=$((count + 1))
    for f in "$target" "${target}_seed_corpus.zip" "$target.dict"; do
      [ -e "$OUT/$f" ] || { echo "FAIL: $OUT/$f missing"; fail=1; }
    done
    [ -x "$OUT/$target" ] || continue
    corpus=$tmp/corpus/$target
    mkdir -p "$corpus"
    unzip -q "$OUT/${target}_seed_corpus.zip" -d "$corpus"
    inputs=$(find "$corpus" -type f | wc -l)
    if ! "$OUT/$target" -runs=0 -dict="$OUT/$target.dict" "$corpus" >"$tmp/$target.log" 2>&1; then
      tail -30 "$tmp/$target.log"
      echo "FAIL: $target over its $inputs seed inputs"
      fail=1
    elif ! grep -q "Dictionary: [1-9][0-9]* entries" "$tmp/$target.log"; then
      echo "FAIL: $target did not load its dictionary"
      fail=1
    else
      echo "ok: $target, $inputs seed inputs"
    fi
  done
done
built=$(find "$OUT" -maxdepth 1 -type f -executable | wc -l)
[ "$built" -eq "$count" ] || { echo "FAIL: $built binaries in \$OUT, $count targets"; fail=1; }
echo "$count targets; $(($(date +%s) - start)) s in all"
exit $fail
