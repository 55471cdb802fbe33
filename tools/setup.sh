#!/usr/bin/env bash
# Idempotent set-up: Debian's ROS 1 packages, a venv with the pinned PyPI needs, and a catkin_make build.
# Quick when everything is already there. Run by `make setup` (and so by `make run` / `make test`).
set -eo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="$ROOT/.venv"
WS="$ROOT/catkin_ws"

DEBS=(
  # build
  cmake g++ make catkin python3-catkin-pkg python3-venv python3-pip
  # ROS 1 runtime (Debian's own packages)
  ros-core rosbash rosout python3-rospy python3-roslaunch python3-rostest librostest-dev python3-rostopic
  python3-rospkg python3-tf2-ros ros-robot-state-publisher
  python3-geometry-msgs python3-nav-msgs python3-sensor-msgs python3-std-msgs python3-std-srvs
  python3-tf2-msgs python3-rosgraph-msgs
  # map_server map images other than PGM (PNG, BMP...): diffbot_sim.world_map reads them with Pillow
  python3-pil
  # tests
  python3-pytest liburdfdom-tools iproute2 procps python3-rosnode
  # tests: sensor_laser.test projects LaserScans to point clouds as ROS users do (laser_geometry)
  python3-laser-geometry
  # teleop.launch opens the teleop in its own terminal window
  xterm
)

log() { printf '[setup] %s\n' "$*"; }

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

missing_debs() {
  local p
  for p in "${DEBS[@]}"; do
    dpkg-query -W -f='${Status}\n' "$p" 2>/dev/null | grep -q "install ok installed" || echo "$p"
  done
}

need=$(missing_debs | tr '\n' ' ')
if [ -n "${need// /}" ]; then
  log "installing Debian packages: $need"
  as_root apt-get update -q
  # shellcheck disable=SC2086
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends $need
fi

REQ="$ROOT/requirements.txt"
STAMP="$VENV/.requirements.sha"
want_sha=$(sha256sum "$REQ" | cut -d' ' -f1)
if [ ! -x "$VENV/bin/python" ] || [ "$(cat "$STAMP" 2>/dev/null)" != "$want_sha" ]; then
  log "creating venv $VENV (system site packages, for Debian's rospy)"
  /usr/bin/python3 -m venv --system-site-packages "$VENV"
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check -r "$REQ"
  echo "$want_sha" > "$STAMP"
fi

# Launch files run `xacro file.xacro`: it must be xacro 1.13.3 plus diffbot_sim.xacro_compat (noetic's
# features), not pip's bare entry point. pip rewrites .venv/bin/xacro whenever it (re)installs xacro, so
# compare the content on every run instead of trusting the requirements stamp. src/ is a fallback import
# path for when the workspace is not sourced.
XACRO_BIN="$VENV/bin/xacro"
XACRO_LAUNCHER="#!$VENV/bin/python
import sys; sys.path.append('$ROOT/src')
from diffbot_sim.xacro_compat import main; sys.exit(main())"
if [ "$(cat "$XACRO_BIN" 2>/dev/null)" != "$XACRO_LAUNCHER" ]; then
  log "installing the xacro launcher (xacro 1.13.3 + diffbot_sim.xacro_compat) as $XACRO_BIN"
  printf '%s\n' "$XACRO_LAUNCHER" > "$XACRO_BIN.tmp"
  chmod 755 "$XACRO_BIN.tmp"
  mv -f "$XACRO_BIN.tmp" "$XACRO_BIN"
fi

# catkin_ws/src/diffbot_sim is a real directory whose entries link to the root's package files. A link to
# the root itself would be a loop that roslib and rosrun walk into (each file found many times).
PKG_LINK="$WS/src/diffbot_sim"
mkdir -p "$PKG_LINK"
for entry in package.xml CMakeLists.txt setup.py cmake src scripts launch urdf config tests worlds; do
  if [ ! -L "$PKG_LINK/$entry" ]; then
    ln -sfn "../../../$entry" "$PKG_LINK/$entry"
  fi
done

BUILD_STAMP="$WS/devel/.diffbot_built"
if [ ! -f "$WS/devel/setup.bash" ] || [ -n "$(find "$ROOT/CMakeLists.txt" "$ROOT/package.xml" "$ROOT/setup.py" "$ROOT/cmake" \
       -newer "$BUILD_STAMP" 2>/dev/null | head -1)" ] || [ ! -f "$BUILD_STAMP" ]; then
  log "building $WS with catkin_make"
  (cd "$WS" && catkin_make -DPYTHON_EXECUTABLE="$VENV/bin/python" -DCATKIN_ENABLE_TESTING=ON >"$WS/catkin_make.log" 2>&1) || {
    tail -30 "$WS/catkin_make.log"; log "catkin_make failed (log: $WS/catkin_make.log)"; exit 1; }
  touch "$BUILD_STAMP"
fi
log "ready: source $WS/devel/setup.bash"
