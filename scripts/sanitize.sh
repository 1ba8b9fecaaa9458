#!/usr/bin/env bash
# AddressSanitizer and UndefinedBehaviorSanitizer over the core (gcc, in
# build_sanitize or $STC_SANITIZE_BUILD), with the core's debug assertions on
# (RelWithDebInfo's flags without -DNDEBUG; Eigen's own index checks stay out,
# as in the other builds). Two uses:
#   bash scripts/sanitize.sh              every gtest of test/unit;
#                                         last line "sanitize: N gtests, M failed"
#   bash scripts/sanitize.sh --rostests   the node and its hostile-input rostests
#                                         (hammer, bad_input), sanitized node and
#                                         test nodes; last line "sanitize: N rostests, M failed"
# Any sanitizer report, failed assertion or failed test fails it. With
# --build-only it builds and stops. Neither use is in the test command
# (docs/fuzzing.md says why).
set -euo pipefail
source "$(dirname "$0")/common.sh"
build="${STC_SANITIZE_BUILD:-$STC_ROOT/build_sanitize}"
jobs="${STC_JOBS:-$(nproc)}"
mode=gtests
build_only=0
for arg in "$@"; do
  case "$arg" in
    --rostests) mode=rostests ;;
    --build-only) build_only=1 ;;
    *) echo "sanitize.sh: unknown argument '$arg' (--rostests, --build-only)"; exit 2 ;;
  esac
done
flags="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
cmake -S "$STC_ROOT" -B "$build" -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g -DEIGEN_NO_DEBUG" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
# The rostests whose node meets hostile input: every malformed kind, and ~1,000
# messages of them interleaved with valid traffic on a running scene.
rostests=(hammer bad_input)
tests=()
if [ "$mode" = gtests ]; then
  for src in "$STC_ROOT"/test/unit/*.cpp; do tests+=("$(basename "$src" .cpp)"); done
  targets=("${tests[@]}")
else
  targets=("${rostests[@]/%/_node}")  # each builds the node executables too
fi
cmake --build "$build" --target "${targets[@]}" -- -j"$jobs" >/dev/null
[ "$build_only" = 1 ] && exit 0

if [ "$mode" = gtests ]; then
  requireAssertions "$build" sanitize "${#tests[@]}"
  preferBuildLibraries "$build"
  export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  runGtests "$build" sanitize "${tests[@]}"
  exit
fi

requireAssertions "$build" sanitize "${#rostests[@]}"
# The node reports into files: roslaunch does not look at a node's exit status,
# so a report is found by its file, whatever the node did after it.
reports="$build/sanitizer_reports"
results="$build/sanitized_rostest_results"
rm -rf "$reports" "$results"
mkdir -p "$reports" "$results"
failed=()
for t in "${rostests[@]}"; do
  start=$(date +%s)
  rc=0
  (
    set +u
    # Only this build's devel space: its node and test nodes, not the release ones.
    # shellcheck disable=SC1091
    source "$build/devel/setup.bash"
    set -u
    preferBuildLibraries "$build"
    export ROS_TEST_RESULTS_DIR="$results"
    export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:log_path=$reports/asan"
    export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:log_path=$reports/ubsan"
    rostest --text sphere_tree_collision "$t.test"
  ) >"$build/rostest_$t.log" 2>&1 || rc=$?
  found=$(find "$reports" -type f | wc -l)
  if [ $rc -eq 0 ] && [ "$found" -eq 0 ]; then
    echo "sanitize: $t.test ok ($(($(date +%s) - start)) s)"
  else
    failed+=("$t")
    echo "sanitize: $t.test FAILED (rostest exit $rc, $found sanitizer reports), log: $build/rostest_$t.log"
    tail -n 20 "$build/rostest_$t.log"
    find "$reports" -type f -exec head -n 30 {} \;
  fi
done
echo "sanitize: ${#rostests[@]} rostests, ${#failed[@]} failed"
[ ${#failed[@]} -eq 0 ]
