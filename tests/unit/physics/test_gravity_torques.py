"""Robot.gravity_torques: the joint torques that hold a body still against gravity (PyBullet's inverse dynamics
at rest), judged by the body: the franka_way fixture arm (7 joints, a hand lumped onto link7, two fingers) under
exactly those torques stays where it is; without them it falls; a payload's weight is held as a force at its
point."""
import math
import os

import pytest

from diffbot_sim.description.model_files import load_file
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.physics import World
from diffbot_sim.transforms import compose, rotate

FRANKA_WAY = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "data",
                          "franka_way")
ARM = [f"panda_joint{i}" for i in range(1, 8)]
START = [0.0, -0.785398163, 0.0, -2.35619449, 0.0, 1.57079632679, 0.785398163397]
DT = 0.001


@pytest.fixture
def arm():
    os.environ["ROS_PACKAGE_PATH"] = os.pathsep.join(filter(None, [os.environ.get("ROS_PACKAGE_PATH"), FRANKA_WAY]))
    text = load_file(os.path.join(FRANKA_WAY, "pandalike_description", "robots", "pandalike.urdf.xacro"),
                     {"gazebo": "true"})
    text = text if isinstance(text, str) else text[0]
    world = World(DT)
    robot = world.load_robot(text, parse_urdf(text, "pandalike"))
    robot.set_joint_positions(robot.indices(ARM), START)
    return world, robot


def hold(world, robot, seconds, torques):
    indices = robot.indices(ARM)
    start = robot.link_pose("panda_hand_tcp")[0]
    for _ in range(round(seconds / DT)):
        robot.set_efforts(indices, torques(indices))
        world.step()
    return math.dist(start, robot.link_pose("panda_hand_tcp")[0])


def test_the_arm_holds_still_under_its_gravity_torques_and_falls_without(arm):
    world, robot = arm
    assert hold(world, robot, 1.0, robot.gravity_torques) < 1e-6
    assert hold(world, robot, 0.3, lambda indices: [0.0] * len(indices)) > 0.05


def test_a_payloads_weight_is_held_at_its_point(arm):
    _, robot = arm
    bare = robot.gravity_torques(robot.indices(ARM))
    loaded = robot.gravity_torques(robot.indices(ARM), ("panda_link8", (0.0, 0.0, 0.1), 1.0))
    point = compose(robot.link_pose("panda_link8"), ((0.0, 0.0, 0.1), (0.0, 0.0, 0.0, 1.0)))[0]
    weight = (0.0, 0.0, 1.0 * robot.gravity)
    for k, name in enumerate(ARM):  # each joint holds the moment of the weight about its axis (link k's z)
        origin, orientation = robot.link_pose(f"panda_link{k + 1}")
        axis = rotate(orientation, (0.0, 0.0, 1.0))
        arm = [p - o for p, o in zip(point, origin)]
        moment = [arm[1] * weight[2] - arm[2] * weight[1], arm[2] * weight[0] - arm[0] * weight[2],
                  arm[0] * weight[1] - arm[1] * weight[0]]
        assert loaded[k] - bare[k] == pytest.approx(-sum(m * a for m, a in zip(moment, axis)), abs=1e-6), name
    assert abs(loaded[3] - bare[3]) > 1.0  # the elbow carries most of it
