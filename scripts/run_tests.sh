#!/usr/bin/env bash
# Command 2 of the README: install, build, and run the whole test suite (GoogleTest via ctest), then the same
# tests under AddressSanitizer + UndefinedBehaviorSanitizer and the threaded ones under ThreadSanitizer
# (scripts/sanitize.sh; VARSLAM_SANITIZERS=0 skips that stage), then a short libFuzzer run of every reader of
# user files (scripts/fuzz.sh; VARSLAM_FUZZ=0 skips it).
set -euo pipefail
cd "$(dirname "$0")/.."
# Each stage prints its wall time, so a slow CI run shows which stage grew.
stage() {  # name, command...
  local name=$1 start=$SECONDS
  shift
  "$@"
  echo "[run_tests] $name: $((SECONDS - start)) s"
}
stage build scripts/build.sh
stage ctest bash -c 'cd build && ctest --output-on-failure -j"$(nproc 2>/dev/null || echo 2)" --timeout 900'
if [[ ${VARSLAM_SANITIZERS:-1} != 0 ]]; then stage sanitizers scripts/sanitize.sh; fi
if [[ ${VARSLAM_FUZZ:-1} != 0 ]]; then stage fuzz scripts/fuzz.sh; fi
echo "[run_tests] all stages: $SECONDS s"
