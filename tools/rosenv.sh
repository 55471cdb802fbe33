#!/usr/bin/env bash
# Runs a command in the workspace's ROS environment (what `source catkin_ws/devel/setup.bash` gives a user).
# ROS setup files read unset variables, so no `set -u` before sourcing.
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck disable=SC1091
source "$ROOT/catkin_ws/devel/setup.bash"
exec "$@"
