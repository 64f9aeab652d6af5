#!/usr/bin/env bash
# Configures and builds zebrageo. Usage: scripts/build.sh [BUILD_DIR] [extra cmake args]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$here/build}"
shift || true
"$here/scripts/setup.sh"
# ccache keeps object files across builds and clones: a rebuild after a small
# change, or CI on a fresh clone, recompiles only what changed.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$here}"
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER_LAUNCHER=ccache "$@" >/dev/null
cmake --build "$build" -j "$(nproc)"
