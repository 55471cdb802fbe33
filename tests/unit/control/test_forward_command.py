"""forward_command.py: forward_command_controller typedefs and the effort/velocity PID controllers."""
import math

import pytest

from diffbot_sim.control.forward_command import (
    CONTROLLER_TYPES,
    ForwardCommandCore,
    JointControllerState,
    JointSpec,
    PidPositionCore,
    PidVelocityCore,
    clamp_to_urdf_limits,
    dimension_error,
    forward_config,
    make_core,
    position_error,
)
from diffbot_sim.control.pid import PidGains
from diffbot_sim.description.urdf_model import Joint
from diffbot_sim.errors import ConfigError

NS = "/arm_controller"
MODEL = {"shoulder": ("revolute", -1.0, 1.0), "wrist": ("continuous", 0.0, 0.0),
         "slider": ("prismatic", 0.0, 0.5), "finger": ("revolute", -4.0, 4.0)}


def test_controller_types_and_interfaces():
    assert CONTROLLER_TYPES == {
        "position_controllers/JointGroupPositionController": "PositionJointInterface",
        "velocity_controllers/JointGroupVelocityController": "VelocityJointInterface",
        "effort_controllers/JointGroupEffortController": "EffortJointInterface",
        "position_controllers/JointPositionController": "PositionJointInterface",
        "velocity_controllers/JointVelocityController": "VelocityJointInterface",
        "effort_controllers/JointEffortController": "EffortJointInterface",
        "effort_controllers/JointPositionController": "EffortJointInterface",
        "effort_controllers/JointGroupPositionController": "EffortJointInterface",
        "velocity_controllers/JointPositionController": "VelocityJointInterface",
        "effort_controllers/JointVelocityController": "EffortJointInterface",
    }


# ---- parameters -------------------------------------------------------------------------------------------

def test_group_config():
    config = forward_config({"type": "x", "joints": ["shoulder", "wrist"]}, NS + "/",
                            "position_controllers/JointGroupPositionController", set(MODEL))
    assert (config.name, config.kind, config.single, config.joints) == (NS, "position", False,
                                                                        ("shoulder", "wrist"))
    assert config.interface == "PositionJointInterface" and config.gains == ()


@pytest.mark.parametrize("joints", [None, "shoulder", [], ["shoulder", 3], [""]])
def test_group_bad_joints(joints):
    with pytest.raises(ConfigError) as err:
        forward_config({"joints": joints}, NS, "velocity_controllers/JointGroupVelocityController", MODEL)
    assert err.value.name == NS + "/joints"


def test_joint_not_in_model():
    with pytest.raises(ConfigError) as err:
        forward_config({"joints": ["shoulder", "elbow"]}, NS, "effort_controllers/JointGroupEffortController",
                       MODEL)
    assert err.value.name == NS + "/joints" and err.value.value == "elbow"
    with pytest.raises(ConfigError) as err:
        forward_config({"joint": "elbow"}, NS, "effort_controllers/JointEffortController", MODEL)
    assert err.value.name == NS + "/joint"


@pytest.mark.parametrize("joint", [None, "", 5])
def test_single_bad_joint(joint):
    with pytest.raises(ConfigError) as err:
        forward_config({"joint": joint}, NS, "position_controllers/JointPositionController", MODEL)
    assert err.value.name == NS + "/joint"


def test_unknown_type_and_bad_namespace():
    with pytest.raises(ConfigError) as err:
        forward_config({"joint": "shoulder"}, NS, "position_controllers/JointTrajectoryController", MODEL)
    assert err.value.name == NS + "/type"
    with pytest.raises(ConfigError) as err:
        forward_config("shoulder", NS, "position_controllers/JointPositionController", MODEL)
    assert err.value.name == NS


def test_pid_config_single_and_group():
    config = forward_config({"joint": "shoulder", "pid": {"p": 100.0, "d": 10.0, "i_clamp": 2.0}}, NS,
                            "effort_controllers/JointPositionController", MODEL)
    assert config.gains == (PidGains(p=100.0, d=10.0, i_clamp_max=2.0, i_clamp_min=-2.0),)
    assert config.pid_namespaces == (NS + "/pid",)
    assert config.specs == (JointSpec("shoulder", "revolute", -1.0, 1.0),)
    assert config.publish_pid_state == (False,)
    params = {"joints": ["shoulder", "slider"], "shoulder": {"pid": {"p": 5.0, "publish_state": True}},
              "slider": {"pid": {"p": 7.0}}}
    config = forward_config(params, NS, "effort_controllers/JointGroupPositionController", MODEL)
    assert [g.p for g in config.gains] == [5.0, 7.0]
    assert config.pid_namespaces == (NS + "/shoulder/pid", NS + "/slider/pid")
    assert config.publish_pid_state == (True, False)


def test_pid_config_accepts_urdf_joints():
    model = {"slider": Joint("slider", "prismatic", "a", "b", has_limit=True, lower=-0.1, upper=0.2)}
    config = forward_config({"joint": "slider", "pid": {"p": 1.0}}, NS,
                            "velocity_controllers/JointPositionController", model)
    assert config.specs == (JointSpec("slider", "prismatic", -0.1, 0.2),)
    assert config.interface == "VelocityJointInterface"


def test_pid_missing_p_names_the_gain():
    with pytest.raises(ConfigError) as err:
        forward_config({"joint": "shoulder", "pid": {"i": 1.0}}, NS, "effort_controllers/JointPositionController",
                       MODEL)
    assert err.value.name == NS + "/pid/p"
    assert "No p gain specified for pid.  Namespace: /arm_controller/pid" in str(err.value)
    with pytest.raises(ConfigError) as err:
        forward_config({"joints": ["shoulder", "slider"], "shoulder": {"pid": {"p": 1.0}}}, NS,
                       "effort_controllers/JointGroupPositionController", MODEL)
    assert err.value.name == NS + "/slider/pid/p"


def test_pid_bad_gain_and_bad_joint_namespace():
    with pytest.raises(ConfigError) as err:
        forward_config({"joint": "wrist", "pid": {"p": 1.0, "d": "x"}}, NS,
                       "effort_controllers/JointVelocityController", {"wrist"})
    assert err.value.name == NS + "/pid/d"
    with pytest.raises(ConfigError) as err:
        forward_config({"joints": ["shoulder"], "shoulder": 3}, NS,
                       "effort_controllers/JointGroupPositionController", MODEL)
    assert err.value.name == NS + "/shoulder"


def test_pid_position_needs_a_model_mapping():
    with pytest.raises(ValueError):
        forward_config({"joint": "shoulder", "pid": {"p": 1.0}}, NS, "effort_controllers/JointPositionController",
                       set(MODEL))


# ---- forwarding -------------------------------------------------------------------------------------------

def group(controller_type, joints=("shoulder", "wrist")):
    return make_core(forward_config({"joints": list(joints)}, NS, controller_type, MODEL))


def test_group_position_starts_at_current_positions_and_forwards():
    core = group("position_controllers/JointGroupPositionController")
    assert isinstance(core, ForwardCommandCore)
    core.start([0.3, -2.0])
    assert core.update([0.0, 0.0], [0.0, 0.0], 0.01) == [0.3, -2.0]
    assert core.command([0.5, 0.6]) is None
    assert core.update([0.0, 0.0], [0.0, 0.0], 0.01) == [0.5, 0.6]
    assert core.update([9.0, 9.0], [1.0, 1.0], 0.01) == [0.5, 0.6]  # re-sent every update


def test_group_dimension_mismatch_keeps_the_old_command():
    core = group("velocity_controllers/JointGroupVelocityController")
    core.start([0.3, -2.0])
    assert core.update([0.3, -2.0], [0.0, 0.0], 0.01) == [0.0, 0.0]
    core.command([1.0, 2.0])
    assert core.command([1.0, 2.0, 3.0]) == ("Dimension of command (3) does not match number of joints (2)! "
                                             "Not executing!")
    assert core.command([]) == dimension_error(0, 2)
    assert core.update([0.0, 0.0], [0.0, 0.0], 0.01) == [1.0, 2.0]


def test_velocity_and_effort_restart_from_zero():
    core = group("effort_controllers/JointGroupEffortController")
    core.command([4.0, 5.0])
    core.start([1.0, 1.0])
    assert core.update([1.0, 1.0], [0.0, 0.0], 0.01) == [0.0, 0.0]


@pytest.mark.parametrize("controller_type, start", [
    ("position_controllers/JointPositionController", 0.7),
    ("velocity_controllers/JointVelocityController", 0.0),
    ("effort_controllers/JointEffortController", 0.0),
])
def test_single_forwarding(controller_type, start):
    core = make_core(forward_config({"joint": "slider"}, NS, controller_type, MODEL))
    core.start([0.7])
    assert core.update([0.7], [0.0], 0.01) == [start]
    assert core.command(2.5) is None
    assert core.update([0.7], [0.0], 0.01) == [2.5]


# ---- PID position -----------------------------------------------------------------------------------------

def pid_core(joint, gains, controller_type="effort_controllers/JointPositionController"):
    return make_core(forward_config({"joint": joint, "pid": gains}, NS, controller_type, MODEL))


def test_clamp_and_error_rules():
    revolute = JointSpec("r", "revolute", -1.0, 1.0)
    assert clamp_to_urdf_limits(revolute, 2.0) == 1.0 and clamp_to_urdf_limits(revolute, -2.0) == -1.0
    assert clamp_to_urdf_limits(JointSpec("c", "continuous"), 10.0) == 10.0
    assert clamp_to_urdf_limits(JointSpec("p", "prismatic", 0.0, 0.5), -0.1) == 0.0
    # continuous: the short way round; prismatic: plain difference
    assert position_error(JointSpec("c", "continuous"), 3.0, -3.0) == pytest.approx(2 * math.pi - 6.0)
    assert position_error(JointSpec("p", "prismatic", 0.0, 0.5), 0.1, 0.4) == pytest.approx(0.3)
    # revolute [-3.2, 3.2]: from 3 to -3 the short way (+0.28) would leave the range at 3.28 -> -6 instead;
    # with [-4, 4] the short way fits
    assert position_error(JointSpec("f", "revolute", -3.2, 3.2), 3.0, -3.0) == pytest.approx(-6.0)
    assert position_error(JointSpec("f", "revolute", -4.0, 4.0), 3.0, -3.0) == pytest.approx(2 * math.pi - 6.0)
    assert position_error(JointSpec("f", "revolute", -4.0, 4.0), 1.0, 1.5) == pytest.approx(0.5)
    # floating/planar/fixed fall into upstream's "prismatic" branch
    assert position_error(JointSpec("x", "fixed"), 1.0, 3.0) == 2.0


def test_pid_position_start_clamps_and_holds():
    core = pid_core("shoulder", {"p": 10.0})
    assert isinstance(core, PidPositionCore)
    core.start([1.2])  # beyond the upper limit 1.0: holds 1.0
    assert core.commands == [1.0]
    # error 1.0 - 1.2 = -0.2 -> -2.0
    assert core.update([1.2], [0.0], 0.01) == [pytest.approx(-2.0)]


def test_pid_position_command_clamped_each_update():
    core = pid_core("shoulder", {"p": 10.0, "d": 0.1})
    core.start([0.0])
    core.update([0.0], [0.0], 0.01)
    core.command(5.0)  # clamped to 1.0 at update; the stored command stays 5.0
    # error 1.0; derivative (1.0 - 0)/0.01 = 100 -> 10 + 0.1·100 = 20
    assert core.update([0.0], [0.0], 0.01) == [pytest.approx(20.0)]
    assert core.commands == [5.0]


def test_pid_position_restart_resets_the_pid():
    core = pid_core("wrist", {"p": 1.0, "d": 1.0})
    core.start([0.0])
    core.command(0.5)
    core.update([0.0], [0.0], 0.1)  # first call after reset: kick d·0.5/0.1 = 5
    assert core.update([0.0], [0.0], 0.1) == [pytest.approx(0.5)]
    core.start([0.2])  # holds 0.2, PID reset
    assert core.update([0.0], [0.0], 0.1) == [pytest.approx(0.2 + 2.0)]


def test_group_pid_position_per_joint_rules():
    params = {"joints": ["wrist", "slider"], "wrist": {"pid": {"p": 2.0}}, "slider": {"pid": {"p": 100.0}}}
    core = make_core(forward_config(params, NS, "effort_controllers/JointGroupPositionController", MODEL))
    core.start([0.0, 0.0])
    assert core.command([3.0, 0.7]) is None  # slider clamped to 0.5
    efforts = core.update([-3.0, 0.1], [0.0, 0.0], 0.01)
    assert efforts == [pytest.approx(2.0 * (6.0 - 2 * math.pi)), pytest.approx(100.0 * 0.4)]
    assert core.command([1.0]) == dimension_error(1, 2)
    assert core.state is None  # only the single controllers publish a state


def test_single_pid_state_every_tenth_update():
    core = pid_core("slider", {"p": 2.0, "i": 1.0, "i_clamp": 0.5, "antiwindup": True})
    core.start([0.1])
    core.command(0.3)
    core.update([0.1], [0.05], 0.01)
    assert core.state == JointControllerState(set_point=0.3, process_value=0.1, process_value_dot=0.05,
                                              error=pytest.approx(0.2), time_step=0.01,
                                              command=pytest.approx(0.4 + 0.002), p=2.0, i=1.0, d=0.0,
                                              i_clamp=0.5, antiwindup=True)
    for _ in range(9):
        core.update([0.1], [0.0], 0.01)
        assert core.state is None
    core.update([0.1], [0.0], 0.01)
    assert core.state is not None and core.loop_count == 11


# ---- PID velocity -----------------------------------------------------------------------------------------

def test_effort_joint_velocity_controller():
    config = forward_config({"joint": "wrist", "pid": {"p": 3.0}}, NS, "effort_controllers/JointVelocityController",
                            {"wrist"})
    core = make_core(config)
    assert isinstance(core, PidVelocityCore)
    core.command(4.0)
    core.start([0.0])  # command back to 0
    assert core.update([0.0], [0.5], 0.01) == [pytest.approx(-1.5)]
    core.command(2.0)
    assert core.update([0.0], [0.5], 0.01) == [pytest.approx(4.5)]
    assert core.state is None  # second update
    core.start([0.0])
    assert core.loop_count == 2


def test_velocity_controller_state_fields():
    core = make_core(forward_config({"joint": "wrist", "pid": {"p": 3.0}}, NS,
                                    "effort_controllers/JointVelocityController", {"wrist"}))
    core.start([0.0])
    core.command(1.0)
    core.update([0.4], [0.5], 0.02)
    state = core.state
    assert (state.set_point, state.process_value, state.process_value_dot) == (1.0, 0.5, 0.0)
    assert state.error == pytest.approx(0.5) and state.command == pytest.approx(1.5) and state.time_step == 0.02
