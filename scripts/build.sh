#!/usr/bin/env bash
# Configures and builds the package (core, node, benchmarks; tests with --tests).
set -euo pipefail
source "$(dirname "$0")/common.sh"
jobs="${STC_JOBS:-$(nproc)}"
cmake -S "$STC_ROOT" -B "$STC_BUILD" -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_INSTALL_PREFIX="$STC_BUILD/install" >/dev/null
cmake --build "$STC_BUILD" -- -j"$jobs"
if [ "${1:-}" = "--tests" ]; then
  make -C "$STC_BUILD" -j"$jobs" tests
fi
