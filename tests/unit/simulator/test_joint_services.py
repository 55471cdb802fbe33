"""simulator.joint_services: gazebo_ros's joint services on fake robots (no master, no physics): which robot's
joint a name means, the effort jobs apply_joint_effort schedules (world_api.JointEffortSchedule, applied at the
time the coming step reaches) and what clear_joint_forces drops."""
import math
from types import SimpleNamespace

import genpy
import pytest
from gazebo_msgs import srv as gsrv

from diffbot_sim.gazebo.world_api import RequestError
from diffbot_sim.simulator.joint_services import JOINT_TYPES, JointServices

DT = 0.001


class Robot:
    """A physics robot as the services use it: joint indices, states, and the efforts set on it."""

    def __init__(self, joints):
        self.joint_index = {name: i for i, name in enumerate(joints)}
        self.efforts = []  # (indices, efforts) per call

    def set_efforts(self, indices, efforts):
        self.efforts.append((list(indices), list(efforts)))

    def joint_states(self, indices):
        return [0.25 * (i + 1) for i in indices], [-1.5 for _ in indices], [0.0 for _ in indices]


def runtime(name, joints, types=None):
    model = SimpleNamespace(joints={j: SimpleNamespace(type=(types or {}).get(j, "revolute")) for j in joints})
    return SimpleNamespace(name=name, ctx=SimpleNamespace(robot=Robot(joints), model=model))


class Api:
    """GazeboApi's side the services use: its sim (robots, sim time, call) and _run (errors raised here)."""

    def __init__(self, robots):
        self.cfg = SimpleNamespace(time_step=DT)
        self.sim = SimpleNamespace(robots=robots, sim_time=0.0, call=lambda action: action())

    def _run(self, action, response):
        response.status_message = action()
        return response


def effort(joint, value, start=0.0, duration=-1.0):
    return gsrv.ApplyJointEffortRequest(joint_name=joint, effort=value, start_time=genpy.Time.from_sec(start),
                                        duration=genpy.Duration.from_sec(duration))


@pytest.fixture
def arm():
    robot = runtime("arm", ["shoulder", "elbow"], {"elbow": "prismatic"})
    return JointServices(Api([robot])), robot.ctx.robot


def test_an_effort_applies_from_its_start_for_its_duration(arm):
    services, robot = arm
    services._apply(effort("elbow", 2.5, start=0.01, duration=0.005))
    services.before_step(0.01 - 2 * DT)  # the coming step reaches 0.009: not yet
    assert robot.efforts == []
    services.before_step(0.01 - DT)  # it reaches 0.010
    assert robot.efforts == [([1], [2.5])]
    services.before_step(0.015 - DT)  # the last step within start + duration
    services.before_step(0.015)
    assert len(robot.efforts) == 2 and len(services.efforts) == 0  # over, and dropped


def test_efforts_on_one_joint_add_up_and_a_start_in_the_past_is_now(arm):
    services, robot = arm
    services.api.sim.sim_time = 1.0
    services._apply(effort("shoulder", 1.0))  # start 0: now
    services._apply(effort("shoulder", 0.5, start=0.5, duration=10.0))
    services.before_step(1.0)
    assert robot.efforts == [([0], [1.0]), ([0], [0.5])]  # both pushed in the same step


def test_clear_drops_only_that_joints_jobs(arm):
    services, robot = arm
    services._apply(effort("shoulder", 1.0))
    services._apply(effort("elbow", 2.0))
    response = services._clear(gsrv.JointRequestRequest(joint_name="shoulder"))
    assert isinstance(response, gsrv.JointRequestResponse)
    services.before_step(0.0)
    assert robot.efforts == [([1], [2.0])]
    services._clear(gsrv.JointRequestRequest(joint_name="nothing"))  # always succeeds


def test_bad_requests_are_refused_with_upstreams_words(arm):
    services, _ = arm
    with pytest.raises(RequestError, match="ApplyJointEffort: joint not found"):
        services._apply(effort("wrist", 1.0))
    with pytest.raises(RequestError, match="ApplyJointEffort: effort is nan"):
        services._apply(effort("elbow", math.nan))
    with pytest.raises(RequestError, match="GetJointProperties: joint not found"):
        services._properties(gsrv.GetJointPropertiesRequest(joint_name="wrist"))
    assert len(services.efforts) == 0


def test_the_first_robot_with_the_joint_name_gets_it():
    first, second = runtime("r1", ["wheel"]), runtime("r2", ["wheel", "lift"])
    services = JointServices(Api([first, second]))
    services._apply(effort("wheel", 3.0))
    services._apply(effort("lift", 4.0))
    services.before_step(0.0)
    assert first.ctx.robot.efforts == [([0], [3.0])] and second.ctx.robot.efforts == [([1], [4.0])]


def test_efforts_of_a_deleted_robot_are_dropped_quietly(arm):
    services, robot = arm
    services._apply(effort("elbow", 1.0))
    services.api.sim.robots = []
    services.before_step(0.0)
    assert robot.efforts == []


def test_properties_give_the_joints_real_type_position_and_rate(arm):
    services, _ = arm
    response = services._properties(gsrv.GetJointPropertiesRequest(joint_name="elbow"))
    assert response.type == JOINT_TYPES["prismatic"] == gsrv.GetJointPropertiesResponse.PRISMATIC
    assert response.position == [0.5] and response.rate == [-1.5] and response.damping == []
    assert response.status_message == "GetJointProperties: got properties"
