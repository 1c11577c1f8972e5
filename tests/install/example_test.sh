#!/usr/bin/env bash
# Installs varslam into a temporary prefix, builds examples/rgbd_folder out of tree against the installed CMake
# package and runs it on a generated 1-s sequence: every frame must come out as a pose line.
# Usage: example_test.sh SOURCE_DIR BUILD_DIR [SHARED_DIR]  (with SHARED_DIR/models, the person filter runs YOLO)
set -euo pipefail
src=$1 build=$2 shared=${3:-}
if [[ -n $shared && -f $shared/models/yolo-fastest-1.1-xl.weights ]]; then export VARSLAM_MODELS=$shared/models; fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
cmake -S "$src/examples/rgbd_folder" -B "$work/example" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release \
  > "$work/configure.log"
cmake --build "$work/example" -j2 > "$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
"$work/prefix/bin/varslam" synth --scenario walking --seconds 1 --seed 4 --no-preview --out "$work/seq" > /dev/null 2>&1
"$work/example/rgbd_folder" "$work/seq" > "$work/poses.txt" 2> "$work/stderr.txt" || { cat "$work/stderr.txt"; exit 1; }
frames=$(ls "$work/seq/rgb" | wc -l)
poses=$(grep -cE '^[0-9.]+( -?[0-9.]+){7}$' "$work/poses.txt")
echo "example: $poses poses for $frames frames; $(tail -1 "$work/stderr.txt")"
head -2 "$work/poses.txt"
[[ $frames -ge 25 && $poses -eq $frames ]]
