#!/usr/bin/env bash
# Runs a command in the workspace's ROS environment (what `source catkin_ws/devel/setup.bash` gives a user).
# ROS setup files read unset variables, so no `set -u` before sourcing.
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# `source FILE` with positional parameters set hands them to FILE (catkin's setup.bash reads its own options
# from them: `rosenv.sh python3 x.py --help` printed catkin's usage), so the command's words are kept aside.
command=("$@")
set --
# shellcheck disable=SC1091
source "$ROOT/catkin_ws/devel/setup.bash"
exec "${command[@]}"
