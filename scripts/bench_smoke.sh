#!/usr/bin/env bash
# Every bench of bench/*.cpp (executable bench_NAME) in its short mode
# (--smoke: a few ticks, small N), so that none rots unseen: fails on a crash
# or a non-zero exit and names the benches that failed. Their figures mean
# nothing here. bench_bullet_* are skipped when Bullet (libbullet-dev) is
# absent, as CMakeLists.txt then builds none.
set -uo pipefail
source "$(dirname "$0")/common.sh"
benches=()
for src in "$STC_ROOT"/bench/*.cpp; do
  name="$(basename "$src" .cpp)"
  if [[ "$name" == bullet_* ]] && ! pkg-config --exists bullet; then
    echo "benches: bench_$name skipped: Bullet (libbullet-dev) is not installed"
    continue
  fi
  benches+=("bench_$name")
done
# Liveness only: a smoke run takes seconds.
STC_PROGRAM_LIMIT=600 runPrograms "$STC_BUILD" benches benches --smoke "${benches[@]}"
