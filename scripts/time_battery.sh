#!/usr/bin/env bash
# Wall time of the battery per case and per kernel family, measured through the `warpcheck` CLI.
#
#   scripts/time_battery.sh sample [CLI]
#       A stratified selection of the registry (`CLI list`) on stdout, kernel<TAB>scalar<TAB>config: per (kernel,
#       scalar) pair M configurations, rotating through the kernel's list so that every family's configurations
#       are covered (M = 3 for SPTD, 2 for the others: 90 of the 429 cases at f34b2b65).
#   scripts/time_battery.sh cases [-c CLI] [-n SAMPLES] [-t THREADS] [-r REPEATS] CASES_FILE > OUT.tsv
#       Runs `CLI validate --kernel K --scalar S --config C --samples N --threads T --quiet` once per case and
#       repeat (one process per run: the wall includes start-up and the registry, ~0.03 s); writes per case
#       family, kernel, scalar, config, samples, threads, the smallest wall and CPU (user + system, all threads)
#       over the repeats, and every wall and CPU.
#   scripts/time_battery.sh run [-c CLI] OUT_PREFIX [validate arguments...]
#       One real `CLI validate` run with the given arguments; its stderr progress lines are time-stamped as they
#       arrive, and a case's wall is the time from its "[k/n] KERNEL / SCALAR / CONFIG" line to the next case's
#       (the last: to the process's end). Writes OUT_PREFIX.stdout, OUT_PREFIX.stderr (stamped), OUT_PREFIX.tsv
#       (the per-case table of `cases`: wall, and CPU from /proc/PID/stat at the same lines) and prints the
#       per-family summary.
#   scripts/time_battery.sh summary OUT.tsv [CLI]
#       Per family: the cases measured, the median, mean and sum of their wall and CPU, and (with CLI, for the
#       registry's case count per family) the family's estimated total: registry cases x mean (wall, CPU).
# CLI defaults to build/warpcheck. The machine is shared: take the smallest of a few repeats per case, and medians
# over cases; state the load (uptime) beside the numbers.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
CLI="$ROOT/build/warpcheck"

# The family of a kernel name (awk function, shared by every awk program below).
FAMILY_AWK='function family(k) {
  if (k ~ /^sphere-projected-cap/) return "projected-cap"
  if (k ~ /^sphere-/) return "sphere"
  if (k ~ /^sptd-/) return "sptd"
  if (k == "polygon-ltc") return "ltc"
  if (k ~ /^(polygon|baseline)-/) return "polygon"
  return "other"
}'

# `CLI list` as kernel<TAB>scalar<TAB>config (the scalar "long double" holds a space; configurations do not).
list_cases() {
  "$1" list | awk '{ if ($2 == "long") print $1 "\t" "long double" "\t" $4; else print $1 "\t" $2 "\t" $3 }'
}

sample_cases() {
  list_cases "$1" | awk -F'\t' "$FAMILY_AWK"'
    { key = $1 "\t" $2; if (!(key in n)) { pairs[++np] = key; kern[key] = $1 } cfg[key, n[key]++] = $3 }
    END {
      for (p = 1; p <= np; ++p) {
        key = pairs[p]; f = family(kern[key]); m = f == "sptd" ? 3 : 2
        for (r = 0; r < m && r < n[key]; ++r) print key "\t" cfg[key, (seen[f] * m + r) % n[key]]
        ++seen[f]
      }
    }'
}

# One validate run of a case; prints "wall cpu" in seconds (cpu: user + system of the process, all threads).
time_case() {
  local TIMEFORMAT='%3R %3U %3S' t
  t=$({ time "$CLI" validate --kernel "$1" --scalar "$2" --config "$3" --samples "$4" --threads "$5" --quiet \
    >/dev/null 2>&1; } 2>&1) || true
  awk '{ printf "%.3f %.3f", $1, $2 + $3 }' <<<"$t"
}

HEADER='family\tkernel\tscalar\tconfig\tsamples\tthreads\twall_min\tcpu_min\twalls\tcpus\n'

run_cases() {
  local samples=1000 threads=1 repeats=1 opt
  OPTIND=1
  while getopts "c:n:t:r:" opt; do
    case $opt in
      c) CLI=$OPTARG ;; n) samples=$OPTARG ;; t) threads=$OPTARG ;; r) repeats=$OPTARG ;;
      *) exit 2 ;;
    esac
  done
  shift $((OPTIND - 1))
  printf '%b' "$HEADER"
  local k s c walls cpus w i
  while IFS=$'\t' read -r k s c; do
    [[ -z "$k" || "$k" == \#* ]] && continue
    walls="" cpus=""
    for ((i = 0; i < repeats; ++i)); do
      read -r w cpu <<<"$(time_case "$k" "$s" "$c" "$samples" "$threads")"
      walls="${walls:+$walls,}$w" cpus="${cpus:+$cpus,}$cpu"
    done
    awk -v k="$k" -v s="$s" -v c="$c" -v n="$samples" -v t="$threads" -v walls="$walls" -v cpus="$cpus" \
      "$FAMILY_AWK"'
      function smallest(list,   m, v, i, lo) { m = split(list, v, ","); lo = v[1]
        for (i = 2; i <= m; ++i) if (v[i] + 0 < lo + 0) lo = v[i]; return lo }
      BEGIN { print family(k) "\t" k "\t" s "\t" c "\t" n "\t" t "\t" smallest(walls) "\t" smallest(cpus) "\t" \
              walls "\t" cpus }' </dev/null
  done <"$1"
}

# CPU seconds (user + system) of the children this shell has reaped, from the file that bash's `times` wrote (its
# second line). `times` must run in this shell: in a command substitution it counts the subshell's children.
children_cpu() {
  awk 'NR == 2 { for (i = 1; i <= 2; ++i) { split($i, p, "m"); c += p[1] * 60 + p[2] } print c }' "$1"
}

run_validate() {
  if [[ "${1:-}" == "-c" ]]; then
    CLI=$2
    shift 2
  fi
  local prefix=$1
  shift
  local fifo pid status=0 tck line st cpu cpu0 cpu1
  tck=$(getconf CLK_TCK)
  fifo=$(mktemp -u)
  mkfifo "$fifo"
  times >"$prefix.times"
  cpu0=$(children_cpu "$prefix.times")
  "$CLI" validate "$@" 2>"$fifo" >"$prefix.stdout" &
  pid=$!
  # Each stderr line with the wall clock and the process's CPU seconds so far (user + system, /proc/PID/stat).
  while IFS= read -r line; do
    cpu=-1  # the process has ended: its CPU is known only at its end
    if read -r -a st 2>/dev/null <"/proc/$pid/stat"; then cpu=$(((st[13] + st[14]) * 1000 / tck)); fi
    printf '%s\t%s\t%s\n' "$EPOCHREALTIME" "$cpu" "$line"
  done <"$fifo" >"$prefix.stderr"
  wait "$pid" || status=$?
  local t_end=$EPOCHREALTIME
  times >"$prefix.times"
  cpu1=$(children_cpu "$prefix.times")
  rm -f "$prefix.times"
  rm -f "$fifo"
  # The case label: "[k/n] KERNEL / SCALAR / CONFIG"; the first stamped line of case k starts it, the next case's
  # (or the process's end, its CPU from the shell's reaped children) ends it.
  awk -F'\t' -v t_end="$t_end" -v last_cpu="$(awk -v a="$cpu0" -v b="$cpu1" 'BEGIN { print 1000 * (b - a) }')" \
    -v header="$HEADER" "$FAMILY_AWK"'
    BEGIN { printf "%s", header }
    match($3, /\[[0-9]+\/[0-9]+\] [^ ]+ \/ (long double|[^ ]+) \/ [^ ]+/) {
      label = substr($3, RSTART, RLENGTH); split(label, a, "] "); k = substr(a[1], 2) + 0
      if (k in start) next
      split(a[2], f, " / "); start[k] = $1; cpu[k] = $2 < 0 ? last_cpu : $2; kern[k] = f[1]; scal[k] = f[2]
      conf[k] = f[3]
      if (k > last) last = k
    }
    END {
      for (k = 1; k <= last; ++k) {
        if (!(k in start)) continue
        e = (k + 1 in start) ? start[k + 1] : t_end; w = sprintf("%.3f", e - start[k])
        c = sprintf("%.3f", (((k + 1) in cpu ? cpu[k + 1] : last_cpu) - cpu[k]) / 1000)
        print family(kern[k]) "\t" kern[k] "\t" scal[k] "\t" conf[k] "\t-\t-\t" w "\t" c "\t" w "\t" c
      }
    }' "$prefix.stderr" >"$prefix.tsv"
  echo "[time_battery] validate exit status $status; per-case wall and CPU in $prefix.tsv"
  summarize "$prefix.tsv" ""
}

summarize() {
  local counts=""
  if [[ -n "${2:-}" ]]; then
    counts=$(list_cases "$2" | awk -F'\t' "$FAMILY_AWK"'{ ++n[family($1)] } END { for (f in n) printf "%s=%d,", f, n[f] }')
  fi
  awk -F'\t' -v counts="$counts" "$FAMILY_AWK"'
    function median(f, col,   m, i, j, t, v) {
      m = cnt[f]; for (i = 1; i <= m; ++i) v[i] = x[col, f, i]
      for (i = 2; i <= m; ++i) for (j = i; j > 1 && v[j - 1] > v[j]; --j) { t = v[j]; v[j] = v[j - 1]; v[j - 1] = t }
      return m % 2 ? v[(m + 1) / 2] : (v[m / 2] + v[m / 2 + 1]) / 2
    }
    function add(f) { ++cnt[f]; x[7, f, cnt[f]] = $7 + 0; x[8, f, cnt[f]] = $8 + 0; sum[7, f] += $7; sum[8, f] += $8 }
    NR > 1 { add($1); add("all") }
    END {
      split(counts, c, ","); for (i in c) if (c[i] != "") { split(c[i], kv, "="); reg[kv[1]] = kv[2]; reg["all"] += kv[2] }
      printf "%-14s %5s %11s %10s %11s %10s %10s %9s %8s %12s %11s\n", "family", "cases", "median_wall", "median_cpu",
             "mean_wall", "mean_cpu", "sum_wall", "sum_cpu", "registry", "est_wall_s", "est_cpu_s"
      n = split("sphere polygon projected-cap sptd ltc other all", order, " ")
      for (i = 1; i <= n; ++i) {
        f = order[i]; if (!cnt[f]) continue
        ew = ec = 0
        if (!(f in reg)) ew = ec = 0
        else if (f != "all") { ew = reg[f] * sum[7, f] / cnt[f]; ec = reg[f] * sum[8, f] / cnt[f] }
        else for (g in reg) if (g != "all" && cnt[g]) { ew += reg[g] * sum[7, g] / cnt[g]; ec += reg[g] * sum[8, g] / cnt[g] }
        printf "%-14s %5d %11.2f %10.2f %11.2f %10.2f %10.1f %9.1f %8s %12s %11s\n", f, cnt[f], median(f, 7),
               median(f, 8), sum[7, f] / cnt[f], sum[8, f] / cnt[f], sum[7, f], sum[8, f], (f in reg) ? reg[f] : "-",
               (f in reg) ? sprintf("%.0f", ew) : "-", (f in reg) ? sprintf("%.0f", ec) : "-"
      }
    }' "$1"
}

mode=${1:-}
[[ $# -gt 0 ]] && shift
case "$mode" in
  sample) sample_cases "${1:-$CLI}" ;;
  cases) run_cases "$@" ;;
  run) run_validate "$@" ;;
  summary) summarize "$1" "${2:-}" ;;
  *)
    sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d' | sed 's/^# \{0,1\}//'
    exit 2
    ;;
esac
