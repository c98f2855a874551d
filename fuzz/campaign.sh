#!/usr/bin/env bash
# fuzz/campaign.sh: run libFuzzer campaigns (fork mode) over warpcheck's fuzz targets and keep what they find.
set -euo pipefail

usage() {
  cat <<'EOF'
usage: fuzz/campaign.sh [--minutes M] [--jobs J] [--targets GLOB] [--build DIR] [--max-len N]
                        [--max-artifacts K]

Runs each libFuzzer target (fuzz_<catalogue kernel>_<scalar>) whose name matches GLOB (default 'fuzz_*';
e.g. 'fuzz_*_double' or 'fuzz_sphere-solid-angle_double') one after the other, each for M minutes (default 1)
with libFuzzer's fork mode on J worker processes (default 1), from the seed corpus data/fuzz/TARGET/corpus and the dictionary
data/fuzz/TARGET/dict when present. The targets must already be built in DIR (default build-fuzz):
  CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=Release -DWARPCHECK_BUILD_FUZZERS=ON
  ninja -C build-fuzz -j1 $(ninja -C build-fuzz -t targets all | grep -o '^fuzz_[a-z0-9-]*_\(float\|double\)' | sort -u)

Per target, afterwards:
  - new inputs are merged into data/fuzz/TARGET/corpus with -merge=1 (only those that add coverage);
  - the first K (default 100; 0 = all) crash/timeout/oom artifacts in time order are each run once and
    deduplicated by its signature (the violated invariant and kernel, or
    the sanitizer's summary with its source line; a target that fails often leaves hundreds of artifacts
    of the same few failures, and running each costs about a second), skipped if a regression with the same signature is
    already triaged "known" (counted in the summary as artifacts_known: the signature is coarse, so such
    an artifact may also hide a new cause of the same invariant violation), minimized (-minimize_crash=1, 30 s; the original is kept if the minimized input
    fails differently), and stored as data/fuzz/TARGET/regressions/SHA1 with
    a one-line triage file SHA1.triage reading "open: SIGNATURE | FIRST LINE OF THE GEOMETRY" (for a
    sanitizer report: its first "runtime error" / "ERROR: ...Sanitizer" line). The replay
    test (ctest fuzz_replay.TARGET) fails on every stored input until the kernel is fixed; the triage line is
    then edited by hand to "fixed: ..." (or "known: ..." for a documented float limit or a finding in a
    published baseline, which the replay runs without asserting its outcome);
  - data/fuzz/summary.json gets (or replaces) the target's entry: minutes, jobs, executions, exec/s, cov and ft
    as libFuzzer last reported them, corpus sizes, the number of artifacts, of those triaged and of those skipped as known, the findings
    stored, the date, this command line and the commit of lib/ and fuzz/ ("+changes" if edited).
Logs and the campaign's working corpus stay in DIR/campaign/TARGET/.
EOF
}

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
MINUTES=1
JOBS=1
GLOB='fuzz_*'
BUILD="$ROOT/build-fuzz"
MAX_LEN=256
MAX_ARTIFACTS=100
COMMAND_LINE="fuzz/campaign.sh $*"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --minutes) MINUTES="$2"; shift 2 ;;
    --jobs) JOBS="$2"; shift 2 ;;
    --targets) GLOB="$2"; shift 2 ;;
    --build) BUILD="$(cd "$2" && pwd)"; shift 2 ;;
    --max-len) MAX_LEN="$2"; shift 2 ;;
    --max-artifacts) MAX_ARTIFACTS="$2"; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "unknown argument: $1" >&2; usage >&2; exit 2 ;;
  esac
done
[[ "$MINUTES" =~ ^[0-9]+$ && "$MINUTES" -ge 1 ]] || { echo "--minutes must be a positive integer" >&2; exit 2; }
[[ "$JOBS" =~ ^[0-9]+$ && "$JOBS" -ge 1 ]] || { echo "--jobs must be a positive integer" >&2; exit 2; }

shopt -s nullglob
TARGETS=()
for bin in "$BUILD"/fuzz_*; do
  name="$(basename "$bin")"
  [[ -x "$bin" && -f "$bin" ]] || continue
  # shellcheck disable=SC2053
  [[ "$name" == $GLOB ]] && TARGETS+=("$name")
done
if [[ ${#TARGETS[@]} -eq 0 ]]; then
  echo "no built target in $BUILD matches '$GLOB' (see --help for the build commands)" >&2
  exit 1
fi

# The signature of a finding: the violated invariant and the kernel, or the sanitizer's summary line.
signature() {
  local out="$1"
  local sig
  sig="$(grep -m1 -o 'warpcheck invariant violated: .*' "$out" | sed -e 's|\[[^]]*/\([^/]*:[0-9]*\)\]|[\1]|' || true)"
  if [[ -n "$sig" ]]; then
    local kernel
    kernel="$(grep -m1 -A1 'warpcheck invariant violated' "$out" | tail -n1 | grep -o '^[a-z0-9_-]* <[a-z]*>' || true)"
    echo "$kernel: ${sig#warpcheck invariant violated: }"
    return
  fi
  sig="$(grep -m1 -E '^SUMMARY: ' "$out" | sed -e 's|/[^ ]*/\([^/ ]*:[0-9]*\)|\1|g' || true)"
  echo "${sig:-unknown failure}"
}

for target in "${TARGETS[@]}"; do
  bin="$BUILD/$target"
  data="$ROOT/data/fuzz/$target"
  work="$BUILD/campaign/$target"
  rm -rf "$work"
  mkdir -p "$work/corpus" "$work/artifacts" "$work/minimized" "$data/corpus" "$data/regressions"
  dict=()
  [[ -f "$data/dict" ]] && dict=("-dict=$data/dict")
  before=$(find "$data/corpus" -type f | wc -l)
  echo "== $target: $MINUTES min, $JOBS job(s), seeds: $before"
  start=$(date +%s)
  "$bin" -fork="$JOBS" -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1 -max_total_time=$((MINUTES * 60)) \
    -max_len="$MAX_LEN" -timeout=10 -rss_limit_mb=2048 -artifact_prefix="$work/artifacts/" "${dict[@]}" \
    "$work/corpus" "$data/corpus" >"$work/fuzz.log" 2>&1 || true
  seconds=$(($(date +%s) - start))
  stats="$(grep -E '^#[0-9]+: cov: ' "$work/fuzz.log" | tail -n1 || true)"
  echo "   last status: ${stats:-none}"

  # Merge the campaign's corpus into the stored one (only inputs that add coverage are copied).
  "$bin" -merge=1 -max_len="$MAX_LEN" "$data/corpus" "$work/corpus" >"$work/merge.log" 2>&1 || true
  after=$(find "$data/corpus" -type f | wc -l)

  # Findings: minimize, deduplicate by signature, store with a triage line.
  declare -A seen=()
  for f in "$data/regressions"/*.triage; do
    line="$(head -n1 "$f")"
    status="${line%%:*}"
    if [[ "$status" == known ]]; then sig="${line#*: }"; seen["${sig%% | *}"]=known; fi
  done
  findings_json="["
  mapfile -t artifacts < <(ls -tr "$work/artifacts" | grep -E '^(crash|timeout|oom|leak)-' || true)
  n_artifacts=${#artifacts[@]}
  if [[ "$MAX_ARTIFACTS" -gt 0 && $n_artifacts -gt $MAX_ARTIFACTS ]]; then artifacts=("${artifacts[@]:0:$MAX_ARTIFACTS}"); fi
  n_triaged=${#artifacts[@]}
  n_known=0
  echo "   artifacts: $n_artifacts, triaged: $n_triaged"
  for name in "${artifacts[@]}"; do
    art="$work/artifacts/$name"
    min="$work/minimized/$(basename "$art")"
    "$bin" -runs=1 "$art" >"$min.raw.out" 2>&1 || true
    raw_sig="$(signature "$min.raw.out")"
    if [[ "${seen[$raw_sig]:-}" == known ]]; then n_known=$((n_known + 1)); continue; fi
    [[ -n "${seen[$raw_sig]:-}" ]] && continue  # deduplicate before the (slow) minimization
    seen["$raw_sig"]=1
    "$bin" -minimize_crash=1 -max_total_time=30 -exact_artifact_path="$min" "$art" >"$min.log" 2>&1 || true
    [[ -s "$min" ]] || cp "$art" "$min"
    "$bin" -runs=1 "$min" >"$min.out" 2>&1 || true
    sig="$(signature "$min.out")"
    if [[ "$sig" != "$raw_sig" ]]; then  # minimization found another failure: keep the original input
      cp "$art" "$min"; cp "$min.raw.out" "$min.out"; sig="$raw_sig"
    fi
    sha="$(sha1sum "$min" | cut -c1-40)"
    cp "$min" "$data/regressions/$sha"
    geometry="$(grep -m1 -A1 'warpcheck invariant violated' "$min.out" | tail -n1 | cut -c1-400 || true)"
    # A sanitizer finding: its first report line (e.g. "polygon_solid_angle.h:242:69: runtime error: ...").
    [[ -n "$geometry" ]] || geometry="$(grep -m1 -E 'runtime error:|ERROR: [A-Za-z]+Sanitizer' "$min.out" |
      sed -e 's|^[^ ]*/\([^/ ]*:[0-9]*:[0-9]*: runtime error\)|\1|' | cut -c1-400 || true)"
    echo "open: $sig | ${geometry:-see the libFuzzer log}" >"$data/regressions/$sha.triage"
    echo "   finding: regressions/$sha: $sig"
    findings_json+="$(python3 -c 'import json,sys; print(json.dumps({"input": sys.argv[1], "signature": sys.argv[2]}))' \
      "data/fuzz/$target/regressions/$sha" "$sig"),"
  done
  unset seen
  findings_json="${findings_json%,}]"

  # Under a lock: two campaigns over disjoint targets may run at once (one per core) and both rewrite the file.
  commit="$(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown)"
  [[ -z "$(git -C "$ROOT" status --porcelain --untracked-files=no -- lib fuzz 2>/dev/null)" ]] || commit+="+changes"
  flock "$ROOT/data/fuzz/.summary.lock" python3 - "$ROOT/data/fuzz/summary.json" "$target" "$MINUTES" "$JOBS" \
    "$seconds" "$stats" "$before" "$after" "$findings_json" "$COMMAND_LINE" "$n_artifacts" "$n_triaged" "$n_known" \
    "$commit" <<'PY'
import json, os, re, sys, datetime
path, target, minutes, jobs, seconds, stats, before, after, findings, command, n_art, n_tri, n_known, commit = sys.argv[1:]
summary = {"description": "libFuzzer campaigns (fuzz/campaign.sh); per target the last campaign's numbers as "
                          "libFuzzer's fork mode last reported them", "targets": {}}
if os.path.exists(path):
    with open(path) as f:
        summary = json.load(f)
def num(key):
    m = re.search(key + r"[: ]\s*(\d+)", stats)
    return int(m.group(1)) if m else None
m = re.match(r"#(\d+):", stats)
summary["targets"][target] = {
    "minutes": int(minutes), "jobs": int(jobs), "wall_seconds": int(seconds),
    "executions": int(m.group(1)) if m else None, "exec_per_s": num("exec/s"),
    "cov": num("cov"), "ft": num("ft"),
    "corpus_files_before": int(before), "corpus_files_after": int(after),
    "crash_artifacts": int(n_art), "artifacts_triaged": int(n_tri), "artifacts_known": int(n_known),
    "findings": json.loads(findings),
    "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
    "command": command, "commit": commit,
}
with open(path, "w") as f:
    json.dump(summary, f, indent=2, sort_keys=True)
    f.write("\n")
PY
done
echo "summary: data/fuzz/summary.json"
