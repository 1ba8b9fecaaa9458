#!/usr/bin/env bash
# Installs the built package (cmake --install) under a temporary directory
# outside the package folder, removed afterwards, compiles the core's
# hello-world example against the installed headers and library alone and
# runs it, and runs the demo headless from there, with nothing of the build
# tree on the ROS paths (demoTicks).
# Outside, because roslaunch searches the whole package folder, and a second
# demo.launch there stops `roslaunch sphere_tree_collision demo.launch`.
# DESTDIR, not --prefix: catkin's setup files go to the configured prefix
# whatever --prefix says, so the install lands whole in DESTDIR/PREFIX.
set -uo pipefail
source "$(dirname "$0")/common.sh"
stage="$(mktemp -d "${TMPDIR:-/tmp}/stc_install.XXXXXX")"
trap 'rm -rf "$stage"' EXIT
configured="$(sed -n 's/^CMAKE_INSTALL_PREFIX:PATH=//p' "$STC_BUILD/CMakeCache.txt")"
prefix="$stage$configured"
DESTDIR="$stage" cmake --install "$STC_BUILD" >/dev/null || { echo "cmake --install failed"; exit 1; }
# A user of the ROS-free core: its installed headers, Eigen and the library, nothing of the source tree.
"${CXX:-g++}" -std=c++17 -O1 -I"$prefix/include" -I/usr/include/eigen3 "$STC_ROOT/examples/hello_world.cpp" \
  -L"$prefix/lib" -Wl,-rpath,"$prefix/lib" -lstc_core -ltbb -o "$stage/hello_world" ||
  { echo "examples/hello_world.cpp does not build against the installed headers"; exit 1; }
"$stage/hello_world" >/dev/null || { echo "hello_world built against the install failed"; exit 1; }
echo "hello_world built against the installed headers and ran"
demoTicks "$prefix/setup.bash" "$prefix" || exit 1
echo "installed demo ran from $prefix"
