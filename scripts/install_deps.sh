#!/usr/bin/env bash
# Installs every Debian 12 package cvg_bench needs. Idempotent: a fast no-op when all are present;
# runs `apt-get update` only when something is missing. Needs root (or sudo).
set -euo pipefail

PACKAGES=(
  build-essential cmake make g++ clang-format catkin-lint
  catkin python3-catkin-pkg ros-core-dev ros-message-generation ros-message-runtime
  ros-std-msgs ros-std-srvs ros-geometry-msgs ros-diagnostic-msgs
  librosbag-dev python3-rosbag librostest-dev python3-rostest python3-rospy python3-roslib
  python3-diagnostic-msgs python3-tf2-ros
  libtf2-dev libtf2-ros-dev libtf2-geometry-msgs-dev libdiagnostic-updater-dev
  libeigen3-dev libceres-dev libboost-dev libboost-math-dev libyaml-cpp-dev nlohmann-json3-dev
  libgtest-dev googletest libbenchmark-dev
  python3-numpy python3-matplotlib python3-yaml
  libvisualization-msgs-dev python3-visualization-msgs
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  rviz xvfb x11-apps
  clang-14 libclang-rt-14-dev
  parallel
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install_deps: installing ${#missing[@]} missing package(s): ${missing[*]}"
$SUDO apt-get update -q
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q "${missing[@]}"
