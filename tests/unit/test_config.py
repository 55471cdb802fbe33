"""config.py: SimConfig, GazeboDiffDriveConfig and JointStateConfig from defaults, plugin tags and private params."""
import math
import os

import pytest

from diffbot_sim import config
from diffbot_sim.config import (
    FALLBACK_MAX_WHEEL_VELOCITY,
    SimConfig,
    as_params,
    gazebo_diff_drive_config,
    joint_state_config,
    sim_config,
)
from diffbot_sim.description.plugin_tags import read_plugins
from diffbot_sim.errors import ConfigError, ModelError

with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "ros1_diff_drive.xml")) as _f:
    ROS1_DIFF_DRIVE = _f.read()


def _gazebo(*plugins):
    return "\n  <gazebo>" + "".join(plugins) + "</gazebo>"


def _drive(parse, make_urdf, plugin=None, params=None, **urdf):
    gazebo = _gazebo(plugin) if plugin else ""
    model = parse(make_urdf(gazebo=gazebo, **urdf))
    return gazebo_diff_drive_config(model, read_plugins(model).diff_drive, params or {})


def _ros2(body, ros=""):
    return (f'<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><ros>{ros}</ros>'
            f"<left_joint>left_wheel_joint</left_joint><right_joint>right_wheel_joint</right_joint>{body}</plugin>")


def _ros1(body):
    return ('<plugin name="dd" filename="libgazebo_ros_diff_drive.so">'
            f"<leftJoint>left_wheel_joint</leftJoint><rightJoint>right_wheel_joint</rightJoint>{body}</plugin>")


# ----------------------------------------------------------------------------------------------- the seed

def test_seed_drive_config(seed_model):
    plugins = read_plugins(seed_model)
    cfg = gazebo_diff_drive_config(seed_model, plugins.diff_drive, {})
    assert cfg.left_joints == ["left_wheel_joint"] and cfg.right_joints == ["right_wheel_joint"]
    assert cfg.wheel_separation == pytest.approx(0.2)
    assert cfg.wheel_diameter == pytest.approx(0.064)
    assert cfg.wheel_radius == pytest.approx(0.032)
    assert cfg.max_wheel_torque == 30.0
    assert cfg.max_wheel_acceleration == 1.8
    assert cfg.update_rate == 100.0
    assert cfg.odometry_frame == "odom" and cfg.robot_base_frame == "base_footprint"
    assert cfg.command_topic == "cmd_vel" and cfg.odometry_topic == "odom"
    assert cfg.publish_odom is True and cfg.publish_odom_tf is True
    assert cfg.publish_wheel_joint_state is False
    assert cfg.odometry_source == "world"
    assert cfg.namespace == "/"


def test_seed_joint_state_config(seed_model):
    plugins = read_plugins(seed_model)
    drive = gazebo_diff_drive_config(seed_model, plugins.diff_drive, {})
    cfg = joint_state_config(seed_model, plugins.joint_state, drive)
    assert cfg.joints == ["left_wheel_joint", "right_wheel_joint", "front_caster_joint", "back_caster_joint"]
    assert cfg.update_rate == 100.0 and cfg.topic == "joint_states" and cfg.namespace == "/"


# ------------------------------------------------------------------------------------------ ROS 1 dialect

def test_ros1_block_maps_to_config(parse, make_urdf):
    cfg = _drive(parse, make_urdf, ROS1_DIFF_DRIVE)
    assert cfg.left_joints == ["left_wheel_joint"] and cfg.right_joints == ["right_wheel_joint"]
    assert cfg.wheel_separation == pytest.approx(0.31)  # the tag, not the URDF's 0.3
    assert cfg.wheel_diameter == pytest.approx(0.11)  # the tag, not the URDF's 0.1
    assert cfg.max_wheel_torque == 12.0
    assert cfg.max_wheel_acceleration == 2.5
    assert cfg.command_topic == "mobile/cmd_vel" and cfg.odometry_topic == "mobile/odom"
    assert cfg.odometry_frame == "odom_frame" and cfg.robot_base_frame == "base_link"
    assert cfg.odometry_source == "encoder"
    assert cfg.publish_odom_tf is False
    assert cfg.publish_odom is True  # ROS 1 default, no tag
    assert cfg.publish_wheel_joint_state is True
    assert cfg.update_rate == 50.0
    assert cfg.namespace == "/bot1"


def test_ros1_publish_wheel_joint_state_feeds_joint_state_config(parse, make_urdf):
    model = parse(make_urdf(gazebo=_gazebo(ROS1_DIFF_DRIVE)))
    plugins = read_plugins(model)
    drive = gazebo_diff_drive_config(model, plugins.diff_drive, {})
    cfg = joint_state_config(model, plugins.joint_state, drive)
    assert cfg.joints == ["left_wheel_joint", "right_wheel_joint"]
    assert cfg.update_rate == 50.0 and cfg.namespace == "/bot1"


def test_no_joint_state_without_plugin_or_flag(parse, make_urdf):
    model = parse(make_urdf(gazebo=_gazebo(_ros1(""))))
    plugins = read_plugins(model)
    drive = gazebo_diff_drive_config(model, plugins.diff_drive, {})
    assert joint_state_config(model, plugins.joint_state, drive) is None


def test_ros1_publish_tf_false_turns_off_odom_and_its_tf(parse, make_urdf):
    cfg = _drive(parse, make_urdf, _ros1("<publishTf>false</publishTf>"))
    assert cfg.publish_odom is False and cfg.publish_odom_tf is False
    # an explicit parameter still wins
    cfg = _drive(parse, make_urdf, _ros1("<publishTf>false</publishTf>"), params={"publish_odom_tf": True})
    assert cfg.publish_odom is False and cfg.publish_odom_tf is True


def test_plugin_tag_numbers_are_read_as_gazebo_reads_them(parse, make_urdf):
    notes = []
    model = parse(make_urdf(gazebo=_gazebo(_ros1("<wheelSeparation>0.31m</wheelSeparation>"
                                                 "<updateRate>50.0 Hz</updateRate>"))))
    cfg = gazebo_diff_drive_config(model, read_plugins(model).diff_drive, {}, notes)
    assert (cfg.wheel_separation, cfg.update_rate) == (0.31, 50.0)
    assert len(notes) == 2 and all("as Gazebo's SDF reader (std::stod) does" in n for n in notes)
    assert any(n.startswith("<wheelSeparation> of /robot/gazebo[1]/plugin[@name='dd']: took 0.31 from '0.31m'")
               for n in notes), notes


def test_private_parameters_stay_strict(parse, make_urdf):
    with pytest.raises(ConfigError, match=r"~wheel_separation: got '0.31m'"):
        _drive(parse, make_urdf, _ros1(""), params={"wheel_separation": "0.31m"})


def test_ros1_defaults_publish(parse, make_urdf):
    cfg = _drive(parse, make_urdf, _ros1(""))
    assert cfg.publish_odom is True and cfg.publish_odom_tf is True
    assert cfg.max_wheel_torque == 5.0 and cfg.odometry_source == "world"
    assert cfg.namespace is None


# ------------------------------------------------------------------------------------------ ROS 2 dialect

def test_ros2_defaults_publish_nothing(parse, make_urdf):
    cfg = _drive(parse, make_urdf, _ros2("<max_wheel_torque>7</max_wheel_torque>"))
    assert cfg.publish_odom is False
    assert cfg.publish_odom_tf is False
    assert cfg.max_wheel_torque == 7.0


@pytest.mark.parametrize("text, expected", [("0", "encoder"), ("1", "world"), (" 0 ", "encoder"),
                                            ("encoder", "encoder"), ("WORLD", "world")])
def test_ros2_odometry_source(parse, make_urdf, text, expected):
    cfg = _drive(parse, make_urdf, _ros2(f"<odometry_source>{text}</odometry_source>"))
    assert cfg.odometry_source == expected


def test_ros2_remapping_reaches_config(parse, make_urdf):
    ros = ("<namespace>ns</namespace><remapping>cmd_vel:=teleop/cmd</remapping>"
           "<argument>--ros-args --remap odom:=wheel/odom</argument>")
    cfg = _drive(parse, make_urdf, _ros2("", ros))
    assert cfg.command_topic == "teleop/cmd" and cfg.odometry_topic == "wheel/odom"
    assert cfg.namespace == "ns"


# ---------------------------------------------------------------------------------- params and fallbacks

def test_private_params_override_tags(seed_model):
    params = {"wheel_separation": 0.25, "max_wheel_torque": "8", "publish_odom_tf": False,
              "odometry_source": "encoder", "command_topic": "other_cmd", "namespace": "",
              "time_step": 0.001}  # a sim param: ignored here
    cfg = gazebo_diff_drive_config(seed_model, read_plugins(seed_model).diff_drive, params)
    assert cfg.wheel_separation == 0.25
    assert cfg.max_wheel_torque == 8.0
    assert cfg.publish_odom_tf is False
    assert cfg.odometry_source == "encoder"
    assert cfg.command_topic == "other_cmd"
    assert cfg.namespace == ""
    assert cfg.wheel_diameter == pytest.approx(0.064)  # untouched tag


def test_params_alone_describe_a_drive(parse, make_urdf):
    model = parse(make_urdf())
    assert gazebo_diff_drive_config(model, None, {}) is None
    cfg = gazebo_diff_drive_config(model, None, {"left_joints": "left_wheel_joint",
                                                 "right_joints": ["right_wheel_joint"]})
    assert cfg.left_joints == ["left_wheel_joint"] and cfg.right_joints == ["right_wheel_joint"]
    assert cfg.wheel_separation == pytest.approx(0.3) and cfg.wheel_diameter == pytest.approx(0.1)


def test_separation_and_diameter_fall_back_to_urdf(parse, make_urdf):
    cfg = _drive(parse, make_urdf, _ros1("<wheelTorque>3</wheelTorque>"), separation=0.42, wheel_radius=0.07)
    assert cfg.wheel_separation == pytest.approx(0.42)
    assert cfg.wheel_diameter == pytest.approx(0.14)


def test_diameter_tag_rescues_a_box_wheel(parse, make_urdf):
    box = '<box size="0.1 0.03 0.1"/>'
    cfg = _drive(parse, make_urdf, _ros1("<wheelDiameter>0.09</wheelDiameter>"), wheel_geometry=box)
    assert cfg.wheel_diameter == pytest.approx(0.09)
    with pytest.raises(ModelError) as info:
        _drive(parse, make_urdf, _ros1(""), wheel_geometry=box)
    assert "left_wheel_link" in str(info.value)


def test_as_params_drops_none(parse, make_urdf):
    params = as_params(_drive(parse, make_urdf, _ros1("")))
    assert "namespace" not in params
    assert params["wheel_separation"] == pytest.approx(0.3)


# ------------------------------------------------------------------------------------------------ errors

@pytest.mark.parametrize("body, tag, value", [
    ("<wheel_separation>wide</wheel_separation>", "wheel_separation", "wide"),
    ("<wheel_diameter>-0.1</wheel_diameter>", "wheel_diameter", "-0.1"),
    ("<wheel_separation>0</wheel_separation>", "wheel_separation", "0"),
    ("<max_wheel_torque>nan</max_wheel_torque>", "max_wheel_torque", "nan"),
    ("<max_wheel_acceleration>inf</max_wheel_acceleration>", "max_wheel_acceleration", "inf"),
    ("<publish_odom>maybe</publish_odom>", "publish_odom", "maybe"),
    ("<update_rate>-5</update_rate>", "update_rate", "-5"),
])
def test_bad_ros2_tag_values(parse, make_urdf, body, tag, value):
    with pytest.raises(ConfigError) as info:
        _drive(parse, make_urdf, _ros2(body))
    message = str(info.value)
    assert f"<{tag}>" in message
    assert "plugin[@name='dd']" in message
    assert repr(value) in message
    assert info.value.value == value


@pytest.mark.parametrize("key, value", [
    ("wheel_separation", -0.2), ("wheel_diameter", "x"), ("max_wheel_torque", float("nan")),
    ("publish_odom_tf", "maybe"), ("update_rate", True), ("left_joints", 5), ("left_joints", [""]),
])
def test_bad_param_values(seed_model, key, value):
    with pytest.raises(ConfigError) as info:
        gazebo_diff_drive_config(seed_model, read_plugins(seed_model).diff_drive, {key: value})
    assert f"parameter ~{key}:" in str(info.value)


def test_bad_ros1_tag_error_names_the_tag_written(parse, make_urdf):
    with pytest.raises(ConfigError) as info:
        _drive(parse, make_urdf, _ros1("<wheelDiameter>-0.1</wheelDiameter>"))
    assert "wheelDiameter" in str(info.value)


def test_unequal_wheel_lists(parse, make_urdf):
    plugin = _ros2("<left_joint>caster_joint</left_joint>")
    with pytest.raises(ConfigError) as info:
        _drive(parse, make_urdf, plugin)
    assert "left_joints/right_joints" in str(info.value)


def test_plugin_naming_missing_joint(parse, make_urdf):
    plugin = _ros1("").replace("<leftJoint>left_wheel_joint", "<leftJoint>left_wheel_jiont")
    with pytest.raises(ModelError) as info:
        _drive(parse, make_urdf, plugin)
    assert "left_wheel_jiont" in str(info.value)
    assert "plugin[@name='dd']" in str(info.value)


def test_param_naming_missing_joint(seed_model):
    with pytest.raises(ModelError) as info:
        gazebo_diff_drive_config(seed_model, read_plugins(seed_model).diff_drive, {"right_joints": "rear_wheel_joint"})
    assert "rear_wheel_joint" in str(info.value)


def test_fixed_joint_cannot_be_a_wheel(parse, make_urdf):
    plugin = _ros1("").replace("<rightJoint>right_wheel_joint", "<rightJoint>base_joint")
    with pytest.raises(ModelError) as info:
        _drive(parse, make_urdf, plugin)
    assert "base_joint" in str(info.value) and "fixed" in str(info.value)


def test_effort_transmission_on_drive_wheel(parse, make_urdf):
    with pytest.raises(ModelError) as info:
        _drive(parse, make_urdf, _ros1(""), right_interface="hardware_interface/EffortJointInterface")
    message = str(info.value)
    assert "right_wheel_joint" in message and "EffortJointInterface" in message
    assert "transmission[@name='right_wheel_joint_trans']" in message
    # the same model with velocity interfaces is fine
    assert _drive(parse, make_urdf, _ros1("")).right_joints == ["right_wheel_joint"]


def test_joint_state_plugin_naming_missing_joint(parse, make_urdf):
    plugin = ('<plugin name="js" filename="libgazebo_ros_joint_state_publisher.so">'
              "<joint_name>left_wheel_joint</joint_name><joint_name>tail_joint</joint_name></plugin>")
    model = parse(make_urdf(gazebo=_gazebo(plugin)))
    plugins = read_plugins(model)
    with pytest.raises(ModelError) as info:
        joint_state_config(model, plugins.joint_state, None)
    assert "tail_joint" in str(info.value)
    assert "plugin[@name='js']" in str(info.value)


def test_joint_state_bad_update_rate(parse, make_urdf):
    plugin = ('<plugin name="js" filename="libgazebo_ros_joint_state_publisher.so">'
              "<jointName>caster_joint</jointName><updateRate>fast</updateRate></plugin>")
    model = parse(make_urdf(gazebo=_gazebo(plugin)))
    with pytest.raises(ConfigError) as info:
        joint_state_config(model, read_plugins(model).joint_state, None)
    assert "update_rate" in str(info.value) and "'fast'" in str(info.value)


def test_model_with_camera_and_unknown_plugin_still_configures(parse, make_urdf):
    camera = ('<gazebo reference="base_link"><sensor type="camera" name="cam"><update_rate>30</update_rate>'
              '</sensor></gazebo>')
    model = parse(make_urdf(gazebo=camera + _gazebo(_ros1(""), '<plugin name="x" filename="libmystery.so"/>')))
    plugins = read_plugins(model)
    cfg = gazebo_diff_drive_config(model, plugins.diff_drive, {})
    assert cfg.left_joints == ["left_wheel_joint"]
    assert sorted(plugins.unsupported) == ["plugin x (libmystery.so)", "sensor cam (type camera)"]


# ------------------------------------------------------------------------------------------- sim_config

def test_sim_config_defaults():
    cfg = sim_config({})
    assert cfg == SimConfig()
    assert cfg.time_step == pytest.approx(1 / 240)
    assert cfg.gui is False and cfg.real_time is True and cfg.cmd_vel_timeout == 0.0
    assert FALLBACK_MAX_WHEEL_VELOCITY > 0


def test_sim_config_values_and_coercion():
    cfg = sim_config({"time_step": "0.002", "gui": "true", "real_time": 0, "x": 1, "yaw": "-1.5",
                      "cmd_vel_timeout": 0.5, "model": " urdf/x.urdf ", "unrelated": object()})
    assert cfg.time_step == 0.002 and cfg.gui is True and cfg.real_time is False
    assert cfg.x == 1.0 and isinstance(cfg.x, float) and cfg.yaw == -1.5
    assert cfg.cmd_vel_timeout == 0.5
    assert cfg.model == "urdf/x.urdf"


@pytest.mark.parametrize("key, value", [
    ("time_step", 0), ("time_step", -0.01), ("time_step", float("nan")), ("time_step", 1.0),
    ("time_step", True), ("time_step", "fast"), ("gui", "maybe"), ("real_time", 2),
    ("cmd_vel_timeout", -1), ("clock_rate", 0), ("gravity", float("inf")), ("model", 3),
    ("publish_ground_truth", "yes please"), ("fast_batch", -0.001), ("fast_batch", 0.5),
    ("send_timeout", 0), ("send_timeout", "never"), ("clock_max_wall_rate", -1),
])
def test_sim_config_rejects(key, value):
    with pytest.raises(ConfigError) as info:
        sim_config({key: value})
    assert f"~{key}" in str(info.value)
    assert info.value.name == f"~{key}"
    if isinstance(value, float) and math.isnan(value):
        assert "finite" in str(info.value)


# --- wheel limits resolved from params, URDF and fallback (config.max_wheel_velocity / wheel_efforts) ---

def _seed_drive():
    import os

    from diffbot_sim.description.model_files import load_file
    from diffbot_sim.description.plugin_tags import read_plugins
    from diffbot_sim.description.urdf_model import parse_urdf
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    model = parse_urdf(load_file(os.path.join(root, "urdf", "diffbot.urdf.xacro")))
    return model, config.gazebo_diff_drive_config(model, read_plugins(model).diff_drive, {})


def test_max_wheel_velocity_precedence():
    model, drive = _seed_drive()
    assert config.max_wheel_velocity(config.sim_config({}), model, drive) == 40.0  # URDF <limit velocity>
    assert config.max_wheel_velocity(config.sim_config({"max_wheel_velocity": 12.5}), model, drive) == 12.5
    model.joints["left_wheel_joint"].velocity_limit = None
    assert config.max_wheel_velocity(config.sim_config({}), model, drive) == config.FALLBACK_MAX_WHEEL_VELOCITY


def test_wheel_efforts_capped_by_urdf_limit():
    model, drive = _seed_drive()
    assert config.wheel_efforts(model, drive) == [30.0, 30.0]  # plugin torque 30, URDF effort 30
    model.joints["right_wheel_joint"].effort_limit = 7.0
    model.joints["left_wheel_joint"].effort_limit = None
    assert config.wheel_efforts(model, drive) == [30.0, 7.0]


@pytest.mark.parametrize("text", ["ENCODER", "2", "ground_truth"])
def test_unmatched_odometry_source_warns_and_uses_world(parse, make_urdf, text):
    """gazebo_ros_diff_drive matches 'encoder' and 'world' exactly; anything else warns and uses world."""
    model = parse(make_urdf(gazebo=_gazebo(_ros1(f"<odometrySource>{text}</odometrySource>"))))
    notes = []
    cfg = gazebo_diff_drive_config(model, read_plugins(model).diff_drive, {}, notes)
    assert cfg.odometry_source == "world"
    assert len(notes) == 1 and "<odometrySource>" in notes[0] and text in notes[0]


@pytest.mark.parametrize("params, ok", [({"seed": 7}, True), ({"seed": 1.5}, False), ({"seed": "x"}, False),
                                        ({"renderer": "EGL"}, True), ({"renderer": "opengl"}, False)])
def test_seed_and_renderer_are_validated_once(params, ok):
    from diffbot_sim.config import sim_config

    if ok:
        cfg = sim_config(params)
        assert cfg.seed == params.get("seed", 0) and cfg.renderer == params.get("renderer", "tiny").lower()
    else:
        with pytest.raises(ConfigError) as err:
            sim_config(params)
        assert f"~{next(iter(params))}" in str(err.value)


@pytest.mark.parametrize("value,expected", [(None, False), ("auto", "auto"), (" AUTO ", "auto"), (True, True),
                                            ("true", True), ("false", False), (0, False)])
def test_ray_process_setting(value, expected):
    cfg = sim_config({} if value is None else {"ray_process": value})
    assert cfg.ray_process == expected


def test_bad_ray_process_setting_names_the_parameter_and_the_choices():
    with pytest.raises(ConfigError, match=r"~ray_process.*true, false or auto"):
        sim_config({"ray_process": "sometimes"})


def test_ray_process_wanted_in_real_time_above_the_auto_threshold():
    from diffbot_sim.config import RAY_PROCESS_AUTO_RAYS, wants_ray_process
    many, few = RAY_PROCESS_AUTO_RAYS, RAY_PROCESS_AUTO_RAYS - 1
    assert wants_ray_process("auto", True, many)
    assert not wants_ray_process("auto", True, few)
    assert not wants_ray_process("auto", False, many)  # fast mode casts in place: it waits for every message
    assert wants_ray_process(True, False, 0)
    assert not wants_ray_process(False, True, many)
