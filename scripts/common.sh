# Shared by the scripts: paths and the environment ROS tools need on Debian.
# shellcheck shell=bash
STC_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
STC_BUILD="${STC_BUILD:-$STC_ROOT/build}"
# A pyenv python may come first on PATH without catkin_pkg: ROS tools use Debian's.
export PATH="/usr/bin:/bin:$PATH"
export ROS_PYTHON_VERSION=3
