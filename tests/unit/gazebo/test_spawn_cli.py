"""spawn_cli: gazebo_ros's spawn_model command line parsed as ROS 1 noetic parses it, and the XML it sends.

Pure: no ROS master, no rospy (tests/unit/gazebo/test_cli.py checks the import).
"""
import math
import xml.etree.ElementTree as ET

import pytest

from diffbot_sim.gazebo import spawn_cli
from diffbot_sim.gazebo.cli import CliError, UsageExit


def spawn(*args, ns="/"):
    return spawn_cli.parse_spawn_args(list(args), default_robot_namespace=ns)


def test_minimal_urdf_param_defaults():
    a = spawn("-urdf", "-param", "robot_description", "-model", "r1")
    assert (a.fmt, a.source, a.source_value, a.model) == ("urdf", "param", "robot_description", "r1")
    assert a.position == (0.0, 0.0, 0.0)
    assert a.orientation == pytest.approx((0.0, 0.0, 0.0, 1.0))
    assert a.joints == [] and a.robot_namespace == "/" and a.reference_frame == ""
    assert a.gazebo_namespace == "/gazebo" and a.spawn_service == "/gazebo/spawn_urdf_model"
    assert not (a.unpause or a.bond or a.package_to_model) and a.wait is None
    assert a.source_label == "-param robot_description"


def test_every_flag():
    a = spawn("-sdf", "-file", "/tmp/m.sdf", "-model", "box", "-x", "1", "-y", "-2.5", "-z", "0.1",
              "-R", "0.1", "-P", "-0.2", "-Y", "1.57", "-J", "left", "0.5", "-J", "right", "-1",
              "-robot_namespace", "/r1", "-unpause", "-wait", "ground_plane", "-reference_frame", "world",
              "-gazebo_namespace", "/sim", "-package_to_model", "-b")
    assert (a.fmt, a.source, a.source_value) == ("sdf", "file", "/tmp/m.sdf")
    assert a.position == (1.0, -2.5, 0.1)
    assert (a.roll, a.pitch, a.yaw) == (0.1, -0.2, 1.57)
    assert a.joints == [("left", 0.5), ("right", -1.0)]
    assert a.robot_namespace == "/r1" and a.unpause and a.wait == "ground_plane"
    assert a.reference_frame == "world" and a.gazebo_namespace == "/sim" and a.package_to_model and a.bond
    assert a.spawn_service == "/sim/spawn_sdf_model"
    assert a.service("set_model_configuration") == "/sim/set_model_configuration"


@pytest.mark.parametrize("args, source, value", [
    (("-file", "a.urdf"), "file", "a.urdf"),
    (("-param", "/r1/robot_description"), "param", "/r1/robot_description"),
    (("-database", "coke_can"), "database", "coke_can"),
    (("-stdin",), "stdin", None),
])
def test_sources(args, source, value):
    a = spawn("-sdf", *args, "-model", "m")
    assert (a.source, a.source_value) == (source, value)


def test_robot_namespace_defaults_to_the_nodes():
    assert spawn("-urdf", "-stdin", "-model", "m", ns="/fleet/").robot_namespace == "/fleet/"
    assert spawn("-urdf", "-stdin", "-model", "m", "-robot_namespace", "", ns="/fleet/").robot_namespace == ""


def test_gazebo_namespace_trailing_slash():
    assert spawn("-urdf", "-stdin", "-model", "m", "-gazebo_namespace", "/gazebo/").spawn_service == \
        "/gazebo/spawn_urdf_model"


@pytest.mark.parametrize("args, words", [
    (("-param", "p", "-model", "m"), "one of the arguments -urdf -sdf is required"),
    (("-urdf", "-model", "m"), "one of the arguments -file -param -database -stdin is required"),
    (("-urdf", "-sdf", "-param", "p", "-model", "m"), "-sdf: not allowed with argument -urdf"),
    (("-urdf", "-param", "p", "-file", "f", "-model", "m"), "-file: not allowed with argument -param"),
    (("-urdf", "-stdin", "-database", "d", "-model", "m"), "not allowed with argument"),
    (("-urdf", "-param", "p"), "the following arguments are required: -model"),
    (("-urdf", "-param", "p", "-model", "m", "extra"), "unrecognized arguments: extra"),
    (("-urdf", "-param", "p", "-model", "m", "-J", "j"), "argument -J: expected 2 arguments"),
    (("-urdf", "-param", "p", "-model", ""), "-model"),
])
def test_bad_command_lines(args, words):
    with pytest.raises(CliError) as err:
        spawn(*args)
    assert words in str(err.value)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("flag", ["-x", "-y", "-z", "-R", "-P", "-Y"])
@pytest.mark.parametrize("value", ["nan", "NaN", "inf", "1e999", "abc", "1,5"])
def test_pose_must_be_finite_numbers(flag, value):
    with pytest.raises(CliError) as err:
        spawn("-urdf", "-param", "p", "-model", "m", flag, value)
    assert str(err.value).startswith(f"{flag}: '{value}'")


def test_pose_dash_words_are_flags_as_upstream():
    """argparse (upstream too) reads '-inf' as an option, not a value: still one line naming the flag."""
    with pytest.raises(CliError) as err:
        spawn("-urdf", "-param", "p", "-model", "m", "-x", "-inf")
    assert str(err.value).startswith("argument -x: expected one argument")
    with pytest.raises(CliError) as err:
        spawn("-urdf", "-param", "p", "-model", "m", "-x=-inf")
    assert str(err.value).startswith("-x: '-inf' is not a finite number")


@pytest.mark.parametrize("value", ["nan", "x"])
def test_joint_position_must_be_a_finite_number(value):
    with pytest.raises(CliError) as err:
        spawn("-urdf", "-param", "p", "-model", "m", "-J", "left_wheel_joint", value)
    assert str(err.value).startswith(f"-J left_wheel_joint: '{value}'")


def test_negative_numbers_are_values_not_flags():
    a = spawn("-urdf", "-param", "p", "-model", "m", "-x", "-1.5", "-Y", "-3.14", "-J", "j", "-0.25")
    assert a.x == -1.5 and a.yaw == -3.14 and a.joints == [("j", -0.25)]


def test_remapping_arguments_ignored():
    a = spawn("-urdf", "-param", "robot_description", "__name:=spawn_urdf", "-model", "r1",
              "__log:=/root/.ros/log/x/spawn_urdf-3.log", "robot_description:=/other", "-x", "2")
    assert a.model == "r1" and a.x == 2.0 and a.source_value == "robot_description"


def test_help():
    with pytest.raises(UsageExit) as usage:
        spawn("-h")
    assert usage.value.status == 0
    for flag in ("-urdf", "-sdf", "-param", "-file", "-database", "-stdin", "-model", "-J", "-robot_namespace",
                 "-unpause", "-wait", "-reference_frame", "-gazebo_namespace", "-package_to_model", "-b"):
        assert flag in usage.value.text


def test_args_orientation_uses_rpy():
    a = spawn("-urdf", "-param", "p", "-model", "m", "-Y", "1.5707963267948966")
    assert a.orientation == pytest.approx((0, 0, math.sqrt(0.5), math.sqrt(0.5)))


def test_database_template():
    text = spawn_cli.database_xml("coke_can")
    root = ET.fromstring(text)
    assert root.tag == "sdf" and root.get("version") == "1.4"
    assert root.find("world").get("name") == "default"
    assert root.find("world/include/uri").text == "model://coke_can"


URDF_MESHES = """<?xml version="1.0"?>
<!-- a comment -->
<robot name="r">
  <link name="a"><visual><geometry><mesh filename="package://my_robot_description/meshes/base.dae"
    scale="1 1 1"/></geometry></visual>
    <collision><geometry><mesh filename="file:///opt/meshes/base.stl"/></geometry></collision></link>
  <link name="b"><visual><geometry><mesh filename="model://already/m.dae"/></geometry></visual>
    <collision><geometry><mesh/></geometry></collision></link>
</robot>"""


def test_package_to_model_rewrites_package_uris_only():
    out = spawn_cli.prepare_model_xml(URDF_MESHES, "-param robot_description", rewrite_package_uris=True)
    meshes = [m.get("filename") for m in ET.fromstring(out).iter("mesh")]
    assert meshes == ["model://my_robot_description/meshes/base.dae", "file:///opt/meshes/base.stl",
                      "model://already/m.dae", None]
    assert 'scale="1 1 1"' in out


def test_package_to_model_off_keeps_text():
    assert spawn_cli.prepare_model_xml(URDF_MESHES, "-file r.urdf") == URDF_MESHES


def test_package_to_model_nothing_to_rewrite_keeps_text():
    text = '<robot name="r"><link name="a"/></robot>'
    assert spawn_cli.prepare_model_xml(text, "-stdin", rewrite_package_uris=True) == text


def test_package_to_model_leaves_sdf_uri_elements():
    sdf = "<sdf version='1.6'><model name='m'><link name='l'><visual name='v'><geometry><mesh>" \
          "<uri>package://p/m.dae</uri></mesh></geometry></visual></link></model></sdf>"
    out = spawn_cli.prepare_model_xml(sdf, "-file m.sdf", rewrite_package_uris=True)
    assert "package://p/m.dae" in out


def test_invalid_xml_names_the_source():
    with pytest.raises(CliError) as err:
        spawn_cli.prepare_model_xml("<robot><link></robot>", "-param /robot_description")
    message = str(err.value)
    assert message.startswith("-param /robot_description: invalid XML: mismatched tag") and "line 1" in message


@pytest.mark.parametrize("text", ["", "   \n", None, 42])
def test_empty_or_non_text_model(text):
    with pytest.raises(CliError) as err:
        spawn_cli.prepare_model_xml(text, "-param robot_description")
    assert str(err.value).startswith("-param robot_description: ")


def test_read_model_file(tmp_path):
    good = tmp_path / "r.urdf"
    good.write_text("<robot name='r'/>")
    assert spawn_cli.read_model_file(str(good)) == "<robot name='r'/>"
    empty = tmp_path / "empty.urdf"
    empty.write_text("")
    for path, words in ((tmp_path / "missing.urdf", "no such file"), (tmp_path, "not a file"),
                        (empty, "the file is empty")):
        with pytest.raises(CliError) as err:
            spawn_cli.read_model_file(str(path))
        assert str(err.value) == f"-file {path}: {words}"
