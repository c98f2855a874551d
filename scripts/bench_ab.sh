#!/usr/bin/env bash
# Usage: scripts/bench_ab.sh REV [FILTER] [REPETITIONS]
#
# The kernel benchmark of the working tree against that of git revision REV, in one program and one run: on a
# shared machine two runs of two binaries differ by more than the change (see docs/measurements.md), interleaved
# repetitions of one program do not. validation/benchmarks/bench_kernels.cpp is compiled twice, once against REV's
# lib/ (its namespace renamed warpcheck_old, its names prefixed "old:") and once against the working tree's ("new:"),
# both in float, and the two are linked into one program. Prints, per kernel and configuration, the float cost per
# sample at 1 and at 500 samples per light (baseline subtracted, medians of the repetitions), their ratio, and the new
# 1-spl cost over the old.
#
#   FILTER        kernels (a regular expression on the catalogue names; default: the per-light setup targets)
#   REPETITIONS   interleaved repetitions of 0.05 s (default 8)
#   CXXFLAGS      compile flags (default: the Release build's, -O3 -DNDEBUG)
set -euo pipefail
if [[ $# -lt 1 || $1 == -h || $1 == --help ]]; then
  sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'
  exit $(($# < 1 ? 2 : 0))
fi
rev=$1
kernels=${2:-sphere-solid-angle|sphere-projected-cap|polygon-solid-angle|polygon-projected-solid-angle|baseline-arvo-triangle|baseline-urena-rectangle}
reps=${3:-8}
flags=${CXXFLAGS:--O3 -DNDEBUG}
# shellcheck source=scripts/revision_tree.sh
source "$(dirname "$0")/revision_tree.sh"
revision_tree bench_ab "$rev"

# One copy of the benchmark per side: names prefixed, float only, its main turned into a registration function.
for side in old new; do
  sed -e "s|std::string(kernel) + \"/\"|std::string(\"$side:\") + kernel + \"/\"|" \
    -e "s|^int main(int argc, char\*\* argv) {|void register_$side() { warpcheck::register_all<float>(); }\nint unused_main_$side(int argc, char** argv) {|" \
    "$root/validation/benchmarks/bench_kernels.cpp" >"$work/bench_$side.cpp"
done
cat >"$work/main.cpp" <<'EOF'
#include <benchmark/benchmark.h>
void register_old();
void register_new();
int main(int argc, char** argv) {
  register_old();
  register_new();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
EOF
defs=(-DWARPCHECK_BENCH_BUILD_TYPE='""' -DWARPCHECK_BENCH_CXX_FLAGS='""' -DWARPCHECK_BENCH_COMPILER='""')
# shellcheck disable=SC2086  # flags is a list of words
{
  g++ -std=c++20 $flags "${defs[@]}" -Dwarpcheck=warpcheck_old -I"$work/old/lib" -isystem /usr/include/eigen3 \
    -c "$work/bench_old.cpp" -o "$work/old.o" &
  g++ -std=c++20 $flags "${defs[@]}" -I"$root/lib" -isystem /usr/include/eigen3 -c "$work/bench_new.cpp" -o "$work/new.o" &
  g++ -std=c++20 -O2 -c "$work/main.cpp" -o "$work/main.o" &
  wait
}
g++ "$work/old.o" "$work/new.o" "$work/main.o" -lbenchmark -lpthread -o "$work/ab"

echo "flags: $flags; $rev (old) against the working tree (new); float; $reps interleaved repetitions"
"$work/ab" --benchmark_filter="^(old|new):(baseline|$kernels)/float/[^/]*/spl=(1|500)\$" --benchmark_min_time=0.05 \
  --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true --benchmark_format=json >"$work/out.json"
python3 - "$work/out.json" <<'EOF'
import collections, json, re, statistics, sys
runs = collections.defaultdict(list)
for b in json.load(open(sys.argv[1]))["benchmarks"]:
    if b.get("run_type") == "iteration":
        runs[b["run_name"]].append(1e9 / b["items_per_second"])
ns = {name: statistics.median(v) for name, v in runs.items()}
rows = collections.defaultdict(dict)
for name in sorted(ns):
    m = re.match(r"(old|new):(.*)/float/(.*)/spl=1$", name)
    if not m or m[2] == "baseline":
        continue
    side, kernel, config = m[1], m[2], m[3]
    one = ns[name] - ns["%s:baseline/float/%s/spl=1" % (side, config)]
    many = ns[name[:-1] + "500"] - ns["%s:baseline/float/%s/spl=500" % (side, config)]
    rows[(kernel, config)][side] = (one, many)
print("%-46s %22s %22s %8s" % ("kernel / config", "old: 1, 500 spl, ratio", "new: 1, 500 spl, ratio", "new/old"))
for (kernel, config), r in rows.items():
    (o1, o5), (n1, n5) = r["old"], r["new"]
    print("%-46s %7.1f %6.1f %6.2f  %7.1f %6.1f %6.2f  %7.3f" % (kernel + " / " + config, o1, o5, o1 / o5, n1, n5, n1 / n5, n1 / o1))
EOF
