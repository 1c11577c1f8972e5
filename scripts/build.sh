#!/usr/bin/env bash
# Configures and builds varslam (Release) into ./build. Arguments are CMake build targets (default: all).
# A unity build (each compiler run takes several sources) builds from nothing faster; when editing and
# rebuilding often, VARSLAM_UNITY_BUILD=OFF recompiles only the file that changed.
set -euo pipefail
cd "$(dirname "$0")/.."
"$(dirname "$0")/setup.sh"
JOBS=$(nproc 2>/dev/null || echo 2)
# ccache keyed on paths relative to the checkout, so another clone of the same sources reuses the cache.
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$(pwd)}
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD="${VARSLAM_UNITY_BUILD:-ON}" >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build build -j"$JOBS" "${targets[@]}"
