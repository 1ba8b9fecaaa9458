#!/usr/bin/env bash
# Installs the Debian packages the package needs, only those that are missing.
set -euo pipefail
packages=(
  cmake g++ git make pkg-config
  catkin ros-base-dev ros-message-generation ros-message-runtime
  libroscpp-dev libtf2-ros-dev libtf2-dev libvisualization-msgs-dev libgeometry-msgs-dev libstd-msgs-dev
  librostest-dev python3-rostest python3-roslaunch libtf2-msgs-dev
  libstd-srvs-dev libros-rosgraph-msgs-dev
  python3-rospy python3-geometry-msgs python3-std-srvs  # scripts/example_client.py
  rosbash  # rosrun, roscd
  libtbb-dev  # oneTBB: the parallel tick (WorldConfig::threads)
  libeigen3-dev libyaml-cpp-dev libfcl-dev libgtest-dev googletest
  libassimp-dev  # mesh loading (stc_mesh): STL, OBJ, DAE
  python3-matplotlib
  libbullet-dev  # benchmarks only: bench_bullet_compare (skipped when absent)
  clang libfuzzer-14-dev
  rviz xvfb xauth imagemagick x11-utils
  catkin-lint
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure  # live tuning (cfg/World.cfg)
  libdiagnostic-updater-dev libdiagnostic-msgs-dev  # /diagnostics
  libsensor-msgs-dev libimage-geometry-dev libtf2-eigen-dev  # the perception camera as a camera
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} Debian packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
$SUDO apt-get install -y --no-install-recommends "${missing[@]}"
