#!/usr/bin/env bash
# Installs the Debian packages varslam builds and tests with. Idempotent: skips apt when all are present.
set -euo pipefail
PKGS=(build-essential cmake pkg-config ccache libopencv-dev libeigen3-dev libceres-dev libyaml-cpp-dev
      libcli11-dev libfmt-dev libspdlog-dev nlohmann-json3-dev zlib1g-dev libturbojpeg0-dev libdeflate-dev
      libgtest-dev libgmock-dev libbenchmark-dev
      opencv-doc libcpp-httplib-dev liboctomap-dev chromium fonts-dejavu-core
      # ROS 1 (Debian's Noetic-era packages): .bag input and the ROS node. Debian's rosbag/bag.h needs pluginlib's
      # headers and the ROS 2 helpers they include; ros-core is roscore, python3-rosbag is `rosbag play/reindex`.
      librosbag-storage-dev libroscpp-dev libsensor-msgs-dev libnav-msgs-dev libgeometry-msgs-dev
      libvisualization-msgs-dev libtf2-msgs-dev libstd-msgs-dev libstd-srvs-dev pluginlib-dev libclass-loader-dev
      librcpputils-dev librcutils-dev libament-index-cpp-dev libmessage-filters-dev libcv-bridge-dev libtf2-ros-dev
      ros-core
      python3-rosbag python3-sensor-msgs
      python3-geometry-msgs python3-nav-msgs python3-tf2-msgs python3-std-srvs curl
      # Executors of a benchmark plan that the tests run it with: GNU parallel, and a one-node Slurm cluster
      # (slurmctld + slurmd + munged, started by tests/report/slurm_one_node.sh, never as system services).
      parallel slurm-wlm munge)
# The viewer's build installs three.js with npm; a machine that has node and npm from elsewhere keeps them.
if ! command -v npm >/dev/null 2>&1; then PKGS+=(nodejs npm); fi
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "[setup] installing: ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
