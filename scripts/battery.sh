#!/usr/bin/env bash
# The README's main command: set up, build, and run the whole validation battery on every kernel and
# configuration, writing reports/results.json, the kernels' sample sets reports/sample-sets.json and the HTML
# report reports/html/index.html (all ignored by git).
# Extra arguments go to `warpcheck validate`.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$ROOT/scripts/setup.sh"
status=0
# Besides the named configurations, WARPCHECK_RANDOM (default 4) random geometries per kernel family, in double and
# long double (README, "Random geometries"); a later --random in the arguments wins.
"$BUILD_DIR/warpcheck" validate --random "${WARPCHECK_RANDOM:-4}" --json "$ROOT/reports/results.json" "$@" || status=$?
echo "[battery] results in $ROOT/reports/results.json (exit $status)"
"$BUILD_DIR/sample_sets" --out "$ROOT/reports/sample-sets.json" --from "$ROOT/reports/results.json"
"$BUILD_DIR/warpcheck" report --out "$ROOT/reports/html" --from "$ROOT/reports/results.json" --data "$ROOT/data" \
  --sample-sets "$ROOT/reports/sample-sets.json"
exit $status
