#!/usr/bin/env bash
# The default benchmark behind BENCHMARKS.md: every synthetic scenario along three real camera paths, two seeds,
# the four configurations; rewrites the generated table of BENCHMARKS.md. Extra arguments go to `varslam bench`
# (e.g. --real /path/to/rgbd_dataset_freiburg3_walking_xyz, --peer "...", --jobs 1).
# Usage: scripts/bench_default.sh [BUILD_DIR] [-- extra bench args]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=$here/build
if [[ $# -gt 0 && $1 != -* ]]; then build=$1; shift; fi
if [[ ${1:-} == -- ]]; then shift; fi
cli=$build/bin/varslam
[[ -x $cli ]] || { echo "bench_default: $cli not built (scripts/build.sh)" >&2; exit 2; }
out=${VARSLAM_BENCH_OUT:-$here/bench_out}
"$cli" bench --out "$out" --cache "${VARSLAM_BENCH_CACHE:-$out/sequences}" \
  --update-benchmarks-md "$here/BENCHMARKS.md" "$@"
echo "bench_default: open $out/index.html"
