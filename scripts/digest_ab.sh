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
# shellcheck source=scripts/revision_tree.sh
source "$(dirname "$0")/revision_tree.sh"
revision_tree digest_ab "$1"
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
