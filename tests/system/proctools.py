"""Helpers for the system tests that run real ROS processes (test_loopback.py, test_two_hosts.py).

Every process is started in a new session through a fresh ``bash`` that sources the workspace's setup file
(what a new terminal gets), so the environment hook runs as it does for a user. Waits poll with deadlines.
Stopping is by the pids we started: SIGINT first (roslaunch then stops its nodes), SIGKILL to the session
and to every descendant we saw if it does not end.
"""
import os
import pty
import select
import signal
import socket
import subprocess
import threading
import time
import xmlrpc.client

from diffbot_sim import waiting

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SETUP = os.path.join(ROOT, "catkin_ws", "devel", "setup.bash")
MODEL = os.path.join(ROOT, "urdf", "diffbot.urdf.xacro")
CALLER = "/pytest_system"


def base_env(ros_home, **overrides):
    """os.environ without ROS_IP/ROS_HOSTNAME (the user set neither), plus ROS_HOME and ``overrides``."""
    env = {k: v for k, v in os.environ.items() if k not in ("ROS_IP", "ROS_HOSTNAME")}
    env["ROS_HOME"] = str(ros_home)
    env.update(overrides)
    return env


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for(predicate, timeout, what, procs=()):
    """``waiting.wait_for`` (AssertionError, polling every 50 ms) that also fails as soon as one of ``procs``
    has exited, with its output."""
    def check():
        value = predicate()
        for proc in () if value else procs:
            if proc.poll() is not None:
                raise AssertionError(f"{proc.args_text} exited ({proc.returncode}) while waiting for {what}:\n"
                                     f"{proc.output()}")
        return value
    return waiting.wait_for(check, timeout, what, 0.05, error=AssertionError)


class Proc:
    """A command run after sourcing the workspace in a fresh bash (optionally via a prefix such as
    ``ip netns exec NS``), in its own session, output to a log file (or a pty when ``tty``)."""

    def __init__(self, command, env, log_dir, name, prefix=(), tty=False):
        self.args_text = command
        self.log_path = os.path.join(str(log_dir), f"{name}.log")
        self.master = self.slave = None
        self._buf = bytearray()
        args = [*prefix, "bash", "-c", f"source {SETUP} && exec {command}"]
        if tty:
            self.master, self.slave = pty.openpty()
            out = self.slave
            stdin = self.slave
            self._reader = threading.Thread(target=self._drain, daemon=True)
        else:
            self._log = open(self.log_path, "w")
            out = self._log
            stdin = subprocess.DEVNULL
        self.popen = subprocess.Popen(args, stdin=stdin, stdout=out, stderr=subprocess.STDOUT, env=env,
                                      start_new_session=True, close_fds=True)
        self.pid = self.popen.pid
        self.seen = {self.pid}  # every descendant we ever saw (roslaunch puts nodes in new sessions)
        if tty:
            self._reader.start()

    def _drain(self):
        fd = self.master  # kill() closes it and sets self.master to None; the read then fails and we end
        while True:
            try:
                ready, _, _ = select.select([fd], [], [], 0.1)
                if ready:
                    chunk = os.read(fd, 4096)
                    if not chunk:
                        return
                    self._buf += chunk
            except (OSError, ValueError):
                return

    def poll(self):
        return self.popen.poll()

    @property
    def returncode(self):
        return self.popen.returncode

    def output(self):
        if self.master is not None:
            return bytes(self._buf[-3000:]).decode("utf-8", "replace")
        try:
            with open(self.log_path, errors="replace") as f:
                return f.read()[-3000:]
        except OSError:
            return ""

    def descendants(self):
        """Live pids of this process and all its descendants (by parent pid); remembered for cleanup."""
        found = tree(self.pid)
        self.seen.update(found)
        return found

    def stop(self, sig=signal.SIGINT, timeout=20.0):
        """Send ``sig`` and wait; returns the seconds it took. SIGKILLs what is left after ``timeout``."""
        self.descendants()
        started = time.monotonic()
        if self.poll() is None:
            try:
                os.kill(self.pid, sig)
            except ProcessLookupError:
                pass
        try:
            self.popen.wait(timeout)
        except subprocess.TimeoutExpired:
            pass
        elapsed = time.monotonic() - started
        self.kill()
        return elapsed

    def kill(self):
        """SIGKILL whatever is left of this process, its session and every descendant we saw."""
        for pid in self.seen:
            if alive(pid):
                try:
                    os.kill(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
        try:
            os.killpg(self.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        try:
            self.popen.wait(10)
        except subprocess.TimeoutExpired:
            pass
        for fd in (self.master, self.slave):
            if fd is not None:
                try:
                    os.close(fd)
                except OSError:
                    pass
        self.master = self.slave = None
        if hasattr(self, "_log"):
            self._log.close()


def _stat(pid):
    with open(f"/proc/{pid}/stat") as f:
        text = f.read()
    if ")" not in text:
        raise OSError(f"pid {pid} vanished")  # read while the process was being reaped
    return text.rsplit(")", 1)[1].split()


def alive(pid):
    try:
        return _stat(pid)[0] != "Z"
    except OSError:
        return False


def tree(root):
    """Live pids of ``root`` and its descendants."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                fields = _stat(int(entry))
            except OSError:
                continue
            if fields[0] != "Z":
                children.setdefault(int(fields[1]), []).append(int(entry))
    found, todo = [], [root]
    while todo:
        pid = todo.pop()
        if pid == root and not alive(pid):
            continue
        found.append(pid)
        todo.extend(children.get(pid, []))
    return found


def comm(pid):
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return " ".join(a.decode("utf-8", "replace") for a in f.read().split(b"\0") if a)[:200]
    except OSError:
        return "?"


def environ(pid):
    with open(f"/proc/{pid}/environ", "rb") as f:
        pairs = [item.split(b"=", 1) for item in f.read().split(b"\0") if b"=" in item]
    return {k.decode(): v.decode("utf-8", "replace") for k, v in pairs}


class Master:
    """The ROS master's XML-RPC API, plus each node's own (getPid) — no rospy node needed."""

    def __init__(self, uri):
        self.uri = uri
        self.proxy = xmlrpc.client.ServerProxy(uri)

    def up(self):
        try:
            return self.proxy.getPid(CALLER)[0] == 1
        except OSError:
            return False

    def state(self):
        code, msg, state = self.proxy.getSystemState(CALLER)
        assert code == 1, msg
        return state

    def publishes(self, node, topic):
        try:
            pubs = self.state()[0]
        except OSError:
            return False
        return any(t == topic and node in nodes for t, nodes in pubs)

    def nodes(self):
        """Nodes with any publication, subscription or service (what ``rosnode list`` shows)."""
        return sorted({n for group in self.state() for _, nodes in group for n in nodes})

    def node_uri(self, node):
        code, msg, uri = self.proxy.lookupNode(CALLER, node)
        assert code == 1, msg
        return uri

    def node_pid(self, node):
        code, msg, pid = xmlrpc.client.ServerProxy(self.node_uri(node)).getPid(CALLER)
        assert code == 1, msg
        return pid


def listening_sockets():
    """Every listening TCP socket and bound UDP socket with its owners: [(proto, host, port, {pid, ...})]."""
    out = subprocess.run(["ss", "-H", "-l", "-t", "-u", "-n", "-p"], capture_output=True, text=True,
                         check=True).stdout
    found = []
    for line in out.splitlines():
        parts = line.split()
        if len(parts) < 6:
            continue
        proto, local = parts[0], parts[4]
        host, _, port = local.rpartition(":")
        host = host.strip("[]")
        if "%" in host:
            host = host.split("%", 1)[0]
        users = line[line.find("users:"):] if "users:" in line else ""
        pids = {int(p.split("=", 1)[1]) for p in users.replace(")", ",").split(",") if p.startswith("pid=")}
        found.append((proto, host, int(port) if port.isdigit() else port, pids))
    return found


def is_loopback(host):
    return host in ("::1", "localhost") or host.startswith("127.") or host.startswith("::ffff:127.")
