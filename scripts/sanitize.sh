#!/usr/bin/env bash
# Builds the core and every gtest (test/unit) with AddressSanitizer and
# UndefinedBehaviorSanitizer in a separate build directory and runs them.
# The core's debug assertions are on (RelWithDebInfo's flags without
# -DNDEBUG; Eigen's own index checks stay out, as in the other builds).
# Any sanitizer report, failed assertion or failed test fails the script. Usage:
#   bash scripts/sanitize.sh            (build dir: build_sanitize, or $STC_SANITIZE_BUILD)
# Last line: "sanitize: N gtests, M failed".
set -euo pipefail
source "$(dirname "$0")/common.sh"
build="${STC_SANITIZE_BUILD:-$STC_ROOT/build_sanitize}"
jobs="${STC_JOBS:-$(nproc)}"
flags="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
cmake -S "$STC_ROOT" -B "$build" -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g -DEIGEN_NO_DEBUG" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
tests=()
for src in "$STC_ROOT"/test/unit/*.cpp; do tests+=("$(basename "$src" .cpp)"); done
cmake --build "$build" --target "${tests[@]}" -- -j"$jobs"

requireAssertions "$build" sanitize "${#tests[@]}"
preferBuildLibraries "$build"
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
runGtests "$build" sanitize "${tests[@]}"
