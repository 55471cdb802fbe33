#!/usr/bin/env bash
# `make nav`: the ROS 1 navigation stack (amcl, map_server, move_base, costmaps, navfn, global_planner,
# base_local_planner, dwa_local_planner, recoveries, voxel_grid) and gmapping, built into nav_ws/ for Debian 12,
# which packages ROS 1's core but neither. Sources: the pinned upstream commits of tools/nav_sources.tsv,
# cloned from GitHub, or with NAV_SOURCES=DIR the pinned tarballs from DIR (a machine without network).
# Idempotent: with nothing changed a second run takes seconds; a change of this script, the pins or the shims
# configures and builds again (--force-cmake: catkin_make alone misses a package set changed). Where ROS Noetic is installed from packages
# (Ubuntu 20.04), nothing is built. `source catkin_ws/devel/setup.bash` then finds the packages: catkin_ws is
# rebuilt with nav_ws as its underlay (tools/setup.sh), so its setup file chains both.
set -eo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WS="$ROOT/nav_ws"
PINNED="$ROOT/tools/nav_sources.tsv"

log() { printf '[nav] %s\n' "$*"; }
fail() { printf '[nav] %s\n' "$*" >&2; exit 1; }

for pkg in move_base gmapping amcl map_server; do
  [ -f "/opt/ros/noetic/share/$pkg/package.xml" ] || { noetic=""; break; }
  noetic=1
done
if [ -n "${noetic:-}" ]; then
  log "ROS Noetic's navigation and gmapping are installed (/opt/ros/noetic): nothing to build"
  exit 0
fi

# Debian packages the sources build against (each checked to exist in bookworm).
DEBS=(
  build-essential cmake catkin libroscpp-dev librosconsole-dev libtf-dev libtf2-dev libtf2-ros-dev
  libtf2-geometry-msgs-dev libtf2-sensor-msgs-dev pluginlib-dev libdynamic-reconfigure-config-init-mutex-dev
  python3-dynamic-reconfigure liblaser-geometry-dev libactionlib-dev libnav-msgs-dev libmap-msgs-dev
  libmove-base-msgs-dev libsdl1.2-dev libsdl-image1.2-dev libyaml-cpp-dev libangles-dev libmessage-filters-dev
  librosbag-dev libdiagnostic-updater-dev libvisualization-msgs-dev libstd-srvs-dev libbullet-dev libeigen3-dev
  liburdf-dev librostest-dev libnodeletlib-dev libnodelet-dev python3-actionlib python3-move-base-msgs
  # the .msg/.srv/.action files the message packages' CMake configs point at (/usr/share/<pkg>/...)
  ros-nav-msgs ros-map-msgs ros-move-base-msgs ros-actionlib-msgs ros-std-srvs ros-visualization-msgs
  ros-geometry-msgs ros-sensor-msgs ros-std-msgs
  # for the tools and tests that use them
  python3-nav-msgs python3-map-msgs python3-tf2-geometry-msgs
)
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

# --- sources: one directory per repository under nav_ws/src, each stamped with what it was made from
mkdir -p "$WS/src"
while IFS=$'\t' read -r name repo commit tarball sha; do
  case "$name" in ''|'#'*) continue ;; esac
  dest="$WS/src/$name"
  want="${NAV_SOURCES:+tarball $tarball $sha}"
  want="${want:-git $commit}"
  # The pinned commit, cloned or as its pinned tarball, is the same source: kept either way (a second run
  # without network after a build from tarballs must not throw the sources away)
  if [ -f "$dest/.diffbot_source" ] && { [ "$(cat "$dest/.diffbot_source")" = "git $commit" ] \
       || [ "$(cat "$dest/.diffbot_source")" = "tarball $tarball $sha" ]; }; then
    continue
  fi
  rm -rf "$dest.tmp"
  mkdir -p "$dest.tmp"
  if [ -n "${NAV_SOURCES:-}" ]; then
    file="$NAV_SOURCES/$tarball"
    [ -f "$file" ] || fail "$file: no such tarball (NAV_SOURCES=$NAV_SOURCES must hold the pinned tarballs of tools/nav_sources.tsv)"
    got=$(sha256sum "$file" | cut -d' ' -f1)
    [ "$got" = "$sha" ] || fail "$file: sha256 $got is not the pinned $sha (tools/nav_sources.tsv)"
    log "unpacking $tarball"
    tar -xzf "$file" -C "$dest.tmp" --strip-components=1
  else
    log "cloning $repo at ${commit:0:7}"
    if ! { git -C "$dest.tmp" init -q && git -C "$dest.tmp" fetch -q --depth 1 "$repo" "$commit" \
             && git -C "$dest.tmp" -c advice.detachedHead=false checkout -q FETCH_HEAD; } 2>"$WS/clone.log"; then
      rm -rf "$dest.tmp"
      fail "could not clone $repo ($(tail -1 "$WS/clone.log")); without network, give the pinned tarballs: make nav NAV_SOURCES=DIR"
    fi
    rm -rf "$dest.tmp/.git"
  fi
  echo "$want" > "$dest.tmp/.diffbot_source"
  rm -rf "$dest"  # only now: a failed fetch leaves the sources that were there
  mv "$dest.tmp" "$dest"
  rm -f "$WS/devel/.diffbot_built"
done < "$PINNED"

# Only the packages named above: the rest of the navigation repository (the metapackage, fake_localization,
# move_slow_and_clear, ...) is left out, as is anything else a clone brings.
WANTED=(amcl map_server move_base costmap_2d nav_core navfn global_planner base_local_planner dwa_local_planner
        clear_costmap_recovery rotate_recovery voxel_grid gmapping openslam_gmapping)
wanted() { local w; for w in "${WANTED[@]}"; do [ "$w" = "$1" ] && return 0; done; return 1; }
while IFS= read -r manifest; do
  dir=$(dirname "$manifest")
  pkg=$(sed -n 's:.*<name>\(.*\)</name>.*:\1:p' "$manifest" | head -1)
  if ! wanted "$pkg"; then
    [ -f "$dir/CATKIN_IGNORE" ] || touch "$dir/CATKIN_IGNORE"
  elif [ -f "$dir/CATKIN_IGNORE" ]; then
    rm -f "$dir/CATKIN_IGNORE"  # wanted: built even if an earlier run or a hand left it out
  fi
done < <(find "$WS/src" -name package.xml)

# --- build, in an environment of its own: not chained on catkin_ws (whose setup sources this workspace).
# Two build-environment shims (tools/nav_compat/, not patches to the sources) for what slam_gmapping (melodic)
# expects of Debian 12: bind's placeholders in the global namespace (Boost 1.81 keeps them out unless asked),
# and pluginlib's old class_list_macros.h name (Debian's pluginlib has only the .hpp).
# A third for the linker: slam_gmapping_replay uses boost::program_options without naming it (older linkers
# followed the libraries' own dependencies; Debian 12's needs --copy-dt-needed-entries to).
COMPAT="$ROOT/tools/nav_compat"
# What the build was made with: this script, the pins and the shims. A change rebuilds.
key=$(cat "$0" "$PINNED" "$COMPAT"/*.h "$COMPAT"/*/*.h | sha256sum | cut -d' ' -f1)
if [ -f "$WS/devel/setup.sh" ] && [ "$(cat "$WS/devel/.diffbot_built" 2>/dev/null)" = "$key" ]; then
  bash "$ROOT/tools/setup.sh" >/dev/null  # (a no-op unless catkin_ws does not chain nav_ws yet)
  log "ready (nothing changed): source $ROOT/catkin_ws/devel/setup.bash"
  exit 0
fi
log "building $WS with catkin_make (about 5 minutes on 2 cores; log $WS/build.log)"
t0=$SECONDS
if ! env -i HOME="$HOME" PATH=/usr/bin:/bin LANG=C.UTF-8 \
     bash -c "cd '$WS' && catkin_make -j2 --force-cmake -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 \
              -DCATKIN_ENABLE_TESTING=OFF -DCMAKE_CXX_FLAGS='-I$COMPAT -include $COMPAT/boost_global_placeholders.h' \
              -DCMAKE_EXE_LINKER_FLAGS=-Wl,--copy-dt-needed-entries" >"$WS/build.log" 2>&1; then
  tail -30 "$WS/build.log"
  fail "catkin_make failed (log: $WS/build.log)"
fi
# What users run, checked to exist: a package left out would only show when move_base fails to load a plugin.
for f in lib/libdwa_local_planner.so lib/libnavfn.so lib/liblayers.so lib/move_base/move_base lib/amcl/amcl \
         lib/map_server/map_server lib/map_server/map_saver lib/gmapping/slam_gmapping; do
  [ -e "$WS/devel/$f" ] || fail "the build made no $WS/devel/$f (log: $WS/build.log)"
done
echo "$key" > "$WS/devel/.diffbot_built"
log "built in $((SECONDS - t0)) s"
bash "$ROOT/tools/setup.sh"  # catkin_ws now chains nav_ws: its setup file finds both
