# shellcheck shell=bash
# Sourced by scripts/bench_ab.sh and scripts/digest_ab.sh: git revision REV's tree as a detached worktree in a
# scratch directory, both removed when the script exits.
# revision_tree NAME REV sets root (this repository) and work (the scratch directory; REV's tree is $work/old).
revision_tree() {
  root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
  work=$(mktemp -d)
  trap 'git -C "$root" worktree remove --force "$work/old" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
  git -C "$root" worktree add --detach "$work/old" "$2" >/dev/null 2>&1 || {
    echo "$1: no revision $2" >&2
    exit 2
  }
}
