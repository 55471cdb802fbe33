#!/usr/bin/env bash
# `make moveit`: MoveIt 1 (noetic-devel, 1.1.14) and the ROS packages it needs that Debian 12 does not ship
# (moveit_msgs, srdfdom, warehouse_ros, octomap_msgs, object_recognition_msgs, ruckig, trac_ik, eigenpy), built into
# moveit_ws/ against Debian's own ROS 1, Boost, OMPL, FCL, octomap, KDL, rviz. Sources: the pinned upstream commits
# of tools/moveit_sources.tsv, cloned from GitHub, or with MOVEIT_SOURCES=DIR[:DIR...] the pinned tarballs found in
# those folders (a machine without network). Idempotent: with nothing changed a second run takes seconds; a change
# of this script, the pins or the shims (tools/moveit_compat/) builds again (catkin_make_isolated rebuilds what
# changed). Where ROS Noetic's MoveIt is installed from packages (Ubuntu 20.04), nothing is built.
# `source catkin_ws/devel/setup.bash` then finds MoveIt: catkin_ws is rebuilt with moveit_ws (and nav_ws, when
# built) as its underlays (tools/setup.sh), so its setup file chains them. MOVEIT_RVIZ=0 leaves out rviz's
# MotionPlanning plugin (moveit_ros_visualization and the perception plugins it needs).
set -eo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WS="$ROOT/moveit_ws"
PINNED="$ROOT/tools/moveit_sources.tsv"
COMPAT="$ROOT/tools/moveit_compat"

log() { printf '[moveit] %s\n' "$*"; }
fail() { printf '[moveit] %s\n' "$*" >&2; exit 1; }

if [ -f /opt/ros/noetic/share/moveit_ros_move_group/package.xml ] \
   && [ -f /opt/ros/noetic/share/moveit_commander/package.xml ]; then
  log "ROS Noetic's MoveIt is installed (/opt/ros/noetic): nothing to build"
  exit 0
fi

# Debian packages the sources build against and the nodes run with (each checked to exist in bookworm).
# Debian has eigen_conversions, kdl_conversions and tf_conversions (libtf-conversions-dev): not built here.
DEBS=(
  build-essential cmake catkin git ros-cmake-modules pkg-config
  libboost-all-dev libeigen3-dev libompl-dev libfcl-dev liboctomap-dev libassimp-dev libqhull-dev
  liburdfdom-dev liburdfdom-headers-dev liburdf-dev libkdl-parser-dev liborocos-kdl-dev libtinyxml2-dev
  libtf-dev libtf2-eigen-dev libtf2-kdl-dev libtf2-geometry-msgs-dev libtf2-ros-dev libtf-conversions-dev
  libeigen-stl-containers-dev libgeometric-shapes-dev librandom-numbers-dev libresource-retriever-dev
  libinteractive-markers-dev pybind11-dev libactionlib-dev libdynamic-reconfigure-config-init-mutex-dev
  libnlopt-cxx-dev libnlopt-dev pluginlib-dev libclass-loader-dev libroslib-dev libangles-dev libyaml-cpp-dev
  libomp-dev libmessage-filters-dev libroscpp-dev librosconsole-dev libxmlrpcpp-dev
  libshape-msgs-dev libvisualization-msgs-dev libstd-srvs-dev libtrajectory-msgs-dev libsensor-msgs-dev
  libgeometry-msgs-dev libstd-msgs-dev libactionlib-msgs-dev libtf2-msgs-dev
  ros-message-generation ros-message-runtime python3-dynamic-reconfigure
  # the .msg files the message packages' CMake configs point at (/usr/share/<pkg>/msg)
  ros-shape-msgs ros-trajectory-msgs ros-visualization-msgs ros-sensor-msgs ros-geometry-msgs ros-std-msgs
  ros-actionlib-msgs ros-tf2-msgs
  # moveit_commander and the Python side of the messages
  python3-numpy python3-pyassimp python3-pykdl python3-tf-conversions python3-tf2-kdl python3-tf python3-lxml
  python3-yaml python3-catkin-pkg python3-actionlib python3-tf2-ros python3-tf2-geometry-msgs python3-rosnode
  python3-shape-msgs python3-visualization-msgs python3-trajectory-msgs python3-sensor-msgs python3-geometry-msgs
  python3-interactive-markers
)
RVIZ_DEBS=(  # rviz's MotionPlanning plugin (moveit_ros_visualization) and the perception plugins it needs
  rviz librviz-dev qtbase5-dev libqt5opengl5-dev libogre-1.12-dev freeglut3-dev libglew-dev libimage-transport-dev
  libcv-bridge-dev libnodeletlib-dev libnodelet-dev
)
rviz="${MOVEIT_RVIZ:-1}"
[ "$rviz" = 0 ] || DEBS+=("${RVIZ_DEBS[@]}")
as_root() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }
need=""
for p in "${DEBS[@]}"; do
  dpkg-query -W -f='${Status}\n' "$p" 2>/dev/null | grep -q "install ok installed" || need="$need $p"
done
if [ -n "$need" ]; then
  log "installing Debian packages:$need"
  as_root apt-get update -q
  # shellcheck disable=SC2086
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends $need
fi

# --- sources: one directory per repository under moveit_ws/src, each stamped with what it was made from
find_tarball() {  # the first of MOVEIT_SOURCES's folders (colon-separated) that holds the tarball
  local dir
  IFS=: read -ra dirs <<< "$MOVEIT_SOURCES"
  for dir in "${dirs[@]}"; do [ -f "$dir/$1" ] && { echo "$dir/$1"; return 0; }; done
  return 1
}
mkdir -p "$WS/src"
while IFS=$'\t' read -r name repo commit tarball sha; do
  case "$name" in ''|'#'*) continue ;; esac
  dest="$WS/src/$name"
  want="${MOVEIT_SOURCES:+tarball $tarball $sha}"
  want="${want:-git $commit}"
  # The pinned commit, cloned or as its pinned tarball, is the same source: kept either way (a second run
  # without network after a build from tarballs must not throw the sources away)
  if [ -f "$dest/.diffbot_source" ] && { [ "$(cat "$dest/.diffbot_source")" = "git $commit" ] \
       || [ "$(cat "$dest/.diffbot_source")" = "tarball $tarball $sha" ]; }; then
    continue
  fi
  rm -rf "$dest.tmp"
  mkdir -p "$dest.tmp"
  if [ -n "${MOVEIT_SOURCES:-}" ]; then
    file=$(find_tarball "$tarball") \
      || fail "$tarball: in none of MOVEIT_SOURCES=$MOVEIT_SOURCES (the folders must hold the pinned tarballs of tools/moveit_sources.tsv)"
    got=$(sha256sum "$file" | cut -d' ' -f1)
    [ "$got" = "$sha" ] || fail "$file: sha256 $got is not the pinned $sha (tools/moveit_sources.tsv)"
    log "unpacking $tarball"
    tar -xzf "$file" -C "$dest.tmp" --strip-components=1
  else
    log "cloning $repo at ${commit:0:7}"
    if ! { git -C "$dest.tmp" init -q && git -C "$dest.tmp" fetch -q --depth 1 "$repo" "$commit" \
             && git -C "$dest.tmp" -c advice.detachedHead=false checkout -q FETCH_HEAD \
             && { [ ! -f "$dest.tmp/.gitmodules" ] \
                  || git -C "$dest.tmp" submodule -q update --init --recursive --depth 1; }; } 2>"$WS/clone.log"; then
      rm -rf "$dest.tmp"
      fail "could not clone $repo ($(tail -1 "$WS/clone.log")); without network, give the pinned tarballs: make moveit MOVEIT_SOURCES=DIR"
    fi
    find "$dest.tmp" -name .git -prune -exec rm -rf {} +
  fi
  echo "$want" > "$dest.tmp/.diffbot_source"
  rm -rf "$dest"  # only now: a failed fetch leaves the sources that were there
  mv "$dest.tmp" "$dest"
  rm -f "$WS/devel/.diffbot_built"
done < "$PINNED"

# Two packages that are not fetched: the project's control_msgs (overlay/, which Debian lacks and
# moveit_simple_controller_manager needs; catkin_ws builds the same one on top) and the pybind11_catkin stand-in.
for link in "control_msgs:../../overlay/control_msgs" "pybind11_catkin:../../tools/moveit_compat/pybind11_catkin"; do
  [ "$(readlink "$WS/src/${link%%:*}" 2>/dev/null)" = "${link#*:}" ] || ln -sfn "${link#*:}" "$WS/src/${link%%:*}"
done

# Only what a user needs to plan and execute; the rest of the repositories (chomp, pilz, benchmarks, servo, the
# ros_control interface, ...) is left out. Bullet's collision plugin is left out too (FCL is MoveIt's default).
CORE=(moveit_core moveit_ros_planning moveit_ros_move_group moveit_planners_ompl moveit_kinematics
      moveit_simple_controller_manager moveit_fake_controller_manager moveit_ros_planning_interface moveit_commander
      moveit_ros_robot_interaction moveit_ros_warehouse moveit_ros_manipulation moveit_ros_occupancy_map_monitor
      moveit_msgs srdfdom warehouse_ros octomap_msgs object_recognition_msgs ruckig eigenpy pybind11_catkin
      control_msgs trac_ik_lib trac_ik_kinematics_plugin)
RVIZ=(moveit_ros_perception moveit_ros_visualization)
select_packages() {  # CATKIN_IGNORE every package not named in the arguments
  local manifest dir pkg
  while IFS= read -r manifest; do
    dir=$(dirname "$manifest")
    pkg=$(sed -n 's:.*<name>\(.*\)</name>.*:\1:p' "$manifest" | head -1)
    if [[ " $* " == *" $pkg "* ]]; then
      rm -f "$dir/CATKIN_IGNORE"
    else
      [ -f "$dir/CATKIN_IGNORE" ] || touch "$dir/CATKIN_IGNORE"
    fi
  done < <(find -L "$WS/src" -name package.xml -not -path "*/cmake/*")
}

# --- build, in an environment of its own (Debian's /usr/bin/python3; not chained on catkin_ws, whose setup
# sources this workspace). Shims in tools/moveit_compat/ (not patches to the sources): pluginlib's old
# class_list_macros.h name for trac_ik; pybind11_catkin on Debian's pybind11; bind's global placeholders, which
# Boost 1.74 still gives but warns about (BOOST_BIND_GLOBAL_PLACEHOLDERS keeps the old behaviour, quietly).
key=$( (cat "$0" "$PINNED"; find "$COMPAT" -type f | LC_ALL=C sort | xargs cat; echo "rviz=$rviz") | sha256sum | cut -d' ' -f1)
if [ -f "$WS/devel/setup.sh" ] && [ "$(cat "$WS/devel/.diffbot_built" 2>/dev/null)" = "$key" ]; then
  bash "$ROOT/tools/setup.sh" >/dev/null  # (a no-op unless catkin_ws does not chain moveit_ws yet)
  log "ready (nothing changed): source $ROOT/catkin_ws/devel/setup.bash"
  exit 0
fi
# Release at -O1 (CMake's Release is -O3): on 2 cores the build is about half as long, and what runs at -O1 is
# MoveIt's own code; collision checking and sampling run in Debian's optimised FCL and OMPL (docs/moveit.md).
CMAKE_ARGS=(-DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS_RELEASE=-O1 -DNDEBUG" -DPYTHON_EXECUTABLE=/usr/bin/python3
  -DCATKIN_ENABLE_TESTING=OFF -DBUILD_TESTING=OFF -DBUILD_TESTS=OFF -DBUILD_EXAMPLES=OFF -DCMAKE_DISABLE_FIND_PACKAGE_Bullet=ON
  -DINSTALL_DOCUMENTATION=OFF -DBUILD_TESTING_SCIPY=OFF -DGENERATE_PYTHON_STUBS=OFF
  "-DCMAKE_CXX_FLAGS=-DBOOST_BIND_GLOBAL_PLACEHOLDERS -I$COMPAT/include")
# A change of the CMake arguments needs every package configured again (catkin_make_isolated keeps each cache);
# each stage stamps the arguments its packages were configured with.
args_key=$(printf '%s\n' "${CMAKE_ARGS[@]}" | sha256sum | cut -d' ' -f1)

build_stage() {  # $1: what it is, then the packages; catkin_make_isolated's progress as [moveit] lines
  local what="$1" stage_log="$WS/build_$1.log" force=""; shift
  [ "$(cat "$WS/build/.diffbot_cmake_args_$what" 2>/dev/null)" = "$args_key" ] || force="--force-cmake"
  select_packages "$@"
  log "building $what: $# packages with catkin_make_isolated -j2 under nice (log $stage_log)"
  # (PYTHONUNBUFFERED: catkin_make_isolated's own lines would otherwise reach the log long after make's)
  (env -i HOME="$HOME" PATH=/usr/bin:/bin LANG=C.UTF-8 ROS_PYTHON_VERSION=3 PYTHONUNBUFFERED=1 \
     nice -n 10 catkin_make_isolated -C "$WS" --merge --build "$WS/build" --devel "$WS/devel" -j2 --no-color $force \
       --cmake-args "${CMAKE_ARGS[@]}" >"$stage_log" 2>&1) &
  local pid=$! seen=0 lines
  while kill -0 "$pid" 2>/dev/null; do
    sleep 5
    lines=$(grep -c '^==> Processing' "$stage_log" 2>/dev/null || true)
    if [ "${lines:-0}" -gt "$seen" ]; then
      grep '^==> Processing' "$stage_log" | sed -n "$((seen + 1)),${lines}p" \
        | sed "s/.*package: '\(.*\)'/[moveit]   \1 ($((SECONDS - t0)) s)/"
      seen=$lines
    fi
  done
  wait "$pid" || return 1
  printf '%s\n' "$args_key" > "$WS/build/.diffbot_cmake_args_$what"
}
t0=$SECONDS
log "building $WS (the first time about an hour on 2 cores; a rebuild only what changed)"
# First move_group with what it plans and executes with (OMPL, the kinematics plugins, the controller managers), so
# a compile error in MoveIt's own C++ shows early and move_group runs before the rest is built; then eigenpy (~45
# heavy files alone) and the planning interface with what it needs (moveit_commander's side).
LATER=(eigenpy moveit_ros_planning_interface moveit_commander moveit_ros_manipulation moveit_ros_robot_interaction
       moveit_ros_warehouse warehouse_ros)
for stage in core python; do
  if [ "$stage" = core ]; then
    set -- $(printf '%s\n' "${CORE[@]}" | grep -vxF "$(printf '%s\n' "${LATER[@]}")")
  else
    set -- "${CORE[@]}"
  fi
  if ! build_stage "$stage" "$@"; then
    grep -B5 -A20 -m3 'error:\|Error ' "$WS/build_$stage.log" | tail -60
    fail "catkin_make_isolated failed (log: $WS/build_$stage.log)"
  fi
done
# What users run, checked to exist: a package left out would only show when move_group fails to load a plugin.
for f in lib/moveit_ros_move_group/move_group lib/libmoveit_ompl_interface.so lib/libmoveit_kdl_kinematics_plugin.so \
         lib/libtrac_ik_kinematics_plugin.so lib/libmoveit_simple_controller_manager.so \
         lib/libmoveit_fake_controller_manager.so lib/libmoveit_move_group_interface.so lib/libeigenpy.so \
         lib/python3/dist-packages/moveit_commander/__init__.py; do
  [ -e "$WS/devel/$f" ] || fail "the build made no $WS/devel/$f (logs: $WS/build_*.log)"
done
rviz_note=""
if [ "$rviz" != 0 ]; then
  if build_stage rviz "${CORE[@]}" "${RVIZ[@]}" && [ -e "$WS/devel/lib/libmoveit_motion_planning_rviz_plugin.so" ]; then
    rviz_note=", with rviz's MotionPlanning plugin"
  else
    log "rviz's MotionPlanning plugin did not build (log: $WS/build_rviz.log); move_group and moveit_commander are unaffected"
    select_packages "${CORE[@]}"
    rviz_note=", without rviz's MotionPlanning plugin"
  fi
fi
echo "$key" > "$WS/devel/.diffbot_built"
echo "$((SECONDS - t0))" > "$WS/devel/.diffbot_build_seconds"
log "built in $((SECONDS - t0)) s$rviz_note"
bash "$ROOT/tools/setup.sh"  # catkin_ws now chains moveit_ws: its setup file finds MoveIt
