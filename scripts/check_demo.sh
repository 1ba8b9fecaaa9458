#!/usr/bin/env bash
# What the README's demo runs, by package name from the build's devel space,
# headless (demoTicks): passes when the world node ticks. A copy of a launch
# file anywhere under the package folder (an install space, say) fails it.
set -uo pipefail
source "$(dirname "$0")/common.sh"
demoTicks "$STC_BUILD/devel/setup.bash" "$STC_ROOT" || exit 1
echo "demo ran by package name from $STC_BUILD/devel"
