#!/usr/bin/env bash
# Installs the built package into a prefix (cmake --install) and runs the demo
# headless from there, with nothing of the build tree on the ROS paths. Passes
# when the installed world node ticks with entities and the gaze simulator's gaze on.
# Judged by what the node logs, not by how fast: the wall-clock bound only
# guards against a hang.
set -uo pipefail
source "$(dirname "$0")/common.sh"
prefix="$STC_BUILD/install"
rm -rf "$prefix"
cmake --install "$STC_BUILD" >/dev/null || { echo "cmake --install failed"; exit 1; }
log="$(mktemp)"
port=$((20000 + RANDOM % 10000))
(
  set +u
  unset ROS_PACKAGE_PATH CMAKE_PREFIX_PATH LD_LIBRARY_PATH PYTHONPATH ROS_MASTER_URI
  # shellcheck disable=SC1091
  source /opt/ros/noetic/setup.bash 2>/dev/null || true
  # shellcheck disable=SC1091
  source "$prefix/setup.bash"
  set -u
  found="$(rospack find sphere_tree_collision)"
  echo "rospack find sphere_tree_collision: $found"
  case "$found" in "$prefix"/*) ;; *) echo "the package was not found in the install prefix"; exit 1 ;; esac
  export ROS_MASTER_URI="http://localhost:$port"
  exec roslaunch -p "$port" sphere_tree_collision demo.launch rviz:=false
) >"$log" 2>&1 &
launcher=$!
ok=1
for _ in $(seq 1 240); do  # liveness bound: 120 s
  # Entities ticking with the gaze on: the installed gaze_simulator's messages reached it.
  if grep -qE "tick [0-9]+: [1-9][0-9]* entities.*gaze on" "$log"; then ok=0; break; fi
  kill -0 "$launcher" 2>/dev/null || break
  sleep 0.5
done
kill -INT "$launcher" 2>/dev/null
wait "$launcher" 2>/dev/null
grep -E "rospack find|gaze on|ERROR|FATAL" "$log" | head -3
[ $ok -eq 0 ] && echo "installed demo ran from $prefix" || { echo "installed demo did not tick; log:"; tail -30 "$log"; }
rm -f "$log"
exit $ok
