#!/usr/bin/env bash
# Mutation score: applies each small mutant of validation/mutants/ to a scratch copy of the committed tree, builds it
# and runs the kill stages in order of cost, stopping at the first that kills. Prints a table and the score and
# appends every result to a TSV file as soon as it is known. `scripts/mutants.sh --help` for the options.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

usage() {
  cat <<'EOF'
Usage: scripts/mutants.sh [--only GLOB] [--samples N] [--random N] [--keep-going] [--stages LIST] [--resume]
                          [--results FILE]
                          [--dir DIR] [--list] [--help]

Applies each mutant validation/mutants/<family>-<name>.patch (a unified diff against lib/ or validation/battery/,
its first line "# slip: ..." saying what slip it models) to a scratch copy of HEAD (a git worktree DIR/tree,
detached, reset before every mutant; the working tree is never touched), builds it in one reused build directory
DIR/tree/build (through ccache when it is installed), and runs the kill stages in order of cost:

  1a the fuzz replays of the family's kernels (ctest fuzz_replay.*; one translation unit to build)
  1b the family's fast gtests (warpcheck_tests --gtest_filter: the family's suites and those on every kernel, see
     family_suites in this script)
  2  the rest of the default run that concerns the family: every fast gtest, every fuzz replay, and the family's
     share of battery.every_case (warpcheck validate --kernel <family's kernels> --samples 1000000; its
     Holm correction spans the family's tests only, not the whole registry's)
  3  the battery: warpcheck validate --kernel <family's kernels> --random R --samples N (the named
     configurations and R random geometries per family, as scripts/battery.sh runs them)

A mutant that does not compile counts as killed by the compiler (every mutant here compiles with -Werror).
A kernel mutant is killed by a battery stage when its run exits with a status other than 0 where the unmutated
build's same run exits 0 (the unmutated runs are made once per family, stage and N, and kept in DIR/baseline/).
A mutant of the battery (family "battery") is run on the negative controls and on sphere-solid-angle, and is
killed when any case's verdicts differ from the unmutated battery's (a control that passes, a false alarm).

Options:
  --only GLOB     run only the mutants whose name (the file name without .patch) matches GLOB; repeatable
  --samples N     samples per case in stage 3 (default 10000000, the acceptance's 10^7; lower for a quick pass)
  --random N      random geometries per family in stage 3 (default 4)
  --keep-going    run every stage even after one kills (which stages see the mutant); the table names the first
  --stages LIST   run only these stages (comma-separated, of 1a,1b,2,3; default all): a quick pass; a mutant
                  that none of them kills is "open", not a survivor, and does not count in the score
  --resume        skip the mutants that already have a result in the TSV file for the same patch (and the same N
                  when the result came from stage 3); an "open" result is run again
  --results FILE  the TSV file results are appended to (default data/mutants/results.tsv, kept in git): mutant,
                  patch sha1, samples, outcome (killed/survived/open), stage (1a, 1b, 2, 3 or -), what killed it,
                  seconds, UTC time
  --dir DIR       scratch directory (default build-mutants/ in the clone, ignored by git)
  --list          list the mutants and their slips, run nothing
  --help          this text

A patch that does not apply to HEAD is a stale mutant: an error before anything runs (exit 2), never a survivor.
Before the first mutant at a HEAD, the unmutated tree runs every fast gtest and fuzz replay (kept as passed in
DIR/baseline/): a test that fails without a mutant would kill every mutant that reaches it.

Exit status: 0 when every mutant ran (whatever the score), 1 when the unmutated tree fails to build or fails its
own tests, 2 on bad arguments or a stale mutant. Run it under nice: a battery stage at 10^7 samples takes minutes per family.
EOF
}

die() { echo "mutants.sh: $*" >&2; exit 2; }

ALL_STAGES="1a 1b 2 3"
ONLY=() STAGES="$ALL_STAGES" SAMPLES=10000000 RANDOM_N=4 KEEP_GOING=0 RESUME=0 RESULTS="" DIR="$ROOT/build-mutants" LIST=0
while [ $# -gt 0 ]; do
  case "$1" in
    --only) [ $# -ge 2 ] || die "--only needs a glob"; ONLY+=("$2"); shift 2 ;;
    --samples) [[ "${2:-}" =~ ^[0-9]+$ ]] || die "--samples needs a positive integer"; SAMPLES="$2"; shift 2 ;;
    --random) [[ "${2:-}" =~ ^[0-9]+$ ]] || die "--random needs a non-negative integer"; RANDOM_N="$2"; shift 2 ;;
    --keep-going) KEEP_GOING=1; shift ;;
    --stages)
      [ $# -ge 2 ] || die "--stages needs a list"
      STAGES=""
      for s in $ALL_STAGES; do [[ ",$2," == *",$s,"* ]] && STAGES="$STAGES${STAGES:+ }$s"; done
      for s in ${2//,/ }; do [[ " $ALL_STAGES " == *" $s "* ]] || die "--stages: unknown stage '$s' (1a,1b,2,3)"; done
      shift 2 ;;
    --resume) RESUME=1; shift ;;
    --results) [ $# -ge 2 ] || die "--results needs a file"; RESULTS="$2"; shift 2 ;;
    --dir) [ $# -ge 2 ] || die "--dir needs a directory"; DIR="$2"; shift 2 ;;
    --list) LIST=1; shift ;;
    -h|--help) usage; exit 0 ;;
    *) die "unknown argument '$1' (--help lists the options)" ;;
  esac
done
[ "$SAMPLES" -gt 0 ] || die "--samples needs a positive integer"
RESULTS="${RESULTS:-$ROOT/data/mutants/results.tsv}"

# ---- the families: kernels (warpcheck validate --kernel), gtest suites (stage 1), fuzz replays (kernel names) ----
# A mutant's family is its file name up to the first '-'.
family_kernels() {
  case "$1" in
    sphere) echo "sphere-solid-angle sphere-visible-area" ;;
    pcap) echo "sphere-projected-cap sphere-projected-cap-exact sphere-projected-cap-polar" ;;
    psa) echo "polygon-solid-angle polygon-solid-angle-clipped" ;;
    ppsa) echo "polygon-projected-solid-angle polygon-projected-solid-angle-biased" ;;
    ltc) echo "polygon-ltc" ;;
    sptd) echo "sptd-uniform-cap sptd-cosine-cap" ;;
    arvo) echo "baseline-arvo-triangle" ;;
    urena) echo "baseline-urena-rectangle" ;;
    turk) echo "baseline-turk-area" ;;
    battery) echo "sphere-solid-angle" ;;  # plus the negative controls (battery_stage)
    *) return 1 ;;
  esac
}
# Suites that concern every kernel (the catalogue's contracts, entry points, round trips, recorded worst cases).
COMMON_SUITES="Catalogue.*:EntryPoints.*:RoundTrip.*:RecordedWorstCases.*:Batch.*:BatchBattery.*"
family_suites() {
  case "$1" in
    sphere) echo "SphereKernels.*:CubeRoot*.*:NearUnitRenormalization.*:$COMMON_SUITES" ;;
    pcap) echo "ProjectedCap*.*:$COMMON_SUITES" ;;
    psa) echo "PolygonSolidAngle.*:PolygonKernels.*:PolygonGeometry.*:PolygonNumerics.*:PolygonFloat.*:$COMMON_SUITES" ;;
    ppsa) echo "PolygonProjected.*:PolygonKernels.*:PolygonNumerics.*:PolygonFloat.*:$COMMON_SUITES" ;;
    ltc) echo "Ltc.*:Mis.*:$COMMON_SUITES" ;;
    sptd) echo "Sptd*.*:$COMMON_SUITES" ;;
    arvo | urena | turk) echo "PolygonBaselines.*:PolygonKernels.*:PolygonFloat.*:$COMMON_SUITES" ;;
    battery)
      echo "Battery.*:BinQuadrature.*:AdaptiveQuadrature.*:Correction.*:PdfConsistency.*:*KnownAnswers.*:Draws.*:\
CapBinner.*:KsFromSlabCounts.*:GridQuadrature*.*:ChiSquareShift.*:KsCdfTolerance.*:NegativeControl*.*:Power.*" ;;
  esac
}
family_fuzz() { [ "$1" = battery ] || family_kernels "$1"; }

# ---- the mutants ----
mapfile -t ALL < <(find "$ROOT/validation/mutants" -maxdepth 1 -name '*.patch' -printf '%f\n' | sed 's/\.patch$//' | sort)
SELECTED=()
for m in "${ALL[@]}"; do
  if [ ${#ONLY[@]} -gt 0 ]; then
    hit=0
    # shellcheck disable=SC2053 # $g is a glob
    for g in "${ONLY[@]}"; do [[ "$m" == $g ]] && hit=1; done
    [ $hit = 1 ] || continue
  fi
  family_kernels "${m%%-*}" >/dev/null || die "mutant '$m': unknown family '${m%%-*}' (family-name.patch)"
  SELECTED+=("$m")
done
[ ${#SELECTED[@]} -gt 0 ] || die "no mutant selected"
slip() { sed -n '1s/^# slip: //p' "$ROOT/validation/mutants/$1.patch"; }
if [ $LIST = 1 ]; then
  for m in "${SELECTED[@]}"; do printf '%-34s %s\n' "$m" "$(slip "$m")"; done
  exit 0
fi

# ---- the scratch tree: a detached worktree of HEAD; the build inside it as build/ (ccache's paths as a clone's) ----
TREE="$DIR/tree" BUILD="$DIR/tree/build"
HEAD_SHA="$(git -C "$ROOT" rev-parse HEAD)"
mkdir -p "$DIR/baseline" "$DIR/logs"
if [ ! -e "$TREE/.git" ]; then
  git -C "$ROOT" worktree add -q --detach "$TREE" "$HEAD_SHA"
fi
reset_tree() { git -C "$TREE" checkout -q --detach -f "$HEAD_SHA" && git -C "$TREE" reset -q --hard && git -C "$TREE" clean -qfd; }
reset_tree
# Stale mutants are errors before anything runs.
for m in "${SELECTED[@]}"; do
  git -C "$TREE" apply --check "$ROOT/validation/mutants/$m.patch" 2>"$DIR/logs/apply.err" ||
    die "stale mutant $m: its patch does not apply to HEAD ($HEAD_SHA): $(head -c 400 "$DIR/logs/apply.err")"
done
if [ ! -f "$BUILD/build.ninja" ]; then
  LAUNCHER=()
  command -v ccache >/dev/null && LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  cmake -S "$TREE" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release "${LAUNCHER[@]}" \
    -DWARPCHECK_WARNINGS_AS_ERRORS=ON >"$DIR/logs/cmake.log" 2>&1 || { echo "cmake failed: $DIR/logs/cmake.log" >&2; exit 1; }
fi
JOBS="${MUTANTS_JOBS:-2}"
# build LOG TARGET...: each stage builds only what it runs (the fuzz replay driver is one translation unit; the
# tests and the command share the catalogue's).
build() {
  local log="$1"
  shift
  ninja -C "$BUILD" -j "$JOBS" "$@" >>"$log" 2>&1
}
ALL_TARGETS=(warpcheck warpcheck_tests warpcheck_fuzz_replay)
TESTS="$BUILD/validation/warpcheck_tests"
# A test binary that is not there after its build kills nothing: the stage (run in a subshell) leaves $ABORT, and
# the run stops with exit 1 instead of counting a kill.
ABORT="$DIR/abort"
rm -f "$ABORT"
run_tests() {
  [ -x "$TESTS" ] || { echo "$TESTS missing after its build" >"$ABORT"; return 0; }
  "$TESTS" "$@"
}

# ---- the stages; each prints what killed the mutant (empty: nothing) ----
# Runs the family's battery run at N samples (stage 2: 10^6 without random geometries; stage 3: N with them) and
# writes the exit status and the verdicts (kernel scalar config test verdict) to $2.{status,verdicts}.
battery_run() {
  local family="$1" out="$2" samples="$3" random="$4" args=() k status=0
  for k in $(family_kernels "$family"); do args+=(--kernel "$k"); done
  [ "$random" -gt 0 ] && args+=(--random "$random")
  # The JSON carries each case's power figures (the smallest error the run would catch), for a survivor's reason.
  "$BUILD/warpcheck" validate "${args[@]}" --samples "$samples" --quiet --json "$out.json" >"$out.table" 2>"$out.err" ||
    status=$?
  if [ "$family" = battery ]; then  # and the negative controls, which must keep failing
    local s2=0
    "$BUILD/warpcheck" validate --negative-controls --samples "$samples" --quiet >>"$out.table" 2>>"$out.err" || s2=$?
    status="$status/$s2"
  fi
  echo "$status" >"$out.status"
  sed -nE 's/^(.*[^ ]) +[^ ]+ +[^ ]+ +(pass|FAIL|fail \(known limitation\))$/\1 \2/p' "$out.table" |
    sed -E 's/  +/ /g' | sort >"$out.verdicts"
}
# Verdict of a battery stage: compares the mutant's run with the unmutated build's (made once, kept in baseline/).
battery_stage() {
  local family="$1" stage="$2" samples="$3" random="$4" m="$5"
  local base="$DIR/baseline/$family-s$stage-n$samples-r$random-$HEAD_SHA" mut="$DIR/logs/$m-s$stage" what
  what="$(build_or_kill "$m" warpcheck)"
  [ -z "$what" ] || { echo "$what"; return; }
  battery_run "$family" "$mut" "$samples" "$random"
  # A kernel mutant whose run passes survives the stage whatever the unmutated run does: no baseline needed.
  [ "$family" != battery ] && [ "$(cat "$mut.status")" = 0 ] && return
  if [ ! -f "$base.status" ]; then  # the unmutated build's run: rebuild it without the mutant, then restore
    reset_tree && build "$DIR/logs/baseline-build.log" "${ALL_TARGETS[@]}" || { echo "unmutated build failed" >&2; exit 1; }
    battery_run "$family" "$base" "$samples" "$random"
    git -C "$TREE" apply "$ROOT/validation/mutants/$m.patch" && build "$DIR/logs/$m-build.log" "${ALL_TARGETS[@]}"
  fi
  if [ "$family" = battery ]; then
    if ! cmp -s "$base.verdicts" "$mut.verdicts"; then
      echo "verdicts differ: $(diff "$base.verdicts" "$mut.verdicts" | grep '^>' | head -1 | cut -c3-)"
    fi
  elif [ "$(cat "$base.status")" = 0 ] && [ "$(cat "$mut.status")" != 0 ]; then
    echo "exit $(cat "$mut.status"): $(grep -E ' (FAIL)$' "$mut.table" | head -1 | sed -E 's/  +/ /g')"
  fi
}
# A mutant that does not compile is killed by the compiler (every mutant here compiles with -Werror).
build_or_kill() { build "$DIR/logs/$1-build.log" "${@:2}" || echo "build: $(grep -m1 'error' "$DIR/logs/$1-build.log" | cut -c1-120)"; }
# Stage 1a: the family's fuzz replays (one translation unit to build).
stage1a() {
  local family="$1" m="$2" k f what
  local log="$DIR/logs/$m-s1a.log"
  : >"$log"
  what="$(build_or_kill "$m" warpcheck_fuzz_replay)"
  [ -z "$what" ] || { echo "$what"; return; }
  for k in $(family_fuzz "$family"); do
    for f in float double; do
      (cd "$BUILD" && ctest --output-on-failure -R "^fuzz_replay\.fuzz_${k}_${f}\$" >>"$log" 2>&1) || { echo "fuzz_replay.fuzz_${k}_$f"; return; }
    done
  done
}
# Stage 1b: the family's fast gtests.
stage1b() {
  local family="$1" m="$2" what
  local log="$DIR/logs/$m-s1b.log"
  what="$(build_or_kill "$m" warpcheck_tests warpcheck)"  # some fast gtests run the command
  [ -z "$what" ] || { echo "$what"; return; }
  run_tests --gtest_filter="$(family_suites "$family")" >"$log" 2>&1 ||
    { echo "gtest: $(sed -nE 's/^\[  FAILED  \] ([^ ]+).*/\1/p' "$log" | head -1)"; return; }
}
stage2() {
  local family="$1" m="$2"
  local log="$DIR/logs/$m-s2.log"
  local what
  what="$(build_or_kill "$m" warpcheck_tests warpcheck warpcheck_fuzz_replay)"
  [ -z "$what" ] || { echo "$what"; return; }
  run_tests >"$log" 2>&1 ||
    { echo "gtest: $(sed -nE 's/^\[  FAILED  \] ([^ ]+).*/\1/p' "$log" | head -1)"; return; }
  (cd "$BUILD" && ctest --output-on-failure -R '^fuzz_replay\.' -j "$JOBS" >>"$log" 2>&1) ||
    { echo "$(sed -nE 's/.*- (fuzz_replay\.[^ ]+) \(Failed\).*/\1/p' "$log" | head -1)"; return; }
  battery_stage "$family" 2 1000000 0 "$m"
}
stage3() { battery_stage "$1" 3 "$SAMPLES" "$RANDOM_N" "$2"; }

# ---- the unmutated tree passes what the stages run, once per HEAD: a test that fails without a mutant kills none ----
gtest_baseline() {
  local ok="$DIR/baseline/tests-$HEAD_SHA.ok" log="$DIR/logs/baseline-tests.log"
  [ -f "$ok" ] && return
  case " $STAGES " in *" 1a "* | *" 1b "* | *" 2 "*) ;; *) return ;; esac
  echo "[mutants] the unmutated tree's fast gtests and fuzz replays (once per HEAD)" >&2
  reset_tree && build "$DIR/logs/baseline-build.log" "${ALL_TARGETS[@]}" || { echo "unmutated build failed" >&2; exit 1; }
  "$TESTS" >"$log" 2>&1 && (cd "$BUILD" && ctest -R '^fuzz_replay\.' -j "$JOBS" >>"$log" 2>&1) || {
    echo "mutants.sh: the unmutated tree fails its own tests (see $log): fix HEAD first" >&2
    exit 1
  }
  touch "$ok"
}
gtest_baseline

# ---- the run ----
[ -f "$RESULTS" ] || printf 'mutant\tpatch_sha1\tsamples\toutcome\tstage\tkilled_by\tseconds\tutc\n' >"$RESULTS"
declare -A ROW
if [ $RESUME = 1 ]; then
  while IFS=$'\t' read -r name sha n outcome stage by secs _; do
    [ "$name" = mutant ] && continue
    # A kill before the battery stage does not depend on N.
    [ "$outcome" = open ] && continue
    [ "$outcome" = killed ] && [ "$stage" != 3 ] && n=any
    ROW["$name $sha $n"]="$outcome	$stage	$by	$secs"
  done <"$RESULTS"
fi
printf '%-34s %-9s %-6s %8s  %s\n' mutant outcome stage seconds "killed by"
killed=0 total=0 open=0
for m in "${SELECTED[@]}"; do
  family="${m%%-*}" patch="$ROOT/validation/mutants/$m.patch"
  sha="$(sha1sum "$patch" | cut -c1-12)"
  key="$m $sha $SAMPLES"
  [ -n "${ROW["$m $sha any"]:-}" ] && key="$m $sha any"
  if [ $RESUME = 1 ] && [ -n "${ROW["$key"]:-}" ]; then
    IFS=$'\t' read -r outcome stage by secs <<<"${ROW["$key"]}"
  else
    start=$(date +%s) outcome=survived stage=- by=""
    reset_tree
    git -C "$TREE" apply "$patch"
    : >"$DIR/logs/$m-build.log"
    for s in $STAGES; do
      what="$(stage$s "$family" "$m")"
      [ ! -f "$ABORT" ] || { echo "mutants.sh: $(cat "$ABORT")" >&2; exit 1; }
      if [ -n "$what" ]; then
        if [ "$outcome" = killed ]; then
          by="$by; stage $s: $what"
        else
          outcome=killed stage=$s by="$what"
        fi
        [ $KEEP_GOING = 1 ] || break
      fi
    done
    [ "$outcome" = killed ] || [ "$STAGES" = "$ALL_STAGES" ] || outcome=open
    secs=$(($(date +%s) - start))
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$m" "$sha" "$SAMPLES" "$outcome" "$stage" "${by//$'\t'/ }" "$secs" \
      "$(date -u +%FT%TZ)" >>"$RESULTS"
  fi
  [ "$outcome" = open ] && open=$((open + 1)) || total=$((total + 1))
  [ "$outcome" = killed ] && killed=$((killed + 1))
  printf '%-34s %-9s %-6s %8s  %s\n' "$m" "$outcome" "$stage" "$secs" "$by"
done
reset_tree
echo
echo "mutation score: $killed of $total killed ($(awk -v k=$killed -v t=$total 'BEGIN { if (t) printf "%.1f", 100 * k / t; else printf "-" }')%)," \
  "stages $STAGES, battery stage at $SAMPLES samples, --random $RANDOM_N; $open open (not killed by the stages run);" \
  "results in $RESULTS"
