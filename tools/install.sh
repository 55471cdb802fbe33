#!/usr/bin/env bash
# `make install PREFIX=DIR`: diffbot_sim, the drop-in packages of overlay/ and, when `make nav` built it, the
# navigation stack, installed into DIR with a venv of their own (DIR/.venv): `source DIR/setup.bash` is then all
# a user needs, with this checkout gone (docs/install.md). Run after tools/setup.sh (the Makefile does).
#
# Builds in a folder of its own (catkin_ws/build_install/), configured for DIR with Debian's /usr/bin/python3 in
# an environment that sources nothing, so no file of the install names this checkout; catkin_ws/build and
# devel (the developers' workspace) are not touched. Incremental: a second install into the same DIR
# configures nothing and copies only what changed (DIR's venv is kept while requirements.txt is unchanged).
set -eo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="$ROOT/catkin_ws/build_install"
NAV_BUILD="$ROOT/nav_ws/build"

log() { printf '[install] %s\n' "$*"; }
fail() { printf '[install] %s\n' "$*" >&2; exit 1; }

[ $# -eq 1 ] && [ -n "$1" ] || fail "usage: tools/install.sh PREFIX (make install PREFIX=DIR)"
PREFIX="$(realpath -m "$1")"
[ -d "$ROOT/catkin_ws/src/diffbot_sim" ] || fail "no $ROOT/catkin_ws/src: run make setup first"

# What a user's fresh login has: nothing of ROS sourced, no pyenv, no venv (the build must not see either).
clean_env=(env -i HOME="$HOME" PATH=/usr/bin:/bin LANG=C.UTF-8 TERM="${TERM:-dumb}")
mkdir -p "$BUILD" "$PREFIX"
# One install at a time per build folder (a test and a user, or two terminals).
exec 9>"$BUILD/.lock"
flock 9

t0=$SECONDS
# The navigation stack first (diffbot_sim's setup files, installed last, are the prefix's), from its own build
# with only the install prefix changed: nothing is compiled again (install relinks what has an RPATH). As
# below, a full `make install` only for another prefix or a new nav build; else `make install/fast` copies.
if [ -f "$ROOT/nav_ws/devel/.diffbot_built" ] && [ -f "$NAV_BUILD/CMakeCache.txt" ]; then
  nav_key="$PREFIX $(cat "$ROOT/nav_ws/devel/.diffbot_built")"
  nav_steps="make -j2 install/fast"
  if [ "$(sed -n 's/^CMAKE_INSTALL_PREFIX:PATH=//p' "$NAV_BUILD/CMakeCache.txt")" != "$PREFIX" ]; then
    nav_steps="cmake -DCMAKE_INSTALL_PREFIX='$PREFIX' . && make -j2 install"
  elif [ "$(cat "$NAV_BUILD/.diffbot_installed" 2>/dev/null)" != "$nav_key" ]; then
    nav_steps="make -j2 install"
  fi
  log "installing the navigation stack (nav_ws) into $PREFIX ($nav_steps; log $NAV_BUILD/install.log)"
  (cd "$NAV_BUILD" && "${clean_env[@]}" bash -c "$nav_steps") >"$NAV_BUILD/install.log" 2>&1 \
    || { tail -30 "$NAV_BUILD/install.log"; fail "nav_ws install failed (log $NAV_BUILD/install.log)"; }
  echo "$nav_key" > "$NAV_BUILD/.diffbot_installed"
fi

# A full `make install` (CMake's check of every target: ~20 s with nothing to do) only when the build's own inputs
# changed since the last one: the packages in catkin_ws/src, the drop-in packages' files, and diffbot_sim's
# CMake files, setup.py, scripts and batch scenarios (and the names, not the text, of the integration tests'
# helper modules, which the stamp holds). Everything else (the Python package, launch files, data) is copied by
# the install step itself, which `make install/fast` runs alone.
SRC="$ROOT/catkin_ws/src"
STAMP="$BUILD/.diffbot_built"
helpers() { (cd "$SRC/diffbot_sim/tests/integration" && ls -- *.py | grep -v '^test_' || true); }
build_inputs_changed() {
  local pkg="$SRC/diffbot_sim" other
  [ -f "$STAMP" ] || { echo "a first build for this prefix"; return; }
  [ "$(cat "$STAMP")" = "$(helpers)" ] || echo "the helpers in tests/integration"
  find -L "$SRC" -maxdepth 0 -newer "$STAMP" -print -quit
  find -L "$pkg/CMakeLists.txt" "$pkg/package.xml" "$pkg/setup.py" "$pkg/cmake" "$pkg/scripts" "$pkg/tests/rostest" \
    \( -name __pycache__ -o -name '*.pyc' \) -prune -o -newer "$STAMP" -print -quit
  for other in "$SRC"/*/; do
    [ "$(basename "$other")" = diffbot_sim ] && continue
    find -L "$other" \( -name __pycache__ -o -name '*.pyc' \) -prune -o -newer "$STAMP" -print -quit
  done
}
configure=()
if [ "$(sed -n 's/^CMAKE_INSTALL_PREFIX:PATH=//p' "$BUILD/CMakeCache.txt" 2>/dev/null)" != "$PREFIX" ]; then
  configure=(cmake "$SRC" -DCMAKE_INSTALL_PREFIX="$PREFIX" -DCATKIN_DEVEL_PREFIX="$BUILD/devel"
             -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCATKIN_ENABLE_TESTING=OFF -DCMAKE_BUILD_TYPE=Release)
  rm -f "$STAMP"
fi
target=install/fast
changed="$(build_inputs_changed)"
changed="${changed%%$'\n'*}"
if [ -n "$changed" ]; then target=install; fi
log "installing catkin_ws/src into $PREFIX (make $target${changed:+, for $changed}; log $BUILD/install.log)"
helpers > "$STAMP.new"  # at the build's start: a file changed while it runs is newer than the stamp it leaves
(cd "$BUILD" && {
   if [ ${#configure[@]} -gt 0 ]; then "${clean_env[@]}" "${configure[@]}"; fi
   "${clean_env[@]}" make -j2 "$target"
 }) >"$BUILD/install.log" 2>&1 || { tail -30 "$BUILD/install.log"; fail "install failed (log $BUILD/install.log)"; }
if [ "$target" = install ]; then mv -f "$STAMP.new" "$STAMP"; else rm -f "$STAMP.new"; fi
grep '^\[install\]' "$BUILD/install.log" || true
log "installed in $((SECONDS - t0)) s: source $PREFIX/setup.bash"
