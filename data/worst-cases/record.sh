#!/bin/sh
# Re-records data/worst-cases/<search>.json for every search (or the searches named as arguments):
#   data/worst-cases/record.sh BUILD_DIR [SECONDS] [SEARCH...]
# One thread, seed 1, SECONDS (default 10) per search. polygon-backward-k2 was recorded separately by the
# 5-minute run (see validation/README-worst-case.md); this script skips it unless it is named.
# Each file records its own command, kernel version, evaluations and seconds.
set -eu
build=$1
seconds=${2:-10}
shift; [ $# -gt 0 ] && shift
dir=$(cd "$(dirname "$0")" && pwd)
if [ $# -gt 0 ]; then searches="$*"; else
  searches=$("$build/warpcheck" worst-case --list | grep -v '^ ' | grep -vx 'polygon-backward-k2')
fi
for s in $searches; do
  "$build/warpcheck" worst-case --search "$s" --seconds "$seconds" --threads 1 --seed 1 --progress 0 \
      --json "$dir/$s.json"
  printf '%s %s\n' "$s" "$(grep -m1 '"worst_error"' "$dir/$s.json")"
done
