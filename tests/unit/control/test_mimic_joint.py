"""mimic_joint.py: MimicJointPlugin tags, PID namespace resolution, the per-step action; URDF <mimic>."""
import math
import xml.etree.ElementTree as ET

import pytest

from diffbot_sim.control.mimic_joint import MimicAction, MimicCore, ignition_clamp, mimic_config, urdf_mimic_target
from diffbot_sim.control.pid import PidGains
from diffbot_sim.description.urdf_model import Mimic
from diffbot_sim.errors import ConfigError, PluginNotLoaded

PATH = "/robot/gazebo[2]/plugin[@name='mimic']"
LIMITS = {"gripper": 1.0, "gripper_sub": 2.5, "free": -1.0}


def config(**tags):
    return mimic_config({"joint": "gripper", "mimicJoint": "gripper_sub", **tags}, PATH, LIMITS.__getitem__)


def test_defaults():
    cfg = config()
    assert (cfg.joint, cfg.mimic_joint, cfg.multiplier, cfg.offset, cfg.sensitiveness) == (
        "gripper", "gripper_sub", 1.0, 0.0, 0.0)
    assert cfg.max_effort == 2.5  # the mimic joint's limit, not the master's
    assert (cfg.has_pid, cfg.pid_namespace, cfg.robot_namespace, cfg.path, cfg.notes) == (False, None, "", PATH, ())


def test_numbers_read_like_gazebo_and_max_effort_tag_wins():
    cfg = config(multiplier=" -2 ", offset="0.1rad", sensitiveness="0.001", maxEffort="5")
    assert (cfg.multiplier, cfg.offset, cfg.sensitiveness, cfg.max_effort) == (-2.0, 0.1, 0.001, 5.0)
    assert len(cfg.notes) == 1 and "<offset> of " + PATH in cfg.notes[0]


def test_reads_the_plugin_element():
    element = ET.fromstring(
        '<plugin name="m" filename="libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so">'
        "<joint> gripper </joint><mimicJoint>gripper_sub</mimicJoint><multiplier>-1</multiplier>"
        "<hasPID/><robotNamespace>my_gen3</robotNamespace></plugin>")
    cfg = mimic_config(element, PATH, LIMITS.__getitem__)
    assert (cfg.joint, cfg.multiplier, cfg.has_pid) == ("gripper", -1.0, True)
    assert cfg.pid_namespace == "/my_gen3/gazebo_ros_control/pid_gains/gripper_sub"


@pytest.mark.parametrize("has_pid, namespace, expected", [
    ("", "", "/gazebo_ros_control/pid_gains/gripper_sub"),
    (None, "/", "/gazebo_ros_control/pid_gains/gripper_sub"),
    ("/gazebo_ros_control/pid_gains/gripper_sub", "robot", "/gazebo_ros_control/pid_gains/gripper_sub"),
    ("my_pid", "/arm/", "/arm/my_pid"),
    ("gains//sub/", "arm", "/arm/gains/sub"),
])
def test_pid_namespace(has_pid, namespace, expected):
    cfg = config(hasPID=has_pid, robotNamespace=namespace)
    assert cfg.has_pid and cfg.pid_namespace == expected


def test_tilde_pid_namespace_refused():
    with pytest.raises(ConfigError, match="hasPID"):
        config(hasPID="~pid")


@pytest.mark.parametrize("tags, message", [
    ({"mimicJoint": "gripper_sub"}, "No joint element present"),
    ({"joint": "gripper"}, "No mimicJoint element present"),
    ({"joint": "nope", "mimicJoint": "gripper_sub"}, 'No joint named "nope"'),
    ({"joint": "gripper", "mimicJoint": "nope"}, 'No (mimic) joint named "nope"'),
])
def test_missing_tags_or_joints_name_the_plugin(tags, message):
    with pytest.raises(PluginNotLoaded) as err:
        mimic_config(tags, PATH, LIMITS.__getitem__)
    text = str(err.value)
    assert message in text and PATH in text and "MimicJointPlugin could not be loaded" in text
    assert "\n" not in text


def test_bad_number_names_the_tag_and_plugin():
    with pytest.raises(ConfigError) as err:
        config(multiplier="abc")
    assert err.value.name == f"<multiplier> of {PATH}"


def test_no_pid_sets_position_of_target():
    mimic = MimicCore(config(multiplier="2", offset="0.1"))
    assert mimic.update(0.3, 0.0, 0.001) == MimicAction("position", pytest.approx(0.7))
    assert mimic.update(0.0, 0.1, 0.001) == ("position", 0.1)  # sensitiveness 0: acts even at zero error


def test_within_sensitiveness_does_nothing_and_at_it_acts():
    mimic = MimicCore(config(sensitiveness="0.25"))
    assert mimic.update(1.0, 0.8, 0.001) is None
    assert mimic.update(1.0, 1.2, 0.001) is None
    assert mimic.update(1.0, 0.75, 0.001) == ("position", 1.0)


def test_nan_position_does_nothing():
    mimic = MimicCore(config(hasPID=""), PidGains(p=10.0))
    assert mimic.update(math.nan, 0.0, 0.001) is None
    assert mimic.update(0.0, math.nan, 0.001) is None


def test_pid_effort_clamped_to_max_effort():
    mimic = MimicCore(config(hasPID="", maxEffort="5"), PidGains(p=10.0))
    assert mimic.update(1.0, 0.0, 0.001) == ("effort", 5.0)
    assert mimic.update(0.0, 0.2, 0.001) == MimicAction("effort", pytest.approx(-2.0))


def test_pid_uses_error_derivative_over_dt():
    mimic = MimicCore(config(hasPID=""), PidGains(p=0.0, d=0.001))
    mimic.update(0.0, 0.0, 0.001)
    assert mimic.update(0.5, 0.0, 0.001).value == pytest.approx(0.5)  # d * (0.5 - 0) / 0.001


def test_pid_without_gains_applies_zero_effort():
    mimic = MimicCore(config(hasPID=""), None)
    assert mimic.update(1.0, 0.0, 0.001) == ("effort", 0.0)


def test_gains_ignored_without_has_pid():
    assert MimicCore(config(), PidGains(p=10.0)).update(1.0, 0.0, 0.001) == ("position", 1.0)


def test_negative_max_effort_pushes_constantly_like_upstream_clamp():
    cfg = mimic_config({"joint": "gripper", "mimicJoint": "free", "hasPID": ""}, PATH, LIMITS.__getitem__)
    assert cfg.max_effort == -1.0 and "always applies 1" in cfg.notes[0]
    mimic = MimicCore(cfg, PidGains(p=10.0))
    assert mimic.update(-1.0, 0.0, 0.001) == ("effort", 1.0)
    assert mimic.update(1.0, 0.0, 0.001) == ("effort", 1.0)


def test_ignition_clamp():
    assert (ignition_clamp(3.0, -1.0, 1.0), ignition_clamp(-3.0, -1.0, 1.0), ignition_clamp(0.5, -1.0, 1.0)) == (
        1.0, -1.0, 0.5)
    assert ignition_clamp(-3.0, 1.0, -1.0) == 1.0


def test_urdf_mimic_target():
    assert urdf_mimic_target(0.5, Mimic("gripper", multiplier=-2.0, offset=0.25)) == pytest.approx(-0.75)
    assert urdf_mimic_target(0.5, Mimic("gripper")) == 0.5


def test_effort_is_updates_number_and_state():
    # the plugin's every-step path (effort) and update give the same efforts from the same PID state
    by_update = MimicCore(config(hasPID="", maxEffort="5", sensitiveness="0.01"), PidGains(p=10.0, i=1.0, d=0.01))
    by_effort = MimicCore(config(hasPID="", maxEffort="5", sensitiveness="0.01"), PidGains(p=10.0, i=1.0, d=0.01))
    for master, mimic in ((0.3, 0.0), (0.3, 0.1), (0.3, 0.295), (1.0, 0.0), (0.2, 0.25), (math.nan, 0.0)):
        action = by_update.update(master, mimic, 0.001)
        assert by_effort.effort(master, mimic, 0.001) == (None if action is None else action.value)
    assert by_effort.effort(0.3, 0.295, 0.001) is None  # within sensitiveness
    assert by_effort.effort(1.0, 0.0, 0.001) == 5.0  # clamped to maxEffort


def test_effort_without_pid_is_none():
    # without <hasPID> the mimic joint is positioned (update's "position" action), never pushed: no effort
    mimic = MimicCore(config(), PidGains(p=10.0))
    assert mimic.effort(1.0, 0.0, 0.001) is None and mimic.update(1.0, 0.0, 0.001) == ("position", 1.0)
