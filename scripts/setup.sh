#!/usr/bin/env bash
# Idempotent set-up: installs the Debian packages warpcheck needs (only those missing), configures and builds.
# Sourced by scripts/battery.sh and scripts/test.sh; can also be run alone. Env: BUILD_DIR (default build),
# WARPCHECK_CMAKE_ARGS (extra cmake arguments, e.g. -DWARPCHECK_SANITIZE=ON), WARPCHECK_WARNINGS_AS_ERRORS (ON or OFF:
# -Werror, default ON: the CI build; OFF for a compiler that warns where GCC 12 does not), WARPCHECK_SLURM (1: also
# install munge and Slurm's slurmctld, slurmd and client for the single-node Slurm test, scripts/slurm/; off by
# default). An argument "--slurm" is WARPCHECK_SLURM=1.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build}"

PACKAGES=(cmake ninja-build g++ libboost1.81-dev libeigen3-dev libopenexr-dev libgtest-dev libbenchmark-dev
          clang clang-format libclang-rt-14-dev libpng-dev chromium zip unzip)
[[ "${1:-}" == --slurm ]] && WARPCHECK_SLURM=1
if [[ "${WARPCHECK_SLURM:-0}" == 1 ]]; then PACKAGES+=(munge slurmctld slurmd slurm-client); fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "[setup] installing missing Debian packages: ${missing[*]}"
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then
    command -v sudo >/dev/null || { echo "[setup] error: need root or sudo to install ${missing[*]}" >&2; exit 2; }
    SUDO=sudo
  fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}"
fi

echo "[setup] configuring $BUILD_DIR"
# shellcheck disable=SC2086
cmake -S "$ROOT" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DWARPCHECK_WARNINGS_AS_ERRORS="${WARPCHECK_WARNINGS_AS_ERRORS:-ON}" ${WARPCHECK_CMAKE_ARGS:-} >/dev/null
echo "[setup] building"
cmake --build "$BUILD_DIR" -j "$(nproc)"
