#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/fuzz_*.cpp) with clang, AddressSanitizer
# and UndefinedBehaviorSanitizer in build_fuzz (or $STC_FUZZ_BUILD), then runs
# each for $STC_FUZZ_SECONDS (default 15: about 75 s for the five) on its
# committed seed corpus fuzz/corpus/<target>/ (read only; new inputs go to the
# build directory; to grow the seeds: fuzz_<target> -merge=1 fuzz/corpus/<target>
# build_fuzz/corpus/<target>). A finding (crash, sanitizer report, uncaught exception,
# leak, timeout, out-of-memory) is saved as build_fuzz/findings/<target>-*.
# Exit status 0: no finding; 1: at least one. Last line, for the test count:
#   fuzz: 5 targets, 1234567 executions, 0 findings
# With --build-only it builds the targets and stops (scripts/test.sh builds them
# while the other tests run; the run after it finds them up to date).
set -euo pipefail
source "$(dirname "$0")/common.sh"
build="${STC_FUZZ_BUILD:-$STC_ROOT/build_fuzz}"
seconds="${STC_FUZZ_SECONDS:-15}"
jobs="${STC_JOBS:-$(nproc)}"
flags="-fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=all -fno-omit-frame-pointer -g"
# RelWithDebInfo without its -DNDEBUG: the core's debug assertions run under the
# fuzzers (every other build of the project leaves them out), and one that fails
# is a finding like a crash. Eigen's own checks of every coefficient access stay
# out (EIGEN_NO_DEBUG): with them the fuzzers ran about 1.6 times fewer inputs.
# With the project's assertions alone, about as many as with -DNDEBUG (49,000 against 47,000 in 60 s).
CC=clang CXX=clang++ cmake -S "$STC_ROOT" -B "$build" -DPYTHON_EXECUTABLE=/usr/bin/python3 \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g -DEIGEN_NO_DEBUG" \
  -DCATKIN_ENABLE_TESTING=OFF \
  -DSTC_FUZZ=ON -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
targets=()
for src in "$STC_ROOT"/fuzz/fuzz_*.cpp; do targets+=("$(basename "$src" .cpp)"); done
cmake --build "$build" --target "${targets[@]}" -- -j"$jobs" >/dev/null
[ "${1:-}" = "--build-only" ] && exit 0

# test.sh sources devel/setup.bash first: without this the fuzzers ran the
# release core, no sanitizers, coverage or assertions (238 edges instead of
# 2,355 on fuzz_gaze).
preferBuildLibraries "$build"
export ASAN_OPTIONS="detect_leaks=1"
# Leaks inside the system's assimp (not the project's code) are not findings: fuzz/lsan.supp.
export LSAN_OPTIONS="suppressions=$STC_ROOT/fuzz/lsan.supp"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
mkdir -p "$build/findings"
findings=0
executions=0
for target in "${targets[@]}"; do
  name="${target#fuzz_}"
  work="$build/corpus/$name"  # this run's new inputs; fresh, so a run replays only the committed seeds
  rm -rf "$work"
  mkdir -p "$work"
  log="$build/$target.log"
  dict=()
  [ -f "$STC_ROOT/fuzz/$name.dict" ] && dict=(-dict="$STC_ROOT/fuzz/$name.dict")
  status=0
  "$build/fuzz/$target" "${dict[@]}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$build/findings/$name-" "$work" "$STC_ROOT/fuzz/corpus/$name" >"$log" 2>&1 || status=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n 1 || true)
  executions=$((executions + ${runs:-0}))
  if [ "$status" -ne 0 ]; then
    findings=$((findings + 1))
    echo "fuzz: $target FINDING (exit $status), log: $log"
    grep -m 1 -E 'ERROR|runtime error|invariant|terminate|Timeout|out-of-memory' "$log" || tail -n 20 "$log"
  else
    echo "fuzz: $target ok, ${runs:-0} executions, ${cov:-cov: ?} edges"
  fi
done
echo "fuzz: ${#targets[@]} targets, $executions executions, $findings findings"
[ "$findings" -eq 0 ]
