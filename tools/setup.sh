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
  # map_server map images other than PGM (PNG, BMP...): diffbot_sim.world.map_image reads them with Pillow
  python3-pil
  # tests
  python3-pytest liburdfdom-tools iproute2 procps python3-rosnode
  # tests: sensor_laser.test projects LaserScans to point clouds as ROS users do (laser_geometry)
  python3-laser-geometry
  # teleop.launch opens the teleop in its own terminal window
  xterm
  # overlay/gazebo_msgs, overlay/controller_manager_msgs: message generation (gencpp/genpy/genlisp come with
  # ros-message-generation), the C++ headers and CMake configs of the messages they use, and the .msg
  # definitions themselves: Debian's lib*-msgs-dev CMake configs point at /usr/share/*/msg, which only the
  # ros-*-msgs packages install. python3-trajectory-msgs: gazebo_msgs.srv.SetJointTrajectory imports it.
  ros-message-generation ros-message-runtime
  libstd-msgs-dev libgeometry-msgs-dev libsensor-msgs-dev libtrajectory-msgs-dev
  ros-std-msgs ros-geometry-msgs ros-sensor-msgs ros-trajectory-msgs
  python3-trajectory-msgs
  # overlay/control_msgs: actions (add_action_files, genaction.py, C++ headers), actionlib_msgs' .msg files,
  # its Python classes; python3-actionlib for FollowJointTrajectory / GripperCommand action servers and clients
  libactionlib-msgs-dev ros-actionlib-msgs python3-actionlib-msgs python3-actionlib
  # view.launch, plot_run, make pictures and the headless picture suites (view_rviz): Debian's rviz 1.14, the
  # world's markers, bags, matplotlib (Agg); Xvfb + Mesa's software OpenGL, xwininfo/xdpyinfo, ImageMagick's import
  rviz python3-visualization-msgs python3-rosbag python3-matplotlib
  xvfb libgl1-mesa-dri x11-utils imagemagick
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
# The developers' and CI's tools (ruff, mypy: `make lint`), in the same venv under a stamp of their own, so that
# STAMP still says the venv holds exactly requirements.txt's pins (an install space seeds its venv on that).
REQ_DEV="$ROOT/requirements-dev.txt"
DEV_STAMP="$VENV/.requirements-dev.sha"
want_dev_sha=$(sha256sum "$REQ_DEV" | cut -d' ' -f1)
if [ "$(cat "$DEV_STAMP" 2>/dev/null)" != "$want_dev_sha" ]; then
  log "installing the developer tools of $(basename "$REQ_DEV") into $VENV"
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check -r "$REQ_DEV"
  echo "$want_dev_sha" > "$DEV_STAMP"
fi

# Launch files run `xacro file.xacro`: it must be xacro 1.13.3 plus diffbot_sim.description.xacro_compat (noetic's
# features), not pip's bare entry point. pip rewrites .venv/bin/xacro whenever it (re)installs xacro, so
# compare the content on every run instead of trusting the requirements stamp. src/ is a fallback import
# path for when the workspace is not sourced.
XACRO_BIN="$VENV/bin/xacro"
XACRO_LAUNCHER="#!$VENV/bin/python
import sys; sys.path.append('$ROOT/src')
from diffbot_sim.description.xacro_compat import main; sys.exit(main())"
if [ "$(cat "$XACRO_BIN" 2>/dev/null)" != "$XACRO_LAUNCHER" ]; then
  log "installing the xacro launcher (xacro 1.13.3 + diffbot_sim.description.xacro_compat) as $XACRO_BIN"
  printf '%s\n' "$XACRO_LAUNCHER" > "$XACRO_BIN.tmp"
  chmod 755 "$XACRO_BIN.tmp"
  mv -f "$XACRO_BIN.tmp" "$XACRO_BIN"
fi

# catkin_ws/src/diffbot_sim is a real directory whose entries link to the root's package files. A link to
# the root itself would be a loop that roslib and rosrun walk into (each file found many times).
PKG_LINK="$WS/src/diffbot_sim"
mkdir -p "$PKG_LINK"
for entry in package.xml CMakeLists.txt setup.py cmake src scripts launch urdf config tests worlds maps examples rviz; do
  if [ ! -L "$PKG_LINK/$entry" ]; then
    ln -sfn "../../../$entry" "$PKG_LINK/$entry"
  fi
done

# moveit_config/ is a second package of this repository, diffbot_arm_moveit_config (MoveIt's files for
# diffbot_arm; it needs MoveIt only when launched): linked as catkin_ws/src/diffbot_arm_moveit_config.
if [ "$(readlink "$WS/src/diffbot_arm_moveit_config" 2>/dev/null)" != "../../moveit_config" ]; then
  ln -sfn "../../moveit_config" "$WS/src/diffbot_arm_moveit_config"
fi

# overlay/ holds drop-in catkin packages for ROS 1 packages Debian does not ship (gazebo_msgs,
# controller_manager_msgs, ...). Each directory with a package.xml is linked as catkin_ws/src/<name> ->
# ../../overlay/<name>. DIFFBOT_SIM_OVERLAY=0 leaves them all out (for a machine with the real packages,
# e.g. a Gazebo install) and removes links left by earlier runs.
OVERLAY="$ROOT/overlay"
overlay_pkgs=()
if [ "${DIFFBOT_SIM_OVERLAY:-1}" != "0" ] && [ -d "$OVERLAY" ]; then
  for d in "$OVERLAY"/*/; do
    if [ -f "$d/package.xml" ]; then overlay_pkgs+=("$(basename "$d")"); fi
  done
fi
is_linked() { [[ " ${overlay_pkgs[*]} " == *" $1 "* ]]; }
# Drop links into overlay/ that are no longer wanted (opted out, or the package was removed).
for link in "$WS"/src/*; do
  if [ -L "$link" ] && [[ "$(readlink "$link")" == ../../overlay/* ]] && ! is_linked "$(basename "$link")"; then
    rm -f "$link"
  fi
done
for name in "${overlay_pkgs[@]}"; do
  link="$WS/src/$name"
  if [ "$(readlink "$link" 2>/dev/null)" != "../../overlay/$name" ]; then
    if [ -e "$link" ] && [ ! -L "$link" ]; then
      log "catkin_ws/src/$name exists and is not a link: leaving it, not linking overlay/$name"; continue
    fi
    ln -sfn "../../overlay/$name" "$link"
  fi
done
if [ "${#overlay_pkgs[@]}" -gt 0 ]; then
  log "overlay packages linked: ${overlay_pkgs[*]}"
elif [ "${DIFFBOT_SIM_OVERLAY:-1}" = "0" ]; then
  log "overlay packages linked: none (DIFFBOT_SIM_OVERLAY=0)"
else
  log "overlay packages linked: none"
fi

BUILD_STAMP="$WS/devel/.diffbot_built"
# What the last build saw of overlay/: line 1 the linked packages, line 2 a hash of their files' paths and
# mtimes. A file newer than the build, a new or deleted file, or another set of packages all rebuild.
OVERLAY_STAMP="$WS/devel/.diffbot_overlay"
overlay_sig() {
  local name
  for name in "${overlay_pkgs[@]}"; do
    echo "package $name"
    (cd "$OVERLAY" && find -L "$name" \( -name __pycache__ -o -name '*.pyc' -o -name '.*' \) -prune \
       -o -type f -printf '%p %T@\n' 2>/dev/null || true) | LC_ALL=C sort
  done | sha256sum | cut -d' ' -f1
}
want_overlay="${overlay_pkgs[*]}
$(overlay_sig)"
# The workspaces `make nav` and `make moveit` build (nav_ws/, moveit_ws/) are this workspace's underlays when they
# exist: catkin then chains them, and `source catkin_ws/devel/setup.bash` alone finds amcl, move_base, gmapping and
# MoveIt too. A change of underlays needs a fresh configure (catkin caches the chain), so it is stamped like the
# overlay packages.
UNDERLAY_STAMP="$WS/devel/.diffbot_underlay"
underlay=""
for under in nav_ws moveit_ws; do
  if [ -f "$ROOT/$under/devel/setup.sh" ] && [ -f "$ROOT/$under/devel/.diffbot_built" ]; then
    underlay="${underlay:+$underlay }$ROOT/$under/devel"
  fi
done
need_build=""
if [ ! -f "$WS/devel/setup.bash" ] || [ ! -f "$BUILD_STAMP" ]; then
  need_build=1
elif [ "$(cat "$UNDERLAY_STAMP" 2>/dev/null)" != "$underlay" ]; then
  log "underlay changed (${underlay:-none}): cleaning $WS/build and $WS/devel"
  rm -rf "$WS/build" "$WS/devel"
  need_build=1
elif [ "$(cat "$OVERLAY_STAMP" 2>/dev/null)" != "$want_overlay" ]; then
  need_build=1
elif [ -n "$(find "$ROOT/CMakeLists.txt" "$ROOT/package.xml" "$ROOT/setup.py" "$ROOT/cmake" -newer "$BUILD_STAMP" 2>/dev/null | head -1)" ]; then
  need_build=1
fi
if [ -n "$need_build" ]; then
  # An overlay package that left the workspace (DIFFBOT_SIM_OVERLAY=0, or removed) keeps its generated code
  # and CMake config in devel/ and its cache entries in build/, where they would still shadow the real
  # package: start from a clean build/ and devel/ then.
  built_before="$(head -1 "$OVERLAY_STAMP" 2>/dev/null || true)"
  for name in $built_before $(cd "$OVERLAY" 2>/dev/null && ls -d -- */ 2>/dev/null | tr -d /); do
    if ! is_linked "$name" && { [ -e "$WS/devel/share/$name" ] || [ -e "$WS/build/$name" ]; }; then
      log "$name left the workspace: cleaning $WS/build and $WS/devel"
      rm -rf "$WS/build" "$WS/devel"
      break
    fi
  done
  log "building $WS with catkin_make"
  t0=$SECONDS
  # shellcheck disable=SC1090
  (set +eu; extend=""; for under in $underlay; do . "$under/setup.sh" $extend; extend=--extend; done
   cd "$WS" && catkin_make -DPYTHON_EXECUTABLE="$VENV/bin/python" -DCATKIN_ENABLE_TESTING=ON >"$WS/catkin_make.log" 2>&1) || {
    tail -30 "$WS/catkin_make.log"; log "catkin_make failed (log: $WS/catkin_make.log)"; exit 1; }
  touch "$BUILD_STAMP"
  printf '%s\n' "$underlay" > "$UNDERLAY_STAMP"
  printf '%s\n' "$want_overlay" > "$OVERLAY_STAMP"
  log "built in $((SECONDS - t0)) s"
fi
log "ready: source $WS/devel/setup.bash"
