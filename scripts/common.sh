# Shared by the scripts: paths and the environment ROS tools need on Debian.
# shellcheck shell=bash
STC_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
STC_BUILD="${STC_BUILD:-$STC_ROOT/build}"
# A pyenv python may come first on PATH without catkin_pkg: ROS tools use Debian's.
export PATH="/usr/bin:/bin:$PATH"
export ROS_PYTHON_VERSION=3
# A build's own libraries before any on LD_LIBRARY_PATH: a sourced ROS
# environment puts the main build's devel/lib there, ahead of a binary's run
# path, so a sanitizer or fuzzer build would load the main build's release core.
preferBuildLibraries() {
  export LD_LIBRARY_PATH="$1/devel/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
}
# requireAssertions BUILD LABEL COUNT: fails, with the closing line of COUNT
# gtests all failed, when BUILD's core was compiled without assert() (it
# then imports no __assert_fail: built with -DNDEBUG).
requireAssertions() {
  local core="$1/devel/lib/libstc_core.so" symbols
  # Read whole before it is searched: `nm | grep -q` under pipefail fails
  # when grep stops at the match and nm dies of the closed pipe (a large
  # symbol table, as the sanitizers' core has).
  symbols=$(nm -D --undefined-only "$core") || symbols=""
  if [[ "$symbols" != *__assert_fail* ]]; then
    echo "$2: $core has no assertions compiled in"
    echo "$2: $3 gtests, $3 failed"
    return 1
  fi
}
# runPrograms BUILD LABEL KIND ARG PROGRAM...: each PROGRAM of BUILD's devel
# space with ARG, run from the source root (as catkin_add_gtest's
# WORKING_DIRECTORY) with its output in BUILD/PROGRAM.log; a line "LABEL:
# PROGRAM ok (N s)" or "... FAILED (exit E, N s)" with the log's tail, then
# "LABEL: N KIND, M failed" and the failed ones' names. STC_PROGRAM_LIMIT
# seconds a program, when set, guard a hang. Returns non-zero when any failed.
runPrograms() {
  local build="$1" label="$2" kind="$3" arg="$4" failed=() t start rc
  shift 4
  for t in "$@"; do
    start=$(date +%s)
    (cd "$STC_ROOT" && timeout "${STC_PROGRAM_LIMIT:-0}" "$build/devel/lib/sphere_tree_collision/$t" "$arg" >"$build/$t.log" 2>&1)
    rc=$?
    if [ $rc -eq 0 ]; then
      echo "$label: $t ok ($(($(date +%s) - start)) s)"
    else
      failed+=("$t")
      echo "$label: $t FAILED (exit $rc, $(($(date +%s) - start)) s), log: $build/$t.log"
      tail -n 40 "$build/$t.log"
    fi
  done
  echo "$label: $# $kind, ${#failed[@]} failed"
  [ ${#failed[@]} -eq 0 ] || { echo "$label: failed: ${failed[*]}"; return 1; }
}
# runGtests BUILD LABEL TEST...: runPrograms for gtests, brief.
runGtests() {
  local build="$1" label="$2"
  shift 2
  runPrograms "$build" "$label" gtests --gtest_brief=1 "$@"
}
# demoTicks SETUP EXPECTED: with only SETUP's environment on the ROS paths and
# a master of its own, runs `roslaunch sphere_tree_collision demo.launch
# rviz:=false` by package name until the world node ticks with entities and
# the gaze simulator's gaze on. Fails when rospack finds the package outside
# EXPECTED, when roslaunch finds two files of one name, or when the node never
# ticks. Judged by what the node logs: the wall-clock bound only guards a hang.
demoTicks() {
  local setup="$1" expected="$2" log port launcher ok=1
  log="$(mktemp)"
  port=$((20000 + RANDOM % 10000))
  (
    set +u
    unset ROS_PACKAGE_PATH CMAKE_PREFIX_PATH LD_LIBRARY_PATH PYTHONPATH ROS_MASTER_URI
    # shellcheck disable=SC1091
    source /opt/ros/noetic/setup.bash 2>/dev/null || true
    # shellcheck disable=SC1090
    source "$setup"
    set -u
    found="$(rospack find sphere_tree_collision)"
    echo "rospack find sphere_tree_collision: $found"
    case "$found" in "$expected" | "$expected"/*) ;; *) echo "the package was not found in $expected"; exit 1 ;; esac
    export ROS_MASTER_URI="http://localhost:$port"
    # Line-buffered: the nodes' log lines reach the log as they are printed
    # (block-buffered into a file, the first ones came about 20 s late).
    exec stdbuf -oL roslaunch -p "$port" sphere_tree_collision demo.launch rviz:=false
  ) >"$log" 2>&1 &
  launcher=$!
  for _ in $(seq 1 240); do  # liveness bound: 120 s
    if grep -qE "tick [0-9]+: [1-9][0-9]* entities.*gaze on" "$log"; then ok=0; break; fi
    kill -0 "$launcher" 2>/dev/null || break
    sleep 0.5
  done
  kill -INT "$launcher" 2>/dev/null
  wait "$launcher" 2>/dev/null
  grep -E "rospack find|gaze on|multiple files|ERROR|FATAL" "$log" | head -3
  [ $ok -eq 0 ] || { echo "the demo did not tick; log:"; tail -30 "$log"; }
  rm -f "$log"
  return $ok
}
