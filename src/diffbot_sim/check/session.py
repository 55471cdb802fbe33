"""robot_check's private ROS session: a roscore on a free port, the controller parameters, and bullet_sim
on it, each in a session of its own and stopped (every descendant) at the end; their logs in a temporary
directory removed at exit. No rospy: the caller joins the master as a node itself."""
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time

#: bullet_sim's node name.
SIM = "/bullet_sim"
#: Private parameters of bullet_sim for the check: headless, 3x real time (see robot_check), ground truth on.
SIM_PARAMS = {"real_time": True, "real_time_factor": 3.0, "publish_ground_truth": True, "gui": False}
MASTER_TIMEOUT = 20.0  # s (wall) for roscore to answer


class SessionError(Exception):
    """The private master or the simulator did not come up or died (one line saying which and why)."""


def _free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _tree(root):
    """Live pids of ``root`` and its descendants (roslaunch starts rosmaster/rosout as its children)."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as handle:
                    fields = handle.read().rsplit(")", 1)[1].split()
            except (OSError, IndexError):
                continue
            if fields[0] != "Z":
                children.setdefault(int(fields[1]), []).append(int(entry))
    found, todo = [], [root]
    while todo:
        pid = todo.pop()
        found.append(pid)
        todo.extend(children.get(pid, []))
    return found


class _Child:
    """A process in its own session, output to a log file; stopped with SIGINT, then SIGKILL."""

    def __init__(self, argv, env, log_path):
        self.log_path = log_path
        with open(log_path, "w") as log:
            self.popen = subprocess.Popen(argv, env=env, stdout=log, stderr=subprocess.STDOUT,
                                          stdin=subprocess.DEVNULL, start_new_session=True, close_fds=True)

    def alive(self):
        return self.popen.poll() is None

    def log(self):
        try:
            with open(self.log_path, errors="replace") as handle:
                return handle.read()
        except OSError:
            return ""

    def stop(self, timeout):
        pid = self.popen.pid
        seen = set(_tree(pid)) if self.alive() else set()
        if self.alive():
            try:
                os.kill(pid, signal.SIGINT)
            except ProcessLookupError:
                pass
            try:
                self.popen.wait(timeout)
            except subprocess.TimeoutExpired:
                pass
        for other in seen | set(_tree(pid) if self.alive() else ()):
            try:
                os.kill(other, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
        try:
            os.killpg(pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        try:
            self.popen.wait(10)
        except subprocess.TimeoutExpired:
            pass


class Session:
    """A private master with the controller parameters, and bullet_sim on it; this process joins as a node.

    ``ROS_MASTER_URI`` and ``ROS_LOG_DIR`` (a temporary directory, removed at the end) are set in this
    process's environment, as rospy and rosparam read them there.
    """

    def __init__(self, model, model_args, yaml_docs):
        self.model, self.model_args, self.yaml_docs = model, model_args, yaml_docs
        self.master = self.sim = None
        self.tmp = None

    def __enter__(self):
        self.tmp = tempfile.mkdtemp(prefix="robot_check_")
        try:
            self._start()
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def _start(self):
        import rosgraph
        import rosparam

        for _attempt in range(3):  # a free port can be taken between the probe and roscore binding it
            port = _free_port()
            os.environ["ROS_MASTER_URI"] = f"http://localhost:{port}"
            os.environ["ROS_LOG_DIR"] = self.tmp
            env = dict(os.environ)
            env.pop("PYTHONUNBUFFERED", None)
            self.master = _Child(["roscore", "-p", str(port)], env, os.path.join(self.tmp, "roscore.log"))
            api = rosgraph.Master("/robot_check", master_uri=os.environ["ROS_MASTER_URI"])
            deadline = time.monotonic() + MASTER_TIMEOUT
            while not api.is_online():
                if not self.master.alive() or time.monotonic() > deadline:
                    break
                time.sleep(0.05)
            if api.is_online():
                break
            self.master.stop(5.0)
            self.master = None
        else:
            raise SessionError(f"roscore did not start (log: {self.tmp}/roscore.log)")
        for docs in self.yaml_docs:
            for values, ns in docs:
                rosparam.upload_params(ns or "/", values)
        api.setParam("/use_sim_time", True)
        params = dict(SIM_PARAMS, model=self.model, model_args=self.model_args)
        for key, value in params.items():
            api.setParam(f"{SIM}/{key}", value)
        self.sim = _Child(["rosrun", "diffbot_sim", "bullet_sim"], env, os.path.join(self.tmp, "bullet_sim.log"))
        self.api = api

    def sim_failure(self):
        """bullet_sim's FATAL line (or its last line) once it has exited; None while it runs."""
        if self.sim is None or self.sim.alive():
            return None
        lines = [line.strip() for line in self.sim.log().splitlines() if line.strip()]
        fatal = [line for line in lines if line.startswith("[FATAL]")]
        text = (fatal or lines or ["(no output)"])[-1]
        return f"bullet_sim exited ({self.sim.popen.returncode}): {message(text)}"

    def sim_warnings(self):
        """The warnings bullet_sim has logged, without rospy's ``[WARN] [time]:`` prefix."""
        return [message(line) for line in self.sim.log().splitlines() if line.startswith("[WARN]")]

    def __exit__(self, *exc):
        if self.sim is not None:
            self.sim.stop(5.0)
        if self.master is not None:
            self.master.stop(5.0)
        if self.tmp is not None:
            shutil.rmtree(self.tmp, ignore_errors=True)
        return False


def message(line):
    """``[WARN] [1700000000.1, 2.0]: text`` -> ``text``."""
    if line.startswith("[") and "]: " in line:
        return line.split("]: ", 1)[1]
    return line
