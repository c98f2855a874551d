#!/usr/bin/env bash
# The README's main command: set up, build, and run the whole validation battery on every kernel and
# configuration, writing results/results.json. Extra arguments go to `warpcheck validate`.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$ROOT/scripts/setup.sh"
mkdir -p "$ROOT/results"
status=0
"$BUILD_DIR/warpcheck" validate --json "$ROOT/results/results.json" "$@" || status=$?
echo "[battery] results in $ROOT/results/results.json (exit $status)"
"$BUILD_DIR/warpcheck" report --out "$ROOT/results/report" --from "$ROOT/results/results.json" --data "$ROOT/data"
exit $status
