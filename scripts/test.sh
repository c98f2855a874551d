#!/usr/bin/env bash
# The README's test command: set up, build, and run the default ("fast") ctest suite.
# Extra arguments go to ctest, e.g. scripts/test.sh -L slow   (ctest uses the last -L given).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$ROOT/scripts/setup.sh"
cd "$BUILD_DIR"
ctest -L fast --output-on-failure -j "$(nproc)" "$@"
