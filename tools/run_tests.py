#!/usr/bin/env python3
"""Runs every test of the project and ends with one line `N passed, N failed`.

Every process it starts gets a user's environment (``user_env``: no ``PYTHONUNBUFFERED`` and the other
variables in NOT_ON_A_USERS_MACHINE), so a fault that only shows on a user's machine shows here too.

pytest (unit tests, no master) runs first; then each rostest suite in tests/integration/*.test, two at a time
(each rostest starts its own master on a free port). rostest is judged by its exit status and its result
XML files, never by its console output, which says OK even when a test node crashed.
Suites whose file name starts with `slow_` run only with --slow (`make test-slow`). Suites whose name starts
with `nav_` need the navigation stack (`make nav`) and run only with --nav (`make test-nav`): each twice, at
real time and in fast mode (rostest arg real_time:=false: as fast as the nodes in the loop allow), fast ones one at
a time so that their figures are the machine's, not a neighbour's; then the shipped navigation batch
(examples/batch/nav.yaml, `--jobs 2`).
Suites whose name starts with `moveit_` need MoveIt (`make moveit`) and run only with --moveit (`make test-moveit`),
each at real time and in fast mode, one at a time (move_group plans on the cores the simulator runs on).
"""
import argparse
import concurrent.futures
import contextlib
import glob
import html
import os
import shutil
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: Variables a user's shell does not have but a development machine or CI may: every process the runner
#: starts runs without them, so the suite passes or fails as it would on a user's machine.
NOT_ON_A_USERS_MACHINE = {
    # Unbuffered output hid an exit status of 120 (a failed flush of buffered output at exit) on CI.
    "PYTHONUNBUFFERED": "makes stdout/stderr unbuffered, hiding faults of buffered output",
    "PYTHONDONTWRITEBYTECODE": "users' Python writes __pycache__; imports must work with it",
    "PYTHONIOENCODING": "changes how text reaches terminals and pipes",
    "PYTHONWARNINGS": "turns warnings on or into errors",
    "PYTHONDEVMODE": "debug hooks and extra warnings",
    "PYTHONFAULTHANDLER": "prints tracebacks a user would not see",
    "PYTHONHASHSEED": "fixes set/dict orders that vary on a user's machine",
    "PYTHONMALLOC": "another allocator",
    "PYTHONSTARTUP": "interactive start-up file",
    "PYTHONINSPECT": "keeps the interpreter alive after a script ends",
    "PYTHONOPTIMIZE": "strips asserts and docstrings",
    "PYTHONBREAKPOINT": "debugger hook",
    # pyenv's Python is this machine's, not a user's; ROS runs on Debian's /usr/bin/python3 (and our venv).
    "PYENV_ROOT": "pyenv is not on a user's machine",
    "PYENV_VERSION": "pyenv is not on a user's machine",
    "PYENV_DIR": "pyenv is not on a user's machine",
    "VIRTUAL_ENV": "a user has no venv active; the workspace's setup puts ours on PATH",
    "CI": "set by CI only; nothing of ours may behave differently under it",
}


def say(text):
    """Print a line of the runner's report; a reader that went away (``| head``) changes no status."""
    from diffbot_sim import streams

    streams.write(sys.stdout, text + "\n")


def user_env(**extra):
    """os.environ without NOT_ON_A_USERS_MACHINE, plus ``extra``: what every spawned process gets."""
    env = {k: v for k, v in os.environ.items() if k not in NOT_ON_A_USERS_MACHINE}
    env.update(extra)
    return env
RESULTS = os.path.join(ROOT, "test-results")
TIMING_MARK = "diffbot_sim: timing-sensitive"


def _why(element):
    """The gist of a JUnit failure: its message, else the exception's text (rosunit writes ``str(exception)``
    and then the traceback), with the traceback's last line, where the failure was raised. Long enough to
    hold a roslaunch log tail that an assertion quotes: CI shows only the end of the output."""
    text = (element.get("message") or "").strip()
    body = (element.text or "").strip()
    if body:
        lines = body.splitlines()
        first_frame = next((i for i, line in enumerate(lines) if line.startswith('  File "')), len(lines))
        text = text or " ".join(lines[:first_frame]) or lines[-1]
        last = lines[-1].strip()
        if last not in text:
            text = f"{text} | {last}"
    return " ".join(text.split())[:1500] or "(no message)"


def count_junit(paths):
    """Return (passed, failed, skipped, failed_names) summed over JUnit XML files."""
    passed = failed = skipped = 0
    names = []
    for path in paths:
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError as err:
            failed += 1
            names.append(f"{os.path.basename(path)}: unreadable result file ({err})")
            continue
        # rosunit writes no <skipped> for a unittest skip; a suite that skips says "SKIPPED <why>" on its
        # stdout (the picture suites, where Xvfb cannot start), which rosunit keeps in <system-out>.
        said_skip = any(line.startswith("SKIPPED ") for out in root.iter("system-out")
                        for line in (out.text or "").splitlines())
        for case in root.iter("testcase"):
            name = f"{case.get('classname', '')}.{case.get('name', '')}"
            bad = case.find("failure") if case.find("failure") is not None else case.find("error")
            if bad is not None:
                failed += 1
                names.append(f"{name}: {_why(bad)}")
            elif case.find("skipped") is not None or said_skip:
                skipped += 1
            else:
                passed += 1
    return passed, failed, skipped, names


def run_pytest(slow):
    out = os.path.join(RESULTS, "pytest.xml")
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", f"--junitxml={out}",
           os.path.join(ROOT, "tests", "unit"), os.path.join(ROOT, "tests", "system")]
    if not slow:
        cmd += ["-m", "not slow"]
    started = time.monotonic()
    proc = subprocess.run(cmd, cwd=ROOT, env=user_env())
    passed, failed, skipped, names = count_junit([out]) if os.path.exists(out) else (0, 0, 0, [])
    if proc.returncode not in (0, 5) and failed == 0:
        failed, names = 1, [f"pytest exited {proc.returncode}"]
    say(f"[tests] pytest: {passed} passed, {failed} failed, {skipped} skipped "
          f"({time.monotonic() - started:.0f} s)")
    return passed, failed, skipped, names


def run_rostest(test_file, mode=None):
    """One rostest suite; ``mode`` "real_time" or "fast" (nav suites) gives it the matching real_time arg. Fast
    is the simulator's real_time:=false: as fast as the nodes in the loop allow, never faster (~wait_for_nodes;
    no factor chosen for the machine)."""
    name = os.path.splitext(os.path.basename(test_file))[0]
    args = []
    if mode is not None:
        args = [f"real_time:={'true' if mode == 'real_time' else 'false'}"]
        name = f"{name}-{mode}"
    base = os.path.join(RESULTS, "rostest", name)
    shutil.rmtree(base, ignore_errors=True)
    os.makedirs(base)
    log_path = os.path.join(base, "console.log")
    started = time.monotonic()
    if name.startswith("slow_"):  # minutes without a line otherwise: say that it runs
        say(f"[tests] rostest {name}: started (a slow suite, minutes; log {log_path})")
    env = user_env(ROS_HOME=os.path.join(base, "ros_home"))
    with open(log_path, "w") as log:
        try:
            proc = subprocess.Popen(["rostest", "--results-base-dir", base, "diffbot_sim", os.path.basename(test_file)]
                                    + args, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=env)
            code = proc.wait(timeout=1200 if mode else 600)
        except subprocess.TimeoutExpired:
            code = "timeout"
            stop_suite(proc, env["ROS_HOME"])
    xmls = [p for p in glob.glob(os.path.join(base, "**", "*.xml"), recursive=True)
            if not os.path.basename(p).startswith("rostest-")]
    passed, failed, skipped, names = count_junit(xmls)
    summary = glob.glob(os.path.join(base, "**", "rostest-*.xml"), recursive=True)
    _, s_failed, _, s_names = count_junit(summary)
    if s_failed and not failed:
        failed, names = s_failed, s_names  # e.g. "test node did not generate test results" (it crashed)
    if code != 0 and failed == 0:
        failed, names = failed + 1, names + [f"{name}: rostest exited {code} (see {log_path})"]
    if passed + failed + skipped == 0:
        failed, names = 1, [f"{name}: ran no test (see {log_path})"]
    return name, passed, failed, skipped, names, time.monotonic() - started


def stop_suite(proc, ros_home):
    """A suite past its time: rostest is asked to stop as Ctrl-C asks (it stops its nodes), then killed; then
    every process still carrying the suite's ROS_HOME (roslaunch gives each node its own process group, so
    no group kill reaches them all) is killed, so no leftover node loads the suites after it."""
    proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout=20)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
    marker = f"ROS_HOME={ros_home}".encode()
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{pid}/environ", "rb") as environ:
                if marker in environ.read().split(b"\0"):
                    os.kill(int(pid), signal.SIGKILL)
        except (OSError, ProcessLookupError):
            pass


def _skip_reason(name):
    """The "SKIPPED <why>" line a rostest suite printed (kept in its result files), for the report."""
    for path in glob.glob(os.path.join(RESULTS, "rostest", name, "**", "*.xml"), recursive=True):
        try:
            with open(path, errors="replace") as result:
                for line in result:
                    if line.startswith("SKIPPED "):
                        return line[len("SKIPPED "):].strip()
        except OSError:
            continue
    return "no reason printed"


NAV_FIXTURES = os.path.join(ROOT, "tests", "data", "nav_way")
#: A Gazebo user's mobile-manipulator packages (their own launch files, YAML and URDF) the arm suites launch.
MANIPULATOR_FIXTURES = os.path.join(ROOT, "tests", "data", "manipulator_way")
#: A Gazebo user's multi-robot packages (a TurtleBot3-class robot, a house of meshes) the multi_way suites launch.
MULTI_FIXTURES = os.path.join(ROOT, "tests", "data", "multi_way")
#: A Gazebo user's car-like robots (a bicycle model with Gazebo in its namespace, a SteerBotHardwareGazebo base).
CAR_FIXTURES = os.path.join(ROOT, "tests", "data", "car_way")
NAV_NEEDS = ("move_base", "amcl", "map_server", "gmapping", "dwa_local_planner")
#: What the moveit_ suites launch and import (built by `make moveit` on Debian 12).
MOVEIT_NEEDS = ("moveit_ros_move_group", "moveit_commander", "moveit_planners_ompl", "moveit_kinematics",
                "trac_ik_kinematics_plugin", "moveit_simple_controller_manager", "diffbot_arm_moveit_config")


def add_package_path(directory):
    """Let rospack find the fixture packages under ``directory`` (ROS_PACKAGE_PATH of every process started)."""
    os.environ["ROS_PACKAGE_PATH"] = os.pathsep.join(
        [p for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p] + [directory])


def run_nav(args):
    """`make test-nav`: the nav_ suites at real time (two at once: each uses a fraction of a core) and then
    in fast mode (one at a time), after checking that `make nav` has been done."""
    missing = [p for p in NAV_NEEDS
               if subprocess.run(["rospack", "find", p], capture_output=True, env=user_env()).returncode != 0]
    if missing:
        say(f"[tests] the navigation stack is not built (rospack finds no {', '.join(missing)}): run `make nav` "
            f"(or `make nav NAV_SOURCES=DIR` without network) first")
        say("0 passed, 1 failed")
        return 1
    # The Gazebo user's own packages (fakebot_gazebo, _slam, _navigation) that nav_gazebo_way_* launch.
    add_package_path(NAV_FIXTURES)
    add_package_path(MULTI_FIXTURES)  # tb3like_gazebo, _slam, _navigation: the nav_multi_* suites
    suites = sorted(glob.glob(os.path.join(ROOT, "tests", "integration", "nav_*.test")))
    if args.only:
        suites = [t for t in suites if args.only in os.path.basename(t)]
    total_p = total_f = 0
    failures = []
    modes = [m for m in (("real_time", args.jobs), ("fast", 1)) if args.mode in (None, m[0])]
    for mode, jobs in modes:
        with cpu_hogs(args.hogs, f"the {mode} suites"):
            results = _run_suites(suites, mode, jobs)
        for name, p, f, s, n, secs in results:
            say(f"[tests] rostest {name}: {p} passed, {f} failed ({secs:.0f} s)")
            for line in _figures(name):
                say(f"[tests]   {line}")
            total_p, total_f = total_p + p, total_f + f + s
            failures += n
    if (not args.only or "batch" in args.only) and args.mode is None:
        p, f, n = run_nav_batch()
        total_p, total_f, failures = total_p + p, total_f + f, failures + n
    for name in failures:
        say(f"[tests] FAILED: {name}")
    say(f"{total_p} passed, {total_f} failed")
    return 1 if total_f else 0


def run_moveit(args):
    """`make test-moveit`: the moveit_ suites at real time, then in fast mode, one at a time, after checking that
    `make moveit` has been done."""
    missing = [p for p in MOVEIT_NEEDS
               if subprocess.run(["rospack", "find", p], capture_output=True, env=user_env()).returncode != 0]
    if missing:
        say(f"[tests] MoveIt is not built (rospack finds no {', '.join(missing)}): run `make moveit` "
            f"(or `make moveit MOVEIT_SOURCES=DIR` without network) first")
        say("0 passed, 1 failed")
        return 1
    add_package_path(MANIPULATOR_FIXTURES)  # mobile_manipulator_gazebo and its _moveit_config
    suites = sorted(glob.glob(os.path.join(ROOT, "tests", "integration", "moveit_*.test")))
    if args.only:
        suites = [t for t in suites if args.only in os.path.basename(t)]
    total_p = total_f = 0
    failures = []
    for mode in [m for m in ("real_time", "fast") if args.mode in (None, m)]:
        with cpu_hogs(args.hogs, f"the {mode} suites"):
            results = _run_suites(suites, mode, 1)
        for name, p, f, s, n, secs in results:
            say(f"[tests] rostest {name}: {p} passed, {f} failed ({secs:.0f} s)")
            for line in _figures(name):
                say(f"[tests]   {line}")
            total_p, total_f = total_p + p, total_f + f + s
            failures += n
    for name in failures:
        say(f"[tests] FAILED: {name}")
    say(f"{total_p} passed, {total_f} failed")
    return 1 if total_f else 0


@contextlib.contextmanager
def cpu_hogs(count, beside):
    """``count`` CPU-bound processes while the block runs (a busy machine), ended after it."""
    hogs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(count)]
    if hogs:
        say(f"[tests] {len(hogs)} CPU hogs running beside {beside}")
    try:
        yield
    finally:
        for hog in hogs:
            hog.kill()
            hog.wait()


def _run_suites(suites, mode, jobs):
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        return list(pool.map(lambda t: run_rostest(t, mode), suites))


def run_nav_batch():
    """The shipped navigation matrix (examples/batch/nav.yaml) through `batch --jobs 2`, as its README says to
    run it: each run one test; its summary table printed."""
    from diffbot_sim.batch import results as batch_results

    out = os.path.join(RESULTS, "batch_nav")
    spec = os.path.join(ROOT, "examples", "batch", "nav.yaml")
    started = time.monotonic()
    proc = subprocess.run(["rosrun", "diffbot_sim", "batch", spec, "--out", out, "--jobs", "2", "--rerun"],
                          capture_output=True, text=True, env=user_env())
    records = list(batch_results.load(os.path.join(out, "results.jsonl")).values())
    passed = sum(r["status"] == "passed" for r in records)
    names = [f"batch nav.yaml: {r['name']} {r['status']}: {r.get('reason', '')} (see {r['log_dir']})"
             for r in records if r["status"] != "passed"]
    if proc.returncode != 0 and not names:
        names = [f"batch nav.yaml: exited {proc.returncode}: {proc.stderr.strip()[-300:]}"]
    failed = len(records) - passed if records else 1
    say(f"[tests] batch examples/batch/nav.yaml: {passed} passed, {failed} failed "
        f"({time.monotonic() - started:.0f} s)")
    for line in proc.stdout.splitlines():
        say(f"[tests]   {line}")
    return passed, failed, names


def _figures(name, mark="FIGURE "):
    """The lines starting with ``mark`` a suite's test printed (kept in its result files): its measured
    figures, or (``RETRIED ``) a start-up it had to repeat for a reason outside the project (the report
    shows each, so a run that needed one says so)."""
    lines = []
    for path in sorted(glob.glob(os.path.join(RESULTS, "rostest", name, "**", "rosunit-*.xml"), recursive=True)):
        with open(path, errors="replace") as result:
            lines += [html.unescape(line.strip()) for line in result if line.startswith(mark)]
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--slow", action="store_true", help="also run slow suites (slow_*.test, pytest -m slow)")
    parser.add_argument("--only", default=None, help="run only rostest suites whose name contains this")
    parser.add_argument("--nav", action="store_true",
                        help="run only the navigation suites (nav_*.test; needs `make nav`), at real time and fast")
    parser.add_argument("--moveit", action="store_true",
                        help="run only the MoveIt suites (moveit_*.test; needs `make moveit`), at real time and fast")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--mode", choices=("real_time", "fast"), default=None,
                        help="--nav, --moveit: only the suites' real-time or fast runs")
    parser.add_argument("--hogs", type=int, default=int(os.environ.get("HOGS", "0")),
                        help="this many CPU-bound processes beside the rostest suites (a busy machine, "
                             "e.g. --only view --hogs 2)")
    args = parser.parse_args()
    if args.nav:
        return run_nav(args)
    if args.moveit:
        return run_moveit(args)
    os.makedirs(RESULTS, exist_ok=True)
    add_package_path(MANIPULATOR_FIXTURES)
    add_package_path(MULTI_FIXTURES)
    add_package_path(CAR_FIXTURES)
    add_package_path(os.path.join(ROOT, "tests", "data", "arm_way"))  # fixed arms of published shapes: arm_way_*
    add_package_path(os.path.join(ROOT, "tests", "data", "franka_way"))  # franka_gazebo's shape: franka_way_*
    total_p = total_f = total_s = 0
    failures = []
    if args.only is None:
        p, f, s, n = run_pytest(args.slow)
        total_p, total_f, total_s = p, f, s
        failures += n
    suites = sorted(t for t in glob.glob(os.path.join(ROOT, "tests", "integration", "*.test"))
                    if not os.path.basename(t).startswith(("nav_", "moveit_")))
    if not args.slow:
        suites = [t for t in suites if not os.path.basename(t).startswith("slow_")]
    if args.only:
        suites = [t for t in suites if args.only in os.path.basename(t)]
    # Suites that time wall-clock bounds (exit within N s) run in a second phase, beside each other only:
    # next to a fast-mode suite, which keeps a core busy, their bounds would measure the neighbour.
    timed = [t for t in suites if TIMING_MARK in open(t).read()]
    phases = [[t for t in suites if t not in timed], timed]
    with cpu_hogs(args.hogs, "the suites"), concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for phase in phases:
            for name, p, f, s, n, secs in pool.map(run_rostest, phase):
                skips = f", {s} skipped: {_skip_reason(name)}" if s else ""
                say(f"[tests] rostest {name}: {p} passed, {f} failed{skips} ({secs:.0f} s)")
                for line in _figures(name, "RETRIED "):
                    say(f"[tests]   {line}")
                total_p, total_f, total_s = total_p + p, total_f + f, total_s + s
                failures += n
    for name in failures:
        say(f"[tests] FAILED: {name}")
    line = f"{total_p} passed, {total_f} failed"
    if total_s:
        line += f", {total_s} skipped"
    say(line)
    return 1 if total_f else 0


if __name__ == "__main__":
    from diffbot_sim import streams  # a closed pipe (`make test | head`) must not turn the status into 120

    try:
        STATUS = main()
    finally:
        streams.finish()
    sys.exit(STATUS)
