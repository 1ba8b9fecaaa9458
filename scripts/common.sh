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
