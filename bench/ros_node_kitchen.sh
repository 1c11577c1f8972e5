#!/usr/bin/env bash
# The real kitchen (../shared/realdata) through the ROS node in real time: the folder written as a bag
# (varslam bag-from-folder), played at 1x into varslam_node under its own roscore; frames dropped, end-to-end
# latency (pair received -> pose published, from the node's ~stats_file) and the live ATE, beside direct real-time
# runs of the folder (paced at 30 Hz) for their spread.  Usage: bench/ros_node_kitchen.sh [BUILD_DIR] [RUNS]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
runs=${2:-3}
bin=$build/bin
kitchen=$root/../shared/realdata/7scenes_redkitchen
[[ -d $kitchen ]] || kitchen=/work/shared/realdata/7scenes_redkitchen
# VARSLAM_KITCHEN_SETTINGS: another settings file for both (e.g. the depth rig given, so neither estimates it).
settings=${VARSLAM_KITCHEN_SETTINGS:-$kitchen/settings.yaml}
work=${VARSLAM_BENCH_DIR:-$(mktemp -d)}
mkdir -p "$work"
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; }
trap cleanup EXIT
py=/usr/bin/python3

# 7-Scenes' clock starts at 0, which a bag cannot hold: the bag's stamps are 1 s later, and so the node's poses.
[[ -f $work/kitchen.bag ]] || "$bin/varslam" bag-from-folder -d "$kitchen" -o "$work/kitchen.bag" --time-offset 1 >&2
for i in $(seq "$runs"); do
  "$bin/varslam" run -q -d "$kitchen" -s "$settings" -o "$work/direct$i" --realtime --pace > "$work/direct$i.log" 2>&1
  $py -c "import json; m=json.load(open('$work/direct$i/metrics.json')); print('direct run $i: live ATE %.2f cm, final ATE %.2f cm, tracked %d of %d' % (100*m['ate_live']['rmse'], 100*m['ate']['rmse'], m['tracked_frames'], m['frames']))"
done

port=$($py -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://127.0.0.1:$port ROS_IP=127.0.0.1 ROS_HOME=$work/ros_home
roscore -p "$port" > "$work/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do rosparam list > /dev/null 2>&1 && break; sleep 0.2; done
for i in $(seq "$runs"); do
  "$bin/varslam_node" __name:=varslam rgb/image:=/camera/rgb/image_color depth/image:=/camera/depth/image \
    _settings_file:="$settings" _stats_file:="$work/node$i.json" > "$work/node$i.log" 2>&1 &
  node=$!
  rosbag record -O "$work/node$i.bag" /varslam/odometry > /dev/null 2>&1 &
  rec=$!
  for _ in $(seq 100); do rostopic info /varslam/odometry 2>/dev/null | grep -q record && break; sleep 0.2; done
  sleep 1
  rosbag play -q "$work/kitchen.bag" > /dev/null 2>&1
  sleep 3
  pkill -INT -P "$rec" || true; kill -INT "$rec" 2>/dev/null || true; wait "$rec" || true
  kill -INT "$node"; wait "$node" || true
  for _ in $(seq 50); do [[ -f $work/node$i.bag ]] && break; sleep 0.1; done
  poses=$($py "$root/tests/ros/bag_to_tum.py" "$work/node$i.bag" /varslam/odometry "$work/node$i.txt")
  "$bin/varslam" eval --gt "$kitchen/groundtruth.txt" --est "$work/node$i.txt" --offset -1 --json "$work/node${i}_eval.json" > /dev/null 2>&1
  $py -c "
import json
s = json.load(open('$work/node$i.json')); e = json.load(open('$work/node${i}_eval.json'))
print('node run $i: %d poses for %d colour messages (dropped %d), latency median %.1f ms p95 %.1f ms, max queue %d, live ATE %.2f cm'
      % ($poses, s['colour_messages'], s['colour_messages'] - s['tracked'] - s['lost'], s['latency_ms_median'],
         s['latency_ms_p95'], s['max_queue'], 100 * e['ate']['rmse']))"
done
