"""controller_cli: controller_manager's spawner, unspawner and controller_manager command lines parsed and
printed as ROS 1 noetic's scripts do.

Pure: no ROS master, no rospy (tests/unit/gazebo/test_cli.py checks the import).
"""
import pytest

from diffbot_sim.gazebo import controller_cli
from diffbot_sim.gazebo.cli import CliError, UsageExit


def test_spawner_defaults():
    a = controller_cli.parse_spawner_args(["joint_state_controller", "velocity_controller"])
    assert a.controllers == ["joint_state_controller", "velocity_controller"]
    assert not a.stopped and a.wait_for is None and a.namespace == ""
    assert a.timeout == 30.0 and a.shutdown_timeout is None


def test_spawner_every_option():
    a = controller_cli.parse_spawner_args(["--stopped", "--wait-for=/ready", "--namespace=/r1", "--timeout=5",
                                       "--shutdown-timeout", "2", "c1", "__name:=spawner", "__log:=/x.log"])
    assert a.controllers == ["c1"] and a.stopped and a.wait_for == "/ready" and a.namespace == "/r1"
    assert a.timeout == 5.0 and a.shutdown_timeout == 2.0


@pytest.mark.parametrize("args", [["--no-timeout", "c"], ["--timeout=0", "c"], ["--timeout", "-1", "c"]])
def test_spawner_waits_forever(args):
    assert controller_cli.parse_spawner_args(args).timeout is None


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
        controller_cli.parse_spawner_args(args)
    assert words in str(err.value)


def test_spawner_help():
    with pytest.raises(UsageExit) as usage:
        controller_cli.parse_spawner_args(["-h"])
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
    assert controller_cli.manager_service(namespace, "load_controller") == expected


def test_controller_type_param():
    assert controller_cli.controller_type_param("", "velocity_controller") == "velocity_controller/type"
    assert controller_cli.controller_type_param("/r1", "jsc") == "/r1/jsc/type"


def test_yaml_file_arguments(tmp_path):
    config = tmp_path / "control.yaml"
    config.write_text("joint_state_controller:\n  type: joint_state_controller/JointStateController\n"
                      "  publish_rate: 50\n"
                      "velocity_controller:\n  type: diff_drive_controller/DiffDriveController\n"
                      "  left_wheel: [l1, l2]\n  pid: {p: 1.0}\n")
    controllers, files = controller_cli.expand_controllers(["first", str(config), "last"])
    assert controllers == ["first", "joint_state_controller", "velocity_controller", "last"]
    assert [path for path, _ in files] == [str(config)]
    leaves = dict(controller_cli.flatten_params(files[0][1]))
    assert leaves == {"joint_state_controller/type": "joint_state_controller/JointStateController",
                      "joint_state_controller/publish_rate": 50,
                      "velocity_controller/type": "diff_drive_controller/DiffDriveController",
                      "velocity_controller/left_wheel": ["l1", "l2"], "velocity_controller/pid/p": 1.0}
    assert dict(controller_cli.flatten_params({"a": {"b": 1}}, "/ns/")) == {"/ns/a/b": 1}


def test_directory_argument_is_a_controller_name(tmp_path, monkeypatch):
    (tmp_path / "velocity_controller").mkdir()
    monkeypatch.chdir(tmp_path)
    assert controller_cli.expand_controllers(["velocity_controller"]) == (["velocity_controller"], [])


@pytest.mark.parametrize("content, words", [("- a\n- b\n", "expected a YAML mapping"), ("a: [1\n", "invalid YAML"),
                                            ("", "expected a YAML mapping")])
def test_bad_yaml_file(tmp_path, content, words):
    config = tmp_path / "bad.yaml"
    config.write_text(content)
    with pytest.raises(CliError) as err:
        controller_cli.expand_controllers([str(config)])
    assert str(err.value).startswith(f"{config}: {words}") and "\n" not in str(err.value)


# ----------------------------------------------------------------------------- unspawner, controller_manager

def test_unspawner_args():
    assert controller_cli.parse_unspawner_args(["a", "b", "__name:=u", "a"]) == ["a", "b"]
    for args in ([], ["-h"], ["--help"], ["__name:=u"]):
        with pytest.raises(UsageExit) as usage:
            controller_cli.parse_unspawner_args(args)
        assert usage.value.status == 1 and "Stops a set of controllers until killed" in usage.value.text


@pytest.mark.parametrize("args, verb, names", [
    (["load", "a", "b"], "load", ["a", "b"]), (["unload", "a"], "unload", ["a"]), (["start", "a"], "start", ["a"]),
    (["stop", "a"], "stop", ["a"]), (["spawn", "a"], "spawn", ["a"]), (["sp", "a"], "spawn", ["a"]),
    (["kill", "a"], "kill", ["a"]), (["kl", "a"], "kill", ["a"]), (["list"], "list", []), (["lc"], "list", []),
    (["list-types"], "list-types", []), (["lt"], "list-types", []), (["load", "a", "__ns:=/r1"], "load", ["a"]),
])
def test_controller_manager_verbs(args, verb, names):
    command = controller_cli.parse_controller_manager_args(args)
    assert (command.verb, command.names) == (verb, names)


def test_controller_manager_reload_and_usage():
    assert controller_cli.parse_controller_manager_args(["reload-libraries"]).restore is False
    assert controller_cli.parse_controller_manager_args(["reload-libraries", "--restore"]).restore is True
    with pytest.raises(UsageExit) as usage:
        controller_cli.parse_controller_manager_args([])
    assert usage.value.status == 0 and "reload-libraries" in usage.value.text
    with pytest.raises(UsageExit) as usage:
        controller_cli.parse_controller_manager_args(["frobnicate", "a"])
    assert usage.value.status == 1


class _Res:
    def __init__(self, hardware_interface):
        self.hardware_interface = hardware_interface


class _State:
    def __init__(self, name, state, interfaces):
        self.name, self.state = name, state
        self.claimed_resources = [_Res(i) for i in interfaces]


def test_controller_manager_printouts():
    assert controller_cli.format_controller_list([]) == ["No controllers are loaded in mechanism control"]
    states = [_State("jsc", "running", ["hardware_interface::JointStateInterface"]),
              _State("vel", "stopped", ["hardware_interface::VelocityJointInterface"] * 2)]
    assert controller_cli.format_controller_list(states) == [
        "'jsc' - 'hardware_interface::JointStateInterface' ( running )",
        "'vel' - 'hardware_interface::VelocityJointInterface' ( stopped )"]
    assert controller_cli.format_switch(True, ["a"], []) == ["Started ['a'] successfully"]
    assert controller_cli.format_switch(True, [], ["a"]) == ["Stopped ['a'] successfully"]
    assert controller_cli.format_switch(False, ["a"], []) == ["Error when starting ['a'] and stopping []"]
    assert controller_cli.format_load(True, "a") == "Loaded 'a'"
    assert controller_cli.format_load(False, "a") == "Error when loading 'a'"
    assert controller_cli.format_unload(True, "a") == "Unloaded 'a' successfully"
    assert controller_cli.format_unload(False, "a") == "Error when unloading 'a'"


# ----------------------------------------------------------------------------- what a node prints and returns

def test_parse_or_status_prints_help_on_stdout_and_errors_on_stderr(capsys):
    args, status = controller_cli.parse_or_status(controller_cli.parse_spawner_args, "spawner",
                                                  ["spawner", "c1", "__name:=s"])
    assert status is None and args.controllers == ["c1"]
    assert controller_cli.parse_or_status(controller_cli.parse_unspawner_args, "unspawner", ["unspawner"]) == \
        (None, 1)
    out, err = capsys.readouterr()
    assert "Stops a set of controllers until killed" in out and err == ""  # noetic: usage on stdout, status 1
    assert controller_cli.parse_or_status(controller_cli.parse_spawner_args, "spawner",
                                          ["spawner", "--timeout=x", "c"]) == (None, 1)
    out, err = capsys.readouterr()
    assert out == "" and err.startswith("spawner: error: --timeout: 'x' is not a number") and err.count("\n") == 1
