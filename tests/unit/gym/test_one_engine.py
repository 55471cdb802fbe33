"""One engine, two front ends: the same model driven with the same commands through bullet_sim's path and
through the Gymnasium scene moves along the same trajectory, to the bit.

bullet_sim's side is its own code with no master: the robot is built by ``simulator.robots._build_robot`` (the
model read and placed, every plugin made by the registry from the model's tags, as at start-up) and run in
the loop's order (every robot's ``before_step``, the physics step, ``after_step`` when a publication is due,
as ``Simulator._step_once``); commands arrive through the diff drive's ``cmd_vel`` callback as a rospy
message. Only what needs a master is stood in for: the ROS endpoints (a publisher with no subscriber, a
subscriber whose callback the test calls) and the Simulator object's few fields the plugins use.

Both worlds start alike: the gym scene lets its robot land with its wheels braked before an episode
(``physics.robot_loading.settle``); bullet_sim's robot is reset (wheels braked) and settled the same way
here, since bullet_sim itself lands it while its sim time runs. From there the trajectories must be equal:
the command timeout (bullet_sim's ``~cmd_vel_timeout``, the gym's ``cmd_vel_timeout``) brakes in both, a
non-finite command is dropped in both, and the acceleration limit and update schedule are the plugin's.
"""
import math
import os
import threading

import pytest
import rospy
from geometry_msgs.msg import Twist

from diffbot_sim import config as cfgmod
from diffbot_sim.description import meshes
from diffbot_sim.gym.goal_env import goal_config
from diffbot_sim.gym.scene import Scene
from diffbot_sim.physics import World
from diffbot_sim.physics.robot_loading import settle
from diffbot_sim.plugins.base import RobotContext
from diffbot_sim.simulator import robots as sim_robots
from diffbot_sim.world.loading import load_world

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
MODEL = os.path.join(ROOT, "urdf", "diffbot_laser.urdf.xacro")  # ~model: a path, as bullet_sim takes it
WORLD = os.path.join(ROOT, "worlds", "room.world")
TIMEOUT = 0.105  # s: shorter than a control period (0.2 s), ending between two of the plugin's 100 Hz updates
STEPS = 48  # physics steps a command is held (one control period of 1/240 s steps)
#: (linear.x, angular.z) commands, each held for STEPS steps: drive, turn, a stale command braked by the
#: timeout, a non-finite one dropped (the previous one holds, and goes stale again), reverse, stop.
COMMANDS = [(0.15, 0.0), (0.15, 0.75), (0.3, -1.5), (math.nan, 0.0), (-0.1, 0.5), (0.0, 0.0), (0.2, 0.0)]


class Endpoint:
    """A rospy publisher or subscriber without a master: nobody listens; a subscriber keeps its callback."""

    def __init__(self, name, callback=None):
        self.resolved_name, self.callback = name, callback

    def get_num_connections(self):
        return 0

    def publish(self, msg):
        pass

    def unregister(self):
        pass


class Loop:
    """What the plugins and ``_build_robot`` use of ``simulator.loop.Simulator``, and its per-step order."""

    def __init__(self, world, cfg):
        self.world, self.cfg = world, cfg
        self.wake = threading.Event()
        self.robots, self.steps, self.warnings = [], 0, []

    @property
    def sim_time(self):
        return self.steps * self.cfg.time_step

    def warn(self, key, text):
        self.warnings.append(text)

    def add_robot(self, runtime, now=None):
        self.robots.append(runtime)
        if now is not None:
            runtime.start(now)

    def step(self):
        """``Simulator._step_once`` for the robots."""
        now = self.sim_time
        for runtime in self.robots:
            runtime.before_step(now)
        self.world.step()
        self.steps += 1
        now = self.sim_time
        if any(now + 1e-9 >= runtime.next_publish() for runtime in self.robots):
            for runtime in self.robots:
                runtime.after_step(now, rospy.Time.from_sec(now), [])


@pytest.fixture
def endpoints(monkeypatch):
    """The robot's subscribers by topic name (publishers and services go nowhere)."""
    subscribers = {}

    def subscriber(ctx, name, msg_class, callback, **kwargs):
        subscribers[name] = ctx._own(Endpoint(name, callback))
        return subscribers[name]
    monkeypatch.setattr(RobotContext, "subscriber", subscriber)
    monkeypatch.setattr(RobotContext, "publisher", lambda ctx, name, msg_class: ctx._own(Endpoint(name)))
    monkeypatch.setattr(RobotContext, "service", lambda ctx, name, srv, handler: ctx._own(Endpoint(name)))
    return subscribers


def pose_and_wheels(robot):
    """The root link's pose and twist, and every wheel joint's position and velocity: the trajectory's sample."""
    pose = robot.base_pose()
    positions, velocities, _ = robot.joint_states(robot.indices(["left_wheel_joint", "right_wheel_joint"]))
    return pose, robot.base_twist(pose), tuple(positions), tuple(velocities)


def through_bullet_sim(endpoints, timeout):
    """The trajectory (one sample per command) of the model in bullet_sim: its world, robot and plugins."""
    cfg = cfgmod.SimConfig(model=MODEL, world=WORLD, real_time=False, cmd_vel_timeout=timeout)
    description = load_world(cfg.world, cfg.map_wall_height)
    # the step given, as sim.launch gives bullet_sim its ~time_step (unset, a Gazebo world's own step rules)
    sim_robots.apply_world_physics(cfg, description, {"time_step": cfg.time_step})
    world = World(cfg.time_step, cfg.gravity)
    try:
        world.load_world(description, meshes.default_cache_dir())
        loop = Loop(world, cfg)
        (spec,) = cfgmod.robot_specs(cfg, {})
        built = sim_robots._build_robot(loop, cfg, spec, {})
        runtime, robot = built.runtime, built.runtime.ctx.robot
        runtime.reset(0.0)  # the wheels braked, as the scene lands its robot
        settle(world, robot)
        runtime.start(0.0)
        cmd_vel = endpoints["/cmd_vel"].callback
        samples = []
        for linear, angular in COMMANDS:
            msg = Twist()
            msg.linear.x, msg.angular.z = linear, angular
            cmd_vel(msg)
            for _ in range(STEPS):
                loop.step()
            samples.append(pose_and_wheels(robot))
        return samples, loop
    finally:
        world.close()


def through_gym(timeout):
    """The same through the Gymnasium scene (the environment's stepping, without its reward and resets)."""
    scene = Scene(goal_config(model=MODEL, world=WORLD, cmd_vel_timeout=timeout))
    try:
        samples = []
        for linear, angular in COMMANDS:
            assert not scene.advance(linear, angular, STEPS)  # touched nothing: every step was taken
            samples.append(pose_and_wheels(scene.robot))
        return samples
    finally:
        scene.close()


def test_the_same_commands_give_the_same_trajectory_in_both_front_ends(endpoints):
    ros, loop = through_bullet_sim(endpoints, TIMEOUT)
    gym = through_gym(TIMEOUT)
    assert any("non-finite" in text for text in loop.warnings)  # the NaN command reached the plugin, and was dropped
    moved = [math.dist(a[0][0], b[0][0]) for a, b in zip(ros, ros[1:])]
    assert min(moved[:2]) > 0.01  # the robot drove
    assert ros == gym  # bit for bit: pose, twist, wheel angles and speeds after every command


def test_the_timeout_brakes_in_both_front_ends(endpoints):
    """The trajectories differ with and without the timeout: the test above would see one front end lose it."""
    ros, _ = through_bullet_sim(endpoints, TIMEOUT)
    held = through_gym(0.0)
    assert ros[0] != held[0]
    # braked after 0.105 s of each 0.2 s command: the wheels stand still at the end of the period
    assert all(abs(v) < 0.5 for v in ros[0][3])
    assert all(abs(v) > 4.0 for v in held[0][3])
