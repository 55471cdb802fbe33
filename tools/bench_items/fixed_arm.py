"""Item ``fixed_arm``: an arm bolted to the world (tests/data/manipulator_way's arm cell: 6 effort joints under an
effort JointTrajectoryController, a `world` link) run from its own Gazebo launch file at Gazebo's 1 ms step,
asked to go as fast as it can (/gazebo/set_physics_properties max_update_rate 0, as Gazebo users ask), following a
long trajectory with its joint states, /tf and the controller's state subscribed: RTF; bare PyBullet stepping
the same arm at the same step, its efforts from a PD on the same targets written every step; the ratio.

The effort arm is the case where no step can be skipped: gazebo_ros_control writes efforts every step (a torque
lasts one step), and the trajectory controller's PID runs at every update."""
import math
import os
import statistics
import time

from benchkit import probes
from benchkit.bare import load
from benchkit.common import ROOT
from benchkit.launching import Launch, subscriber
from benchkit.report import Item

from diffbot_sim.waiting import wait_for

FIXTURES = os.path.join(ROOT, "tests", "data", "manipulator_way")
ARM_XACRO = os.path.join(FIXTURES, "arm_cell_description", "urdf", "arm_cell.urdf.xacro")
NAMESPACE = "/my_arm"
JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
          "wrist_3_joint"]
#: Gazebo's default step, the arm cell's world's (it states none)
STEP = 0.001
#: the spawn's -J positions (rad): where both sides start
START = [0.0, -0.3, 1.2, 0.6, 0.0, 0.0]


def targets(t):
    """The arm's joint targets [rad] at time t [s]: slow sines about the start, every joint moving."""
    return [q + 0.3 * math.sin(0.5 * t + k) for k, q in enumerate(START)]


def _package_path():
    paths = [p for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    if FIXTURES not in paths:
        os.environ["ROS_PACKAGE_PATH"] = os.pathsep.join(paths + [FIXTURES])


def probe_fixed_arm(options):
    """Ask for as-fast-as-possible physics (max_update_rate 0) as a Gazebo user does, send a long trajectory on
    the arm controller's command topic, leave, and measure RTF as probe_rtf."""
    import rospy
    from gazebo_msgs.srv import GetPhysicsProperties, SetPhysicsProperties, SetPhysicsPropertiesRequest
    from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
    rospy.init_node("bench_fixed_arm", disable_signals=True)
    rospy.wait_for_service("/gazebo/set_physics_properties", 60)
    physics = rospy.ServiceProxy("/gazebo/get_physics_properties", GetPhysicsProperties)()
    request = SetPhysicsPropertiesRequest(time_step=physics.time_step, max_update_rate=0.0,
                                          gravity=physics.gravity, ode_config=physics.ode_config)
    if not rospy.ServiceProxy("/gazebo/set_physics_properties", SetPhysicsProperties)(request).success:
        raise RuntimeError("set_physics_properties refused max_update_rate 0")
    pub = rospy.Publisher(f"{NAMESPACE}/arm_controller/command", JointTrajectory, queue_size=1, latch=True)
    msg = JointTrajectory(joint_names=JOINTS)
    for k in range(1, int(round(options["trajectory_s"] / 0.1)) + 1):
        msg.points.append(JointTrajectoryPoint(positions=targets(k * 0.1),
                                               time_from_start=rospy.Duration.from_sec(k * 0.1)))
    wait_for(lambda: pub.get_num_connections() > 0, 60, "the arm controller's command topic")
    pub.publish(msg)
    time.sleep(0.5)  # written at once on the open connection; then leave, or fast mode would wait for this node
    pub.unregister()
    probes.probe_rtf(options)


def bare_fixed_arm(seconds):
    """The arm cell loaded as bullet_sim loads it (fixed base), at the 1 ms step, its efforts a PD on the same
    targets computed and written every step: the least Python an effort arm needs."""
    import pybullet

    from diffbot_sim.physics import World
    _package_path()
    text, parsed = load(ARM_XACRO)
    world = World(STEP)
    try:
        robot = world.load_robot(text, parsed)
        joints = robot.indices(JOINTS)
        robot.set_joint_positions(joints, START)
        robot.free_joints(joints)
        gains = [(150.0, 2.0)] * len(joints)
        client = world.client

        def step(t):
            states = pybullet.getJointStates(robot.body, joints, physicsClientId=client)
            efforts = [p * (q - s[0]) - d * s[1] for (p, d), q, s in zip(gains, targets(t), states)]
            pybullet.setJointMotorControlArray(robot.body, joints, pybullet.TORQUE_CONTROL, forces=efforts,
                                               physicsClientId=client)
            pybullet.stepSimulation(physicsClientId=client)
        for k in range(500):
            step(k * STEP)
        steps, start = 500, time.perf_counter()
        while time.perf_counter() - start < seconds:
            step(steps * STEP)
            steps += 1
        elapsed = time.perf_counter() - start
    finally:
        world.close()
    return {"rtf": (steps - 500) * STEP / elapsed}


def fixed_arm(seconds, repeats):
    """Simulator and bare PyBullet in back-to-back pairs; medians and the median of the pairs' ratios."""
    _package_path()
    runs = {"sim": [], "bare": [], "ratio": []}
    args = ["arm_cell_gazebo", "arm_cell.launch", "gui:=false", "paused:=false"]
    for _ in range(repeats):
        bare = bare_fixed_arm(seconds / 2)["rtf"]
        with Launch(args, "fixed_arm") as launch:
            for topic in (f"{NAMESPACE}/joint_states", "/tf", f"{NAMESPACE}/arm_controller/state"):
                subscriber(launch, [topic])
            sim = launch.probe("fixed_arm", seconds=seconds, warmup=3.0, leave=True, sim_node="/gazebo",
                               trajectory_s=30.0 * (seconds + 6.0))["rtf"]
        runs["bare"].append(bare)
        runs["sim"].append(sim)
        runs["ratio"].append(sim / bare)
    return {"rtf": statistics.median(runs["sim"]), "bare_rtf": statistics.median(runs["bare"]),
            "ratio": statistics.median(runs["ratio"]), "runs": runs}


def rows(r):
    if not r.get("fixed_arm"):
        return []
    a = r["fixed_arm"]
    return [("fast-mode RTF, 6-joint effort arm bolted to the world, 1 ms step", f"{a['rtf']:.1f}", ""),
            ("  / bare PyBullet, same arm, step and targets (median of pairs)", f"{a['ratio']:.2f}", ">= 0.5")]


ITEMS = [Item("fixed_arm", lambda q: fixed_arm(4 if q else 10, 1 if q else 3), rows)]
PROBES = {"fixed_arm": probe_fixed_arm}
