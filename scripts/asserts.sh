#!/usr/bin/env bash
# The core's debug assertions, which every other build leaves out (-DNDEBUG):
# the core and the gtests that reach them built at -O2 with assert() on in
# build_asserts (or $STC_ASSERTS_BUILD), then run. test_parallel_tick takes
# planStages' checks at 2 and 4 threads (no movable body in two members'
# blocks), test_wide_passes the same at 2 threads on a 500-body scene at the
# default thresholds, test_sleeping the held manifolds' order, test_static_cover its masks.
# A failed assertion (abort) or a failed test fails it. With --build-only it
# builds and stops (scripts/test.sh builds while the other tests run).
# Last line: "asserts: N gtests, M failed".
set -euo pipefail
source "$(dirname "$0")/common.sh"
build="${STC_ASSERTS_BUILD:-$STC_ROOT/build_asserts}"
jobs="${STC_JOBS:-$(nproc)}"
tests=(test_parallel_tick test_wide_passes test_sleeping test_static_cover)
# Release's flags without -DNDEBUG; Eigen's own index checks stay out, as in
# the fuzzers' build.
cmake -S "$STC_ROOT" -B "$build" -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS_RELEASE="-O2 -DEIGEN_NO_DEBUG" >/dev/null
cmake --build "$build" --target "${tests[@]}" -- -j"$jobs" >/dev/null
[ "${1:-}" = "--build-only" ] && exit 0

# The core that the tests load must call assert's failure handler somewhere.
requireAssertions "$build" asserts "${#tests[@]}"
preferBuildLibraries "$build"
runGtests "$build" asserts "${tests[@]}"
