"""Keyboard teleop node ``teleop_key``: keys typed in its terminal become Twists on ``cmd_vel``.

A thin shell around :mod:`diffbot_sim.teleop.keymap` (what a key means) and :mod:`diffbot_sim.teleop.terminal` (how keys
are read). One thread does everything: wait up to 50 ms for a key, let the keymap answer, publish, redraw
the status line. Whatever ends the node (the Ctrl-C key, SIGINT, SIGTERM, SIGHUP, standard input closing,
an exception, a ROS shutdown request) publishes exactly one all-zero Twist while the node is still up, then
restores the terminal.

Publications:
    cmd_vel (geometry_msgs/Twist): linear.x (m/s) and angular.z (rad/s), REP 103 signs. Relative, so
        ``cmd_vel:=...`` and namespaces apply. Queue size 1: an old key is worth nothing.

Subscriptions:
    odom (nav_msgs/Odometry): optional; while it arrives, the status line shows the pose x, y, yaw.

Parameters (private; defaults in :class:`diffbot_sim.teleop.keymap.TeleopConfig`):
    ~speed (float, m/s), ~turn (float, rad/s): speeds at start.
    ~repeat_rate (float, Hz): re-publish the last command at this rate; 0: only on key presses.
    ~key_timeout (float, s): stop when no key arrived for this long while moving; 0: never.
    ~speed_limit (float, m/s), ~turn_limit (float, rad/s): ceilings of the speed keys.

Exit status: 0 after a quit (key, signal, end of input, ROS shutdown); 2 when standard input is not a
terminal or a parameter is invalid; 1 on an unexpected error (with its traceback).
"""
import os
import signal
import sys
import threading
import time

import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from diffbot_sim import streams
from diffbot_sim.errors import ConfigError, TerminalError
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.nodes._entry import entry_point
from diffbot_sim.teleop.keymap import BANNER, STOP, Teleop, TeleopConfig, format_status
from diffbot_sim.teleop.terminal import EOF, StatusLine, raw_terminal, read_key, require_tty
from diffbot_sim.transforms import yaw_from_quaternion

NODE_NAME = "teleop_key"
#: Longest wait for a key; bounds how late a ROS shutdown request and the status line are noticed.
POLL_PERIOD = 0.05
#: Odometry older than this (s, wall clock) is no longer shown: its publisher has probably stopped.
ODOM_FRESH = 1.0
#: Longest wait for the final stop to leave through every connection before the node shuts down (s).
DRAIN_TIMEOUT = 0.5
_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


@entry_point
def main():
    """Run the node; return the process exit status.

    Output that cannot be written (a hung-up terminal, ``teleop_key | head -1``) never changes the status
    (:mod:`._entry`).
    """
    stdin = 0
    try:
        require_tty(stdin)
    except TerminalError as err:
        streams.write(sys.stderr, f"{err}\n")
        return 2
    signals = _SignalFlag()
    signals.install()
    try:
        try:
            rospy.init_node(NODE_NAME, disable_signals=True)
            config, out, odom = _setup()
        except ConfigError as err:
            rospy.logfatal(str(err))
            rospy.signal_shutdown("invalid parameter")
            return 2
        except (rospy.ROSException, OSError):
            if signals.received is None:
                raise
        if signals.received is not None:
            return 0  # interrupted during start-up, e.g. while rospy waited for the master
        signals.loop_started()
        reason = _run(stdin, Teleop(config), out, odom, signals)
        rospy.signal_shutdown(reason)
        return 0
    finally:
        signals.uninstall()


def _setup():
    """Read the parameters and create the topics; returns ``(config, output, odom)``.

    Raises:
        ConfigError: a parameter is invalid.
    """
    params = rospy.get_param("~", {})
    config = TeleopConfig.from_mapping(params)
    for name in TeleopConfig.unknown(params):
        rospy.logwarn("ignoring unknown parameter ~%s", name)
    out = _Output(rospy.Publisher("cmd_vel", Twist, queue_size=1))
    # Runs before rospy closes its topics on a shutdown request (e.g. `rosnode kill`), so the stop still
    # reaches subscribers; when main() quits by itself it has sent the stop already.
    rospy.on_shutdown(out.final_stop)
    odom = _LatestOdom()
    rospy.Subscriber("odom", Odometry, odom.store, queue_size=1)
    rospy.loginfo("%s: publishing on %s; speed %g m/s, turn %g rad/s, repeat_rate %g Hz, key_timeout %g s, "
                  "limits %g m/s / %g rad/s", rospy.get_name(), out.topic, config.speed, config.turn,
                  config.repeat_rate, config.key_timeout, config.speed_limit, config.turn_limit)
    return config, out, odom


def _run(stdin, teleop, out, odom, signals):
    """The key loop; returns why it ended. The final stop is sent before the terminal is restored."""
    status = StatusLine(sys.stdout)
    streams.write(sys.stdout, BANNER + "\n")
    reason = "exception"
    with raw_terminal(stdin):
        try:
            while True:
                if signals.received is not None:
                    reason = f"signal {signal.Signals(signals.received).name}"
                    break
                if teleop.quit_requested:
                    reason = "quit key"
                    break
                if rospy.is_shutdown():
                    reason = "ROS shutdown"
                    break
                wait = teleop.next_deadline(time.monotonic())
                key = read_key(stdin, POLL_PERIOD if wait is None else min(wait, POLL_PERIOD), signals.fd)
                if key == EOF:
                    reason = "standard input closed"
                    break
                now = time.monotonic()
                if key is not None:
                    out.send(teleop.press(key, now))
                out.send(teleop.tick(now))
                status.show(format_status(out.last, teleop.speed, teleop.turn, odom.pose(now)))
        finally:
            out.final_stop()
            status.end()
    return reason


class _Output:
    """The ``cmd_vel`` publisher, guarded so nothing is published after the one final stop."""

    def __init__(self, pub):
        self._pub = pub
        self._lock = threading.Lock()
        self._stopped = False
        self.last = STOP
        self.topic = pub.resolved_name

    def send(self, command):
        """Publish ``command`` (a keymap Command, or None for nothing)."""
        if command is None:
            return
        with self._lock:
            if self._stopped:
                return
            self._publish(command)

    def final_stop(self):
        """Publish the all-zero Twist once, and wait (bounded) until it has left through every connection."""
        with self._lock:
            if self._stopped:
                return
            self._stopped = True
            try:
                sent = _sent_counts(self._pub)
                self._publish(STOP)
                _wait_delivered(self._pub, sent, DRAIN_TIMEOUT)
            except rospy.ROSException as err:
                rospy.logerr("could not publish the final stop on %s: %s", self.topic, err)

    def _publish(self, command):
        self._pub.publish(ros_msgs.twist(command.linear, command.angular))
        self.last = command
        rospy.logdebug("publish x:%.3f, z:%.3f", command.linear, command.angular)


def _sent_counts(pub):
    return {id(conn): getattr(conn, "stat_num_msg", 0) for conn in list(pub.impl.connections)}


def _wait_delivered(pub, before, timeout):
    """Wait until every connection has written one more message than in ``before``, or ``timeout`` passes.

    With ``queue_size`` set, rospy hands each message to a per-connection writer thread; a shutdown right
    after ``publish()`` would close the socket before that thread wrote the stop. The transport's message
    counter (``stat_num_msg``, rospy 1.15) rises once the bytes are in the socket.
    """
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        pending = [conn for conn in list(pub.impl.connections)
                   if not getattr(conn, "done", True)
                   and getattr(conn, "stat_num_msg", 0) <= before.get(id(conn), 0)]
        if not pending:
            return
        time.sleep(0.002)


class _LatestOdom:
    """Keeps the newest odometry message; the callback only stores, the main thread reads."""

    def __init__(self):
        self._latest = None  # (monotonic receipt time, msg); replaced whole, so reads need no lock

    def store(self, msg):
        """Subscriber callback."""
        self._latest = (time.monotonic(), msg)

    def pose(self, now):
        """``(x, y, yaw)`` of the newest message if it is fresh, else None."""
        latest = self._latest
        if latest is None or now - latest[0] > ODOM_FRESH:
            return None
        pose = latest[1].pose.pose
        q = pose.orientation
        return pose.position.x, pose.position.y, yaw_from_quaternion(q.x, q.y, q.z, q.w)


class _SignalFlag:
    """SIGINT/SIGTERM/SIGHUP handlers that record the signal and wake the key wait.

    In the key loop the handler raises nothing, so a signal cannot cut a publish or the terminal restore in
    half; the wake-up pipe (``signal.set_wakeup_fd``) ends the ``select`` at once, so the final stop goes out
    without waiting for the poll period. Before the loop, rospy may be retrying to reach the master, which
    only ends on a ROS shutdown: then the handler requests one.
    """

    def __init__(self):
        self.received = None
        self._in_loop = False
        self.fd = None
        self._write_fd = None
        self._previous = {}
        self._previous_wakeup = -1

    def install(self):
        """Install the handlers and the wake-up pipe (main thread only)."""
        self.fd, self._write_fd = os.pipe()
        os.set_blocking(self.fd, False)
        os.set_blocking(self._write_fd, False)
        self._previous_wakeup = signal.set_wakeup_fd(self._write_fd, warn_on_full_buffer=False)
        for sig in _SIGNALS:
            self._previous[sig] = signal.signal(sig, self._handle)

    def uninstall(self):
        """Put the previous handlers back and close the pipe."""
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)
        self._previous.clear()
        if self._write_fd is not None:
            signal.set_wakeup_fd(self._previous_wakeup)
            os.close(self._write_fd)
            os.close(self.fd)
            self.fd = self._write_fd = None

    def loop_started(self):
        """From now on the key loop notices signals itself."""
        self._in_loop = True

    def _handle(self, signum, _frame):
        if self.received is None:
            self.received = signum
            if not self._in_loop:
                # In this (main) thread, as rospy's own handler does: the retry loop holds rospy's topic
                # lock (re-entrant), which a shutdown from another thread would wait for forever.
                rospy.signal_shutdown(f"signal {signal.Signals(signum).name} during start-up")
