#!/usr/bin/env bash
# Command 1 of the README: install, build, and run the main job on the built-in default input
# (a short synthetic dynamic scene generated on the spot).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh varslam_cli  # the CLI only; run_tests.sh builds the tests
exec build/bin/varslam demo --out out/demo "$@"
