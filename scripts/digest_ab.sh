#!/usr/bin/env bash
# Usage: scripts/digest_ab.sh REV
#
# Whether the working tree's kernels give the samples and densities of git revision REV's, bit for bit:
# validation/tools/kernel_digest.cpp (every catalogue kernel on random geometries, in float, double and long double)
# compiled against both lib/ trees and run; prints the kernels whose hash differs and exits 1 if any does.
#   CXXFLAGS   compile flags (default: the Release build's, -O3 -DNDEBUG)
set -euo pipefail
if [[ $# -ne 1 || $1 == -h || $1 == --help ]]; then
  sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'
  exit $(($# == 1 ? 0 : 2))
fi
flags=${CXXFLAGS:--O3 -DNDEBUG}
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'git -C "$root" worktree remove --force "$work/old" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
git -C "$root" worktree add --detach "$work/old" "$1" >/dev/null 2>&1 || {
  echo "digest_ab: no revision $1" >&2
  exit 2
}
# shellcheck disable=SC2086  # flags is a list of words
for side in old new; do
  lib=$([[ $side == old ]] && echo "$work/old/lib" || echo "$root/lib")
  g++ -std=c++20 $flags -I"$lib" -isystem /usr/include/eigen3 "$root/validation/tools/kernel_digest.cpp" \
    -o "$work/digest_$side" &
done
wait
"$work/digest_old" >"$work/old.txt" &
"$work/digest_new" >"$work/new.txt"
wait
echo "$(wc -l <"$work/new.txt") kernel and scalar hashes, $1 against the working tree ($flags)"
if diff "$work/old.txt" "$work/new.txt" >"$work/diff.txt"; then
  echo "identical"
else
  grep '^>' "$work/diff.txt" | awk '{print "differs: " $2 " " $3}'
  exit 1
fi
