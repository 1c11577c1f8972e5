#!/usr/bin/env bash
# Command 2 of the README: install, build, and run the whole test suite (GoogleTest via ctest).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
cd build
ctest --output-on-failure -j"$(nproc 2>/dev/null || echo 2)" --timeout 900
