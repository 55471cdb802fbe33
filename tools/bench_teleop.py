#!/usr/bin/env python3
"""Measure the keyboard teleop: keypress -> Twist latency, and its CPU use while idle.

Run in the workspace's ROS environment:  bash tools/rosenv.sh python3 tools/bench_teleop.py
It starts its own ``roscore -p <free port>`` (and stops it), runs the real ``teleop_key`` node on a
pseudo-terminal, and prints the figures as a Markdown table.

Latency: a key is written into the pty master (timestamp before ``os.write``), and a /cmd_vel subscriber in
this process timestamps the Twist in its callback; both use ``time.monotonic()`` in the same process. Keys
alternate ``i`` / ``k`` and the next key is typed only after the previous Twist arrived plus a gap, so the
figure is one keypress's path (pty -> select -> keymap -> publish -> TCPROS -> callback), not a backlog.

Idle CPU: utime + stime of the node's process from /proc/<pid>/stat over a window with no keys, as % of one
core; once with nothing on ``odom`` and once while this script publishes Odometry at 50 Hz (the status line
then redraws the pose).
"""
import argparse
import math
import os
import pty
import select
import signal
import socket
import statistics
import subprocess
import sys
import threading
import time
import xmlrpc.client

from diffbot_sim.waiting import wait_for

PKG = "diffbot_sim"
NODE = "teleop_key_bench"


def free_port():
    with socket.socket() as sock:
        sock.bind(("localhost", 0))
        return sock.getsockname()[1]


def cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as stat:
        fields = stat.read().rsplit(")", 1)[1].split()
    # fields[0] is field 3 (state); utime and stime are fields 14 and 15.
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def idle_cpu(pid, seconds):
    start_cpu, start = cpu_seconds(pid), time.monotonic()
    time.sleep(seconds)
    return 100.0 * (cpu_seconds(pid) - start_cpu) / (time.monotonic() - start)


def percentile(values, q):
    """Nearest-rank percentile."""
    ordered = sorted(values)
    return ordered[max(0, math.ceil(q / 100.0 * len(ordered)) - 1)]


class Drain(threading.Thread):
    """Reads the pty master so the node never blocks on its terminal; keeps the output."""

    def __init__(self, fd):
        super().__init__(daemon=True)
        self.fd, self.data, self.halted = fd, bytearray(), threading.Event()

    def run(self):
        while not self.halted.is_set():
            if select.select([self.fd], [], [], 0.05)[0]:
                try:
                    chunk = os.read(self.fd, 4096)
                except OSError:
                    return
                if not chunk:
                    return
                self.data += chunk


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--keys", type=int, default=200, help="keypresses for the latency figure")
    parser.add_argument("--gap", type=float, default=0.02, help="pause after each Twist before the next key (s)")
    parser.add_argument("--idle", type=float, default=20.0, help="length of each idle CPU window (s)")
    args = parser.parse_args()

    port = free_port()
    os.environ["ROS_MASTER_URI"] = f"http://localhost:{port}"
    roscore = subprocess.Popen(["roscore", "-p", str(port)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                               stdin=subprocess.DEVNULL, start_new_session=True)
    teleop = master = slave = None
    try:
        import rosgraph
        import rospy
        from geometry_msgs.msg import Twist
        from nav_msgs.msg import Odometry

        wait_for(lambda: rosgraph.is_master_online(), 30.0, "roscore", 0.005)
        rospy.init_node("bench_teleop", disable_signals=True)
        received = []
        rospy.Subscriber("/cmd_vel", Twist, lambda msg: received.append(time.monotonic()))
        odom_pub = rospy.Publisher("/odom", Odometry, queue_size=10)

        master, slave = pty.openpty()
        drain = Drain(master)
        drain.start()
        teleop = subprocess.Popen(["rosrun", PKG, "teleop_key", f"__name:={NODE}"], stdin=slave, stdout=slave,
                                  stderr=slave, start_new_session=True, close_fds=True)
        wait_for(lambda: b"we are ready" in drain.data, 60.0, "the teleop banner", 0.005)
        me = rospy.get_name()

        def connected():
            try:
                uri = rosgraph.Master(me).lookupNode(f"/{NODE}")
                info = xmlrpc.client.ServerProxy(uri).getBusInfo(me)[2]
            except Exception:  # not registered yet
                return False
            return any(c[2] == "o" and c[4] == "/cmd_vel" and c[1] == me for c in info)

        wait_for(connected, 60.0, "the teleop's cmd_vel connection", 0.005)

        latencies = []
        for n in range(args.keys):
            count = len(received)
            typed = time.monotonic()
            os.write(master, b"i" if n % 2 == 0 else b"k")
            wait_for(lambda: len(received) > count, 5.0, f"the Twist of key {n}", 0.005)
            latencies.append(received[count] - typed)
            time.sleep(args.gap)
        os.write(master, b"s")
        time.sleep(0.5)

        cpu_idle = idle_cpu(teleop.pid, args.idle)
        halt = threading.Event()

        def publish_odom():
            msg = Odometry()
            msg.pose.pose.orientation.w = 1.0
            while not halt.wait(0.02):
                msg.pose.pose.position.x += 0.001
                odom_pub.publish(msg)

        odom_thread = threading.Thread(target=publish_odom, daemon=True)
        odom_thread.start()
        time.sleep(1.0)  # let the odom subscription connect
        cpu_odom = idle_cpu(teleop.pid, args.idle)
        halt.set()
        odom_thread.join()

        os.write(master, b"\x03")
        code = teleop.wait(10.0)
        ms = [1000.0 * x for x in latencies]
        load = os.getloadavg()
        print(f"| keypress -> Twist latency, {len(ms)} keys | median {statistics.median(ms):.2f} ms, "
              f"p99 {percentile(ms, 99):.2f} ms, max {max(ms):.2f} ms, min {min(ms):.2f} ms |")
        print(f"| idle CPU, nothing on odom, {args.idle:.0f} s | {cpu_idle:.2f} % of one core |")
        print(f"| idle CPU, Odometry at 50 Hz, {args.idle:.0f} s | {cpu_odom:.2f} % of one core |")
        print(f"| teleop exit status after Ctrl-C | {code} |")
        print(f"| load average during the run (1/5/15 min) | {load[0]:.2f} / {load[1]:.2f} / {load[2]:.2f} "
              f"on {os.cpu_count()} cores |")
        rospy.signal_shutdown("done")
        return 0
    finally:
        if teleop is not None and teleop.poll() is None:
            os.killpg(teleop.pid, signal.SIGKILL)
            teleop.wait()
        for fd in (master, slave):
            if fd is not None:
                os.close(fd)
        roscore.send_signal(signal.SIGINT)
        try:
            roscore.wait(15.0)
        except subprocess.TimeoutExpired:
            os.killpg(roscore.pid, signal.SIGKILL)
            roscore.wait()


if __name__ == "__main__":
    from diffbot_sim import streams  # a closed pipe (`make test | head`) must not turn the status into 120

    try:
        STATUS = main()
    finally:
        streams.finish()
    sys.exit(STATUS)
