#!/bin/bash
# Submits a battery and/or a worst-case search to Slurm as job arrays, one task per shard, and a merge job that
# runs when every task has succeeded (--dependency=afterok): see README.md, "Beyond one machine".
#
#   scripts/slurm/submit.sh --out DIR [--warpcheck EXE] [--battery-shards N] [--search NAME --search-shards M
#                           --seconds T] [--sbatch ARG]... [-- VALIDATE_ARGS...]
#
#   --out DIR           results directory, on a file system every node sees (created if missing)
#   --warpcheck EXE     the warpcheck executable every node runs (default: build/warpcheck of this tree)
#   --battery-shards N  run the battery in N shards (default 0: no battery); VALIDATE_ARGS after -- select the
#                       kernels and set --samples, --seed, --alpha, --correction, --threads
#   --search NAME       run the worst-case search NAME in --search-shards M shards (default 1) of --seconds T
#                       each (default 3600), with --search-args ARGS (e.g. "--seed 5 --threads 4")
#   --sbatch ARG        an extra sbatch argument for every job (e.g. --partition=long, --time=2:00:00); repeatable
#
# Prints the job ids. A task that is preempted or requeued resumes from its shard's file. Results: DIR/battery.json
# (the merged run), DIR/html/index.html (its report), DIR/search.json (the merged search); the shards' files beside.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
here="$root/scripts/slurm"
out="" exe="$root/build/warpcheck" battery=0 search="" search_shards=1 seconds=3600 search_args=""
sbatch_args=()
while (($#)); do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --warpcheck) exe=$2; shift 2 ;;
    --battery-shards) battery=$2; shift 2 ;;
    --search) search=$2; shift 2 ;;
    --search-shards) search_shards=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --search-args) search_args=$2; shift 2 ;;
    --sbatch) sbatch_args+=("$2"); shift 2 ;;
    --) shift; break ;;
    -h|--help) sed -n '2,20p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "submit.sh: unknown option '$1' (--help)" >&2; exit 2 ;;
  esac
done
[[ -n "$out" ]] || { echo "submit.sh: --out DIR is required" >&2; exit 2; }
[[ -x "$exe" ]] || { echo "submit.sh: $exe is not executable (--warpcheck EXE)" >&2; exit 2; }
((battery > 0)) || [[ -n "$search" ]] || { echo "submit.sh: nothing to run (--battery-shards, --search)" >&2; exit 2; }
mkdir -p "$out"
out=$(cd "$out" && pwd)
exe=$(cd "$(dirname "$exe")" && pwd)/$(basename "$exe")
common=(--parsable --chdir="$out" "${sbatch_args[@]}")
deps=""
if ((battery > 0)); then
  id=$(sbatch "${common[@]}" --array="0-$((battery - 1))" --output="$out/battery-%a.log" \
    --export="ALL,WARPCHECK=$exe,WARPCHECK_OUT=$out,WARPCHECK_SHARDS=$battery" "$here/battery.sbatch" "$@")
  echo "battery: job array $id ($battery shards)"
  deps+=":${id%%;*}"
fi
if [[ -n "$search" ]]; then
  # shellcheck disable=SC2086 # search_args is a list of options
  id=$(sbatch "${common[@]}" --array="0-$((search_shards - 1))" --output="$out/search-%a.log" \
    --export="ALL,WARPCHECK=$exe,WARPCHECK_OUT=$out,WARPCHECK_SHARDS=$search_shards" "$here/search.sbatch" \
    --search "$search" --seconds "$seconds" $search_args)
  echo "search: job array $id ($search_shards shards)"
  deps+=":${id%%;*}"
else
  search_shards=0
fi
id=$(sbatch "${common[@]}" --dependency="afterok$deps" --output="$out/merge.log" \
  --export="ALL,WARPCHECK=$exe,WARPCHECK_OUT=$out,WARPCHECK_BATTERY_SHARDS=$battery,WARPCHECK_SEARCH_SHARDS=$search_shards" \
  "$here/merge.sbatch")
echo "merge: job $id (after the arrays succeed)"
