#!/usr/bin/env bash
# What each real-sensor effect costs: a static scene along the kitchen's camera path rendered with the default
# sensor plus one effect of the kinect1 preset at a time, then with all of them, each tracked deterministically
# without the person detector. Prints one line per variant: name, ATE RMSE (cm).
# Usage: bench/sensor_ablation.sh OUT_DIR [SECONDS] [SEED]
set -euo pipefail
out=${1:?usage: bench/sensor_ablation.sh OUT_DIR [SECONDS] [SEED]}
seconds=${2:-20}
seed=${3:-1}
root=$(cd "$(dirname "$0")/.." && pwd)
varslam=${VARSLAM:-$root/build/bin/varslam}
path=$root/../shared/realdata/7scenes_redkitchen
mkdir -p "$out"
declare -A variants=(
  [default]=""
  [depth_steps]="--sensor-set inverse_depth_step=0.00285 depth_noise_blur_px=3 dark_dropout=0.5"
  [time_offset]="--sensor-set depth_time_offset_s=0.016"
  [misregistration]="--sensor-set depth_offset_m=0.002,0,0"
  [rolling_shutter]="--sensor-set rolling_shutter_s=0.025"
  [distortion]="--sensor-set k1=0.2312 k2=-0.7849 k3=0.9172"
  [intrinsics]="--sensor-set focal_error=0.005 principal_point_error_px=2"
  [kinect1]="--sensor kinect1"
)
for name in default depth_steps time_offset misregistration rolling_shutter distortion intrinsics kinect1; do
  seq=$out/seq_$name
  if [[ ! -f $seq/scenario.json ]]; then
    # shellcheck disable=SC2086
    "$varslam" synth --scenario static --seconds "$seconds" --seed "$seed" --path "$path" --no-preview \
      --out "$seq" ${variants[$name]} >"$out/synth_$name.log" 2>&1
  fi
  "$varslam" run -d "$seq" --out "$out/run_$name" --set semantic.detector=none >"$out/run_$name.log" 2>&1
  ate=$(grep -m1 '^ATE' "$out/run_$name.log" | awk '{print $3}')
  echo "$name $ate"
done | tee "$out/ablation.txt"
