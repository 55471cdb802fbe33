"""One scenario run on this machine: its own master, log folders and temp folder, every process ended after.

A run is ``rostest --reuse-master <test> k:=v ...`` against a ``rosmaster`` started for it on a free port (so
this module knows the port: the clock probe, ``diffbot_sim.nodes.clock_probe``, reads the sim time the run
reached from that master's /clock). Its folder ``<out>/runs/<name>/`` holds ``console.log`` (rostest's output),
``results/`` (rostest's XML), ``ros_home/``, ``log/`` (ROS_LOG_DIR: every node's log) and ``tmp/`` (TMPDIR).

Every process of the run carries ``DIFFBOT_BATCH_RUN=<marker>`` in its environment: roslaunch puts each node
in a session of its own, so a process group cannot reach them all, but the inherited variable does
(:func:`processes_of`). When the run ends, by itself, by its timeout or by a stop request, every process still
carrying the marker is ended (SIGINT, then SIGTERM, then SIGKILL).

No rospy here (the probe is a child process).
"""
import glob
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import xml.etree.ElementTree as ET
import xmlrpc.client

from diffbot_sim.batch.scenarios import Run

MARKER = "DIFFBOT_BATCH_RUN"
#: Variables a user's shell lacks (as tools/run_tests.py removes them): runs behave as on a user's machine.
NOT_INHERITED = ("PYTHONUNBUFFERED", "PYTHONDONTWRITEBYTECODE", "PYTHONWARNINGS", "PYTHONHASHSEED", "ROS_MASTER_URI",
                 "ROS_HOME", "ROS_LOG_DIR", "TMPDIR", MARKER)
FIGURE = re.compile(r"^FIGURE (.*)$", re.M)
METRIC = re.compile(r"^METRIC ([A-Za-z_][A-Za-z0-9_]*)=(-?[0-9.eE+-]+|nan|inf)\s*$", re.M)


def free_port():
    """A TCP port free on loopback now (the OS's choice)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def processes_of(marker):
    """Pids of this machine's processes whose environment carries ``DIFFBOT_BATCH_RUN=<marker>``."""
    # "<batch id>/" names every run of a batch (a prefix); a full marker ends at the variable's NUL.
    needle = f"{MARKER}={marker}".encode() + (b"" if marker.endswith("/") else b"\0")
    pids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) == os.getpid():
            continue
        try:
            with open(f"/proc/{entry}/environ", "rb") as f:
                env = f.read()
        except OSError:
            continue
        if needle in env:
            pids.append(int(entry))
    return pids


def end_processes(marker, grace=3.0):
    """End every process carrying ``marker`` (SIGINT, SIGTERM after ``grace`` s, SIGKILL after as long again,
    as roslaunch ends its nodes); returns how many there were."""
    pids = processes_of(marker)
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGKILL):
        if not pids:
            break
        for pid in pids:
            try:
                os.kill(pid, sig)
            except ProcessLookupError:
                pass
        deadline = time.monotonic() + (grace if sig != signal.SIGKILL else 5.0)
        while time.monotonic() < deadline:
            pids = [p for p in pids if _alive(p)]
            if not pids:
                break
            time.sleep(0.05)
    return len(pids)


def _alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def _wait_port(port, proc, deadline):
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            return False
        with socket.socket() as s:
            s.settimeout(0.2)
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return True
        time.sleep(0.02)
    return False


def _cases(paths):
    """(test cases, failed cases, first failure line, figures, metrics) of JUnit files."""
    tests = failures = 0
    why, figures, metrics = "", [], {}
    for path in paths:
        try:
            root = ET.parse(path).getroot()
        except (ET.ParseError, OSError) as err:
            failures += 1
            why = why or f"{os.path.basename(path)}: unreadable ({err})"
            continue
        for case in root.iter("testcase"):
            tests += 1
            bad = case.find("failure") if case.find("failure") is not None else case.find("error")
            if bad is not None:
                failures += 1
                text = (bad.get("message") or bad.text or "").strip().splitlines()
                why = why or f"{case.get('name')}: {text[-1] if text else bad.tag}"
        for out in root.iter("system-out"):
            figures += FIGURE.findall(out.text or "")
            for key, value in METRIC.findall(out.text or ""):
                metrics[key] = float(value)
    return tests, failures, why, figures, metrics


def judge(results_dir, code, timed_out):
    """The verdict of a finished run from rostest's exit ``code`` and result XML:
    (status, tests, failures, reason, figures, metrics). Passed: exit 0, at least one test case, none failed."""
    node_files = glob.glob(os.path.join(glob.escape(results_dir), "**", "rosunit-*.xml"), recursive=True)
    summary = glob.glob(os.path.join(glob.escape(results_dir), "**", "rostest-*.xml"), recursive=True)
    tests, failures, why, figures, metrics = _cases(node_files)
    s_tests, s_failures, s_why, _, _ = _cases(summary)
    figures = list(dict.fromkeys(figures))  # rosout and stdout both carry each FIGURE line
    if timed_out:
        return "timeout", tests, failures, "timed out", figures, metrics
    if tests == 0:
        reason = s_why or (f"rostest exited {code} and wrote no test result" if code else "no test case ran")
        return "error", s_tests, max(s_failures, 1), reason, figures, metrics
    if failures:
        return "failed", tests, failures, why, figures, metrics
    if s_failures or code != 0:
        return "error", tests, max(s_failures, 1), s_why or f"rostest exited {code}", figures, metrics
    return "passed", tests, 0, "", figures, metrics


def read_sim_time(path):
    try:
        with open(path) as f:
            return float(f.read().strip() or 0.0)
    except (OSError, ValueError):
        return 0.0


def run_once(run: Run, out_dir, batch_id, node, stop: threading.Event | None = None, attempt=1,
             python=sys.executable):
    """Run ``run`` here, its folder under ``out_dir``; returns its record (a dict, results.jsonl's fields), or
    None when ``stop`` was set before it ended (the run is not recorded: a resumed batch runs it again)."""
    run_dir = os.path.join(out_dir, "runs", run.name)
    shutil.rmtree(run_dir, ignore_errors=True)
    for sub in ("results", "ros_home", "log", "tmp"):
        os.makedirs(os.path.join(run_dir, sub))
    marker = f"{batch_id}/{run.name}/{attempt}"
    base_env = {k: v for k, v in os.environ.items() if k not in NOT_INHERITED}
    base_env.update({MARKER: marker, "ROS_HOME": os.path.join(run_dir, "ros_home"),
                     "ROS_LOG_DIR": os.path.join(run_dir, "log"), "TMPDIR": os.path.join(run_dir, "tmp")})
    started = time.time()
    wall0 = time.monotonic()
    code, timed_out, stopped = None, False, False
    clock_file = os.path.join(run_dir, "sim_time")
    try:
        master = port = None
        with open(os.path.join(run_dir, "master.log"), "w") as mlog:
            for _ in range(5):  # another process may take the port between choosing and binding it
                port = free_port()
                master = subprocess.Popen(["rosmaster", "--core", "-p", str(port), "-w", "3"], stdout=mlog,
                                          stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=base_env,
                                          start_new_session=True)
                if _wait_port(port, master, time.monotonic() + 20.0):
                    break
                master.kill()
                master.wait()
                master = None
        if master is None:
            return make_record(run, "error", node, run_dir, started, time.monotonic() - wall0, 0.0, 0, 1,
                           "could not start a rosmaster (see master.log)", [], {}, attempt)
        env = dict(base_env, ROS_MASTER_URI=f"http://127.0.0.1:{port}")
        # roscore sets /run_id (rostest --reuse-master requires it); a bare rosmaster does not.
        xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"]).setParam("/batch", "/run_id", marker.replace("/", "-"))
        with open(os.path.join(run_dir, "probe.log"), "w") as plog:
            subprocess.Popen([python, "-m", "diffbot_sim.nodes.clock_probe", clock_file], stdout=plog,
                             stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=env, start_new_session=True)
        cmd = ["rostest", "--reuse-master", "--results-base-dir", os.path.join(run_dir, "results"), run.test_path]
        cmd += [f"{k}:={v}" for k, v in run.args.items()]
        with open(os.path.join(run_dir, "console.log"), "w") as log:
            log.write("$ " + " ".join(cmd) + "\n")
            log.flush()
            proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=env,
                                    start_new_session=True)
            deadline = wall0 + run.timeout
            while True:
                try:
                    code = proc.wait(timeout=0.1)
                    break
                except subprocess.TimeoutExpired:
                    pass
                if stop is not None and stop.is_set():
                    stopped = True
                    break
                if time.monotonic() > deadline:
                    timed_out = True
                    break
        wall = time.monotonic() - wall0
    finally:
        end_processes(marker)
    if stopped:
        return None
    sim = read_sim_time(clock_file)
    status, tests, failures, reason, figures, metrics = judge(os.path.join(run_dir, "results"), code, timed_out)
    return make_record(run, status, node, run_dir, started, wall, sim, tests, failures, reason, figures, metrics,
                       attempt)


def make_record(run, status, node, run_dir, started, wall, sim, tests, failures, reason, figures, metrics, attempt):
    """A results.jsonl record (``started``: the run's start, seconds since the epoch)."""
    return {"name": run.name, "args": dict(run.args), "status": status, "wall_s": round(wall, 3),
            "sim_s": round(sim, 3), "rtf": round(sim / wall, 3) if wall > 0 else 0.0, "node": node,
            "log_dir": run_dir, "tests": tests, "failures": failures, "test": run.test, "reason": reason,
            "figures": figures, "metrics": metrics, "attempt": attempt,
            "started": time.strftime("%Y-%m-%dT%H:%M:%S", time.localtime(started))}
