#!/usr/bin/env bash
# `make run`: the simulator headless with the seed robot (sim.launch) in the background, and the keyboard
# teleop in the foreground of this terminal. Ctrl-C (or q... see the banner) ends both; nothing is left.
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
LOG_DIR="${ROS_HOME:-$HOME/.ros}/log"
mkdir -p "$LOG_DIR"
SIM_LOG="$LOG_DIR/diffbot_sim_run.log"

if [ ! -t 0 ]; then
  echo "make run: standard input is not a terminal, so there is no keyboard teleop; running the simulator" \
       "alone (Ctrl-C stops it). Drive it with: rostopic pub /cmd_vel geometry_msgs/Twist ..." >&2
  exec roslaunch diffbot_sim sim.launch "$@"
fi

# Own session: the terminal's Ctrl-C reaches only the teleop; we stop roslaunch ourselves, with SIGINT,
# and wait for it (roslaunch then stops every node it started).
setsid roslaunch diffbot_sim sim.launch "$@" >"$SIM_LOG" 2>&1 </dev/null &
SIM_PID=$!
stop_sim() {
  if kill -0 "$SIM_PID" 2>/dev/null; then
    kill -INT "$SIM_PID" 2>/dev/null
    for _ in $(seq 1 100); do kill -0 "$SIM_PID" 2>/dev/null || break; sleep 0.1; done
    kill -0 "$SIM_PID" 2>/dev/null && kill -KILL -- "-$SIM_PID" 2>/dev/null
  fi
  wait "$SIM_PID" 2>/dev/null
}
trap stop_sim EXIT
trap : INT TERM HUP

echo "Starting the simulator (log: $SIM_LOG) ..."
for _ in $(seq 1 150); do
  if ! kill -0 "$SIM_PID" 2>/dev/null; then
    echo "make run: the simulator exited; its log follows:" >&2; tail -20 "$SIM_LOG" >&2; exit 1
  fi
  rostopic list 2>/dev/null | grep -qx /odom && break
  sleep 0.2
done
rosrun diffbot_sim teleop_key
