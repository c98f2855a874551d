#!/usr/bin/env bash
# Fails when a tracked C++ file differs from what .clang-format makes of it, and names the files.
# Run by ctest (test "format", label fast). Reformat with: clang-format-14 -i $(git ls-files '*.h' '*.cpp')
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
FORMAT="$(command -v clang-format-14 || command -v clang-format || true)"
[[ -n "$FORMAT" ]] || { echo "check_format: clang-format not found (scripts/setup.sh installs it)" >&2; exit 2; }
if git rev-parse --git-dir >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files '*.h' '*.cpp')
else
  mapfile -t files < <(find lib validation fuzz reports -name '*.h' -o -name '*.cpp' 2>/dev/null)
fi
existing=()
for f in "${files[@]}"; do [[ -f "$f" ]] && existing+=("$f"); done
# One clang-format process for all files (one per file costs a process start each); it names each file that
# differs in its "file:line:col: error: code should be clang-formatted" lines.
rc=0
out="$("$FORMAT" --dry-run -Werror "${existing[@]}" 2>&1 >/dev/null)" || rc=$?
mapfile -t bad < <(sed -n 's/^\(.*\):[0-9]*:[0-9]*: error: code should be clang-formatted.*/\1/p' <<<"$out" | sort -u)
if ((rc != 0 && ${#bad[@]} == 0)); then
  printf 'check_format: %s failed:\n%s\n' "$FORMAT" "$out" >&2
  exit 2
fi
if ((${#bad[@]})); then
  echo "check_format: ${#bad[@]} file(s) not formatted by .clang-format:" >&2
  printf '  %s\n' "${bad[@]}" >&2
  exit 1
fi
echo "check_format: ${#existing[@]} files formatted"
