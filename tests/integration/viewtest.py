"""Shared helpers of the headless picture suites (view_rviz, view_gui): an Xvfb server, ``view.launch`` (or
``sim.launch``) started against the rostest master as a user would start it, screenshots, and rviz's own
services.

Callbacks only record; the test thread asserts. Waits poll with deadlines (diffbot_sim.waiting.wait_for).
"""
import os
import re
import signal
import struct
import subprocess
import threading
import unittest
import xmlrpc.client

import genpy
import rosgraph
import rospy
import yaml
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log

from diffbot_sim.view import xscreen
from diffbot_sim.waiting import wait_for

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
ROBOT = os.path.join(ROOT, "tests", "data", "robots", "view_robot.urdf")
WORLD = os.path.join(ROOT, "tests", "data", "worlds", "laser_room.world")
#: roslaunch's colours (ESC [ ... m), terminal-title sequences (ESC ] ... BEL) and "=====" rules in its log
TERMINAL_ESCAPE = re.compile(r"\x1b\[[0-9;]*m|\x1b\][^\x07]*\x07|={5,}")


class _SendFilePathRequest(genpy.Message):
    """rviz/SendFilePath's request (``std_msgs/String path``: on the wire, one string), written by hand:
    Debian's rviz ships no Python module for its services. roscpp's service server accepts md5sum ``*``."""

    _type, _md5sum, _has_header, _full_text = "rviz/SendFilePathRequest", "*", False, "std_msgs/String path"
    __slots__ = ["path"]
    _slot_types = ["string"]

    def __init__(self, path=""):
        super().__init__()
        self.path = path

    def serialize(self, buff):
        data = self.path.encode()
        buff.write(struct.pack("<I", len(data)) + data)


class _SendFilePathResponse(genpy.Message):
    _type, _md5sum, _has_header, _full_text = "rviz/SendFilePathResponse", "*", False, "bool success"
    __slots__ = ["success"]
    _slot_types = ["bool"]

    def __init__(self):
        super().__init__()
        self.success = False

    def deserialize(self, data):
        self.success = bool(data[0]) if data else False
        return self


class SendFilePath:
    _type, _md5sum = "rviz/SendFilePath", "*"
    _request_class, _response_class = _SendFilePathRequest, _SendFilePathResponse


class View:
    """``roslaunch diffbot_sim LAUNCH ARGS`` (``view.launch`` unless ``launch``) on a fresh Xvfb, on the rostest
    master.

    ``start()`` raises xscreen.XvfbUnavailable when no X server can be had (the only reason to skip).
    """

    def __init__(self, args, log_name, launch="view.launch"):
        self.args, self.log_name, self.launch = list(args), log_name, launch
        self.xvfb = None
        self.proc = None
        self.lock = threading.Lock()
        self.logs = []
        self.odom = []
        home = os.environ.get("ROS_HOME") or os.path.join(os.path.expanduser("~"), ".ros")
        self.home = home
        self.log_path = os.path.join(home, log_name + ".log")

    # -------------------------------------------------------------------------------------- lifecycle

    def start(self):
        rospy.on_shutdown(self.stop)  # rostest ends a test node by signal: leave no X server or rviz behind
        self.xvfb = xscreen.Xvfb().__enter__()
        self.log_sub = rospy.Subscriber("/rosout", Log, self._keep, callback_args=self.logs, queue_size=1000)
        self.odom_sub = rospy.Subscriber("/odom", Odometry, self._keep, callback_args=self.odom, queue_size=100)
        self.cmd = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
        os.makedirs(self.home, exist_ok=True)
        self.log_file = open(self.log_path, "w")
        self.proc = subprocess.Popen(["roslaunch", "diffbot_sim", self.launch] + self.args,
                                     env=self.xvfb.env(), stdout=self.log_file, stderr=subprocess.STDOUT,
                                     stdin=subprocess.DEVNULL, start_new_session=True)
        return self

    def stop(self):
        if self.proc is not None and self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGINT)
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait(5)
        if self.xvfb is not None:
            self.xvfb.stop()

    def restart(self):
        """Stop everything (rviz, the simulator, Xvfb) and start again; the first launch log is kept as
        ``<log>.first``."""
        self.stop()
        self.log_file.close()
        os.replace(self.log_path, self.log_path + ".first")
        with self.lock:
            self.logs.clear()
            self.odom.clear()
        self.start()

    def rviz_start_failed(self):
        """Why rviz's own start-up failed, or None when it did not (or the cause is not rviz's): rviz printed
        its start line ("rviz version", so our view_rviz had written its config and become rviz) and then
        either roslaunch reports rviz dead while the simulator lives, or rviz is alive without its services."""
        lines = self.log_lines()
        if not any("rviz version" in line for line in lines):
            return None
        died = [line.strip() for line in lines if "has died" in line]
        if any("[bullet_sim" in line for line in died):
            return None
        if any("[rviz" in line for line in died):
            return " / ".join(died)
        if self.proc.poll() is None and not self.service_up("/rviz/load_config_discarding_changes"):
            return "rviz is running without its services (hung)"
        return None

    @staticmethod
    def service_up(name):
        try:
            rosgraph.Master("/test_view").lookupService(name)
            return True
        except Exception:  # rosgraph.MasterError: not (yet) advertised
            return False

    def _keep(self, msg, store):
        with self.lock:
            store.append(msg)

    def alive(self):
        """Fail when roslaunch ended: a required node (bullet_sim, rviz) died."""
        if self.proc.poll() is not None:
            raise AssertionError(f"roslaunch {self.launch} exited {self.proc.returncode} (see {self.log_path}); "
                                 f"{self.deaths()}; its log ends:\n" + self.tail())

    def deaths(self):
        """roslaunch's lines naming each node that died (exit code, command), and the lines of errors the
        nodes printed: what the failure line of a CI run, which keeps only the gist, must carry first."""
        lines = [line.strip() for line in self.log_lines()]
        wanted = ("has died", "Error", "error:", "Traceback", "Segmentation", "Aborted", "terminate called")
        harmless = ("media_export", "librospack")  # rviz asks rospack for a package Debian does not ship
        found = [line[:300] for line in lines
                 if any(w in line for w in wanted) and not any(h in line for h in harmless)]
        return " / ".join(found[-6:]) or "no node's death or error in its log"

    def tail(self, lines=15):
        return "\n".join(self.log_lines()[-lines:])

    def log_lines(self):
        """The launch log's lines, without roslaunch's terminal escapes and rules (TERMINAL_ESCAPE)."""
        self.log_file.flush()
        with open(self.log_path, errors="replace") as f:
            return [TERMINAL_ESCAPE.sub("", line.rstrip("\n")) for line in f]

    def wait(self, predicate, timeout, what):
        """Poll ``predicate`` (failing at once when roslaunch ends) until true, within ``timeout`` s."""
        def check():
            self.alive()
            return predicate()
        return wait_for(check, timeout, what, 0.1, error=AssertionError)

    # ---------------------------------------------------------------------------------------- ROS side

    def last_odom(self):
        with self.lock:
            return self.odom[-1] if self.odom else None

    def errors_from(self, node, level=Log.WARN):
        """rosout messages of ``node`` at ``level`` or worse, as ``"LEVEL: text"`` lines."""
        names = {Log.DEBUG: "DEBUG", Log.INFO: "INFO", Log.WARN: "WARN", Log.ERROR: "ERROR", Log.FATAL: "FATAL"}
        with self.lock:
            return [f"{names.get(m.level, m.level)}: {m.msg}" for m in self.logs if m.name == node and
                    m.level >= level]

    def node_uri(self, node):
        try:
            return rosgraph.Master("/test_view").lookupNode(node)
        except Exception:
            return None

    def subscriptions(self, node):
        """Topics ``node`` subscribes, from the master."""
        _, subs, _ = rosgraph.Master("/test_view").getSystemState()
        return sorted(topic for topic, nodes in subs if node in nodes)

    def received(self, node):
        """``{topic: messages received}`` of ``node``, from its own bus statistics (roscpp's
        getBusStats slave call, which answers [publish stats, subscribe stats] without the usual status
        code; per connection [id, bytes, messages, drops, connected])."""
        uri = self.node_uri(node)
        if uri is None:
            return {}
        stats = with_timeout(lambda: xmlrpc.client.ServerProxy(uri).getBusStats("/test_view"), 10.0,
                             f"{node}'s getBusStats")
        counts = {}
        for topic, connections in stats[1]:
            counts[topic] = counts.get(topic, 0) + sum(c[2] for c in connections)
        return counts

    def load_config(self, path, timeout=20.0):
        """Make rviz open ``path``: every display is rebuilt from it. The ``_discarding_changes`` service,
        because plain ``~load_config`` first asks, in a dialog, whether to save the changed config, and
        waits for an answer nobody gives under Xvfb (seen: the call never returned)."""
        service = "/rviz/load_config_discarding_changes"
        rospy.wait_for_service(service, timeout)
        proxy = rospy.ServiceProxy(service, SendFilePath)
        response = with_timeout(lambda: proxy(path), timeout, f"rviz's {service} {path}")
        assert response.success, f"rviz could not load {path}"

    def drive_until(self, linear, angular, done, timeout, what):
        """Publish a Twist at 20 Hz (wall) until ``done()`` holds, then a zero one; AssertionError naming
        ``what`` after ``timeout`` wall seconds. Judged by what the robot did, not by how long it was told to:
        on a starved machine a command reaches the simulator late, and a fixed drive time moves it less."""
        twist = Twist()
        twist.linear.x, twist.angular.z = linear, angular

        def moved():
            self.cmd.publish(twist)
            return done()
        try:
            wait_for(lambda: self.alive() or moved(), timeout, what, 0.05, error=AssertionError)
        finally:
            self.cmd.publish(Twist())

    # -------------------------------------------------------------------------------------- X side

    def windows(self):
        return xscreen.list_windows(self.xvfb.display)

    def screenshot(self):
        return xscreen.screenshot(self.xvfb.display)


class PictureSuite(unittest.TestCase):
    """What the picture suites share: a View started on Xvfb, stopped at the end, and every test skipped
    (with the reason printed as ``SKIPPED <suite>: <why>``, which the runner reports) only when Xvfb cannot
    start."""

    view = None
    skip_reason = None

    @classmethod
    def start_view(cls, suite, view, ready=None):
        """Start ``view`` and wait for ``ready()`` (waits that raise AssertionError); False (the suite skips)
        when no X server can be had.

        rviz is Debian's rviz 1.14 on Ogre and llvmpipe under Xvfb, not ours: twice in some forty ``make test``
        runs (CI among them) its start-up ended the launch right after its window appeared, where no run of
        ours could tell why. When ``ready()`` fails and the launch log shows that rviz itself started and then
        died (``rviz_start_failed``), not the simulator, the view is started once more, saying so with the first
        log's evidence (kept as ``<log>.first``); a second failure fails the suite. Anything after start-up
        is judged as it comes."""
        cls.view = view
        try:
            view.start()
        except xscreen.XvfbUnavailable as err:
            cls.skip_reason = f"Xvfb cannot start here: {err}"
            print(f"SKIPPED {suite}: {cls.skip_reason}", flush=True)
            return False
        if ready is None:
            return True
        try:
            ready()
        except AssertionError as err:
            why = view.rviz_start_failed()
            if why is None:
                raise
            print(f"RETRIED {suite}: rviz failed while starting ({why}); the view started once more", flush=True)
            print(f"  the first start's failure: {err}", flush=True)
            view.restart()
            ready()
        return True

    @classmethod
    def tearDownClass(cls):
        if cls.view is not None:
            cls.view.stop()

    def setUp(self):
        if self.skip_reason:
            self.skipTest(self.skip_reason)


def with_timeout(call, timeout, what):
    """``call()`` in a thread; AssertionError naming ``what`` when it has not returned within ``timeout`` s
    (a service call or XML-RPC request to a hung rviz would otherwise block the test for ever)."""
    box = {}

    def run():
        try:
            box["value"] = call()
        except BaseException as err:  # handed to the test thread below
            box["error"] = err
    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(timeout)
    if thread.is_alive():
        raise AssertionError(f"no answer from {what} within {timeout:g} s")
    if "error" in box:
        raise box["error"]
    return box["value"]


def save_frame(image, name):
    """Keep a screenshot next to the suite's logs (ROS_HOME), for whoever reads a failure."""
    home = os.environ.get("ROS_HOME") or os.path.join(os.path.expanduser("~"), ".ros")
    xscreen.save_png(image, os.path.join(home, name + ".png"), exact=True)


def generated_config():
    """The config view_rviz wrote for this run (ROS_HOME/diffbot_sim/view.rviz), as a dict."""
    home = os.environ.get("ROS_HOME") or os.path.join(os.path.expanduser("~"), ".ros")
    with open(os.path.join(home, "diffbot_sim", "view.rviz")) as f:
        return yaml.safe_load(f)


def config_variant(config, path, **enabled):
    """Write ``config`` to ``path`` with the displays named in ``enabled`` switched on or off
    (``RobotModel=False``; a name may start a display's name: ``LaserScan`` matches ``LaserScan /scan``)."""
    import copy

    variant = copy.deepcopy(config)
    for display in variant["Visualization Manager"]["Displays"]:
        for name, on in enabled.items():
            if display.get("Name", "").startswith(name):
                display["Enabled"] = on
                display["Value"] = on
    with open(path, "w") as f:
        yaml.safe_dump(variant, f, sort_keys=False)
    return path
