#!/usr/bin/env bash
# Runs the kernel benchmarks (Google Benchmark JSON into data/bench/results.json) and prints the ratio table
# (validation/tools/bench_table.cpp).
#   scripts/bench.sh                      build dir build/, --benchmark_min_time=0.5s
#   BUILD=build-bench MIN_TIME=0.05 scripts/bench.sh [extra benchmark args, e.g. --benchmark_filter=sphere]
# Builds warpcheck_bench and bench_table with one job. Timings on a loaded machine are unreliable: the JSON
# records the context (CPU count, load) that Google Benchmark reports.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="$ROOT/${BUILD:-build}"
MIN_TIME="${MIN_TIME:-0.5}"
if [[ ! -f "$BUILD_DIR/build.ninja" ]]; then
  cmake -S "$ROOT" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
ninja -C "$BUILD_DIR" -j1 warpcheck_bench bench_table >/dev/null
mkdir -p "$ROOT/data/bench"
"$BUILD_DIR/warpcheck_bench" --benchmark_min_time="$MIN_TIME" --benchmark_out="$ROOT/data/bench/results.json" \
  --benchmark_out_format=json --benchmark_format=console "$@" >/dev/null
"$BUILD_DIR/bench_table" "$ROOT/data/bench/results.json"
