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
# runGtests BUILD LABEL TEST...: each gtest of BUILD's devel space, run from the
# source root (as catkin_add_gtest's WORKING_DIRECTORY) with its output in
# BUILD/TEST.log; a line "LABEL: TEST ok (N s)" or "... FAILED" with the log's
# tail, then "LABEL: N gtests, M failed". Returns non-zero when any failed.
runGtests() {
  local build="$1" label="$2" failed=0 t start
  shift 2
  for t in "$@"; do
    start=$(date +%s)
    if (cd "$STC_ROOT" && "$build/devel/lib/sphere_tree_collision/$t" --gtest_brief=1 >"$build/$t.log" 2>&1); then
      echo "$label: $t ok ($(($(date +%s) - start)) s)"
    else
      failed=$((failed + 1))
      echo "$label: $t FAILED ($(($(date +%s) - start)) s), log: $build/$t.log"
      tail -n 40 "$build/$t.log"
    fi
  done
  echo "$label: $# gtests, $failed failed"
  [ "$failed" -eq 0 ]
}
