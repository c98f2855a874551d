#!/usr/bin/env bash
# The restructure's acceptance check: every registry case at 10^6 samples through the warpcheck binary before the
# restructure (2760acf) and after it (f34b2b65, the restructure alone: the later quadrature changes alter expected
# counts on purpose), compared result by result with scripts/compare_results.py.
#
# Each binary takes many hours of CPU, so the run is resumable across machines. Every case runs alone into its own
# JSON file, and a finished file is never read back by warpcheck (2760acf's --resume parses its file with a reader
# that can change a double's last bit); a killed case is run again. The finished cases are stored here, joined,
# compressed and without the residual maps, and a run continues from them.
#   data/restructure-check/run.sh run   [WORK]   build both binaries in WORK (default /tmp/restructure-check) and run
#                                                 the cases not yet finished, two at a time, at nice 19
#   data/restructure-check/run.sh store [WORK]   store WORK's finished cases here (after a run, or while it runs)
#   data/restructure-check/run.sh compare        compare the stored cases
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
[[ ${1:-} == one ]] || WORK="${2:-/tmp/restructure-check}"  # one: WORK from the environment
declare -A COMMIT=([before]=2760acf [after]=f34b2b65)
KERNELS=(sphere-solid-angle sphere-visible-area sptd-uniform-cap sptd-cosine-cap sphere-projected-cap
         sphere-projected-cap-exact polygon-ltc baseline-urena-rectangle baseline-arvo-triangle baseline-turk-area
         polygon-solid-angle polygon-solid-angle-clipped polygon-projected-solid-angle
         polygon-projected-solid-angle-biased)
# Cases the restructure renamed, "kernel config" after -> before (the same configuration, one kernel name).
declare -A RENAMED=(
  ["sptd-uniform-cap phase-g-0.5"]="sptd-phase g-0.5"
  ["sptd-uniform-cap phase-g-minus-0.7"]="sptd-phase g-minus-0.7"
  ["sptd-uniform-cap phase-g-0.99"]="sptd-phase g-0.99"
  ["sptd-uniform-cap phase-sphere-light-hg-0.9"]="sptd-phase-sphere-light hg-0.9"
  ["sptd-uniform-cap phase-sphere-light-back-0.6"]="sptd-phase-sphere-light back-0.6")

build() {  # $1: before or after
  local tree="$WORK/$1"
  [[ -d "$tree" ]] || git -C "$ROOT" worktree add --detach "$tree" "${COMMIT[$1]}" >/dev/null
  cmake -S "$tree" -B "$tree/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DWARPCHECK_BUILD_BENCHMARKS=OFF >/dev/null
  ninja -C "$tree/build" warpcheck >/dev/null
}

# "kernel<TAB>scalar<TAB>config" of every case, after the restructure's names, kernels in the order of KERNELS.
cases() {
  local k
  for k in "${KERNELS[@]}"; do
    "$WORK/after/build/warpcheck" list | awk -v k="$k" '$1 == k {
      s = $2; c = $3; if ($2 == "long") { s = "long double"; c = $4 } print $1 "\t" s "\t" c }'
  done
}

# The seed that gives a renamed case the stream it had before: a case's streams start from
# seed ^ fnv1a(kernel 0x1f scalar 0x1f config) in both binaries.
seed_for_rename() {  # $1 $2 $3: after's kernel, scalar, config; $4 $5: before's kernel, config
  python3 - "$@" <<'EOF'
import sys
def fnv1a(s, h=1469598103934665603):
    for c in s.encode():
        h = ((h ^ c) * 1099511628211) % 2**64
    return h
k, s, c, bk, bc = sys.argv[1:]
print(1 ^ fnv1a(f"{bk}\x1f{s}\x1f{bc}") ^ fnv1a(f"{k}\x1f{s}\x1f{c}"))
EOF
}

file_of() { echo "$1__${2// /-}__$3.json"; }

one() {  # $1: side; $2: "kernel<TAB>scalar<TAB>config" (after's names); runs the case unless it has finished
  local side=$1 kernel scalar config seed=1 rc=0 t0 out
  IFS=$'\t' read -r kernel scalar config <<<"$2"
  out="$WORK/$side.results/$(file_of "$kernel" "$scalar" "$config")"
  [[ -f "$out" ]] && return 0
  if [[ -n "${RENAMED["$kernel $config"]:-}" ]]; then
    local before_kernel before_config
    read -r before_kernel before_config <<<"${RENAMED["$kernel $config"]}"
    if [[ $side == before ]]; then kernel=$before_kernel config=$before_config
    else seed=$(seed_for_rename "$kernel" "$scalar" "$config" "$before_kernel" "$before_config"); fi
  fi
  t0=$(date +%s)
  nice -n 19 "$WORK/$side/build/warpcheck" validate --kernel "$kernel" --scalar "$scalar" --config "$config" \
    --samples 1000000 --seed "$seed" --threads 1 --quiet --json "$out.part" >/dev/null || rc=$?
  if ((rc <= 1)); then  # 1: a test failed, which is a result too
    mv "$out.part" "$out"
    printf '%s\t%s\t%s\t%s\t%s\n' "$side" "$kernel" "$scalar" "$config" "$(($(date +%s) - t0))" >>"$WORK/times.tsv"
  else
    echo "$side $kernel / $scalar / $config: warpcheck exited with $rc" >&2
  fi
}

# A side's stored cases into one file per case, and its finished cases back into one file.
split_stored() {  # $1: side
  python3 - "$HERE/$1.json.xz" "$WORK/$1.results" <<'EOF'
import json, lzma, sys
doc = json.load(lzma.open(sys.argv[1]))
cases = {}
for r in doc["results"]:
    cases.setdefault((r["kernel"], r["scalar"], r["config"]), []).append(r)
for (k, s, c), rs in cases.items():
    with open(f"{sys.argv[2]}/{k}__{s.replace(' ', '-')}__{c}.json", "w") as f:
        json.dump(dict(doc, results=rs), f)
EOF
}
join_results() {  # $1: side
  python3 - "$WORK/$1.results" <<'EOF'
import glob, json, sys
docs = [json.load(open(p)) for p in sorted(glob.glob(sys.argv[1] + "/*.json"))]
head = {k: v for k, v in docs[0].items() if k not in ("results", "seed", "statistical_tests")}
out = dict(head, results=[{k: v for k, v in r.items() if k != "map"} for d in docs for r in d["results"]])
json.dump(out, sys.stdout, separators=(",", ":"))
EOF
}

case "${1:-}" in
  run)
    mkdir -p "$WORK"
    build before && build after
    for s in before after; do
      [[ -d "$WORK/$s.results" || ! -f "$HERE/$s.json.xz" ]] || { mkdir -p "$WORK/$s.results"; split_stored "$s"; }
      mkdir -p "$WORK/$s.results"
    done
    export WORK
    cases | while read -r line; do printf 'before\t%s\nafter\t%s\n' "$line" "$line"; done |
      xargs -d '\n' -P 2 -I{} bash -c 'IFS=$'"'\t'"' read -r s rest <<<"$1"; "$0" one "$s" "$rest"' "$0" {} ;;
  one) one "$2" "$3" ;;  # used by run
  store)
    for s in before after; do
      compgen -G "$WORK/$s.results/*.json" >/dev/null || continue
      join_results "$s" | xz -9 -c >"$HERE/$s.json.xz"
    done ;;
  compare)
    renames=()
    for k in "${!RENAMED[@]}"; do
      read -r bk bc <<<"${RENAMED[$k]}"; read -r ak ac <<<"$k"; renames+=(--rename "$bk/$bc=$ak/$ac")
    done
    python3 "$ROOT/scripts/compare_results.py" <(xz -dc "$HERE/before.json.xz") <(xz -dc "$HERE/after.json.xz") \
      --replace registry_projected_cap.cpp=validation/catalogue/projected_cap.cpp "${renames[@]}" ;;
  *) sed -n 2,13p "${BASH_SOURCE[0]}"; exit 2 ;;
esac
