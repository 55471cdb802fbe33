"""description.plugin_tags: the <gazebo><plugin> blocks in both dialects, as canonical raw values."""
import os

import pytest

from diffbot_sim.description.plugin_tags import read_plugins
from diffbot_sim.errors import ModelError


def _gazebo(*plugins):
    return "\n  <gazebo>" + "".join(plugins) + "</gazebo>"


DATA = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data")
with open(os.path.join(DATA, "ros1_diff_drive.xml")) as _f:
    ROS1_DIFF_DRIVE = _f.read()


def test_seed_ros2_block(seed_model):
    plugins = read_plugins(seed_model)
    block = plugins.diff_drive
    assert block.dialect == "ros2"
    assert block.values["left_joints"] == ["left_wheel_joint"]
    assert block.values["right_joints"] == ["right_wheel_joint"]
    assert block.values["wheel_separation"] == "0.2"
    assert block.values["wheel_diameter"] == "0.064"
    assert block.values["max_wheel_torque"] == "30"
    assert block.values["max_wheel_acceleration"] == "1.8"
    assert block.values["namespace"] == "/"
    assert block.values["command_topic"] == "cmd_vel"
    assert block.values["odometry_topic"] == "odom"
    assert block.unknown_tags == []
    assert "plugin[@name='differential_drive_controller']" in block.path
    assert plugins.unsupported == [] and plugins.warnings == []


def test_seed_joint_state_block_repeated_joint_name(seed_model):
    block = read_plugins(seed_model).joint_state
    assert block.values["joints"] == ["left_wheel_joint", "right_wheel_joint", "front_caster_joint",
                                      "back_caster_joint"]
    assert block.values["update_rate"] == "100"
    assert block.values["topic"] == "joint_states"
    assert block.values["namespace"] == "/"


def test_ros1_camel_case_block(parse, make_urdf):
    block = read_plugins(parse(make_urdf(gazebo=_gazebo(ROS1_DIFF_DRIVE)))).diff_drive
    assert block.dialect == "ros1"
    assert block.values == {
        "update_rate": "50", "left_joints": ["left_wheel_joint"], "right_joints": ["right_wheel_joint"],
        "wheel_separation": "0.31", "wheel_diameter": "0.11", "max_wheel_torque": "12",
        "max_wheel_acceleration": "2.5", "command_topic": "mobile/cmd_vel", "odometry_topic": "mobile/odom",
        "odometry_frame": "odom_frame", "robot_base_frame": "base_link", "odometry_source": "encoder",
        "publish_odom_tf": "false", "publish_wheel_joint_state": "true", "namespace": "/bot1",
    }
    assert block.unknown_tags == []  # legacyMode, rosDebugLevel, alwaysOn, publishWheelTF are known no-ops


def test_unknown_tag_is_recorded(parse, make_urdf):
    plugin = ('<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><leftJoint>left_wheel_joint</leftJoint>'
              '<rightJoint>right_wheel_joint</rightJoint><wheelSeperation>0.3</wheelSeperation></plugin>')
    block = read_plugins(parse(make_urdf(gazebo=_gazebo(plugin)))).diff_drive
    assert block.unknown_tags == ["wheelSeperation"]
    assert "wheel_separation" not in block.values


@pytest.mark.parametrize("ros, expected", [
    ("<remapping>cmd_vel:=robot/cmd</remapping><remapping>odom:=robot/odometry</remapping>",
     ("robot/cmd", "robot/odometry")),
    ("<argument>--ros-args --remap cmd_vel:=c2</argument><argument>--ros-args -r odom:=o2</argument>",
     ("c2", "o2")),
    ("<argument>--ros-args --remap ~/cmd_vel:=c3 --remap /odom:=o3</argument>", ("c3", "o3")),
    ("<remapping>other:=x</remapping>", ("cmd_vel", "odom")),
])
def test_ros2_remapping(parse, make_urdf, ros, expected):
    plugin = f"""<plugin name="dd" filename="libgazebo_ros_diff_drive.so">
      <ros><namespace>/demo</namespace>{ros}</ros>
      <left_joint>left_wheel_joint</left_joint><right_joint>right_wheel_joint</right_joint>
      <command_topic>cmd_vel</command_topic><odometry_topic>odom</odometry_topic></plugin>"""
    block = read_plugins(parse(make_urdf(gazebo=_gazebo(plugin)))).diff_drive
    assert block.dialect == "ros2"
    assert block.values["namespace"] == "/demo"
    assert (block.values["command_topic"], block.values["odometry_topic"]) == expected


def test_ros2_multiple_wheel_pairs_are_lists(parse, make_urdf):
    plugin = """<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><num_wheel_pairs>2</num_wheel_pairs>
      <left_joint>a</left_joint><right_joint>b</right_joint><left_joint>c</left_joint><right_joint>d</right_joint>
      </plugin>"""
    block = read_plugins(parse(make_urdf(gazebo=_gazebo(plugin)))).diff_drive
    assert block.values["left_joints"] == ["a", "c"]
    assert block.values["right_joints"] == ["b", "d"]


def test_ros1_joint_state_comma_list(parse, make_urdf):
    plugin = """<plugin name="js" filename="libgazebo_ros_joint_state_publisher.so">
      <robotNamespace>/r1</robotNamespace><updateRate>25</updateRate>
      <jointName>left_wheel_joint, right_wheel_joint,caster_joint</jointName></plugin>"""
    block = read_plugins(parse(make_urdf(gazebo=_gazebo(plugin)))).joint_state
    assert block.dialect == "ros1"
    assert block.values == {"namespace": "/r1", "update_rate": "25",
                            "joints": ["left_wheel_joint", "right_wheel_joint", "caster_joint"]}


def test_filename_without_lib_prefix_or_suffix_is_recognised(parse, make_urdf):
    plugin = ('<plugin name="dd" filename="gazebo_ros_diff_drive"><leftJoint>left_wheel_joint</leftJoint>'
              '<rightJoint>right_wheel_joint</rightJoint></plugin>')
    plugins = read_plugins(parse(make_urdf(gazebo=_gazebo(plugin))))
    assert plugins.diff_drive is not None
    assert plugins.unsupported == []


def test_unsupported_plugins_and_sensors_are_listed(parse, make_urdf):
    camera = """
  <gazebo reference="base_link">
    <sensor type="camera" name="front_cam">
      <camera><horizontal_fov>1.0</horizontal_fov></camera>
      <plugin name="cam_ctrl" filename="libgazebo_ros_camera.so"/>
    </sensor>
  </gazebo>"""
    other = _gazebo('<plugin name="imu_thing" filename="libhector_gazebo_ros_imu.so"/>'
                    '<plugin name="control" filename="libgazebo_ros_control.so"/>')
    plugins = read_plugins(parse(make_urdf(gazebo=camera + other)))
    assert "sensor front_cam (type camera)" in plugins.unsupported
    assert "plugin imu_thing (libhector_gazebo_ros_imu.so)" in plugins.unsupported
    assert not any("gazebo_ros_control" in item for item in plugins.unsupported)  # done natively
    assert plugins.diff_drive is None and plugins.joint_state is None


def test_second_diff_drive_is_ignored_with_warning(parse, make_urdf):
    first = ('<plugin name="one" filename="libgazebo_ros_diff_drive.so"><leftJoint>left_wheel_joint</leftJoint>'
             '<rightJoint>right_wheel_joint</rightJoint></plugin>')
    second = first.replace('"one"', '"two"').replace("left_wheel_joint", "x")
    plugins = read_plugins(parse(make_urdf(gazebo=_gazebo(first, second))))
    assert plugins.diff_drive.values["left_joints"] == ["left_wheel_joint"]
    assert len(plugins.warnings) == 1 and "'two'" in plugins.warnings[0]


def test_plugin_without_filename(parse, make_urdf):
    model = parse(make_urdf(gazebo=_gazebo('<plugin name="nameless"/>')), "m.urdf")
    with pytest.raises(ModelError) as info:
        read_plugins(model)
    assert "plugin[@name='nameless']" in str(info.value) and "filename" in str(info.value)
