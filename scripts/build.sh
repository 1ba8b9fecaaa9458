#!/usr/bin/env bash
# Configures and builds the package (core, node, benchmarks; tests with --tests).
set -euo pipefail
source "$(dirname "$0")/common.sh"
jobs="${STC_JOBS:-$(nproc)}"
# catkin's environment cache puts only existing directories on PYTHONPATH: made
# before the first configure, the generated messages' Python package is found by
# the Python rostests (example_client) of a fresh build too.
mkdir -p "$STC_BUILD/devel/lib/python3/dist-packages"
cmake -S "$STC_ROOT" -B "$STC_BUILD" -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_INSTALL_PREFIX="$STC_BUILD/install" >/dev/null
cmake --build "$STC_BUILD" -- -j"$jobs"
if [ "${1:-}" = "--tests" ]; then
  make -C "$STC_BUILD" -j"$jobs" tests
fi
