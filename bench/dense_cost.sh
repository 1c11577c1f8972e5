#!/usr/bin/env bash
# The dense map's cost to tracking in real-time mode: the same sequence with and without --dense-map, interleaved
# (off, on, off, on, ...), paced at the sensor's rate as a live camera feeds it. Prints each run's tracking median
# and p95 (metrics.json timings.tracking) and, with the dense map, its fusion time per keyframe.
#   bench/dense_cost.sh DATASET_DIR [REPEATS=3] [OUT=/tmp/varslam_dense_cost] [-- extra run options]
set -euo pipefail
data=$1; reps=${2:-3}; out=${3:-/tmp/varslam_dense_cost}
shift $(( $# < 3 ? $# : 3 )); [ "${1:-}" = "--" ] && shift
bin="$(dirname "$0")/../build/bin/varslam"
mkdir -p "$out"
for i in $(seq 1 "$reps"); do
  for mode in off on; do
    extra=(); [ "$mode" = on ] && extra=(--dense-map)
    "$bin" run -d "$data" --realtime --pace -q --out "$out/${mode}_$i" "${extra[@]}" "$@" >/dev/null 2>&1
    python3 - "$out/${mode}_$i/metrics.json" "$mode" "$i" <<'PY'
import json, sys
m = json.load(open(sys.argv[1])); t = m["timings"]["tracking"]
d = m.get("dense_map")
extra = "" if not d else " dense: %d keyframes, fuse median %.1f ms p95 %.1f ms, %d re-fusions, final rebuild %.0f ms" % (
    d["keyframes"], d["fuse_ms"]["median"], d["fuse_ms"]["p95"], d["reintegrations"], d["final_rebuild_ms"])
print("%-3s run %s: tracking median %.2f ms p95 %.2f ms, ATE %.2f cm%s" % (sys.argv[2], sys.argv[3], t["median_ms"],
      t["p95_ms"], 100 * m.get("ate", {}).get("rmse", float("nan")), extra))
PY
  done
done
