"""The install space as a user gets it: ``make install PREFIX=DIR``, then ``source DIR/setup.bash`` alone.

One install per run, into a temporary prefix outside the checkout (wiped first, so a file the rules no longer
install cannot linger; its path is fixed per checkout so that the install build, catkin_ws/build_install, needs
no new configure). Every program then runs from a clean environment (``env -i`` with HOME, PATH=/usr/bin:/bin,
TERM, LANG, and the user's ROS_MASTER_URI and ROS_HOME; only DIR/setup.bash sourced; cwd outside the checkout),
and, where the machine allows a private mount namespace, with the checkout itself hidden under an empty tmpfs:
its source tree, catkin_ws/devel and .venv might as well be deleted. Nothing of the checkout is deleted.

Checked: no installed text file names the checkout, and the installed programs start the install space's own
Python; what the installed launch files and batch examples use is installed; ``roslaunch diffbot_sim
sim.launch`` drives the seed robot forward as commanded, upright, judged by its ground truth
(/gazebo/get_model_state); ``teleop_key`` starts on a terminal and quits on Ctrl-C; ``robot_check --help``
exits 0; a Gazebo user's launch file (gazebo_ros's empty_world.launch, spawn_model, controller_manager's
spawner) drives its ros_control robot; a node whose Python lacks PyBullet says so in one line and exits 1.
"""
import fcntl
import glob
import hashlib
import json
import math
import os
import pty
import re
import select
import shutil
import signal
import subprocess
import tempfile
import time

import pytest
from proctools import ROOT, alive, free_port, tree

from diffbot_sim import waiting

PREFIX = os.path.join(tempfile.gettempdir(),
                      f"diffbot_sim-install-test-{os.getuid()}-{hashlib.sha1(ROOT.encode()).hexdigest()[:8]}")
INSTALL_TIMEOUT = 600.0  # s: a first install configures and builds catkin_ws/build_install (~2 min on 2 cores)
START_TIMEOUT = 60.0     # s: roslaunch, the master, the simulator's first /clock on a busy 2-core machine
SPEED = 0.3              # m/s commanded
SETTLE = 2.0             # sim s for the wheels to reach the commanded speed
WINDOW = 3.0             # sim s of driving judged
READY_TEXT = b"we are ready"  # teleop_key's banner

#: Runs inside the clean environment with the install space's Python: `driver.py MODEL CMD_TOPIC` waits for the
#: simulator and the model's command subscriber, commands SPEED forward (again every 0.05 s wall, for a
#: controller with a cmd_vel_timeout), and prints the body's pose after SETTLE and then WINDOW sim seconds (the
#: simulator's, by the stamps of /gazebo/get_model_state's answers).
DRIVER = f"""
import json, sys, time
import rosgraph
import rospy
from gazebo_msgs.srv import GetModelState
from geometry_msgs.msg import Twist

model, topic = sys.argv[1:3]
# rospy reads /use_sim_time once, in init_node: wait until the launch file has set it (else wall time).
master, deadline = rosgraph.Master("/install_test_driver"), time.monotonic() + {START_TIMEOUT}
while True:
    try:
        if master.hasParam("/use_sim_time"):
            break
    except OSError:
        pass
    if time.monotonic() > deadline:
        sys.exit("no /use_sim_time parameter")
    time.sleep(0.1)
rospy.init_node("install_test_driver")
rospy.wait_for_service("/gazebo/get_model_state", {START_TIMEOUT})
model_state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)
cmd_vel = rospy.Publisher(topic, Twist, queue_size=1)
deadline = time.monotonic() + {START_TIMEOUT}
while cmd_vel.get_num_connections() == 0 or rospy.get_time() == 0.0:
    if time.monotonic() > deadline:
        sys.exit(f"nobody subscribes to {{topic}}, or no /clock")
    time.sleep(0.05)

def pose():
    # t: the simulator's sim time of the pose (the answer's stamp, as gazebo_ros stamps it), not this node's
    # clock, which lags it by a varying amount on a busy machine
    state = model_state(model, "")
    p, q = state.pose.position, state.pose.orientation
    return dict(ok=state.success, t=state.header.stamp.to_sec(), x=p.x, y=p.y, z=p.z, qx=q.x, qy=q.y, qz=q.z,
                qw=q.w)

def drive(seconds):  # command SPEED until the simulator's sim time has gone seconds on (the poses' stamps)
    command = Twist()
    command.linear.x = {SPEED}
    until = pose()["t"] + seconds
    while pose()["t"] < until:
        cmd_vel.publish(command)
        time.sleep(0.05)

drive({SETTLE})
start = pose()
drive({WINDOW})
end = pose()
cmd_vel.publish(Twist())
print(json.dumps(dict(start=start, end=end)))
"""
#: A Gazebo user's files (tests/data/gazebo_way/, as test_gazebo_way.py runs them) copied out of the checkout:
#: their $(find diffbot_sim)/tests/data/... paths become the copy's folder.
GAZEBO_WAY = {"gazebo_way": ["my_robot.launch", "my_robot.urdf.xacro", "wall.world"],
              "robots": ["ros_control_4wd.urdf", "ros_control_4wd.yaml"]}


@pytest.fixture(scope="module")
def hide():
    """The command prefix that runs a program in a private mount namespace with the checkout under an empty
    tmpfs (as root, or in a user namespace), or () where the machine allows neither."""
    check = f'mount -t tmpfs none "{ROOT}" && test ! -e "{ROOT}/Makefile"'
    for unshare in (["unshare", "-m"], ["unshare", "-r", "-m"]):
        if shutil.which("unshare") and subprocess.run([*unshare, "sh", "-c", check], capture_output=True,
                                                      timeout=30).returncode == 0:
            return tuple(unshare)
    return ()


def clean_argv(command, hide, ros_home, port):
    """argv of ``command`` (a shell command line) run as a user's fresh login would after sourcing only
    PREFIX/setup.bash; ``hide`` is the fixture's command prefix."""
    env = ["env", "-i", f"HOME={os.environ.get('HOME', '/root')}", "PATH=/usr/bin:/bin",
           f"TERM={os.environ.get('TERM', 'dumb')}", f"LANG={os.environ.get('LANG', 'C.UTF-8')}",
           f"ROS_HOME={ros_home}", f"ROS_MASTER_URI=http://localhost:{port}"]
    login = [*env, "bash", "-c", f"source '{PREFIX}/setup.bash' && exec {command}"]
    if not hide:
        return login
    quoted = " ".join("'" + arg.replace("'", "'\\''") + "'" for arg in login)
    return [*hide, "sh", "-c", f'mount -t tmpfs none "{ROOT}" && exec {quoted}']


class Started:
    """A program started by clean_argv in its own session; stop() ends it and every descendant it had."""

    def __init__(self, argv, cwd, log_path=None, tty=False):
        self.master = None
        if tty:
            self.master, slave = pty.openpty()
            self.popen = subprocess.Popen(argv, cwd=cwd, stdin=slave, stdout=slave, stderr=slave,
                                          start_new_session=True, close_fds=True)
            os.close(slave)
        else:
            with open(log_path, "w") as log:
                self.popen = subprocess.Popen(argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=log,
                                              stderr=subprocess.STDOUT, start_new_session=True, close_fds=True)
        self.log_path, self.seen, self.text = log_path, {self.popen.pid}, b""

    def read(self):
        """What the program printed so far (a pty's output is drained here)."""
        if self.master is not None:
            while select.select([self.master], [], [], 0)[0]:
                try:
                    chunk = os.read(self.master, 4096)
                except OSError:
                    break
                if not chunk:
                    break
                self.text += chunk
            return self.text.decode("utf-8", "replace")
        with open(self.log_path, errors="replace") as log:
            return log.read()

    def stop(self, timeout=20.0):
        self.seen.update(tree(self.popen.pid))
        if self.popen.poll() is None:
            os.kill(self.popen.pid, signal.SIGINT)
        try:
            self.popen.wait(timeout)
        except subprocess.TimeoutExpired:
            pass
        for pid in self.seen:
            if alive(pid):
                os.kill(pid, signal.SIGKILL)
        if self.master is not None:
            os.close(self.master)
            self.master = None
        return self.popen.wait(10)


def wait_until(predicate, timeout, what, started):
    """``waiting.wait_for`` (polling every 0.1 s) on a process ``started``: fails at once when it has exited,
    notes the processes it started meanwhile (``started.seen``), and ends a failure with its output's tail."""
    def check():
        if predicate():
            return True
        assert started.popen.poll() is None, \
            f"exited ({started.popen.returncode}) before {what}:\n{started.read()[-3000:]}"
        started.seen.update(tree(started.popen.pid))
        return False
    waiting.wait_for(check, timeout, what, 0.1,
                     error=lambda message: AssertionError(f"{message}:\n{started.read()[-3000:]}"))


def tilt(pose):
    """Angle (rad) between the body's z axis and the world's, from its quaternion."""
    return math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (pose["qx"] ** 2 + pose["qy"] ** 2))))


def yaw(pose):
    x, y, z, w = pose["qx"], pose["qy"], pose["qz"], pose["qw"]
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


#: a path to a C/C++ source or header file, as __FILE__ leaves it in a binary
SOURCE_PATH = re.compile(rb"/[\w./+-]+\.(?:c|cc|cpp|cxx|h|hh|hpp|hxx)(?=\x00)")


@pytest.fixture(scope="module")
def installed():
    """`make install PREFIX=...` into a wiped prefix; the prefix path, this run's alone until the module ends."""
    with open(PREFIX + ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        shutil.rmtree(PREFIX, ignore_errors=True)
        proc = subprocess.run(["make", "-C", ROOT, "install", f"PREFIX={PREFIX}"], stdin=subprocess.DEVNULL,
                              capture_output=True, text=True, timeout=INSTALL_TIMEOUT)
        assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
        yield PREFIX


def test_no_installed_file_names_the_checkout(installed):
    # The venv's packages (.venv/lib) are pip's; compiled .pyc files keep their build path as a label that
    # Python replaces by the real one when it loads them.
    named = []
    for folder, dirs, files in os.walk(installed):
        if os.path.relpath(folder, installed) == ".venv":
            dirs.remove("lib")
        for name in files:
            path = os.path.join(folder, name)
            if name.endswith(".pyc") or os.path.islink(path):
                continue
            with open(path, "rb") as f:
                data = f.read()
            if data.startswith(b"\x7fELF"):
                # compiled C++ (the navigation stack, when built) keeps its sources' paths for its log lines
                # (__FILE__): a label, never opened; any other mention of the checkout is a dependency
                data = SOURCE_PATH.sub(b"", data)
            if ROOT.encode() in data:
                named.append(os.path.relpath(path, installed))
    assert not named, f"installed files that name the checkout {ROOT}: {named[:20]}"
    for script in ("lib/diffbot_sim/bullet_sim", "lib/gazebo_ros/spawn_model", "lib/controller_manager/spawner",
                   "share/diffbot_sim/tests/rostest/test_real_robot.py"):
        with open(os.path.join(installed, script)) as f:
            assert f.readline() == f"#!{installed}/.venv/bin/python\n", script


def test_what_the_installed_launch_files_and_examples_use_is_installed(installed):
    share = os.path.join(installed, "share", "diffbot_sim")
    sources = glob.glob(os.path.join(share, "launch", "*.launch"))
    sources += glob.glob(os.path.join(share, "tests", "rostest", "*.test"))
    scenarios = glob.glob(os.path.join(share, "examples", "batch", "*.yaml"))
    assert sources and scenarios, f"no launch files or batch examples under {share}"
    used = set()
    for path in sources:
        with open(path) as f:
            text = f.read()
        # $(find diffbot_sim)/config/x.yaml, and find('diffbot_sim') + '/maps/' in $(eval ...)
        used.update(re.findall(r"\$\(find diffbot_sim\)/([\w./-]+)", text))
        used.update(re.findall(r"find\('diffbot_sim'\) \+ '/([\w./-]+)'", text))
    for path in scenarios:
        with open(path) as f:
            used.update(re.findall(r"^\s*test:\s*diffbot_sim/(\S+)", f.read(), re.MULTILINE))
    missing = sorted(rel for rel in used if not os.path.exists(os.path.join(share, rel)))
    assert not missing, f"used but not installed under {share}: {missing}"
    assert {"maps/", "tests/rostest/drive.test"} <= used  # the scan itself still sees them


def drive(argv, cwd, sim, model, topic):
    """Run DRIVER against ``sim`` (a Started roslaunch); the body's motion over WINDOW by its ground truth:
    (metres forward along its heading at the start, metres sideways, sim seconds, the two poses)."""
    (cwd / "driver.py").write_text(DRIVER)
    driver = subprocess.Popen(argv(f"python3 '{cwd / 'driver.py'}' {model} {topic}"), cwd=cwd, text=True,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    deadline = time.monotonic() + 3 * START_TIMEOUT
    while driver.poll() is None and sim.popen.poll() is None and time.monotonic() < deadline:
        time.sleep(0.1)
    if driver.poll() is None:
        os.killpg(driver.pid, signal.SIGKILL)
    out, err = driver.communicate()
    assert driver.returncode == 0, (f"driver: {driver.returncode}\n{out}{err}\nroslaunch "
                                    f"({sim.popen.poll()}):\n{sim.read()[-3000:]}")
    poses = json.loads(out.strip().splitlines()[-1])
    start, end = poses["start"], poses["end"]
    assert start["ok"] and end["ok"], poses
    heading = yaw(start)
    dx, dy = end["x"] - start["x"], end["y"] - start["y"]
    assert abs(end["z"] - start["z"]) < 0.01 and max(tilt(start), tilt(end)) < 0.05, f"not upright: {poses}"
    return (dx * math.cos(heading) + dy * math.sin(heading), -dx * math.sin(heading) + dy * math.cos(heading),
            end["t"] - start["t"], poses)


def test_sim_launch_drives_the_seed_robot_and_the_tools_start(installed, hide, tmp_path):
    port = free_port()

    def argv(command):
        return clean_argv(command, hide, tmp_path / "ros_home", port)

    sim = Started(argv(f"roslaunch -p {port} diffbot_sim sim.launch real_time_factor:=3"), tmp_path,
                  tmp_path / "sim.log")
    try:
        forward, sideways, elapsed, poses = drive(argv, tmp_path, sim, "diffbot", "/cmd_vel")
        assert WINDOW <= elapsed < WINDOW + 1.0, poses
        assert forward == pytest.approx(SPEED * elapsed, rel=0.1), f"{forward} m forward in {elapsed} s: {poses}"
        assert abs(sideways) < 0.05, poses

        teleop = Started(argv("rosrun diffbot_sim teleop_key"), tmp_path, tty=True)
        try:
            wait_until(lambda: READY_TEXT.decode() in teleop.read(), START_TIMEOUT, "teleop_key's banner", teleop)
            os.write(teleop.master, b"\x03")  # Ctrl-C
            teleop.popen.wait(10)
            assert teleop.popen.returncode == 0, teleop.read()[-2000:]
        finally:
            teleop.stop()
    finally:
        sim.stop()

    check = subprocess.run(argv("rosrun diffbot_sim robot_check --help"), cwd=tmp_path, capture_output=True,
                           text=True, timeout=START_TIMEOUT)
    assert check.returncode == 0 and "usage:" in check.stdout, check.stdout + check.stderr


def test_a_gazebo_users_launch_file_runs_through_the_drop_in_packages(installed, hide, tmp_path):
    # gazebo_ros's empty_world.launch, $(find xacro)/xacro, spawn_model, controller_manager's spawner and a
    # ros_control diff_drive_controller: the 4-wheel robot drives on /mobile_base_controller/cmd_vel.
    user = tmp_path / "my_robot_gazebo"
    user.mkdir()
    for folder, names in GAZEBO_WAY.items():
        for name in names:
            with open(os.path.join(ROOT, "tests", "data", folder, name)) as f:
                text = f.read()
            for other in GAZEBO_WAY:
                text = text.replace(f"$(find diffbot_sim)/tests/data/{other}", str(user))
            (user / name).write_text(text)
    port = free_port()

    def argv(command):
        return clean_argv(command, hide, tmp_path / "ros_home", port)

    sim = Started(argv(f"roslaunch -p {port} '{user / 'my_robot.launch'}'"), tmp_path, tmp_path / "gazebo_way.log")
    try:
        forward, sideways, elapsed, poses = drive(argv, tmp_path, sim, "my_robot", "/mobile_base_controller/cmd_vel")
        assert forward == pytest.approx(SPEED * elapsed, rel=0.1), f"{forward} m forward in {elapsed} s: {poses}"
        assert abs(sideways) < 0.05, poses
    finally:
        sim.stop()


def test_a_python_without_pybullet_gets_one_line(installed, tmp_path):
    # The install space's own Python with PyBullet made unimportable: what a node started by another Python
    # (the issue's `#!/usr/bin/env python3` finding pyenv's) meets.
    node = os.path.join(installed, "lib", "diffbot_sim", "bullet_sim")
    run = (f"python3 -c \"import runpy, sys; sys.modules['pybullet'] = None; sys.argv = ['{node}']; "
           f"runpy.run_path('{node}', run_name='__main__')\"")
    proc = subprocess.run(clean_argv(run, (), tmp_path / "ros_home", free_port()), cwd=tmp_path,
                          capture_output=True, text=True, timeout=START_TIMEOUT)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert len(lines) == 1 and "pybullet is missing" in lines[0] and "pip install pybullet" in lines[0], lines
