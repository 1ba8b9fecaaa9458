#!/usr/bin/env bash
# Install what is missing, build, run every test (gtest + rostest) and end with
# one line "N passed, N failed". Exit status is non-zero unless all passed.
set -uo pipefail
source "$(dirname "$0")/common.sh"
bash "$STC_ROOT/scripts/install_deps.sh" || exit 1
bash "$STC_ROOT/scripts/build.sh" --tests || { echo "0 passed, 1 failed"; exit 1; }
rm -rf "$STC_BUILD/test_results"
# ROS setup files read unset variables: source them without -u.
set +u
# shellcheck disable=SC1091
source "$STC_BUILD/devel/setup.bash"
set -u
# The fuzzers' sanitizer build (about 4 minutes of compiling on 2 cores), then
# the assertions' build (about 3), go on while the tests run, most of which wait
# on ROS masters and nodes; no test depends on timing. Their logs are kept for
# the checks below, which build again (up to date then, or failing the same
# way) and run them.
fuzz_build_log="$STC_BUILD/fuzz_build.log"
asserts_build_log="$STC_BUILD/asserts_build.log"
{
  bash "$STC_ROOT/scripts/fuzz.sh" --build-only >"$fuzz_build_log" 2>&1 ||
    { echo "fuzz build failed, log: $fuzz_build_log"; tail -n 20 "$fuzz_build_log"; }
  bash "$STC_ROOT/scripts/asserts.sh" --build-only >"$asserts_build_log" 2>&1 ||
    { echo "asserts build failed, log: $asserts_build_log"; tail -n 20 "$asserts_build_log"; }
} &
side_builds=$!
# run_tests exits 0 even when a test fails: the result files decide.
make -C "$STC_BUILD" run_tests -j1 2>&1 | tee "$STC_BUILD/run_tests.log" | grep -E "^\[ *(RUN|  OK|  FAILED|  PASSED) |^\[ROSTEST\]|FAILURE|Error|error:" || true
# Checks that are scripts, recorded as test cases beside the gtests and rostests.
check() { /usr/bin/python3 "$STC_ROOT/scripts/run_check.py" "$STC_BUILD/test_results" "$@" || true; }
check catkin_lint -- /usr/bin/catkin_lint --strict --skip-path build "$STC_ROOT"
check installed_demo -- bash "$STC_ROOT/scripts/check_install.sh"
# What the README's demo runs: by package name from the devel space, after the install above.
check demo_by_name -- bash "$STC_ROOT/scripts/check_demo.sh"
# Every bench in its short mode (--smoke): none crashes or fails unseen.
check benches -- bash "$STC_ROOT/scripts/bench_smoke.sh"
# The constants the docs quote still match the code; the README's core example runs.
check doc_constants -- /usr/bin/python3 "$STC_ROOT/scripts/check_doc_constants.py"
check hello_world -- "$STC_BUILD/devel/lib/sphere_tree_collision/hello_world"
# libFuzzer under ASan + UBSan on the message-to-core path and mesh bytes, 8 s a
# target here (about 40 s; STC_FUZZ_SECONDS sets it, docs/fuzzing.md).
wait "$side_builds" || true
check fuzz -- env STC_FUZZ_SECONDS="${STC_FUZZ_SECONDS:-8}" bash "$STC_ROOT/scripts/fuzz.sh"
# The core's debug assertions, at 2 and 4 threads among others (scripts/asserts.sh).
check asserts -- bash "$STC_ROOT/scripts/asserts.sh"
/usr/bin/python3 "$STC_ROOT/scripts/count_results.py" "$STC_BUILD/test_results"
