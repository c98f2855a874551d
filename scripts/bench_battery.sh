#!/usr/bin/env bash
# Runs the battery's own benchmarks (validation/benchmarks/bench_battery.cpp: fixed cost per case, per-sample cost
# against the kernel's own loop, a user's sampler with an expensive pdf) and writes their Google Benchmark JSON.
#   scripts/bench_battery.sh [OUT.json] [extra benchmark args, e.g. --benchmark_filter=per_sample]
#   BUILD=build-bench scripts/bench_battery.sh data/bench/battery/after.json
# OUT.json defaults to data/bench/battery/battery.json (a folder of its own: data/bench/*.json are the kernel
# benchmarks, whose names the catalogue test checks). Builds warpcheck_bench_battery with one job. Every battery
# call runs on one thread and is timed by its CPU clock; the JSON's context records the build type, flags and load.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="$ROOT/${BUILD:-build}"
OUT="${1:-$ROOT/data/bench/battery/battery.json}"
[[ $# -gt 0 ]] && shift
if [[ ! -f "$BUILD_DIR/build.ninja" ]]; then
  cmake -S "$ROOT" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
ninja -C "$BUILD_DIR" -j1 warpcheck_bench_battery >/dev/null
mkdir -p "$(dirname "$OUT")"
"$BUILD_DIR/warpcheck_bench_battery" --benchmark_out="$OUT" --benchmark_out_format=json --benchmark_format=console "$@"
