#!/usr/bin/env python3
"""The real ``teleop_key`` node on a pseudo-terminal: keys typed into the pty become Twists on /cmd_vel.

Each case starts a fresh node with ``rosrun`` (stdin/stdout/stderr on the pty slave, its own session), waits
for its banner and for its connection to our subscriber, types keys into the pty master and checks the
Twists that arrive, the exit status, and that the pty's termios attributes are exactly as before. Callbacks
only record; the test thread asserts; every wait polls a predicate with a deadline.
"""
import itertools
import os
import pty
import re
import select
import signal
import subprocess
import tempfile
import termios
import threading
import time
import unittest
import xmlrpc.client

import rosgraph
import rosnode
import rospy
import rostest
from geometry_msgs.msg import Twist

from diffbot_sim import waiting

PKG = "diffbot_sim"
READY_TEXT = b"we are ready"
START_TIMEOUT = 40.0   # s: rosrun + rospy import + registration, on a busy 2-core machine
MSG_TIMEOUT = 5.0      # s: a key's Twist (normally a few ms)
EXIT_TIMEOUT = 10.0    # s: node exit after a quit
STOP_BOUND = 1.0       # s: signal / end of input -> final zero Twist (measured: tens of ms)
REMAPPED = "/teleop_test/remapped_cmd_vel"
ANSI = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


class Recorder:
    """Subscriber callback target: keeps (monotonic receipt time, linear.x, angular.z) per message."""

    def __init__(self):
        self._lock = threading.Lock()
        self._msgs = []

    def __call__(self, msg):
        with self._lock:
            self._msgs.append((time.monotonic(), msg.linear.x, msg.angular.z, msg.linear.y, msg.linear.z,
                               msg.angular.x, msg.angular.y))

    def clear(self):
        with self._lock:
            self._msgs = []

    def all(self):
        with self._lock:
            return list(self._msgs)

    def __len__(self):
        with self._lock:
            return len(self._msgs)


class PtyReader(threading.Thread):
    """Drains the pty master so the node never blocks on a full terminal, and keeps what it printed."""

    def __init__(self, master):
        super().__init__(daemon=True)
        self._master = master
        self._halt = threading.Event()
        self._lock = threading.Lock()
        self._data = bytearray()

    def run(self):
        while not self._halt.is_set():
            ready, _, _ = select.select([self._master], [], [], 0.05)
            if not ready:
                continue
            try:
                chunk = os.read(self._master, 4096)
            except OSError:
                return
            if not chunk:
                return
            with self._lock:
                self._data += chunk

    def output(self):
        with self._lock:
            return bytes(self._data)

    def halt(self):
        self._halt.set()
        self.join(2.0)


class TestTeleopPty(unittest.TestCase):
    names = itertools.count(1)

    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_teleop_pty")
        cls.msgs = Recorder()
        cls.sub = rospy.Subscriber("/cmd_vel", Twist, cls.msgs)  # no queue limit: never drop a message
        cls.remapped_msgs = Recorder()
        cls.remapped_sub = rospy.Subscriber(REMAPPED, Twist, cls.remapped_msgs)

    def setUp(self):
        self.proc = None
        self.master = self.slave = None
        self.reader = None
        # The previous case's node must be gone from our subscriber, so ">= 1 connection" means this one.
        self.wait_for(lambda: self.sub.get_num_connections() == 0 and self.remapped_sub.get_num_connections() == 0,
                      10.0, "old teleop connections to close")
        self.msgs.clear()
        self.remapped_msgs.clear()

    def tearDown(self):
        if self.proc is not None and self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)  # its own session: also takes anything it started
            self.proc.wait(10.0)
        if self.reader is not None:
            self.reader.halt()
        for fd in (self.master, self.slave):
            if fd is not None:
                os.close(fd)

    # -- helpers ---------------------------------------------------------------------------------------------

    def wait_for(self, predicate, timeout, what):
        """``waiting.wait_for`` polling every 2 ms (key-to-Twist times are measured in ms); a failure carries the
        teleop's output."""
        return waiting.wait_for(predicate, timeout, what, 0.002,
                                error=lambda message: self.failureException(message + self._output_tail()))

    def _output_tail(self):
        if self.reader is None:
            return ""
        return "\nnode output (tail):\n" + self.reader.output()[-1500:].decode("utf-8", "replace")

    def start(self, *args, sub=None):
        """Start a teleop on a fresh pty; return once its banner is out and it is connected to ``sub``."""
        sub = self.sub if sub is None else sub
        self.master, self.slave = pty.openpty()
        self.attrs_before = termios.tcgetattr(self.slave)
        self.reader = PtyReader(self.master)
        self.reader.start()
        self.last_name = next(self.names)
        name = f"teleop_key_{self.last_name}"
        self.proc = subprocess.Popen(["rosrun", PKG, "teleop_key", f"__name:={name}", *args],
                                     stdin=self.slave, stdout=self.slave, stderr=self.slave,
                                     start_new_session=True, close_fds=True)
        self.wait_for(lambda: READY_TEXT in self.reader.output() or self.proc.poll() is not None,
                      START_TIMEOUT, "the ready banner")
        self.assertIsNone(self.proc.poll(), "teleop exited during start-up" + self._output_tail())
        self.wait_for(lambda: self.publisher_connected(name, sub.resolved_name), START_TIMEOUT,
                      f"{name} to connect to our {sub.resolved_name} subscriber")
        # The node is in key mode while it runs (else "restored afterwards" would prove nothing).
        self.assertFalse(termios.tcgetattr(self.slave)[3] & termios.ECHO, "echo still on while running")
        self.assertFalse(termios.tcgetattr(self.slave)[3] & termios.ISIG, "signal keys still on while running")

    def publisher_connected(self, node, topic):
        """True once ``node``'s publisher on ``topic`` lists a connection to this test node.

        Our subscriber counts a connection before it is even made, and the publisher adds its side only
        after the handshake: a key typed in between would be published to nobody. The publisher's own
        bus info (what ``rosnode info`` shows) is the moment it starts sending to us.
        """
        try:
            uri = rosgraph.Master(rospy.get_name()).lookupNode(f"/{node}")
            _, _, info = xmlrpc.client.ServerProxy(uri).getBusInfo(rospy.get_name())
        except (rosgraph.MasterError, OSError, xmlrpc.client.Error):
            return False
        return any(c[2] == "o" and c[4] == topic and c[1] == rospy.get_name() for c in info)

    def type(self, keys):
        os.write(self.master, keys.encode("latin-1"))

    def press_and_expect(self, key, linear, angular, recorder=None):
        recorder = self.msgs if recorder is None else recorder
        count = len(recorder)
        self.type(key)
        self.wait_for(lambda: len(recorder) > count, MSG_TIMEOUT, f"the Twist of key {key!r}")
        msg = recorder.all()[count]
        self.assertAlmostEqual(msg[1], linear, places=6, msg=f"linear.x after {key!r}")
        self.assertAlmostEqual(msg[2], angular, places=6, msg=f"angular.z after {key!r}")
        self.assertEqual(msg[3:], (0.0, 0.0, 0.0, 0.0), f"other Twist fields after {key!r}")
        return msg

    def wait_exit(self):
        try:
            code = self.proc.wait(EXIT_TIMEOUT)
        except subprocess.TimeoutExpired:
            self.fail("teleop did not exit" + self._output_tail())
        # Its connection closes after its last bytes: once it is gone, every Twist it sent was recorded.
        self.wait_for(lambda: self.sub.get_num_connections() == 0, 10.0, "the teleop connection to close")
        return code

    def assert_terminal_restored(self):
        self.assertEqual(termios.tcgetattr(self.slave), self.attrs_before, "pty attributes not restored")

    def assert_ends_with_one_zero(self, since):
        """After index ``since`` exactly one Twist arrived, and it is all zeros."""
        after = self.msgs.all()[since:]
        self.assertEqual([m[1:] for m in after], [(0.0,) * 6], "expected exactly one final zero Twist")
        return after[0][0]

    # -- cases -------------------------------------------------------------------------------------------------

    def test_move_keys_rep103_and_ctrl_c(self):
        self.start()
        self.press_and_expect("i", 1.0, 0.0)   # forward: +x
        self.press_and_expect("k", -1.0, 0.0)  # backward
        self.press_and_expect("j", 0.0, 1.0)   # left: +z (counter-clockwise)
        self.press_and_expect("l", 0.0, -1.0)  # right
        self.press_and_expect("s", 0.0, 0.0)
        # An unbound key publishes nothing: the next Twist is the one of the key typed after it.
        count = len(self.msgs)
        self.press_and_expect("aA \ri", 1.0, 0.0)
        self.assertEqual(len(self.msgs), count + 1)
        before_quit = len(self.msgs)
        self.type("\x03")
        self.assertEqual(self.wait_exit(), 0, self._output_tail())
        self.assert_ends_with_one_zero(before_quit)
        self.assert_terminal_restored()
        self.assertNotIn(b"Traceback", self.reader.output())

    def test_speed_keys_scale_from_params(self):
        self.start("_speed:=0.5", "_turn:=2.0")
        self.press_and_expect("i", 0.5, 0.0)
        self.press_and_expect("q", 0.55, 0.0)   # speed key re-publishes the motion at the new speed
        self.press_and_expect("j", 0.0, 2.2)
        self.press_and_expect("x", 0.0, 2.2)    # linear only
        self.press_and_expect("i", 0.495, 0.0)
        self.press_and_expect("c", 0.495, 0.0)  # angular only
        self.press_and_expect("l", 0.0, -1.98)
        self.type("\x03")
        self.assertEqual(self.wait_exit(), 0)
        self.assert_terminal_restored()

    def test_key_timeout_stops_without_a_key(self):
        self.start("_key_timeout:=0.3")
        typed = time.monotonic()
        self.press_and_expect("i", 1.0, 0.0)
        self.wait_for(lambda: len(self.msgs) >= 2, MSG_TIMEOUT, "the key-timeout stop")
        stop = self.msgs.all()[1]
        self.assertEqual(stop[1:], (0.0,) * 6)
        delay = stop[0] - typed
        print(f"[teleop_pty] key_timeout 0.3 s: stop {delay * 1000:.0f} ms after the key")
        self.assertGreaterEqual(delay, 0.28)
        self.assertLess(delay, 0.3 + STOP_BOUND)
        # The timeout stops once; a key that is not bound does not restart the motion.
        self.type("a")
        before_quit = len(self.msgs)
        self.assertEqual(before_quit, 2)
        self.type("\x03")
        self.assertEqual(self.wait_exit(), 0)
        self.assert_ends_with_one_zero(before_quit)
        self.assert_terminal_restored()

    def _signal_case(self, sig):
        self.start()
        self.press_and_expect("i", 1.0, 0.0)
        before = len(self.msgs)
        sent = time.monotonic()
        os.kill(self.proc.pid, sig)  # rosrun execs the node: this is the node's own pid
        self.wait_for(lambda: len(self.msgs) > before, STOP_BOUND * 5, f"the stop after {sig.name}")
        latency = self.msgs.all()[before][0] - sent
        print(f"[teleop_pty] {sig.name} -> zero Twist: {latency * 1000:.1f} ms")
        self.assertEqual(self.wait_exit(), 0, self._output_tail())
        self.assert_ends_with_one_zero(before)
        self.assertLess(latency, STOP_BOUND)
        self.assert_terminal_restored()
        self.assertNotIn(b"Traceback", self.reader.output())

    def test_sigterm_stops_robot_and_restores_terminal(self):
        self._signal_case(signal.SIGTERM)

    def test_sighup_stops_robot_and_restores_terminal(self):
        self._signal_case(signal.SIGHUP)

    def test_sigint_stops_robot_and_restores_terminal(self):
        self._signal_case(signal.SIGINT)

    def test_ros_shutdown_request_stops_robot(self):
        self.start()
        name = f"/teleop_key_{self.last_name}"
        self.press_and_expect("i", 1.0, 0.0)
        before = len(self.msgs)
        # `rosnode kill`: the node's XML-RPC shutdown, handled in a rospy thread, not the key loop.
        self.assertEqual(rosnode.kill_nodes([name]), ([name], []))
        self.assertEqual(self.wait_exit(), 0, self._output_tail())
        self.assert_ends_with_one_zero(before)
        self.assert_terminal_restored()
        self.assertNotIn(b"Traceback", self.reader.output())

    def test_stdin_closed_stops_robot(self):
        self.start()
        self.press_and_expect("i", 1.0, 0.0)
        before = len(self.msgs)
        self.reader.halt()
        sent = time.monotonic()
        os.close(self.master)  # the terminal hangs up: the node's stdin reads end-of-file
        self.master = None
        self.wait_for(lambda: len(self.msgs) > before, STOP_BOUND * 5, "the stop after end of input")
        latency = self.msgs.all()[before][0] - sent
        print(f"[teleop_pty] stdin closed -> zero Twist: {latency * 1000:.1f} ms")
        self.assertEqual(self.wait_exit(), 0, "exit status 120 is a failed flush of buffered output at exit")
        self.assert_ends_with_one_zero(before)
        self.assertLess(latency, STOP_BOUND)

    def _start_split(self, stdout):
        """Start a teleop with stdin on a fresh pty, stdout on ``stdout`` and stderr in a file we read."""
        self.master, self.slave = pty.openpty()
        self.attrs_before = termios.tcgetattr(self.slave)
        self.stderr_file = tempfile.TemporaryFile()
        self.last_name = next(self.names)
        name = f"teleop_key_{self.last_name}"
        self.proc = subprocess.Popen(["rosrun", PKG, "teleop_key", f"__name:={name}"],
                                     stdin=self.slave, stdout=stdout, stderr=self.stderr_file,
                                     start_new_session=True, close_fds=True)
        self.wait_for(lambda: self.publisher_connected(name, self.sub.resolved_name) or self.proc.poll() is not None,
                      START_TIMEOUT, f"{name} to connect to our {self.sub.resolved_name} subscriber")
        self.assertIsNone(self.proc.poll(), "teleop exited during start-up: " + self.stderr_text())

    def stderr_text(self):
        self.stderr_file.seek(0)
        return self.stderr_file.read().decode("utf-8", "replace")

    def assert_clean_stderr(self):
        text = self.stderr_text()
        for bad in ("Exception ignored", "Traceback", "BrokenPipeError"):
            self.assertNotIn(bad, text)

    def test_stdout_pipe_closed_exits_0(self):
        """``teleop_key | head -1`` after head has gone: every write to stdout meets a closed pipe."""
        read_end, write_end = os.pipe()
        os.close(read_end)  # the reader is gone before the node writes its banner
        try:
            self._start_split(write_end)
        finally:
            os.close(write_end)
        self.press_and_expect("i", 1.0, 0.0)
        self.press_and_expect("q", 1.1, 0.0)
        before = len(self.msgs)
        self.type("\x03")
        self.assertEqual(self.wait_exit(), 0, self.stderr_text())
        self.assert_ends_with_one_zero(before)
        self.assert_terminal_restored()
        self.assert_clean_stderr()

    def test_terminal_gone_during_redraw_exits_0(self):
        """The terminal hangs up while the status line is being rewritten key after key."""
        self._start_split(self.slave)
        self.type("i" + "qz" * 40)  # each key rewrites the status line
        os.close(self.master)
        self.master = None
        self.assertEqual(self.wait_exit(), 0, self.stderr_text())
        msgs = self.msgs.all()
        self.assertTrue(msgs, "no Twist at all")
        self.assertEqual(msgs[-1][1:], (0.0,) * 6, "the last Twist is not the final stop")
        self.assertEqual(sum(1 for m in msgs if m[1:] == (0.0,) * 6), 1, "expected exactly one zero Twist")
        self.assert_clean_stderr()

    def test_remap_moves_the_topic(self):
        self.start(f"cmd_vel:={REMAPPED}", sub=self.remapped_sub)
        self.press_and_expect("i", 1.0, 0.0, recorder=self.remapped_msgs)
        self.type("\x03")
        self.wait_for(lambda: self.proc.poll() is not None, EXIT_TIMEOUT, "exit")
        self.assertEqual(self.proc.returncode, 0)
        self.assertEqual([m[1:3] for m in self.remapped_msgs.all()], [(1.0, 0.0), (0.0, 0.0)])
        self.assertEqual(len(self.msgs), 0, "published on /cmd_vel despite the remap")

    def test_no_tty_exits_2_with_one_line(self):
        proc = subprocess.Popen(["rosrun", PKG, "teleop_key", f"__name:=teleop_key_{next(self.names)}"],
                                stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                start_new_session=True)
        try:
            out, err = proc.communicate(timeout=START_TIMEOUT)
        finally:
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
        err = err.decode("utf-8", "replace")
        self.assertEqual(proc.returncode, 2, err)
        self.assertNotIn("Traceback", err)
        lines = err.strip().splitlines()
        self.assertEqual(len(lines), 1, err)
        self.assertIn("standard input is not a terminal", lines[0])
        self.assertIn("rosrun diffbot_sim teleop_key", lines[0])
        self.assertEqual(out, b"")
        self.assertEqual(len(self.msgs), 0)

    def test_bad_parameter_exits_2_naming_it(self):
        self.master, self.slave = pty.openpty()
        self.attrs_before = termios.tcgetattr(self.slave)
        self.reader = PtyReader(self.master)
        self.reader.start()
        self.proc = subprocess.Popen(["rosrun", PKG, "teleop_key", f"__name:=teleop_key_{next(self.names)}",
                                      "_speed:=-1.0"],
                                     stdin=self.slave, stdout=self.slave, stderr=self.slave,
                                     start_new_session=True, close_fds=True)
        self.assertEqual(self.proc.wait(START_TIMEOUT), 2)
        self.wait_for(lambda: b"~speed" in self.reader.output(), 5.0, "the error message")
        output = ANSI.sub("", self.reader.output().decode("utf-8", "replace"))
        self.assertNotIn("Traceback", output)
        self.assertIn("parameter ~speed: got -1.0, expected a finite number >= 0", output)
        self.assertEqual(len([line for line in output.splitlines() if line.strip()]), 1, output)
        self.assert_terminal_restored()
        self.assertEqual(len(self.msgs), 0)


if __name__ == "__main__":
    rostest.rosrun(PKG, "teleop_pty", TestTeleopPty)
