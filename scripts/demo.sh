#!/usr/bin/env bash
# The main job: install what is missing, build, run the demo. With a display,
# rviz opens with the shipped config; without one, the node runs headless and
# prints a line per second with tick counts. Extra arguments go to roslaunch.
set -euo pipefail
source "$(dirname "$0")/common.sh"
bash "$STC_ROOT/scripts/install_deps.sh"
bash "$STC_ROOT/scripts/build.sh" --demo
# ROS setup files read unset variables: source them without -u.
set +u
# shellcheck disable=SC1091
source "$STC_BUILD/devel/setup.bash"
set -u
rviz=true
if [ -z "${DISPLAY:-}" ]; then
  echo "demo: no DISPLAY, running headless (rviz:=false)"
  rviz=false
fi
exec roslaunch sphere_tree_collision demo.launch rviz:=$rviz "$@"
