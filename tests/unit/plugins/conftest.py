"""A ros_control rig without a ROS master: one of the fixture arms (tests/data/robots/arm_*.urdf) in a PyBullet
DIRECT world, its controller YAML as the parameter server (``get_param`` of the modules under test reads it), and
a robot context whose ROS endpoints are recorded instead of registered (rospy's Publisher, Subscriber and Service
objects are not made: nothing here talks to a master)."""
import os
from types import SimpleNamespace

import pytest
import yaml

from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.physics import World
from diffbot_sim.plugins.base import RobotContext

ROBOTS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "data",
                      "robots")
DT = 1.0 / 240.0


def parameter_server(tree):
    """``get_param(name, default)`` over ``tree`` (nested dicts, as ``rosparam load`` puts a YAML at ``/``)."""
    def get_param(name, default):
        node = tree
        for part in [p for p in name.split("/") if p]:
            if not isinstance(node, dict) or part not in node:
                return default
            node = node[part]
        return node
    return get_param


class Endpoint:
    """A recorded publisher, subscriber or service: its name, and what a test publishes or calls through it."""

    def __init__(self, kind, name, msg_class, callback=None):
        self.kind, self.name, self.resolved_name, self.msg_class = kind, name, name, msg_class
        self.callback = callback
        self.published = []
        self.closed = False

    def publish(self, msg):
        self.published.append(msg)

    def get_num_connections(self):
        return 1  # somebody listens: controllers build what they would publish

    def unregister(self):
        self.closed = True


class RecordingContext(RobotContext):
    """A RobotContext whose endpoints are :class:`Endpoint` records (``endpoints``: name -> Endpoint)."""

    def __post_init__(self):
        super().__post_init__()
        self.endpoints = {}
        self.released = []

    def _record(self, endpoint):
        self.endpoints[endpoint.name] = endpoint
        return self._own(endpoint)

    def publisher(self, name, msg_class):
        return self._record(Endpoint("publisher", name, msg_class))

    def subscriber(self, name, msg_class, callback, **kwargs):
        return self._record(Endpoint("subscriber", name, msg_class, callback))

    def service(self, name, srv_class, handler):
        return self._record(Endpoint("service", name, srv_class, handler))

    def release(self, handle):
        self.released.append(handle.name)
        if handle in self.handles:
            self.handles.remove(handle)
        handle.closed = True


class Sim:
    """The simulator as plugins see it: sim time, ``call``/``post`` run at once (the test is the loop)."""

    def __init__(self, world):
        self.world = world
        self.sim_time = 0.0
        self.paused = False
        self.wake = SimpleNamespace(set=lambda: None)
        self.warned = []

    def call(self, action, timeout=None):
        return action()

    def post(self, action):
        action()

    def warn(self, key, text):
        self.warned.append(text)


class ArmRig:
    """One fixture arm standing on the ground; on the 'parameter server' its YAML (unless ``use_yaml`` is false)
    updated with ``params``."""

    def __init__(self, name, params=None, use_yaml=True):
        path = os.path.join(ROBOTS, f"{name}.urdf")
        text = open(path).read()
        self.model = parse_urdf(text, path)
        self.world = World(DT)
        self.robot = self.world.load_robot(text, self.model)
        yaml_path = os.path.join(ROBOTS, f"{name}.yaml")
        self.params = (yaml.safe_load(open(yaml_path)) or {}) if use_yaml and os.path.exists(yaml_path) else {}
        self.params.update(params or {})
        self.sim = Sim(self.world)
        cfg = SimpleNamespace(time_step=DT, autostart_controllers=False)
        self.ctx = RecordingContext(sim=self.sim, cfg=cfg, spec=SimpleNamespace(name="", tf_prefix=None),
                                    model=self.model, robot=self.robot, params={}, namespace=None, private="~")

    def joint(self, name):
        """(position, velocity) of joint ``name`` as the physics has it (ground truth, not the hardware's)."""
        positions, velocities, _ = self.robot.joint_states([self.robot.joint_index[name]])
        return positions[0], velocities[0]

    def close(self):
        self.world.close()


@pytest.fixture
def arm_rig():
    """``arm_rig(name, params=None, use_yaml=True)`` -> an :class:`ArmRig`, closed after the test."""
    made = []

    def make(name, params=None, use_yaml=True):
        made.append(ArmRig(name, params, use_yaml))
        return made[-1]
    yield make
    for rig in made:
        rig.close()
