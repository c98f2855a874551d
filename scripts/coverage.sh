#!/usr/bin/env bash
# Line and branch coverage of lib/ (gcc --coverage, gcovr), measured twice:
#   tests    the default test run (ctest -L fast) with battery.every_case at 10^4 samples instead of 10^6
#            (coverage needs no statistics; the cases are the same);
#   battery  warpcheck validate on every named configuration and RANDOM random geometries per family (default 4,
#            as scripts/battery.sh runs the battery), at SAMPLES samples per case (default 10^4: which paths a case
#            takes, not whether it passes).
# Writes coverage/{tests,battery}.json (gcovr's JSON), coverage/summary.md (the table per kernel header for the
# README) and coverage/untaken.md (the branches of lib/'s sample and pdf functions that the battery never takes, each
# with its reason from data/coverage/untaken-reasons.tsv), and both to data/coverage/summary.json, which the HTML
# report shows (commit it with the measured commit's figures).
# Usage: scripts/coverage.sh [--random N] [--samples N]; BUILD_DIR (default build-coverage). Takes long: a
# separate unoptimised-ish build (-O1) of the tests and the CLI, then both runs under gcov's counters. The counters
# are updated atomically: the battery's threads otherwise race on them, and gcov then reports negative counts that
# gcovr refuses.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${BUILD_DIR:-$ROOT/build-coverage}"
OUT="$ROOT/coverage"
RANDOM_N=4  # as scripts/battery.sh runs the battery
SAMPLES=10000
while [ $# -gt 0 ]; do
  case "$1" in
    --random) RANDOM_N="$2"; shift 2 ;;
    --samples) SAMPLES="$2"; shift 2 ;;
    *) echo "usage: scripts/coverage.sh [--random N] [--samples N]" >&2; exit 2 ;;
  esac
done
command -v gcovr >/dev/null || { echo "[coverage] installing gcovr"; apt-get install -y -q gcovr >/dev/null; }

LAUNCHER=""
command -v ccache >/dev/null && LAUNCHER=-DCMAKE_CXX_COMPILER_LAUNCHER=ccache
cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_FLAGS="-O1 -g --coverage -fprofile-update=atomic" \
  -DCMAKE_EXE_LINKER_FLAGS=--coverage -DWARPCHECK_WARNINGS_AS_ERRORS=OFF $LAUNCHER >/dev/null
ninja -C "$BUILD" -j"${JOBS:-2}" warpcheck warpcheck_tests warpcheck_fuzz_replay warpcheck_fuzz_tests
mkdir -p "$OUT"

# gcovr over lib/ only; branches the compiler adds for exceptions and unreachable code are left out.
collect() {
  gcovr --root "$ROOT" --object-directory "$BUILD" --filter "$ROOT/lib/" --exclude-throw-branches \
    --exclude-unreachable-branches --json "$OUT/$1.json" >/dev/null
  find "$BUILD" -name '*.gcda' -delete
}

# warpcheck validate as JOBS single-threaded processes, one shard each: the atomic counters make threads of one
# process contend (a sphere case at 10^6 samples: 2.4 s of CPU on one thread, 9.3 s on two), while processes merge
# their counts into the .gcda files when they exit. Failing tests are results here, not errors.
validate_in_shards() {
  local jobs="${JOBS:-2}" i
  for ((i = 0; i < jobs; i++)); do "$BUILD/warpcheck" "$@" --threads 1 --shard "$i/$jobs" & done
  wait || true
}

find "$BUILD" -name '*.gcda' -delete
echo "[coverage] default test run (battery.every_case at 10^4 samples)"
(cd "$BUILD" && ctest -L fast -E '^battery\.every_case$' -j"${JOBS:-2}" --output-on-failure >"$OUT/tests.log" 2>&1) ||
  echo "[coverage] some tests failed under coverage (see coverage/tests.log)"
validate_in_shards validate --samples 10000 --quiet >>"$OUT/tests.log" 2>&1
collect tests

echo "[coverage] battery: named configurations and --random $RANDOM_N at $SAMPLES samples"
validate_in_shards validate --random "$RANDOM_N" --samples "$SAMPLES" --quiet >"$OUT/battery.log" 2>&1
collect battery

COMMIT="$(git -C "$ROOT" rev-parse --short=8 HEAD)$(git -C "$ROOT" diff --quiet HEAD -- lib || echo ' with changes to lib/')"
mkdir -p "$ROOT/data/coverage"
python3 "$ROOT/scripts/coverage_summary.py" "$OUT/tests.json" "$OUT/battery.json" "$OUT/summary.md" "$OUT/untaken.md" \
  "random $RANDOM_N, $SAMPLES samples" --root "$ROOT" --reasons "$ROOT/data/coverage/untaken-reasons.tsv" \
  --json "$ROOT/data/coverage/summary.json" --commit "$COMMIT"
cat "$OUT/summary.md"
echo "[coverage] untaken sampling-path branches: $OUT/untaken.md"
