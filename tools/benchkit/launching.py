"""Launching the simulator for a measurement: each item starts its own master (``roslaunch -p PORT``) and stops
it with SIGINT, so nothing is shared between items; probes and subscribers run in child processes, one ROS
node each."""
import json
import os
import signal
import socket
import statistics
import subprocess
import sys
import time

from benchkit.common import BENCH, RESULTS


def free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def sim_args(*extra):
    """``roslaunch`` arguments of ``sim.launch`` with ``extra`` (``name:=value``)."""
    return ["diffbot_sim", "sim.launch"] + list(extra)


def probe_argv(kind, options):
    """The command line of a probe process (``bench.py --probe KIND``) given its options."""
    return [sys.executable, BENCH, "--probe", kind, "--options", json.dumps(options)]


class Launch:
    """``roslaunch -p PORT ...`` with its own master; stopped with SIGINT (then SIGKILL) on exit."""

    def __init__(self, args, log_name):
        self.port = free_port()
        self.env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{self.port}",
                        ROS_HOME=os.path.join(RESULTS, "ros_home"))
        self.args = ["roslaunch", "-p", str(self.port)] + list(args)
        self.log_path = os.path.join(RESULTS, f"{log_name}.log")
        self.proc = None
        self.children = []

    def __enter__(self):
        os.makedirs(RESULTS, exist_ok=True)
        self.log = open(self.log_path, "w")
        self.started = time.time()
        self.proc = subprocess.Popen(self.args, env=self.env, stdout=self.log, stderr=subprocess.STDOUT,
                                     stdin=subprocess.DEVNULL, start_new_session=True)
        return self

    def spawn(self, argv):
        """A helper process (a subscriber) against this launch's master; stopped with SIGINT on exit."""
        proc = subprocess.Popen(argv, env=self.env, stdout=subprocess.PIPE, stderr=self.log,
                                stdin=subprocess.DEVNULL, text=True)
        self.children.append(proc)
        return proc

    def probe(self, kind, timeout=300, **options):
        """Run the probe ``kind`` against this master and return its JSON answer."""
        out = subprocess.run(probe_argv(kind, options), env=self.env, stdout=subprocess.PIPE, stderr=self.log,
                             text=True, timeout=timeout, stdin=subprocess.DEVNULL)
        lines = [line for line in out.stdout.splitlines() if line.startswith("{")]
        if out.returncode != 0 or not lines:
            raise RuntimeError(f"probe {kind} failed (exit {out.returncode}); see {self.log_path}")
        return json.loads(lines[-1])

    def stop_children(self):
        """Stop the subscriber processes; what each counted (None for one that did not answer)."""
        counts = []
        for proc in self.children:
            proc.send_signal(signal.SIGINT)
        for proc in self.children:
            try:
                out, _ = proc.communicate(timeout=10)
                counts.append(json.loads(out.strip().splitlines()[-1]) if out.strip() else None)
            except (subprocess.TimeoutExpired, ValueError, IndexError):
                proc.kill()
                counts.append(None)
        self.children = []
        return counts

    def subscriber_messages(self):
        """Stop the subscriber processes: ``{topic: messages received}`` over all of them."""
        return {k: v for c in self.stop_children() if c for k, v in c.items()}

    def __exit__(self, *exc):
        self.stop_children()
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
        self.log.close()


def subscriber(launch, topics):
    """A separate process subscribing ``topics`` (as `rostopic echo` would, without printing)."""
    return launch.spawn(probe_argv("count", {"topics": topics}))


def startup_times(runs, extra=(), ros_home=None, before_each=None):
    """``roslaunch diffbot_sim sim.launch *extra`` -> first ``/odom``, wall seconds, ``runs`` times: the probe is up
    and polling for the master before roslaunch starts. ``before_each()`` runs before each (to empty a cache)."""
    times = []
    for i in range(runs):
        if before_each is not None:
            before_each()
        port = free_port()
        env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{port}",
                   ROS_HOME=ros_home or os.path.join(RESULTS, "ros_home"))
        probe = subprocess.Popen(probe_argv("first_odom", {}), env=env, stdout=subprocess.PIPE,
                                 stderr=subprocess.DEVNULL, text=True)
        time.sleep(0.5)  # the probe is up and polling for the master before the clock starts
        start = time.time()
        with open(os.path.join(RESULTS, f"startup{i}.log"), "w") as log:
            proc = subprocess.Popen(["roslaunch", "-p", str(port)] + sim_args(*extra), env=env, stdout=log,
                                    stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, start_new_session=True)
            try:
                out, _ = probe.communicate(timeout=90)
                times.append(json.loads(out.strip().splitlines()[-1])["first_odom_epoch"] - start)
            finally:
                proc.send_signal(signal.SIGINT)
                try:
                    proc.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    os.killpg(proc.pid, signal.SIGKILL)
                    proc.wait()
    return {"median_s": statistics.median(times), "runs_s": times}
