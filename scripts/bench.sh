#!/usr/bin/env bash
# Runs the kernel benchmarks (Google Benchmark JSON into data/bench/) and prints the ratio table
# (validation/tools/bench_table.cpp) for each build variant:
#   portable     build dir $BUILD (default build/), the project's flags (no -march): results.json
#   x86-64-v3    build dir $BUILD-x86-64-v3, -march=x86-64-v3 -ffp-contract=off (FMA, AVX2: std::fma is one
#                instruction; no other product is fused, as GCC would by default for C++ on an FMA target):
#                results-x86-64-v3.json.
#   scripts/bench.sh                               portable only; 5 interleaved repetitions of 0.1 s, medians
#   VARIANTS="portable x86-64-v3" scripts/bench.sh  both builds, one after the other
#   BUILD=build-bench MIN_TIME=0.05 REPETITIONS=3 scripts/bench.sh [extra benchmark args, e.g.
#                                                  --benchmark_filter=sphere]
# Builds warpcheck_bench and bench_table with one job. Timings on a loaded machine are unreliable: compare ratios
# within one run (the table's), not absolute times across runs; the JSON records the context (CPU count, load,
# compile flags).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_BASE="$ROOT/${BUILD:-build}"
MIN_TIME="${MIN_TIME:-0.1}"
REPETITIONS="${REPETITIONS:-5}"
LAUNCHER=()
if command -v ccache >/dev/null; then LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
mkdir -p "$ROOT/data/bench"
for variant in ${VARIANTS:-portable}; do
  case "$variant" in
    portable) build_dir="$BUILD_BASE" flags="" out="$ROOT/data/bench/results.json" ;;
    x86-64-v3) build_dir="$BUILD_BASE-x86-64-v3" flags="-march=x86-64-v3 -ffp-contract=off" out="$ROOT/data/bench/results-x86-64-v3.json" ;;
    *) echo "bench.sh: unknown variant $variant (portable, x86-64-v3)" >&2 && exit 2 ;;
  esac
  configure() {  # build dir, CMAKE_CXX_FLAGS
    [[ -f "$1/build.ninja" ]] ||
      cmake -S "$ROOT" -B "$1" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS="$2" "${LAUNCHER[@]}" >/dev/null
  }
  configure "$build_dir" "$flags"
  configure "$BUILD_BASE" ""
  # The table tool does not depend on the flags: the portable build's serves both.
  ninja -C "$build_dir" -j1 warpcheck_bench >/dev/null
  ninja -C "$BUILD_BASE" -j1 bench_table >/dev/null
  "$build_dir/warpcheck_bench" --benchmark_min_time="$MIN_TIME" --benchmark_repetitions="$REPETITIONS" \
    --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=false \
    --benchmark_out="$out" --benchmark_out_format=json --benchmark_format=console "$@" >/dev/null
  echo "== $variant =="
  "$BUILD_BASE/bench_table" "$out"
done
