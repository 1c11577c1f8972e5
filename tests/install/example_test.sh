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
# Its standard output is its own: one pose line per frame and nothing else (the library logs to standard error).
lines=$(wc -l < "$work/poses.txt")
[[ $frames -ge 25 && $poses -eq $frames && $lines -eq $poses ]]

# A consumer with a header of its own named like one of ours (core/camera.hpp) and its own include folder first:
# the public headers include only <varslam/...>, so neither shadows the other. Built as C++17.
mkdir -p "$work/clash/core"
cat > "$work/clash/core/camera.hpp" <<'HPP'
#pragma once
struct Camera { int users_own_camera = 1; };
HPP
cat > "$work/clash/main.cpp" <<'CPP'
#include "core/camera.hpp"
#include <cstdio>
#include <varslam/varslam.hpp>
int main() {
  Camera c;
  varslam::Config config;
  config.set("camera.fx", 600.0);
  const bool bags = varslam::BagReader::supported();  // links the bag reader (and ROS, where it was built)
  std::printf("bags %s\n", bags ? "supported" : "not supported");
  return (c.users_own_camera == 1 && config.get("camera.fx") == "600") ? 0 : 1;
}
CPP
cat > "$work/clash/CMakeLists.txt" <<'CMK'
cmake_minimum_required(VERSION 3.22)
project(clash LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 17)
set(CMAKE_CXX_EXTENSIONS OFF)
find_package(varslam REQUIRED)
add_executable(clash main.cpp)
target_include_directories(clash PRIVATE "${CMAKE_SOURCE_DIR}")
target_link_libraries(clash PRIVATE varslam::varslam)
CMK
cmake -S "$work/clash" -B "$work/clash/build" -DCMAKE_PREFIX_PATH="$work/prefix" > "$work/clash.log" 2>&1
cmake --build "$work/clash/build" > "$work/clash_build.log" 2>&1 || { cat "$work/clash_build.log"; exit 1; }
"$work/clash/build/clash" || { echo "the consumer's own core/camera.hpp or the C++17 Config failed"; exit 1; }
# Nothing but the public API is installed.
if ls "$work/prefix/include/varslam" | grep -qvE '\.hpp$'; then echo "internal headers installed"; exit 1; fi
echo "clash: a C++17 consumer with its own core/camera.hpp builds and runs"
