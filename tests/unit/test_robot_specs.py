"""config.py: the ~robots list (several namespaced robots in one simulator), frame prefixes, namespacing."""
import pytest

from diffbot_sim.config import (
    GazeboDiffDriveConfig,
    JointStateConfig,
    RobotSpec,
    SimConfig,
    place_in_namespace,
    prefix_frame,
    robot_specs,
)
from diffbot_sim.errors import ConfigError


def test_without_robots_the_single_robot_takes_model_and_pose_from_the_node():
    sim = SimConfig(model="/m.urdf", model_args="a:=1", x=1.0, y=2.0, z=0.1, yaw=0.5)
    (spec,) = robot_specs(sim, {})
    assert spec == RobotSpec(name="", model="/m.urdf", model_args="a:=1", x=1.0, y=2.0, z=0.1, yaw=0.5)


def test_names_and_dicts_mix():
    specs = robot_specs(SimConfig(), {"robots": ["robot1", {"name": "/robot2/", "x": 1, "yaw": 3.1,
                                                             "model": " /r2.urdf ", "tf_prefix": "/r2/"}]})
    assert [s.name for s in specs] == ["robot1", "robot2"]
    assert specs[1].x == 1.0 and specs[1].yaw == 3.1 and specs[1].model == "/r2.urdf"
    assert specs[1].tf_prefix == "r2" and specs[0].tf_prefix is None


def test_an_empty_robot_list_starts_an_empty_world():
    """empty_world.launch starts the simulator with ``~robots: []``: robots come from spawn_model."""
    assert robot_specs(SimConfig(), {"robots": []}) == []


@pytest.mark.parametrize("robots, culprit", [
    ("robot1", "~robots"),
    ([{"x": 1}], "~robots[0].name"),
    (["robot1", 3], "~robots[1]"),
    ([{"name": "1bad"}], "~robots[0].name"),
    ([{"name": "a b"}], "~robots[0].name"),
    ([{"name": "r", "colour": "red"}], "~robots[0].colour"),
    ([{"name": "r", "x": "far"}], "~robots[0].x"),
    ([{"name": "r", "yaw": float("nan")}], "~robots[0].yaw"),
    ([{"name": "r", "x": 0}, {"name": "r", "x": 1}], "~robots[1].name"),
    ([{"name": "r1"}, {"name": "r2"}], "~robots[1]"),  # same spawn position
])
def test_bad_robot_lists_name_the_entry(robots, culprit):
    with pytest.raises(ConfigError) as err:
        robot_specs(SimConfig(), {"robots": robots})
    assert err.value.name == culprit
    assert culprit in str(err.value)


def test_prefix_frame_follows_robot_state_publisher():
    assert prefix_frame("robot1", "odom") == "robot1/odom"
    assert prefix_frame("/robot1/", "/base_link") == "robot1/base_link"
    assert prefix_frame("", "odom") == "odom"


def test_a_named_robot_moves_its_endpoints_and_frames():
    drive = GazeboDiffDriveConfig(namespace="/", odometry_frame="odom")
    joints = JointStateConfig(joints=["a"], namespace="/")
    place_in_namespace(RobotSpec(name="robot1"), drive, joints)
    assert drive.namespace == "/robot1" and joints.namespace == "/robot1"
    assert (drive.odometry_frame, drive.robot_base_frame) == ("robot1/odom", "robot1/base_footprint")


def test_tf_prefix_overrides_and_empty_prefix_keeps_frames():
    drive = GazeboDiffDriveConfig()
    place_in_namespace(RobotSpec(name="robot1", tf_prefix="r1"), drive, None)
    assert drive.odometry_frame == "r1/odom"
    drive = GazeboDiffDriveConfig()
    place_in_namespace(RobotSpec(name="robot1", tf_prefix=""), drive, None)
    assert (drive.namespace, drive.odometry_frame) == ("/robot1", "odom")


def test_the_unnamed_robot_is_left_alone():
    drive = GazeboDiffDriveConfig(namespace="/ns")
    place_in_namespace(RobotSpec(), drive, None)
    assert (drive.namespace, drive.odometry_frame) == ("/ns", "odom")


def test_robots_without_a_model_share_the_node_model():
    sim = SimConfig(model="/m/robot.urdf.xacro", model_args="a:=1")
    specs = robot_specs(sim, {"robots": [{"name": "r1"}, {"name": "r2", "y": 1.0, "model": "/m/other.urdf"}]})
    assert (specs[0].model, specs[0].model_args) == ("/m/robot.urdf.xacro", "a:=1")
    assert (specs[1].model, specs[1].model_args) == ("/m/other.urdf", "a:=1")
