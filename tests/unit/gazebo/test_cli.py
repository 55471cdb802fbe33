"""gazebo_cli: spawn_model's and controller_manager's command lines parsed as ROS 1 noetic parses them.

Pure: no ROS master, no rospy (the module must not import it).
"""
import math
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

from diffbot_sim.gazebo import cli as gazebo_cli
from diffbot_sim.gazebo.cli import CliError, UsageExit


def spawn(*args, ns="/"):
    return gazebo_cli.parse_spawn_args(list(args), default_robot_namespace=ns)


def test_no_rospy_at_import():
    code = "import sys; import diffbot_sim.gazebo.cli; sys.exit('rospy' in sys.modules)"
    subprocess.run([sys.executable, "-c", code], check=True, cwd=gazebo_cli.__file__.rsplit("/", 2)[0])


# ------------------------------------------------------------------------------------------- spawn_model

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
    assert gazebo_cli.strip_remappings(["a", "b:=c", "__ns:=/x", "d"]) == ["a", "d"]


def test_help():
    with pytest.raises(UsageExit) as usage:
        spawn("-h")
    assert usage.value.status == 0
    for flag in ("-urdf", "-sdf", "-param", "-file", "-database", "-stdin", "-model", "-J", "-robot_namespace",
                 "-unpause", "-wait", "-reference_frame", "-gazebo_namespace", "-package_to_model", "-b"):
        assert flag in usage.value.text


@pytest.mark.parametrize("rpy, expected", [
    ((0, 0, math.pi / 2), (0, 0, math.sqrt(0.5), math.sqrt(0.5))),
    ((math.pi, 0, 0), (1, 0, 0, 0)),
    ((0, math.pi / 2, 0), (0, math.sqrt(0.5), 0, math.sqrt(0.5))),
    # tf.transformations.quaternion_from_euler(0.1, 0.2, 0.3) (axes 'sxyz'; scipy from_euler("xyz") agrees)
    ((0.1, 0.2, 0.3), (0.034270798550482096, 0.10602051106179562, 0.1435721750273919, 0.9833474432563558)),
])
def test_quaternion_as_tf(rpy, expected):
    assert gazebo_cli.quaternion_from_euler(*rpy) == pytest.approx(expected, abs=1e-12)


def test_quaternion_is_static_axes_rotation():
    """Static xyz: R = Rz(yaw) Ry(pitch) Rx(roll); compare with the matrix of the quaternion."""
    r, p, y = 0.3, -0.4, 1.1
    qx, qy, qz, qw = gazebo_cli.quaternion_from_euler(r, p, y)
    m_q = [[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
           [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
           [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]]
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    m = [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
         [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
         [-sp, cp * sr, cp * cr]]
    for row_q, row in zip(m_q, m):
        assert row_q == pytest.approx(row, abs=1e-12)


def test_args_orientation_uses_rpy():
    a = spawn("-urdf", "-param", "p", "-model", "m", "-Y", "1.5707963267948966")
    assert a.orientation == pytest.approx((0, 0, math.sqrt(0.5), math.sqrt(0.5)))


def test_database_template():
    text = gazebo_cli.database_xml("coke_can")
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
    out = gazebo_cli.prepare_model_xml(URDF_MESHES, "-param robot_description", rewrite_package_uris=True)
    meshes = [m.get("filename") for m in ET.fromstring(out).iter("mesh")]
    assert meshes == ["model://my_robot_description/meshes/base.dae", "file:///opt/meshes/base.stl",
                      "model://already/m.dae", None]
    assert 'scale="1 1 1"' in out


def test_package_to_model_off_keeps_text():
    assert gazebo_cli.prepare_model_xml(URDF_MESHES, "-file r.urdf") == URDF_MESHES


def test_package_to_model_nothing_to_rewrite_keeps_text():
    text = '<robot name="r"><link name="a"/></robot>'
    assert gazebo_cli.prepare_model_xml(text, "-stdin", rewrite_package_uris=True) == text


def test_package_to_model_leaves_sdf_uri_elements():
    sdf = "<sdf version='1.6'><model name='m'><link name='l'><visual name='v'><geometry><mesh>" \
          "<uri>package://p/m.dae</uri></mesh></geometry></visual></link></model></sdf>"
    out = gazebo_cli.prepare_model_xml(sdf, "-file m.sdf", rewrite_package_uris=True)
    assert "package://p/m.dae" in out


def test_invalid_xml_names_the_source():
    with pytest.raises(CliError) as err:
        gazebo_cli.prepare_model_xml("<robot><link></robot>", "-param /robot_description")
    message = str(err.value)
    assert message.startswith("-param /robot_description: invalid XML: mismatched tag") and "line 1" in message


@pytest.mark.parametrize("text", ["", "   \n", None, 42])
def test_empty_or_non_text_model(text):
    with pytest.raises(CliError) as err:
        gazebo_cli.prepare_model_xml(text, "-param robot_description")
    assert str(err.value).startswith("-param robot_description: ")


def test_read_model_file(tmp_path):
    good = tmp_path / "r.urdf"
    good.write_text("<robot name='r'/>")
    assert gazebo_cli.read_model_file(str(good)) == "<robot name='r'/>"
    empty = tmp_path / "empty.urdf"
    empty.write_text("")
    for path, words in ((tmp_path / "missing.urdf", "no such file"), (tmp_path, "not a file"),
                        (empty, "the file is empty")):
        with pytest.raises(CliError) as err:
            gazebo_cli.read_model_file(str(path))
        assert str(err.value) == f"-file {path}: {words}"


# ------------------------------------------------------------------------------------------- spawner

def test_spawner_defaults():
    a = gazebo_cli.parse_spawner_args(["joint_state_controller", "velocity_controller"])
    assert a.controllers == ["joint_state_controller", "velocity_controller"]
    assert not a.stopped and a.wait_for is None and a.namespace == ""
    assert a.timeout == 30.0 and a.shutdown_timeout is None


def test_spawner_every_option():
    a = gazebo_cli.parse_spawner_args(["--stopped", "--wait-for=/ready", "--namespace=/r1", "--timeout=5",
                                       "--shutdown-timeout", "2", "c1", "__name:=spawner", "__log:=/x.log"])
    assert a.controllers == ["c1"] and a.stopped and a.wait_for == "/ready" and a.namespace == "/r1"
    assert a.timeout == 5.0 and a.shutdown_timeout == 2.0


@pytest.mark.parametrize("args", [["--no-timeout", "c"], ["--timeout=0", "c"], ["--timeout", "-1", "c"]])
def test_spawner_waits_forever(args):
    assert gazebo_cli.parse_spawner_args(args).timeout is None


@pytest.mark.parametrize("args, words", [
    ([], "the following arguments are required: controller"),
    (["__name:=spawner"], "the following arguments are required: controller"),
    (["--timeout=abc", "c"], "--timeout: 'abc' is not a number"),
    (["--timeout=nan", "c"], "--timeout: 'nan' is not a finite number"),
    (["--shutdown-timeout=x", "c"], "--shutdown-timeout: 'x'"),
    (["--bogus", "c"], "unrecognized arguments: --bogus"),
])
def test_spawner_bad_args(args, words):
    with pytest.raises(CliError) as err:
        gazebo_cli.parse_spawner_args(args)
    assert words in str(err.value)


def test_spawner_help():
    with pytest.raises(UsageExit) as usage:
        gazebo_cli.parse_spawner_args(["-h"])
    assert usage.value.status == 0
    for option in ("--stopped", "--wait-for", "--namespace", "--timeout", "--no-timeout", "--shutdown-timeout"):
        assert option in usage.value.text


@pytest.mark.parametrize("namespace, expected", [
    ("", "controller_manager/load_controller"),
    ("/r1", "/r1/controller_manager/load_controller"),
    ("/r1/", "/r1/controller_manager/load_controller"),
    ("r1", "r1/controller_manager/load_controller"),
])
def test_manager_service_names(namespace, expected):
    assert gazebo_cli.manager_service(namespace, "load_controller") == expected


def test_controller_type_param():
    assert gazebo_cli.controller_type_param("", "velocity_controller") == "velocity_controller/type"
    assert gazebo_cli.controller_type_param("/r1", "jsc") == "/r1/jsc/type"


def test_yaml_file_arguments(tmp_path):
    config = tmp_path / "control.yaml"
    config.write_text("joint_state_controller:\n  type: joint_state_controller/JointStateController\n"
                      "  publish_rate: 50\n"
                      "velocity_controller:\n  type: diff_drive_controller/DiffDriveController\n"
                      "  left_wheel: [l1, l2]\n  pid: {p: 1.0}\n")
    controllers, files = gazebo_cli.expand_controllers(["first", str(config), "last"])
    assert controllers == ["first", "joint_state_controller", "velocity_controller", "last"]
    assert [path for path, _ in files] == [str(config)]
    leaves = dict(gazebo_cli.flatten_params(files[0][1]))
    assert leaves == {"joint_state_controller/type": "joint_state_controller/JointStateController",
                      "joint_state_controller/publish_rate": 50,
                      "velocity_controller/type": "diff_drive_controller/DiffDriveController",
                      "velocity_controller/left_wheel": ["l1", "l2"], "velocity_controller/pid/p": 1.0}
    assert dict(gazebo_cli.flatten_params({"a": {"b": 1}}, "/ns/")) == {"/ns/a/b": 1}


def test_directory_argument_is_a_controller_name(tmp_path, monkeypatch):
    (tmp_path / "velocity_controller").mkdir()
    monkeypatch.chdir(tmp_path)
    assert gazebo_cli.expand_controllers(["velocity_controller"]) == (["velocity_controller"], [])


@pytest.mark.parametrize("content, words", [("- a\n- b\n", "expected a YAML mapping"), ("a: [1\n", "invalid YAML"),
                                            ("", "expected a YAML mapping")])
def test_bad_yaml_file(tmp_path, content, words):
    config = tmp_path / "bad.yaml"
    config.write_text(content)
    with pytest.raises(CliError) as err:
        gazebo_cli.expand_controllers([str(config)])
    assert str(err.value).startswith(f"{config}: {words}") and "\n" not in str(err.value)


# ----------------------------------------------------------------------------- unspawner, controller_manager

def test_unspawner_args():
    assert gazebo_cli.parse_unspawner_args(["a", "b", "__name:=u", "a"]) == ["a", "b"]
    for args in ([], ["-h"], ["--help"], ["__name:=u"]):
        with pytest.raises(UsageExit) as usage:
            gazebo_cli.parse_unspawner_args(args)
        assert usage.value.status == 1 and "Stops a set of controllers until killed" in usage.value.text


@pytest.mark.parametrize("args, verb, names", [
    (["load", "a", "b"], "load", ["a", "b"]), (["unload", "a"], "unload", ["a"]), (["start", "a"], "start", ["a"]),
    (["stop", "a"], "stop", ["a"]), (["spawn", "a"], "spawn", ["a"]), (["sp", "a"], "spawn", ["a"]),
    (["kill", "a"], "kill", ["a"]), (["kl", "a"], "kill", ["a"]), (["list"], "list", []), (["lc"], "list", []),
    (["list-types"], "list-types", []), (["lt"], "list-types", []), (["load", "a", "__ns:=/r1"], "load", ["a"]),
])
def test_controller_manager_verbs(args, verb, names):
    command = gazebo_cli.parse_controller_manager_args(args)
    assert (command.verb, command.names) == (verb, names)


def test_controller_manager_reload_and_usage():
    assert gazebo_cli.parse_controller_manager_args(["reload-libraries"]).restore is False
    assert gazebo_cli.parse_controller_manager_args(["reload-libraries", "--restore"]).restore is True
    with pytest.raises(UsageExit) as usage:
        gazebo_cli.parse_controller_manager_args([])
    assert usage.value.status == 0 and "reload-libraries" in usage.value.text
    with pytest.raises(UsageExit) as usage:
        gazebo_cli.parse_controller_manager_args(["frobnicate", "a"])
    assert usage.value.status == 1


class _Res:
    def __init__(self, hardware_interface):
        self.hardware_interface = hardware_interface


class _State:
    def __init__(self, name, state, interfaces):
        self.name, self.state = name, state
        self.claimed_resources = [_Res(i) for i in interfaces]


def test_controller_manager_printouts():
    assert gazebo_cli.format_controller_list([]) == ["No controllers are loaded in mechanism control"]
    states = [_State("jsc", "running", ["hardware_interface::JointStateInterface"]),
              _State("vel", "stopped", ["hardware_interface::VelocityJointInterface"] * 2)]
    assert gazebo_cli.format_controller_list(states) == [
        "'jsc' - 'hardware_interface::JointStateInterface' ( running )",
        "'vel' - 'hardware_interface::VelocityJointInterface' ( stopped )"]
    assert gazebo_cli.format_switch(True, ["a"], []) == ["Started ['a'] successfully"]
    assert gazebo_cli.format_switch(True, [], ["a"]) == ["Stopped ['a'] successfully"]
    assert gazebo_cli.format_switch(False, ["a"], []) == ["Error when starting ['a'] and stopping []"]
    assert gazebo_cli.format_load(True, "a") == "Loaded 'a'"
    assert gazebo_cli.format_load(False, "a") == "Error when loading 'a'"
    assert gazebo_cli.format_unload(True, "a") == "Unloaded 'a' successfully"
    assert gazebo_cli.format_unload(False, "a") == "Error when unloading 'a'"
