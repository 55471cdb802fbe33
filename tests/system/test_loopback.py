"""Loopback by default: with the documented set-up (neither ROS_IP nor ROS_HOSTNAME set, then
``source catkin_ws/devel/setup.bash``), every socket our processes listen on is bound to loopback.

Real processes: ``roscore``, ``roslaunch diffbot_sim sim.launch`` and ``rosrun diffbot_sim teleop_key`` on a
pseudo-terminal, each in its own session, with their own master port and ROS_HOME. Their pids (and every
descendant: roscore's rosmaster and rosout, roslaunch's nodes) are matched against ``ss -ltunp``.

Known exceptions, listed here and reported, never skipped silently: Debian's roscpp nodes (``/rosout`` and
``/robot_state_publisher``) bind their XML-RPC server to 0.0.0.0 whatever ROS_HOSTNAME says. Only that one
port of those two nodes is allowed off loopback; their TCPROS and UDPROS sockets must be on loopback too.
"""
import shutil
import signal

import pytest
from proctools import (
    MODEL,
    Master,
    Proc,
    alive,
    base_env,
    comm,
    environ,
    free_port,
    is_loopback,
    listening_sockets,
    wait_for,
)

# roscpp (Debian's build) binds the XML-RPC server to all interfaces: the only sockets allowed off loopback.
KNOWN_EXCEPTIONS = {"/rosout": "roscpp XML-RPC server", "/robot_state_publisher": "roscpp XML-RPC server"}
START_TIMEOUT = 60.0
STOP_BOUND = 20.0  # s for roslaunch/roscore to stop after SIGINT (roslaunch escalates to SIGTERM after 15 s)

pytestmark = pytest.mark.skipif(shutil.which("ss") is None, reason="needs `ss` (iproute2)")


def test_every_listening_socket_of_ours_is_on_loopback(tmp_path, record_testsuite_property):
    port = free_port()
    env = base_env(tmp_path / "ros_home", ROS_MASTER_URI=f"http://localhost:{port}")
    master = Master(f"http://localhost:{port}")
    procs = []
    try:
        core = Proc(f"roscore -p {port}", env, tmp_path, "roscore")
        procs.append(core)
        wait_for(master.up, START_TIMEOUT, "the master", [core])
        sim = Proc(f"roslaunch diffbot_sim sim.launch model:={MODEL}", env, tmp_path, "sim_launch")
        procs.append(sim)
        teleop = Proc("rosrun diffbot_sim teleop_key", env, tmp_path, "teleop", tty=True)
        procs.append(teleop)
        wait_for(lambda: master.publishes("/bullet_sim", "/odom") and master.publishes("/teleop_key", "/cmd_vel")
                 and master.publishes("/robot_state_publisher", "/tf_static")
                 and master.publishes("/rosout", "/rosout_agg"),
                 START_TIMEOUT, "the simulator, robot_state_publisher, rosout and the teleop", procs)

        # The hook did it: our node runs with ROS_HOSTNAME=localhost and no ROS_IP.
        sim_env = environ(master.node_pid("/bullet_sim"))
        assert sim_env.get("ROS_HOSTNAME") == "localhost" and "ROS_IP" not in sim_env, sim_env.get("ROS_HOSTNAME")

        nodes = {name: (master.node_pid(name), master.node_uri(name)) for name in master.nodes()}
        ours = {}
        for proc in procs:
            for pid in proc.descendants():
                ours[pid] = comm(pid)
        for name, (pid, _) in nodes.items():
            assert pid in ours, f"node {name} (pid {pid}) is not one of the processes this test started"
        assert set(nodes) >= {"/bullet_sim", "/teleop_key", "/rosout", "/robot_state_publisher"}, \
            f"nodes: {sorted(nodes)}; sim.launch output:\n{sim.output()}"
        master_pid = master.proxy.getPid("/pytest_system")[2]
        assert master_pid in ours

        exception_ports = {(nodes[n][0], int(nodes[n][1].rstrip("/").rsplit(":", 1)[1])): n
                           for n in KNOWN_EXCEPTIONS if n in nodes}
        checked, allowed, bad = [], [], []
        per_pid = {}
        for proto, host, sport, pids in listening_sockets():
            for pid in pids & set(ours):
                per_pid[pid] = per_pid.get(pid, 0) + 1
                entry = f"{proto} {host}:{sport} pid {pid} ({ours[pid][:80]})"
                if is_loopback(host):
                    checked.append(entry)
                elif proto == "tcp" and (pid, sport) in exception_ports:
                    node = exception_ports[(pid, sport)]
                    allowed.append(f"{node}: {KNOWN_EXCEPTIONS[node]} on {host}:{sport}")
                else:
                    bad.append(entry)
        report = "known exceptions (not on loopback): " + ("; ".join(sorted(allowed)) or "none")
        print(f"[loopback] {len(checked)} sockets on loopback; {report}")
        record_testsuite_property("loopback_exceptions", report)
        assert not bad, "listening off loopback:\n" + "\n".join(bad)
        # The check saw real sockets: every rospy process listens (XML-RPC + TCPROS), so does the master.
        for name in ("/bullet_sim", "/teleop_key"):
            assert per_pid.get(nodes[name][0], 0) >= 2, f"ss showed no sockets of {name}: is ss -p working?"
        assert per_pid.get(master_pid, 0) >= 1
        # The exceptions are what we said they are, and only that.
        assert len(allowed) <= len(KNOWN_EXCEPTIONS)

        # Stopping: Ctrl-C ends the teleop; SIGINT ends roslaunch and its nodes; nothing is left behind.
        teleop_pids = teleop.descendants()
        teleop.stop(signal.SIGINT, STOP_BOUND)
        assert teleop.returncode == 0, teleop.output()
        sim_pids = sim.descendants()
        took = sim.stop(signal.SIGINT, STOP_BOUND)
        print(f"[loopback] roslaunch sim.launch stopped {took:.1f} s after SIGINT")
        assert sim.returncode == 0, sim.output()
        assert took < STOP_BOUND
        left = [p for p in sim_pids + teleop_pids if alive(p) and ours.get(p) == comm(p)]  # same pid, same command
        assert not left, f"left behind: {[ours[p] for p in left]}"
    finally:
        for proc in reversed(procs):
            proc.stop(signal.SIGINT, STOP_BOUND)
