"""Items ``fixed_arm`` and ``fixed_arm_cell``: a 6-joint effort arm bolted to the world, run from its own Gazebo
launch file at Gazebo's 1 ms step, asked to go as fast as it can (/gazebo/set_physics_properties max_update_rate
0, as Gazebo users ask), following a long trajectory on its effort JointTrajectoryController's command topic with
its joint states, /tf and the controller's state subscribed: RTF; bare PyBullet stepping the same arm at the same
step, its efforts from a PD with the controller's gains on the same targets, computed and written every step;
the ratio, in back-to-back pairs.

``fixed_arm`` is issue 40's arm: tests/data/arm_way's UR5-like arm (ur_gazebo's shape: UR5's links and
published effort gains, no gripper, the controller manager at the root namespace, state at 125 Hz), spawned
0.1 m up with its joints at 0 and led to the trajectory's start in 2 s. ``fixed_arm_cell`` (run with it) is
tests/data/manipulator_way's arm cell: the same kind of arm with a gripper, whose finger is a POSITION_PID
joint of the same hardware and whose three mimic joints each have a mimic plugin with a PID, and gazebo_grasp_fix
gathering the fingers' contacts every step; in the robot's namespace.

The effort arm is the case where no step can be skipped: gazebo_ros_control writes efforts every step (a torque
lasts one step), and the trajectory controller's PID runs at every update. Beside the RTFs, each side's CPU time
per sim second (the simulator's process, all its threads; bare PyBullet's process) gives ``cpu_ratio``, which a
busy machine sways less than the RTFs: both sides then wait for a core, the simulator with its ROS nodes more."""
import math
import os
import statistics
import time
from dataclasses import dataclass

import yaml
from benchkit import probes
from benchkit.bare import load
from benchkit.common import ROOT
from benchkit.launching import Launch, subscriber
from benchkit.report import Item

from diffbot_sim.waiting import wait_for

DATA = os.path.join(ROOT, "tests", "data")
JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
          "wrist_3_joint"]
#: Gazebo's default step, the step of both arms' worlds (they state none)
STEP = 0.001


@dataclass(frozen=True)
class FixedArm:
    """One arm of the item: its fixture packages, launch, controller and where the probe finds them."""

    packages: str  # the folder of its fixture packages, put on ROS_PACKAGE_PATH
    xacro: str  # its description, relative to ``packages``
    controllers: str  # its controller YAML, relative to ``packages``
    controller: str  # the effort trajectory controller's name in that YAML
    namespace: str  # the controller manager's namespace ("" at the root)
    launch: tuple  # roslaunch package, file and arguments
    spawn_z: float  # m: where the launch spawns the model (its world joint holds it there)
    start: tuple  # rad: the joints' middle positions, the sines' centre, clear of the ground
    lead_in: float  # s to reach the trajectory's start from where the spawn leaves the arm (0: spawned there)

    def path(self, relative):
        return os.path.join(self.packages, relative)

    def topics(self):
        """What a user watches: joint states, /tf, the controller's state."""
        return [f"{self.namespace}/joint_states", "/tf", f"{self.namespace}/{self.controller}/state"]

    def gains(self):
        """The controller's (p, d) per joint, for bare PyBullet's PD."""
        with open(self.path(self.controllers)) as f:
            params = yaml.safe_load(f)[self.controller]["gains"]
        return [(float(params[j]["p"]), float(params[j].get("d", 0.0))) for j in JOINTS]


ARMS = {
    "fixed_arm": FixedArm(os.path.join(DATA, "arm_way"), "ur5like_gazebo/urdf/ur5like.xacro",
                          "ur5like_gazebo/config/ur5like_controllers.yaml", "eff_joint_traj_controller", "",
                          ("ur5like_gazebo", "ur5like_bringup.launch", "gui:=false", "paused:=false"), 0.1,
                          (0.0, -1.3, 1.3, -1.57, -1.57, 0.0), 2.0),
    "fixed_arm_cell": FixedArm(os.path.join(DATA, "manipulator_way"), "arm_cell_description/urdf/arm_cell.urdf.xacro",
                               "arm_cell_gazebo/config/arm_cell_controllers.yaml", "arm_controller", "/my_arm",
                               ("arm_cell_gazebo", "arm_cell.launch", "gui:=false", "paused:=false"), 0.0,
                               (0.0, -0.3, 1.2, 0.6, 0.0, 0.0), 0.0),  # its spawn -J positions
}


def targets(start, t):
    """The arm's joint targets [rad] at time t [s]: slow sines about ``start``, every joint moving."""
    return [q + 0.3 * math.sin(0.5 * t + k) for k, q in enumerate(start)]


def trajectory_points(start, seconds, lead_in):
    """(time_from_start [s], positions) every 0.1 s for ``seconds``; after a ``lead_in`` to the first target when
    the arm does not start there."""
    points = [(lead_in, targets(start, 0.0))] if lead_in else []
    return points + [(lead_in + k * 0.1, targets(start, k * 0.1)) for k in range(1, int(round(seconds / 0.1)) + 1)]


def _package_path():
    """Both arms' fixture folders on ROS_PACKAGE_PATH (for this process's xacro and the launches), at once: rospkg
    keeps the packages it found the first time."""
    paths = [p for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    os.environ["ROS_PACKAGE_PATH"] = os.pathsep.join(paths + sorted({a.packages for a in ARMS.values()} - set(paths)))


def probe_fixed_arm(options):
    """Ask for as-fast-as-possible physics (max_update_rate 0) as a Gazebo user does, send a long trajectory on
    the controller's ``command`` topic, leave, and measure RTF as probe_rtf."""
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
    pub = rospy.Publisher(options["command"], JointTrajectory, queue_size=1, latch=True)
    msg = JointTrajectory(joint_names=JOINTS)
    for t, positions in trajectory_points(options["start"], options["trajectory_s"], options.get("lead_in", 0.0)):
        msg.points.append(JointTrajectoryPoint(positions=positions, time_from_start=rospy.Duration.from_sec(t)))
    wait_for(lambda: pub.get_num_connections() > 0, 60, "the arm controller's command topic")
    pub.publish(msg)
    time.sleep(0.5)  # written at once on the open connection; then leave, or fast mode would wait for this node
    pub.unregister()
    probes.probe_rtf(options)


def bare_fixed_arm(arm, seconds):
    """The arm loaded as bullet_sim loads it (fixed base), at the 1 ms step, its efforts a PD with the controller's
    gains on the same targets, computed and written every step: the least Python an effort arm needs. RTF, and
    CPU seconds per sim second."""
    import pybullet

    from diffbot_sim.physics import World
    _package_path()
    text, parsed = load(arm.path(arm.xacro))
    world = World(STEP)
    try:
        robot = world.load_robot(text, parsed, position=(0.0, 0.0, arm.spawn_z))
        joints = robot.indices(JOINTS)
        robot.set_joint_positions(joints, arm.start)
        robot.free_joints(joints)
        gains = arm.gains()
        client = world.client

        def step(t):
            states = pybullet.getJointStates(robot.body, joints, physicsClientId=client)
            efforts = [p * (q - s[0]) - d * s[1] for (p, d), q, s in zip(gains, targets(arm.start, t), states)]
            pybullet.setJointMotorControlArray(robot.body, joints, pybullet.TORQUE_CONTROL, forces=efforts,
                                               physicsClientId=client)
            pybullet.stepSimulation(physicsClientId=client)
        for k in range(500):
            step(k * STEP)
        steps, start, cpu = 500, time.perf_counter(), time.process_time()
        while time.perf_counter() - start < seconds:
            step(steps * STEP)
            steps += 1
        elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu
    finally:
        world.close()
    sim_s = (steps - 500) * STEP
    return {"rtf": sim_s / elapsed, "cpu_per_sim_s": cpu / sim_s}


def fixed_arm(name, seconds, repeats):
    """Simulator and bare PyBullet in back-to-back pairs; medians and the medians of the pairs' ratios."""
    arm = ARMS[name]
    _package_path()
    runs = {"sim": [], "bare": [], "ratio": [], "sim_cpu": [], "bare_cpu": [], "cpu_ratio": []}
    for _ in range(repeats):
        bare = bare_fixed_arm(arm, seconds / 2)
        with Launch(list(arm.launch), name) as launch:
            for topic in arm.topics():
                subscriber(launch, [topic])
            sim = launch.probe("fixed_arm", seconds=seconds, warmup=3.0, leave=True, sim_node="/gazebo",
                               command=f"{arm.namespace}/{arm.controller}/command", start=arm.start,
                               lead_in=arm.lead_in,
                               trajectory_s=30.0 * (seconds + 6.0))
        sim_cpu = sim["cpu_percent"] / 100.0 / sim["rtf"]  # CPU seconds per sim second
        for key, value in (("sim", sim["rtf"]), ("bare", bare["rtf"]), ("ratio", sim["rtf"] / bare["rtf"]),
                           ("sim_cpu", sim_cpu), ("bare_cpu", bare["cpu_per_sim_s"]),
                           ("cpu_ratio", bare["cpu_per_sim_s"] / sim_cpu)):
            runs[key].append(value)
    return {"rtf": statistics.median(runs["sim"]), "bare_rtf": statistics.median(runs["bare"]),
            "ratio": statistics.median(runs["ratio"]), "cpu_ratio": statistics.median(runs["cpu_ratio"]),
            "runs": runs}


def _rows(name, what):
    def rows(r):
        if not r.get(name):
            return []
        a = r[name]
        return [(f"fast-mode RTF, {what}, bolted to the world, 1 ms step", f"{a['rtf']:.1f}", ""),
                ("  / bare PyBullet, same arm, step and targets (median of pairs)", f"{a['ratio']:.2f}", ">= 0.5"),
                ("  the same by CPU time per sim second (bare's / the simulator's)", f"{a['cpu_ratio']:.2f}", "")]
    return rows


ITEMS = [Item("fixed_arm", lambda q: fixed_arm("fixed_arm", 4 if q else 10, 1 if q else 3),
              _rows("fixed_arm", "6-joint effort arm (UR5-like, effort trajectory controller)")),
         Item("fixed_arm_cell", lambda q: fixed_arm("fixed_arm_cell", 4 if q else 10, 1 if q else 3),
              _rows("fixed_arm_cell", "the arm cell (6 effort joints, gripper: 3 mimic PIDs, grasp fix)"),
              part_of="fixed_arm")]
PROBES = {"fixed_arm": probe_fixed_arm}
