#!/usr/bin/env bash
# The install space's Python environment; run by diffbot_sim's install rules (cmake/install_space.cmake), so by
# `make install PREFIX=DIR` and by a plain `catkin_make install` alike:
#   install_venv.sh DEST PREFIX REQUIREMENTS [SEED_VENV]
# DEST is where the files go now ($DESTDIR$PREFIX: the same as PREFIX unless staging), PREFIX where they will
# be used. Makes DEST/.venv: a venv over Debian's /usr/bin/python3 with its system site packages (rospy, the
# message packages) plus the pinned PyPI packages of REQUIREMENTS (PyBullet, xacro 1.13.3, numpy, ray, ...,
# none of which Debian ships), and DEST/.venv/bin/xacro, the launcher of xacro 1.13.3 with diffbot_sim's noetic
# layer that launch files run as `xacro` (the install space's env hook puts .venv/bin first on PATH; the xacro
# drop-in package's $(find xacro)/xacro runs it too). The installed nodes' first line names .venv/bin/python.
#
# Quick when nothing changed (a stamp of REQUIREMENTS). A fresh venv is seeded from SEED_VENV (the checkout's
# .venv, which `make setup` made with pip from the same REQUIREMENTS) by hard links when it can, a copy
# otherwise: under a second where pip would take half a minute to unpack ~650 MB of wheels again.
set -eo pipefail

DEST="$1"
PREFIX="$2"
REQ="$3"
SEED="${4:-}"
PYTHON=/usr/bin/python3
VENV="$DEST/.venv"
FINAL="$PREFIX/.venv"

log() { printf '[install] %s\n' "$*"; }
fail() { printf '[install] %s\n' "$*" >&2; exit 1; }

[ -n "$DEST" ] && [ -n "$PREFIX" ] && [ -f "$REQ" ] \
  || fail "usage: install_venv.sh DEST PREFIX REQUIREMENTS [SEED_VENV]"
[ -x "$PYTHON" ] || fail "$PYTHON is missing: the install space runs on Debian's python3 (apt-get install python3)"

want_sha=$(sha256sum "$REQ" | cut -d' ' -f1)
STAMP="$VENV/.requirements.sha"
if [ ! -x "$VENV/bin/python" ] || [ "$(cat "$STAMP" 2>/dev/null)" != "$want_sha" ]; then
  rm -f "$STAMP"
  log "creating $VENV (Debian's python3 with its system site packages, for rospy)"
  # No pip of its own: the seed brings one, else Debian's (python3-pip, a system site package) installs.
  "$PYTHON" -m venv --without-pip --system-site-packages "$VENV"
  site=$("$VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
  seed_site="$SEED/lib/$(basename "$(dirname "$site")")/site-packages"
  if [ -n "$SEED" ] && [ "$(cat "$SEED/.requirements.sha" 2>/dev/null)" = "$want_sha" ] && [ -d "$seed_site" ]; then
    # pip installed exactly these pins there. Hard links cost nothing, and no file is ever changed in place
    # (pip replaces files, it does not edit them).
    log "seeding it from $SEED (made by pip from the same $(basename "$REQ"))"
    (cd "$seed_site" && for entry in * .[!.]*; do
       if [ -e "$entry" ]; then cp -al "$entry" "$site/" 2>/dev/null || cp -a "$entry" "$site/"; fi
     done)
    # The packages' commands (pip, ray, ...); their first line is pointed at this venv below.
    for script in "$SEED"/bin/*; do
      if [ -f "$script" ] && [ ! -L "$script" ] && head -1 "$script" | grep -q '^#!.*/bin/python[0-9.]*$'; then
        cp -p "$script" "$VENV/bin/"
      fi
    done
  else
    log "installing $(basename "$REQ") into $VENV with pip"
    "$VENV/bin/python" -m pip install -q --disable-pip-version-check -r "$REQ" \
      || fail "pip could not install $REQ into $VENV (above; Debian's pip is python3-pip)"
  fi
  echo "$want_sha" > "$STAMP"
fi

# Every command of the venv starts the venv's Python where it will be used (PREFIX, not a staging DEST or the
# seed's venv).
for script in "$VENV"/bin/*; do
  if [ -f "$script" ] && [ ! -L "$script" ] && head -1 "$script" | grep -q '^#!.*/bin/python[0-9.]*$' \
     && [ "$(head -1 "$script")" != "#!$FINAL/bin/python" ]; then
    sed -i "1s|.*|#!$FINAL/bin/python|" "$script"
  fi
done

# xacro 1.13.3 with diffbot_sim.description.xacro_compat (noetic's features), not pip's bare entry point. pip
# rewrites .venv/bin/xacro whenever it (re)installs xacro, so it is written on every install. The install
# space's Python packages are a fallback import path for when its setup file is not sourced.
REPAIR="$FINAL/bin/python -m pip install -r $PREFIX/share/diffbot_sim/requirements.txt"
LAUNCHER="#!$FINAL/bin/python
import sys; sys.path.append('$PREFIX/lib/python3/dist-packages')
try:
    import xacro  # noqa: F401
except ImportError as err:
    sys.exit(f'xacro: {err}: install it with $REPAIR')
from diffbot_sim.description.xacro_compat import main; sys.exit(main())"
if [ "$(cat "$VENV/bin/xacro" 2>/dev/null)" != "$LAUNCHER" ]; then
  printf '%s\n' "$LAUNCHER" > "$VENV/bin/xacro.tmp"
  chmod 755 "$VENV/bin/xacro.tmp"
  mv -f "$VENV/bin/xacro.tmp" "$VENV/bin/xacro"
fi
log "ready: $VENV"
