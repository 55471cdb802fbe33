"""Config-level pieces of the plugins that need no ROS master: the skid-steer tags, controller discovery, and the
model's Gazebo tag reading (both forms, bad values, dangling references)."""

import pytest

from diffbot_sim import config
from diffbot_sim.control.controller_lookup import find_controllers
from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import ConfigError, ModelError

PATH = "/robot/gazebo[1]/plugin[@name='skid']"
JOINTS = ("left_front_joint", "left_rear_joint", "right_front_joint", "right_rear_joint")


# ----------------------------------------------------------------------------------------------- skid steer

def _four_wheels(names=JOINTS, fixed=()):
    body = ('<link name="base_link"><inertial><mass value="5"/>'
            '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>')
    for i, name in enumerate(names):
        kind = "fixed" if name in fixed else "continuous"
        x, y = 0.2 if i % 2 == 0 else -0.2, 0.25 if i < 2 else -0.25
        body += (f'<link name="w{i}"><collision><geometry><cylinder radius="0.1" length="0.05"/></geometry>'
                 '</collision></link>'
                 f'<joint name="{name}" type="{kind}"><parent link="base_link"/><child link="w{i}"/>'
                 f'<origin xyz="{x} {y} 0"/><axis xyz="0 1 0"/></joint>')
    return f'<robot name="skid">{body}</robot>'


def test_skid_steer_tags_become_a_drive_config(parse):
    model = parse(_four_wheels(("fl", "rl", "fr", "rr")))
    values = {"leftFrontJoint": "fl", "leftRearJoint": "rl", "rightFrontJoint": "fr", "rightRearJoint": "rr",
              "wheelSeparation": "0.5", "wheelDiameter": "0.2", "torque": "20", "commandTopic": "base/cmd_vel",
              "odometryTopic": "base/odom", "odometryFrame": "odom_s", "robotBaseFrame": "base_s",
              "updateRate": "40", "broadcastTF": "true", "covariance_x": "0.1", "covariance_y": "0.2",
              "covariance_yaw": "0.3", "robotNamespace": "skid", "alwaysOn": "true"}
    cfg = config.skid_steer_config(model, values, PATH)
    assert (cfg.left_joints, cfg.right_joints) == (["fl", "rl"], ["fr", "rr"])
    assert (cfg.wheel_separation, cfg.wheel_diameter, cfg.max_wheel_torque, cfg.update_rate) == (0.5, 0.2, 20.0, 40.0)
    assert (cfg.command_topic, cfg.odometry_topic) == ("base/cmd_vel", "base/odom")
    assert (cfg.odometry_frame, cfg.robot_base_frame, cfg.namespace) == ("odom_s", "base_s", "skid")
    assert cfg.publish_odom_tf is True
    assert (cfg.covariance_x, cfg.covariance_y, cfg.covariance_yaw) == (0.1, 0.2, 0.3)
    assert cfg.odometry_source == "world"


def test_skid_steer_defaults_are_the_ros1_plugins(parse):
    cfg = config.skid_steer_config(parse(_four_wheels()), {}, PATH)
    assert cfg.left_joints == ["left_front_joint", "left_rear_joint"]
    assert cfg.right_joints == ["right_front_joint", "right_rear_joint"]
    assert (cfg.wheel_separation, cfg.wheel_diameter) == (0.4, 0.15)  # the plugin's, not the URDF's (0.5, 0.2)
    assert cfg.publish_odom_tf is False  # broadcastTF defaults to false
    assert (cfg.covariance_x, cfg.covariance_y, cfg.covariance_yaw) == (1e-4, 1e-4, 0.01)
    assert cfg.max_wheel_acceleration == 0.0 and cfg.odometry_source == "world"
    assert (cfg.command_topic, cfg.odometry_topic, cfg.odometry_frame) == ("cmd_vel", "odom", "odom")


@pytest.mark.parametrize("tag, value", [("torque", "strong"), ("wheelSeparation", "-0.4"),
                                        ("wheelDiameter", "0"), ("updateRate", "fast"), ("broadcastTF", "yes"),
                                        ("covariance_yaw", "-1")])
def test_skid_steer_bad_value_names_the_plugin_and_the_value(parse, tag, value):
    with pytest.raises(ConfigError) as err:
        config.skid_steer_config(parse(_four_wheels()), {tag: value}, PATH)
    assert PATH in str(err.value) and repr(value) in str(err.value)


@pytest.mark.parametrize("tag", ["torque", "wheelSeparation", "updateRate", "broadcastTF"])
def test_skid_steer_bad_value_names_the_tag_as_written(parse, tag):
    with pytest.raises(ConfigError) as err:
        config.skid_steer_config(parse(_four_wheels()), {tag: "bad"}, PATH)
    assert f"<{tag}>" in str(err.value)


def test_skid_steer_bad_joint_names_the_tag_and_the_joint(parse):
    model = parse(_four_wheels())
    with pytest.raises(ConfigError, match="<leftRearJoint>"):
        config.skid_steer_config(model, {"leftRearJoint": " "}, PATH)
    with pytest.raises(ModelError, match="names joint 'nope'"):
        config.skid_steer_config(model, {"rightFrontJoint": "nope"}, PATH)
    with pytest.raises(ModelError, match="'left_rear_joint' is fixed"):
        config.skid_steer_config(parse(_four_wheels(fixed=("left_rear_joint",))), {}, PATH)


# ----------------------------------------------------------------------------------------- find_controllers

DDC = {"type": "diff_drive_controller/DiffDriveController", "left_wheel": "l", "right_wheel": "r"}
JSC = {"type": "joint_state_controller/JointStateController", "publish_rate": 50}
PARAMS = {
    "robot": {
        "mobile_base_controller": DDC,
        "arm": {"joint_state_controller": JSC, "description": {"type": "box"}},  # "box": not a controller type
        "gazebo_ros_control": {"pid_gains": {"l": {"p": 1.0}},
                               "ghost": {"type": "velocity_controllers/JointVelocityController"}},
    },
    "elsewhere": {"other_controller": {"type": "effort_controllers/JointEffortController", "joint": "j"}},
    "use_sim_time": True,
}


def test_find_controllers_finds_nested_type_dicts_under_the_namespace():
    tree = PARAMS
    found = find_controllers(tree, "/robot")
    assert found == {"/robot/mobile_base_controller": DDC, "/robot/arm/joint_state_controller": JSC}


def test_find_controllers_accepts_a_relative_namespace():
    tree = PARAMS
    assert set(find_controllers(tree, "robot")) == {"/robot/mobile_base_controller",
                                                         "/robot/arm/joint_state_controller"}


def test_find_controllers_falls_back_to_the_whole_tree():
    tree = PARAMS
    found = find_controllers(tree, "/empty")
    assert set(found) == {"/robot/mobile_base_controller", "/robot/arm/joint_state_controller",
                          "/elsewhere/other_controller"}
    assert "/robot/gazebo_ros_control/ghost" not in found


def test_find_controllers_at_the_root():
    tree = PARAMS
    assert set(find_controllers(tree, "/")) == {"/robot/mobile_base_controller",
                                                     "/robot/arm/joint_state_controller",
                                                     "/elsewhere/other_controller"}


def test_find_controllers_with_none_anywhere():
    tree = {"robot": {"gazebo_ros_control": {"x": {"type": "a/b"}}}, "n": 1}
    assert find_controllers(tree, "/robot") == {}


# -------------------------------------------------------------------------------------- Gazebo tag reading

def _element(xml):
    import xml.etree.ElementTree as ET

    return ET.fromstring(xml)


@pytest.mark.parametrize("xml, expected", [("<mu1>0.5</mu1>", "0.5"), ('<mu1 value="0.7"/>', "0.7"),
                                           ("<mu1>\n  0.25 \n</mu1>", "0.25"), ('<mu1 value=" 2 "/>', "2"),
                                           ('<mu1 value="0.3">0.9</mu1>', "0.9"), ("<mu1/>", "")])
def test_tag_value_reads_both_forms(xml, expected):
    assert tag_value(_element(xml)) == expected


def _surface_model(parse, gazebo):
    return parse(f'<robot name="s"><link name="base_link"/><link name="wheel"/>'
                 f'<joint name="wheel_joint" type="continuous"><parent link="base_link"/><child link="wheel"/></joint>'
                 f'{gazebo}</robot>', "s.urdf")


def test_surface_text_and_attribute_forms_mixed(parse):
    model = _surface_model(parse, '<gazebo reference="wheel"><mu1>0.5</mu1><mu2 value="0.4"/><kp value="1e6"/>'
                                  '<kd>20</kd><minDepth>0.001</minDepth><maxVel value="0.1"/>'
                                  '<laserRetro>100</laserRetro>'
                                  '<fdir1 value="1 0 0"/><material>Gazebo/Black</material></gazebo>'
                                  '<gazebo reference="base_link"><mu1 value="0.2"/></gazebo>')
    assert model.surface("wheel") == {"mu1": 0.5, "mu2": 0.4, "kp": 1e6, "kd": 20.0, "minDepth": 0.001,
                                      "maxVel": 0.1, "laserRetro": 100.0, "fdir1": (1.0, 0.0, 0.0)}
    assert model.surface("base_link") == {"mu1": 0.2}
    assert model.surface("nothing") == {}
    assert model.warnings == []


def test_surface_fdir1_text_form_is_a_three_tuple(parse):
    model = _surface_model(parse, '<gazebo reference="wheel"><fdir1>0 1 0</fdir1></gazebo>')
    assert model.surface("wheel") == {"fdir1": (0.0, 1.0, 0.0)}


@pytest.mark.parametrize("tags, kept, bad", [
    ("<mu1>slippery</mu1><mu2>0.3</mu2>", {"mu2": 0.3}, "mu1"),
    ('<kp value="${kp}"/><kd value="1"/>', {"kd": 1.0}, "kp"),
    ("<fdir1>1 0</fdir1><mu1>0.5</mu1>", {"mu1": 0.5}, "fdir1"),
    ("<mu1>nan</mu1>", {}, "mu1"),
])
def test_surface_value_not_a_number_is_skipped_with_one_warning(parse, tags, kept, bad):
    model = _surface_model(parse, f'<gazebo reference="wheel">{tags}</gazebo>')
    assert model.surface("wheel") == kept
    assert model.surface("wheel") == kept  # asked again: still one warning
    assert len(model.warnings) == 1
    warning = model.warnings[0]
    assert "s.urdf" in warning and f"/robot/gazebo[@reference='wheel']/{bad}" in warning
    assert "Gazebo's default" in warning


def test_gazebo_reference_naming_nothing_warns_once(parse):
    model = _surface_model(parse, '<gazebo reference="caster_{side}_1_joint"><mu1>0.1</mu1></gazebo>'
                                  '<gazebo reference="wheel_joint"><implicitSpringDamper>1</implicitSpringDamper>'
                                  '</gazebo>'
                                  '<gazebo reference="wheel"><mu1>0.1</mu1></gazebo>')
    assert len(model.warnings) == 1
    assert "caster_{side}_1_joint" in model.warnings[0] and "names no link or joint" in model.warnings[0]
    assert model.surface("wheel") == {"mu1": 0.1}


@pytest.mark.parametrize("kind, name, key", [
    ("imu", "/imu", "imu/imu"), ("imu", "/robot1/imu data", "imu/robot1/imu_data"),
    ("sensor", "laser-front", "sensor/laser_front"),
    ("camera", "3d cam", "camera/n3d_cam"), ("gps", "", "gps/unnamed"),
])
def test_summary_keys_are_legal_ros_names(kind, name, key):
    import rosgraph.names

    from diffbot_sim.plugins.base import summary_key
    assert summary_key(kind, name) == key and rosgraph.names.is_legal_name(key)
