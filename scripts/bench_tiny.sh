#!/usr/bin/env bash
# A one-minute smoke benchmark (1 scenario, 1 path, 1 seed, 2 configurations, 2 s) and the browser check of
# its pages. Usage: scripts/bench_tiny.sh [BUILD_DIR]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
out=${VARSLAM_BENCH_OUT:-/tmp/varslam_bench_tiny}
"$build/bin/varslam" bench --scenarios walking --paths rgbd_dataset_freiburg3_sitting_static --seeds 1 \
  --seconds 2 --configs huber,full --out "$out"
cat "$out/table.md"
if command -v chromium >/dev/null; then
  "$here/scripts/check_report_in_browser.sh" "$out/index.html" "$out/index.png"
  for r in "$out"/runs/*/*/report.html; do "$here/scripts/check_report_in_browser.sh" "$r"; done
fi
