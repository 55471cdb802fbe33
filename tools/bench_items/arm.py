"""Item ``arm``: a base with a 6-joint arm (tests/data/robots/mobile_arm6) following a long position trajectory in
fast mode, /joint_states, /tf, /odom and the controller's state subscribed: RTF; bare PyBullet stepping the same
model with the same joint targets; the ratio. Trajectory command -> first motion of the arm (sim time,
/gazebo/link_states), median of 20, at real time."""
import json
import math
import os
import statistics
import time

from benchkit import probes
from benchkit.bare import check_upright, load, wheel_speeds
from benchkit.common import CIRCLE, ROBOTS, STEP
from benchkit.launching import Launch, sim_args, subscriber
from benchkit.report import Item

from diffbot_sim.waiting import wait_for

ARM_MODEL = os.path.join(ROBOTS, "mobile_arm6.urdf.xacro")
ARM_YAML = os.path.join(ROBOTS, "mobile_arm6.yaml")
ARM_JOINTS = [f"joint_{k}" for k in range(1, 7)]
#: (wheel radius, wheel separation) [m] of mobile_arm6, as its diff drive plugin reads them
ARM_WHEELS = (0.032, 0.2)


def arm_targets(t):
    """The arm's joint targets [rad] at time t [s]: slow sines, every joint moving."""
    return [0.6 * math.sin(0.5 * t + k) for k in range(6)]


def probe_arm_motion(options):
    """Send a long trajectory (``trajectory_s`` of sim time, points every 0.1 s) on /arm_controller/command, then
    measure RTF as probe_rtf. With ``leave``, the probe closes its command publishers once they were sent (fast
    mode waits after each /clock tick for nodes that publish commands: staying, the probe measured itself)."""
    import rospy
    from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
    rospy.init_node("bench_arm", disable_signals=True)
    pub = rospy.Publisher("/arm_controller/command", JointTrajectory, queue_size=1, latch=True)
    msg = JointTrajectory(joint_names=ARM_JOINTS)
    for k in range(1, int(round(options.get("trajectory_s", 60.0) / 0.1)) + 1):
        msg.points.append(JointTrajectoryPoint(positions=arm_targets(k * 0.1),
                                               time_from_start=rospy.Duration.from_sec(k * 0.1)))
    wait_for(lambda: pub.get_num_connections() > 0, 60, "the trajectory controller's command topic")
    pub.publish(msg)
    if options.get("leave"):
        time.sleep(0.5)  # written at once on the open connection; the controller keeps a trajectory it was sent
        pub.unregister()
    probes.probe_rtf(options)


def _tip(msg):
    for name, pose in zip(msg.name, msg.pose):
        if name.endswith("::link_6"):
            return (pose.position.x, pose.position.y, pose.position.z)
    raise RuntimeError("no link_6 in link_states")


def probe_arm_latency(options):
    """Trajectory command -> first motion: sim time from the command's start (the next control update after
    its receipt: stamp 0) to the first /gazebo/link_states where the arm's last link has moved 1 mm."""
    import rospy
    from gazebo_msgs.msg import LinkStates
    from rosgraph_msgs.msg import Clock
    from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
    rospy.init_node("bench_arm_latency", disable_signals=True)
    states = []
    clock = []
    # link_states carry no stamp: each is stamped with the newest /clock (100 Hz: a 10 ms resolution)
    rospy.Subscriber("/gazebo/link_states", LinkStates, lambda m: states.append((clock[-1] if clock else 0.0, m)),
                     queue_size=2000)
    rospy.Subscriber("/clock", Clock, lambda m: clock.append(m.clock.to_sec()), queue_size=10)
    pub = rospy.Publisher("/arm_controller/command", JointTrajectory, queue_size=1)
    wait_for(lambda: pub.get_num_connections() > 0 and clock and states, 60, "the arm and link_states")
    delays = []
    for trial in range(options["count"]):
        target = 0.3 if trial % 2 == 0 else -0.3
        time.sleep(0.5)
        before = _tip(states[-1][1])
        sent = clock[-1]
        msg = JointTrajectory(joint_names=ARM_JOINTS)
        msg.points.append(JointTrajectoryPoint(positions=[target] * 6, time_from_start=rospy.Duration(1.0)))
        pub.publish(msg)
        wait_for(lambda before=before: math.dist(_tip(states[-1][1]), before) > 0.001, 30, "the arm moving")
        moved = next(t for t, m in states if t >= sent and math.dist(_tip(m), before) > 0.001)
        delays.append(moved - sent)
    print(json.dumps({"command_to_motion_median_s": statistics.median(delays), "max_s": max(delays),
                      "trials": len(delays)}), flush=True)


def bare_arm(seconds):
    """mobile_arm6 loaded as bullet_sim loads it, joints as the position trajectory drives them (stiff position
    motors, targets renewed every 10 ms), wheels turning, stepped by PyBullet alone."""
    from diffbot_sim.physics import World
    text, parsed = load(ARM_MODEL)
    world = World(STEP)
    try:
        robot = world.load_robot(text, parsed)
        joints = robot.indices(ARM_JOINTS)
        wheels = robot.indices(["left_wheel_joint", "right_wheel_joint"])
        # Set going as the simulator does it, or the robot falls over (an earlier version of this reference did:
        # full wheel speed and the arm's first targets at once tipped it on its side within 2 s, and a robot on
        # its side steps at twice the speed): the circle's wheel speeds reached at the plugin's 1.8 m/s^2, the
        # arm blended in from rest over the first second, as its trajectory controller starts it.
        speeds = wheel_speeds(CIRCLE, ARM_WHEELS[1], ARM_WHEELS[0])
        ramp = CIRCLE[0] / 1.8

        def command(t):
            share = min(1.0, t / ramp)
            robot.set_velocities(wheels, [share * v for v in speeds], [30.0, 30.0])
            blend = min(1.0, t)
            robot.set_positions(joints, [blend * q for q in arm_targets(t)], [1e4] * 6, 1.0)
        for k in range(480):
            command(k * STEP)
            world.step()
        steps, start = 480, time.perf_counter()
        while time.perf_counter() - start < seconds:
            if steps % 2 == 0:
                command(steps * STEP)
            world.step()
            steps += 1
        elapsed = time.perf_counter() - start
        check_upright(robot, "mobile arm")
    finally:
        world.close()
    return {"rtf": (steps - 480) * STEP / elapsed}


def arm(seconds, repeats):
    runs = {"sim": [], "bare": []}
    args = sim_args("real_time:=false", f"model:={ARM_MODEL}", f"controllers:={ARM_YAML}",
                    "robot_state_publisher:=false")
    for _ in range(repeats):
        runs["bare"].append(bare_arm(seconds / 2)["rtf"])
        with Launch(args, "arm") as launch:
            for topic in ("/joint_states", "/tf", "/odom", "/arm_controller/state"):
                subscriber(launch, [topic])
            # the trajectory outlasts the window (4 s of warm-up and leaving + the window, at up to RTF 60)
            runs["sim"].append(launch.probe("arm_motion", seconds=seconds, warmup=3.0, leave=True,
                                            trajectory_s=60.0 * (seconds + 4.0))["rtf"])
    with Launch(sim_args(f"model:={ARM_MODEL}", f"controllers:={ARM_YAML}", "robot_state_publisher:=false"),
                "arm_latency") as launch:
        latency = launch.probe("arm_latency", count=20, timeout=300)
    sim, bare = statistics.median(runs["sim"]), statistics.median(runs["bare"])
    return {"rtf": sim, "bare_rtf": bare, "ratio": sim / bare, "runs": runs, **latency}


def rows(r):
    if not r.get("arm"):
        return []
    a = r["arm"]
    return [("fast-mode RTF, base + 6-joint arm on a trajectory", f"{a['rtf']:.1f}", ">= 30"),
            ("  / bare PyBullet, same model and targets", f"{a['ratio']:.2f}", ">= 0.5"),
            ("  trajectory command -> first motion (sim, median)", f"{a['command_to_motion_median_s'] * 1000:.1f} ms",
             "<= 10 ms (one control period)")]


ITEMS = [Item("arm", lambda q: arm(4 if q else 10, 1 if q else 3), rows)]
PROBES = {"arm_motion": probe_arm_motion, "arm_latency": probe_arm_latency}
