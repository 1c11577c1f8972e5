#!/usr/bin/env bash
# Maps across sessions on the real kitchen: a map built on one part of the sequence, then separate
# localization-only sessions started at several frames. Prints, per session: frames localized, frames until the
# first fix, ATE in the map's frame (eval --map). Usage: bench/map_sessions.sh [OUT_DIR] [-- extra run options]
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-/tmp/varslam_map_sessions}
shift || true
[[ "${1:-}" == "--" ]] && shift
EXTRA=("$@")
KITCHEN=${VARSLAM_KITCHEN:-../shared/realdata/7scenes_redkitchen}
BIN=${VARSLAM_BIN:-build/bin/varslam}
mkdir -p "$OUT"

build_map() {  # name first count
  [[ -f "$OUT/$1.map" ]] || "$BIN" run -d "$KITCHEN" --first "$2" -n "$3" --save-map "$OUT/$1.map" -o "$OUT/$1" \
    "${EXTRA[@]}" >"$OUT/$1.log" 2>&1
}

session() {  # map first count
  local dir="$OUT/$1_s$2${MAPPING:+_mapping}"
  rm -rf "$dir"  # this script's own output of an earlier sitting
  "$BIN" run -d "$KITCHEN" --first "$2" -n "$3" --load-map "$OUT/$1.map" $([[ -n "${MAPPING:-}" ]] || echo --localization-only) --min-tracked-share 0 \
    -o "$dir" "${EXTRA[@]}" >"$dir.log" 2>&1 || { echo "$1 start $2: run failed (see $dir.log)"; return; }
  "$BIN" eval --gt "$KITCHEN/groundtruth.txt" --est "$dir/CameraTrajectory.txt" --map "$OUT/$1.map" \
    --json "$dir/eval_map.json" >/dev/null 2>&1 || true
  python3 - "$KITCHEN" "$dir" "$1" "$2" "$3" <<'PY'
import json, sys
kitchen, run, name, first, count = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5])
stamps = [float(l.split()[0]) for l in open(f"{kitchen}/rgb.txt") if l.strip() and not l.startswith('#')]
index = {round(s, 4): i for i, s in enumerate(stamps)}
m = json.load(open(f"{run}/metrics.json"))
poses = [float(l.split()[0]) for l in open(f"{run}/CameraTrajectory.txt") if l.strip() and not l.startswith('#')]
# The first fix is the first pose tracking gave live; frames placed back from it afterwards
# (relocalization.place_back_lost_frames) are in the final trajectory but never were live.
live = [float(l.split()[0]) for l in open(f"{run}/LiveTrajectory.txt") if l.strip() and not l.startswith('#')]
first_fix = min((index.get(round(t, 4), 10**9) for t in live), default=None)
try:
    ate = json.load(open(f"{run}/eval_map.json"))["ate"]["rmse"] * 100
except Exception:
    ate = float('nan')
n = m["frames"]
print(f"{name} start {first}: {m['tracked_frames']}/{n} localized live ({100*m['tracked_frames']/n:.1f} %), "
      f"{len(poses)}/{n} in the trajectory, "
      f"first fix after {first_fix - first if first_fix is not None else 'none'} frames, ATE in map frame {ate:.2f} cm, "
      f"relocalizations {m['relocalizations']}")
PY
}

# Forward: map of 0-599, sessions to the end of the sequence. Reverse: map of 600-999, sessions of 200 frames.
frames_of() {  # map first
  if [[ $1 == fwd ]]; then echo $((1000 - $2)); else echo 200; fi
}
build_map fwd 0 600
build_map rev 600 400
sessions=${ONLY:-"fwd:600 fwd:700 fwd:800 fwd:900 rev:0 rev:200 rev:400"}
for s in $sessions; do session "${s%:*}" "${s#*:}" "$(frames_of "${s%:*}" "${s#*:}")"; done
