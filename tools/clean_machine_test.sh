#!/usr/bin/env bash
# Runs `make test` (and checks that `make run` brings up /odom) as a new user would: in a fresh
# `debootstrap --variant=minbase bookworm` chroot, a clean clone of this checkout's HEAD, entered with
# `env -i`. Needs root and the network to Debian's mirror and PyPI. ~20 min, most of it installing.
#   sudo bash tools/clean_machine_test.sh [--nav NAV_SOURCES_DIR] [CHROOT_DIR]   (the directory is deleted after)
# --nav also runs `make nav NAV_SOURCES=...` (the pinned tarballs copied in) and `make test-nav` there
# (about 35 min more).
set -eo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
NAV_DIR=""
if [ "${1:-}" = "--nav" ]; then
  NAV_DIR="$(cd "${2:?--nav needs the folder of the navigation tarballs}" && pwd)"; shift 2
fi
DIR="${1:-/var/tmp/diffbot_clean_machine}"
log() { printf '[clean-machine] %s\n' "$*"; }

command -v debootstrap >/dev/null || { apt-get update -q && apt-get install -y -q debootstrap; }
cleanup() {
  for m in run/netns dev/pts dev proc sys; do
    mountpoint -q "$DIR/$m" 2>/dev/null && umount -l "$DIR/$m" || true
  done
  rm -rf "$DIR"
}
trap cleanup EXIT
cleanup
log "debootstrap minbase bookworm into $DIR"
debootstrap --variant=minbase bookworm "$DIR" http://deb.debian.org/debian >"$DIR.debootstrap.log" 2>&1 \
  || { tail -20 "$DIR.debootstrap.log"; exit 1; }
cp /etc/resolv.conf "$DIR/etc/resolv.conf"
# debootstrap writes no /etc/hosts (Debian's installer does): without it `localhost` does not resolve and no
# ROS master can reach itself. Give the chroot what every installed Debian machine has.
[ -s "$DIR/etc/hosts" ] || printf '127.0.0.1\tlocalhost\n127.0.1.1\t%s\n::1\tlocalhost ip6-localhost ip6-loopback\n' \
  "$(hostname)" > "$DIR/etc/hosts"
# This sandbox reaches PyPI through a TLS-intercepting proxy whose CA only the host trusts (its pip.conf
# names the bundle). Hand the chroot the same trust, and nothing else of the host's configuration.
if [ -f /etc/ssl/certs/ca-certificates.crt ]; then
  mkdir -p "$DIR/etc/ssl/certs" && cp /etc/ssl/certs/ca-certificates.crt "$DIR/etc/ssl/host-ca.crt"
  printf '[global]\ncert = /etc/ssl/host-ca.crt\n' > "$DIR/etc/pip.conf"
fi
mount -t proc proc "$DIR/proc"; mount -t sysfs sys "$DIR/sys"
mount --bind /dev "$DIR/dev"; mount --bind /dev/pts "$DIR/dev/pts"
log "minimal tools a user has before cloning (git, make, sudo-less root)"
chroot "$DIR" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin DEBIAN_FRONTEND=noninteractive \
  bash -c 'apt-get update -q >/dev/null && apt-get install -y -q --no-install-recommends git make ca-certificates >/dev/null'
git clone -q "$ROOT" "$DIR/root/project"
log "make test in the chroot (env -i)"
set +e
env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin TERM=xterm LANG=C.UTF-8 \
  chroot "$DIR" /bin/bash -lc 'cd /root/project && make test' 2>&1 | tee "$DIR.make_test.log" | grep -E '^\[|passed|failed'
status=${PIPESTATUS[0]}
log "make test exited $status"
log "make run (no terminal: simulator alone) until /odom appears"
env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin TERM=xterm LANG=C.UTF-8 \
  chroot "$DIR" /bin/bash -lc 'cd /root/project; setsid make run </dev/null >/tmp/run.log 2>&1 & run=$!;
    source catkin_ws/devel/setup.bash; for i in $(seq 1 150); do rostopic list 2>/dev/null | grep -qx /odom && break; sleep 0.2; done;
    if rostopic echo -n 1 /odom/header/frame_id; then echo "make run: /odom is up"; r=0; else echo "make run: no /odom"; tail /tmp/run.log; r=1; fi;
    kill -INT -- -$run 2>/dev/null; for i in $(seq 1 50); do kill -0 $run 2>/dev/null || break; sleep 0.2; done;
    exit $r'
run_status=$?
nav_status=0
if [ -n "$NAV_DIR" ]; then
  mkdir -p "$DIR/root/nav-sources" && cp "$NAV_DIR"/*.tar.gz "$DIR/root/nav-sources/"
  log "make nav NAV_SOURCES=/root/nav-sources, then make test-nav, in the chroot (env -i)"
  env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin TERM=xterm LANG=C.UTF-8 \
    chroot "$DIR" /bin/bash -lc 'cd /root/project && make nav NAV_SOURCES=/root/nav-sources && make test-nav' 2>&1 \
    | tee "$DIR.make_test_nav.log" | grep -E '^\[|passed|failed|FIGURE'
  nav_status=${PIPESTATUS[0]}
  log "make nav && make test-nav exited $nav_status"
fi
# Whatever the chroot left running (a chroot shares the host's process table: pkill by name in it would
# also hit the host's own ROS processes), identified by its root directory.
for proc in /proc/[0-9]*; do
  [ "$(readlink "$proc/root" 2>/dev/null)" = "$(readlink -f "$DIR")" ] && kill -KILL "${proc#/proc/}" 2>/dev/null
done
set -e
[ "$status" -eq 0 ] && [ "$run_status" -eq 0 ] && [ "$nav_status" -eq 0 ]
