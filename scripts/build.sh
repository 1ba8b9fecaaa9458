#!/usr/bin/env bash
# Configures and builds the package (core, nodes, benchmarks; tests with --tests; only
# the demo's nodes with --demo).
set -euo pipefail
source "$(dirname "$0")/common.sh"
jobs="${STC_JOBS:-$(nproc)}"
# catkin's environment cache puts only existing directories on PYTHONPATH: made
# before the first configure, the generated messages' Python package is found by
# the Python rostests (example_client) of a fresh build too.
mkdir -p "$STC_BUILD/devel/lib/python3/dist-packages"
# `make install` goes outside the package folder: roslaunch searches the whole
# folder, and a second demo.launch there stops the demo. (An install space an
# older check_install.sh left in the build directory goes for the same reason.)
rm -rf "$STC_BUILD/install"
install_prefix="${STC_INSTALL_PREFIX:-${TMPDIR:-/tmp}/sphere_tree_collision_install}"
cmake -S "$STC_ROOT" -B "$STC_BUILD" -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_INSTALL_PREFIX="$install_prefix" >/dev/null
if [ "${1:-}" = "--demo" ]; then
  # The demo's three nodes and what they link, not the benchmarks: a newcomer's
  # first build is a third of the whole.
  cmake --build "$STC_BUILD" --target collision_world_node gaze_simulator rockfall_spawner -- -j"$jobs"
  exit 0
fi
cmake --build "$STC_BUILD" -- -j"$jobs"
if [ "${1:-}" = "--tests" ]; then
  make -C "$STC_BUILD" -j"$jobs" tests
fi
