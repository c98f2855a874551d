#!/bin/sh
# Re-records data/worst-cases/<search>.json for every search (or the searches named as arguments):
#   data/worst-cases/record.sh BUILD_DIR [SECONDS] [SEARCH...]
# One thread, seed 1, SECONDS (default 10) per search. polygon-backward-k2 was recorded separately by the
# long runs (see docs/worst-case.md); this script skips it unless it is named.
# A short search can find less than the record it replaces (the old input came from a longer or luckier run),
# so when a record exists its input is re-evaluated with the current kernels (warpcheck worst-case --evaluate
# OLD --json) and the worse of the two is kept: the old input with its new error, or the new search's.
# Each file records its own command, kernel version, evaluations and seconds.
set -eu
build=$1
seconds=${2:-10}
shift; [ $# -gt 0 ] && shift
dir=$(cd "$(dirname "$0")" && pwd)
if [ $# -gt 0 ]; then searches="$*"; else
  searches=$("$build/warpcheck" worst-case --list | grep -v '^ ' | grep -vx 'polygon-backward-k2')
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
error_of() { sed -n 's/^  "worst_error": \(.*\),$/\1/p' "$1" | head -n 1; }
for s in $searches; do
  out="$dir/$s.json"
  "$build/warpcheck" worst-case --search "$s" --seconds "$seconds" --threads 1 --seed 1 --progress 0 \
      --json "$tmp/new.json"
  keep="$tmp/new.json"
  if [ -f "$out" ] && "$build/warpcheck" worst-case --search "$s" --evaluate "$out" --json "$tmp/old.json" >/dev/null; then
    # awk compares the two errors (null or nan lose).
    if awk -v a="$(error_of "$tmp/old.json")" -v b="$(error_of "$tmp/new.json")" \
        'BEGIN { na = (a == "null" || a ~ /nan/); nb = (b == "null" || b ~ /nan/); exit !(!na && (nb || a + 0 > b + 0)) }'; then
      keep="$tmp/old.json"
    fi
  fi
  cp "$keep" "$out"
  printf '%s %s (%s)\n' "$s" "$(error_of "$out")" "$([ "$keep" = "$tmp/old.json" ] && echo 'old input, re-evaluated' || echo 'new search')"
done
