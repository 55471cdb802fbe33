"""simulator.robots' tf_prefix of a spawned robot, as Noetic's gazebo_ros plugins find it: searchParam
("tf_prefix") upward from the robot's namespace, no fallback to the namespace (parameters faked: no master)."""
import pytest

from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.simulator import robots


@pytest.fixture
def params(monkeypatch):
    """The parameter server, as a dict robots.get_param reads."""
    server = {}
    monkeypatch.setattr(robots, "get_param", lambda name, default: server.get(name, default))
    return server


@pytest.mark.parametrize("server, namespace, prefix", [
    ({}, "/robot1", ""),  # none set: none (Noetic, gazebo_ros_pkgs #1143/#1173: no fallback)
    ({"/robot1/tf_prefix": "robot1"}, "/robot1", "robot1"),
    ({"/robot1/tf_prefix": "/robot1/"}, "robot1", "robot1"),  # slashes stripped, relative namespace
    ({"/tf_prefix": "all"}, "/fleet/robot1", "all"),  # found upward
    ({"/tf_prefix": "all", "/fleet/tf_prefix": "fleet"}, "/fleet/robot1", "fleet"),  # the nearest wins
    ({"/fleet/robot1/tf_prefix": "", "/tf_prefix": "all"}, "/fleet/robot1", ""),  # set empty: found, empty
    ({"/robot2/tf_prefix": "robot2"}, "/robot1", ""),  # a sibling's is not searched
    ({"/tf_prefix": "all"}, "", "all"),
    ({"/robot1/tf_prefix": 7}, "/robot1", "7"),
])
def test_search_tf_prefix_is_roscpps_search_param(params, server, namespace, prefix):
    params.update(server)
    assert robots.search_tf_prefix(namespace) == prefix


def spawned(namespace_tags):
    plugins = "".join(f"<gazebo><plugin name='p{i}' filename='libgazebo_ros_diff_drive.so'>{tag}</plugin></gazebo>"
                      for i, tag in enumerate(namespace_tags))
    return parse_urdf(f"<robot name='r'><link name='base_link'/>{plugins}</robot>", "spawned.urdf")


def test_a_spawned_robot_searches_from_its_first_robot_namespace(params):
    params.update({"/r1/tf_prefix": "one", "/r2/tf_prefix": "two"})
    model = spawned(["<robotNamespace></robotNamespace>", "<robotNamespace>/r1</robotNamespace>",
                     "<robotNamespace>/r2</robotNamespace>"])
    assert robots._spawned_tf_prefix(model) == "one"



def test_a_spawned_robot_without_a_namespace_searches_from_the_root(params):
    """The plugins' node handle is then the root's: roscpp's searchParam finds /tf_prefix (none set: none)."""
    model = spawned(["", "<robotNamespace></robotNamespace>"])
    assert robots._spawned_tf_prefix(model) == ""
    params.update({"/tf_prefix": "everyone"})
    assert robots._spawned_tf_prefix(model) == "everyone"
