"""Two hosts: roscore + the simulator in one network namespace, a driver in another, joined by a veth pair
with private addresses. Each side opts in to the network with ROS_IP=<its address> (the documented way);
commands cross (the robot moves) and odometry comes back.

Needs root (``ip netns``); skipped with the reason otherwise. Namespace and link names carry this process's
pid, so parallel runs do not collide; they are always deleted, and every process left in them is killed.
"""
import json
import os
import shutil
import signal
import subprocess

import pytest
from proctools import MODEL, Proc, base_env, wait_for

START_TIMEOUT = 60.0
TAG = f"{os.getpid() % 100000}"
NS_SIM, NS_DRIVER = f"dbsim{TAG}", f"dbdrv{TAG}"
VETH_SIM, VETH_DRIVER = f"dbs{TAG}", f"dbd{TAG}"  # interface names: at most 15 characters
SUBNET = f"10.213.{os.getpid() % 250 + 1}"
SIM_IP, DRIVER_IP = f"{SUBNET}.1", f"{SUBNET}.2"
MASTER_URI = f"http://{SIM_IP}:11311"

# The driver, run in the other namespace: publish 0.3 m/s on /cmd_vel at 10 Hz until odom shows the robot
# moving forward, then print what it saw (and who it talked to) as one JSON line.
DRIVER = r"""
import json, sys, time, rosgraph, rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
rospy.init_node("remote_driver", disable_signals=True)
odom = []
rospy.Subscriber("/odom", Odometry, lambda m: odom.append(m), queue_size=10)
pub = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
deadline = time.monotonic() + 60.0
first = None
while time.monotonic() < deadline:
    cmd = Twist(); cmd.linear.x = 0.3; pub.publish(cmd)
    if odom and first is None:
        first = odom[-1].pose.pose.position.x
    if odom and odom[-1].pose.pose.position.x > 0.1 and odom[-1].twist.twist.linear.x > 0.2:
        break
    time.sleep(0.1)
pub.publish(Twist())
last = odom[-1] if odom else None
print(json.dumps({
    "odom_messages": len(odom),
    "first_x": first,
    "x": last.pose.pose.position.x if last else None,
    "vx": last.twist.twist.linear.x if last else None,
    "me": rospy.get_node_uri(),
    "sim": rosgraph.Master("/remote_driver").lookupNode("/bullet_sim"),
    "odom_from": last._connection_header["callerid"] if last else None,
}), flush=True)
time.sleep(0.5)  # let the stop leave before the node goes
rospy.signal_shutdown("done")
"""


def ip(*args, check=True):
    return subprocess.run(["ip", *args], capture_output=True, text=True, check=check)


def netns_pids(ns):
    out = ip("netns", "pids", ns, check=False).stdout
    return [int(p) for p in out.split()]


@pytest.fixture
def namespaces():
    if os.geteuid() != 0:
        pytest.skip(f"needs root to create network namespaces (ip netns); running as uid {os.geteuid()}")
    if shutil.which("ip") is None:
        pytest.skip("needs `ip` (iproute2)")
    created = []
    try:
        for ns in (NS_SIM, NS_DRIVER):
            ip("netns", "add", ns)
            created.append(ns)
        ip("link", "add", VETH_SIM, "type", "veth", "peer", "name", VETH_DRIVER)
        for ns, dev, addr in ((NS_SIM, VETH_SIM, SIM_IP), (NS_DRIVER, VETH_DRIVER, DRIVER_IP)):
            ip("link", "set", dev, "netns", ns)
            ip("-n", ns, "addr", "add", f"{addr}/24", "dev", dev)
            ip("-n", ns, "link", "set", dev, "up")
            ip("-n", ns, "link", "set", "lo", "up")
    except subprocess.CalledProcessError as err:
        _cleanup(created)
        pytest.skip(f"cannot create network namespaces: `{' '.join(err.cmd)}` said {err.stderr.strip()!r}")
    try:
        yield
    finally:
        _cleanup(created)


def _cleanup(created):
    for ns in created:
        for pid in netns_pids(ns):  # only what this test started can be in a namespace it created
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        ip("netns", "del", ns, check=False)  # takes the veth pair with it
    ip("link", "del", VETH_SIM, check=False)  # in case it never moved into a namespace


def test_commands_and_odom_cross_two_namespaces(namespaces, tmp_path):
    # The namespaces really are separate hosts: no route between them except the veth pair.
    ping = ip("netns", "exec", NS_DRIVER, "ping", "-c", "1", "-W", "2", SIM_IP, check=False)
    if shutil.which("ping"):
        assert ping.returncode == 0, ping.stdout + ping.stderr
    sim_env = base_env(tmp_path / "home_sim", ROS_IP=SIM_IP, ROS_MASTER_URI=MASTER_URI)
    drv_env = base_env(tmp_path / "home_driver", ROS_IP=DRIVER_IP, ROS_MASTER_URI=MASTER_URI)
    in_sim, in_drv = ("ip", "netns", "exec", NS_SIM), ("ip", "netns", "exec", NS_DRIVER)
    procs = []
    try:
        core = Proc("roscore -p 11311", sim_env, tmp_path, "roscore", prefix=in_sim)
        procs.append(core)
        wait_for(lambda: ip("netns", "exec", NS_SIM, "ss", "-Hltn", "sport = :11311", check=False).stdout,
                 START_TIMEOUT, f"the master on {MASTER_URI}", [core])
        sim = Proc(f"roslaunch --wait diffbot_sim sim.launch model:={MODEL}", sim_env, tmp_path, "sim", prefix=in_sim)
        procs.append(sim)
        script = tmp_path / "driver.py"
        script.write_text(DRIVER)
        driver = Proc(f"python3 {script}", drv_env, tmp_path, "driver", prefix=in_drv)
        procs.append(driver)
        wait_for(lambda: driver.poll() is not None, START_TIMEOUT + 60, "the driver to finish", [sim, core])
        out = driver.output()
        assert driver.returncode == 0, out
        result = json.loads([line for line in out.splitlines() if line.startswith("{")][-1])
        print(f"[two_hosts] {result}")
        # Odom came back, and the commands went across: the robot moved forward.
        assert result["odom_messages"] > 0, f"{out}\nsim.launch output:\n{sim.output()}"
        assert result["x"] > 0.1 and result["vx"] > 0.2, f"{result}\nsim.launch output:\n{sim.output()}"
        # Who talked to whom: each side advertised its own address, and the odom came from the simulator.
        assert result["me"].startswith(f"http://{DRIVER_IP}:"), result
        assert result["sim"].startswith(f"http://{SIM_IP}:"), result
        assert result["odom_from"] == "/bullet_sim"
        # With ROS_IP set (the opt-in) the hook leaves ROS_HOSTNAME alone and ROS binds to every interface.
        listen = ip("netns", "exec", NS_SIM, "ss", "-Hltn", "sport = :11311", check=True).stdout.split()
        assert "0.0.0.0:11311" in listen or f"{SIM_IP}:11311" in listen, listen
    finally:
        for proc in reversed(procs):
            proc.stop(signal.SIGINT, 20.0)
