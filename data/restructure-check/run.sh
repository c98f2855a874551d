#!/usr/bin/env bash
# The restructure's acceptance check: every registry case at 10^6 samples through the warpcheck binary before the
# restructure (2760acf) and after it (f34b2b65, the restructure alone: the later quadrature changes alter expected
# counts on purpose), compared result by result with scripts/compare_results.py.
#
# Each binary takes hours of CPU, so the run is resumable across machines: the partial results are stored here,
# compressed and without the residual maps (which --resume does not need), and a run continues from them.
#   data/restructure-check/run.sh run   [WORK]   build both binaries in WORK (default /tmp/restructure-check) and run
#                                                 both sides, one thread each, kernel by kernel, at nice 19
#   data/restructure-check/run.sh store [WORK]   store WORK's partial results here (after a run, or while it runs)
#   data/restructure-check/run.sh compare        compare the stored results
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
WORK="${2:-/tmp/restructure-check}"
declare -A COMMIT=([before]=2760acf [after]=f34b2b65)
KERNELS=(sphere-solid-angle sphere-visible-area sptd-uniform-cap sptd-cosine-cap sptd-phase sptd-phase-sphere-light
         sphere-projected-cap sphere-projected-cap-exact polygon-ltc baseline-urena-rectangle baseline-arvo-triangle
         baseline-turk-area polygon-solid-angle polygon-solid-angle-clipped polygon-projected-solid-angle
         polygon-projected-solid-angle-biased)

build() {  # $1: before or after
  local tree="$WORK/$1"
  [[ -d "$tree" ]] || git -C "$ROOT" worktree add --detach "$tree" "${COMMIT[$1]}" >/dev/null
  cmake -S "$tree" -B "$tree/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DWARPCHECK_BUILD_BENCHMARKS=OFF >/dev/null
  ninja -C "$tree/build" warpcheck >/dev/null
}

# One JSON file per kernel, so that a finished kernel's results are never read back: 2760acf's --resume reads its file
# with a parser that can change a double's last bit, and rewrites it so.
side() {  # $1: before or after; runs every kernel of KERNELS in order, each into its own file
  local k
  [[ -d "$WORK/$1.results" || ! -f "$HERE/$1.json.xz" ]] || split_stored "$1"
  mkdir -p "$WORK/$1.results"
  for k in "${KERNELS[@]}"; do
    nice -n 19 "$WORK/$1/build/warpcheck" validate --kernel "$k" --samples 1000000 --threads 1 \
      --json "$WORK/$1.results/$k.json" --resume >/dev/null 2>>"$WORK/$1.log" || true  # a failing test is a result
  done
}

# The stored file of a side (all its kernels' results, no maps) into one file per kernel, and back.
split_stored() {
  mkdir -p "$WORK/$1.results"
  xz -dc "$HERE/$1.json.xz" | python3 -c '
import json, sys
doc = json.load(sys.stdin)
for k in sorted({r["kernel"] for r in doc["results"]}):
    with open(sys.argv[1] + "/" + k + ".json", "w") as f:
        json.dump(dict(doc, results=[r for r in doc["results"] if r["kernel"] == k]), f)' "$WORK/$1.results"
}
join_results() {
  python3 -c '
import glob, json, sys
docs = [json.load(open(p)) for p in sorted(glob.glob(sys.argv[1] + "/*.json"))]
out = dict(docs[0], results=[dict((k, v) for k, v in r.items() if k != "map") for d in docs for r in d["results"]])
json.dump(out, sys.stdout, separators=(",", ":"))' "$WORK/$1.results"
}

case "${1:-}" in
  run)
    mkdir -p "$WORK"
    build before && build after
    side before & side after & wait ;;
  store)
    for s in before after; do
      compgen -G "$WORK/$s.results/*.json" >/dev/null || continue
      join_results "$s" | xz -9 -c >"$HERE/$s.json.xz"
    done ;;
  compare)
    python3 "$ROOT/scripts/compare_results.py" <(xz -dc "$HERE/before.json.xz") <(xz -dc "$HERE/after.json.xz") \
      --replace registry_projected_cap.cpp=validation/catalogue/projected_cap.cpp ;;
  *) sed -n 2,11p "${BASH_SOURCE[0]}"; exit 2 ;;
esac
