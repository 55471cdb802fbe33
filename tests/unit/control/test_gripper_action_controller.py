"""gripper_action_controller.py: parameters, goals, success before stall, stall abort, cancel, both variants."""
import math

import pytest

from diffbot_sim.control.gripper_action_controller import (
    ABORTED,
    EFFORT_TYPE,
    NO_GAINS_WARNING,
    NOT_RUNNING,
    POSITION_TYPE,
    SUCCEEDED,
    GripperActionCore,
    GripperResult,
    gripper_action_config,
    is_finite_goal,
)
from diffbot_sim.control.pid import PidGains
from diffbot_sim.errors import ConfigError

NS = "/gripper_controller"


def core(params=None, controller_type=POSITION_TYPE, time=0.0, position=0.0):
    config = gripper_action_config({"joint": "finger", **(params or {})}, NS, controller_type)
    gripper = GripperActionCore(config)
    gripper.starting(time, position)
    return gripper


# ------------------------------------------------------------------------------------------------ config

def test_defaults_are_upstreams():
    config = gripper_action_config({"joint": " finger "}, NS + "/", POSITION_TYPE)
    assert (config.name, config.variant, config.joint) == (NS, "position", "finger")
    assert (config.goal_tolerance, config.max_effort, config.stall_velocity_threshold, config.stall_timeout,
            config.action_monitor_rate) == (0.01, 0.0, 0.001, 1.0, 20.0)
    assert config.action_monitor_period == pytest.approx(0.05)
    assert config.gains is None and config.warnings == ()


def test_tolerance_and_max_effort_taken_as_absolute_values_ints_accepted():
    config = gripper_action_config({"joint": "f", "goal_tolerance": -0.02, "max_effort": -5, "stall_timeout": 2,
                                    "stall_velocity_threshold": -1.0}, NS, POSITION_TYPE)
    assert (config.goal_tolerance, config.max_effort, config.stall_timeout) == (0.02, 5.0, 2.0)
    assert config.stall_velocity_threshold == -1.0  # upstream does not take |.| of this one


@pytest.mark.parametrize("params, culprit", [
    ({}, "/gripper_controller/joint"),
    ({"joint": ""}, "/gripper_controller/joint"),
    ({"joint": ["a", "b"]}, "/gripper_controller/joint"),
    ({"joint": "f", "stall_timeout": "long"}, "/gripper_controller/stall_timeout"),
    ({"joint": "f", "goal_tolerance": math.nan}, "/gripper_controller/goal_tolerance"),
    ({"joint": "f", "action_monitor_rate": 0}, "/gripper_controller/action_monitor_rate"),
    ({"joint": "f", "gains": 3}, "/gripper_controller/gains"),
    ({"joint": "f", "gains": {"f": {"p": "x"}}}, "/gripper_controller/gains/f/p"),
])
def test_bad_parameters_name_the_parameter(params, culprit):
    with pytest.raises(ConfigError) as err:
        gripper_action_config(params, NS, EFFORT_TYPE)
    assert err.value.name == culprit


def test_unknown_type_is_refused():
    with pytest.raises(ConfigError, match="GripperActionController"):
        gripper_action_config({"joint": "f"}, NS, "gripper_action_controller/GripperActionController")


def test_effort_variant_reads_gains_of_its_joint():
    config = gripper_action_config({"joint": "f", "gains": {"f": {"p": 200, "d": 1, "i": 5, "i_clamp": 1}}},
                                   NS, EFFORT_TYPE)
    assert config.variant == "effort"
    assert config.gains == PidGains(p=200, i=5, d=1, i_clamp_max=1, i_clamp_min=-1)
    assert config.warnings == ()


def test_effort_variant_without_gains_loads_with_upstreams_two_lines_and_never_pushes():
    gripper = core({"max_effort": 10, "gains": {"other": {"p": 5}}}, EFFORT_TYPE)
    assert gripper.config.gains is None
    assert gripper.config.warnings == (
        "No p gain specified for pid.  Namespace: /gripper_controller/gains/finger", NO_GAINS_WARNING)
    gripper.goal("g", 1.0, 10.0, 0.0)
    assert gripper.update(0.1, 0.1, 0.0, 0.0).command == 0.0


def test_position_variant_ignores_gains():
    config = gripper_action_config({"joint": "f"}, NS, POSITION_TYPE)
    assert config.gains is None and config.warnings == ()


# ------------------------------------------------------------------------------------------------ position variant

def test_starting_holds_current_position_with_default_max_effort():
    gripper = core({"max_effort": -3.0}, position=0.02)
    out = gripper.update(0.01, 0.01, 0.05, 0.0)
    assert (out.command, out.effort, out.events) == (0.02, 3.0, ())


def test_goal_commands_position_and_reports_goal_max_effort_as_sent():
    gripper = core()
    assert gripper.goal("g", 0.5, -7.0, 0.0) is None
    out = gripper.update(0.01, 0.01, 0.1, 0.2)
    assert (out.command, out.effort, out.events) == (0.5, -7.0, ())


def test_goal_reached_succeeds_with_previous_updates_effort():
    gripper = core({"max_effort": 2.0})
    gripper.update(0.0, 0.01, 0.0, 0.0)  # computed command: the default 2.0
    gripper.goal("g", 0.5, 7.0, 0.0)
    assert gripper.update(0.01, 0.01, 0.40, 1.0).events == ()  # computed command becomes 7.0
    out = gripper.update(0.02, 0.01, 0.495, 1.0)
    assert out.events == (("g", SUCCEEDED, GripperResult(position=0.495, effort=7.0, stalled=False,
                                                         reached_goal=True)),)
    assert out.command == 0.5  # the command stays applied
    assert gripper.active_goal is None
    assert gripper.update(0.03, 0.01, 0.495, 0.0).events == ()


def test_goal_check_runs_before_the_new_command_is_computed():
    gripper = core({"max_effort": 2.0})
    gripper.update(0.0, 0.01, 0.0, 0.0)
    gripper.goal("g", 0.0, 9.0, 0.0)  # already there
    (event,) = gripper.update(0.01, 0.01, 0.0, 0.0).events
    assert event.outcome == SUCCEEDED and event.result.effort == 2.0  # not the goal's 9.0


def test_goal_tolerance_is_strict():
    gripper = core({"goal_tolerance": 0.25})
    gripper.goal("g", 1.0, 1.0, 0.0)
    assert gripper.update(0.01, 0.01, 0.75, 1.0).events == ()
    assert gripper.update(0.02, 0.01, 0.7500001, 1.0).events[0].outcome == SUCCEEDED


def test_stall_aborts_with_stalled_true_after_timeout_since_goal():
    gripper = core({"stall_timeout": 0.5, "stall_velocity_threshold": 0.01}, time=0.0)
    gripper.goal("g", 0.0, 1.0, 10.0)  # closing on an object: stuck at 0.03
    assert gripper.update(10.25, 0.01, 0.03, 0.0).events == ()
    assert gripper.update(10.5, 0.01, 0.03, 0.01).events == ()  # exactly the timeout, |v| == threshold
    (event,) = gripper.update(10.75, 0.01, 0.03, -0.005).events
    assert event == ("g", ABORTED, GripperResult(position=0.03, effort=1.0, stalled=True, reached_goal=False))
    assert gripper.update(20.0, 0.01, 0.03, 0.0).events == ()


def test_motion_refreshes_the_stall_timer():
    gripper = core({"stall_timeout": 0.5})
    gripper.goal("g", 0.0, 1.0, 0.0)
    gripper.update(0.4, 0.01, 0.5, -0.002)  # moving: last movement 0.4
    assert gripper.update(0.8, 0.01, 0.5, 0.0).events == ()
    assert gripper.update(0.95, 0.01, 0.5, 0.0).events[0].outcome == ABORTED


def test_success_is_checked_before_stall():
    gripper = core({"stall_timeout": 0.5})
    gripper.goal("g", 0.1, 1.0, 0.0)
    (event,) = gripper.update(5.0, 0.01, 0.105, 0.0).events
    assert event.outcome == SUCCEEDED and not event.result.stalled


def test_no_goal_no_events_and_no_stall():
    gripper = core({"stall_timeout": 0.1})
    assert gripper.update(100.0, 0.01, 1.0, 0.0).events == ()


def test_new_goal_preempts_the_active_one():
    gripper = core()
    gripper.goal("a", 0.5, 1.0, 0.0)
    assert gripper.goal("b", 0.2, 2.0, 0.1) == "a"
    assert gripper.active_goal == "b"
    assert gripper.cancel("a", 0.2) is False
    assert gripper.update(0.3, 0.01, 0.0, 0.0).command == 0.2


def test_cancel_holds_current_position_with_default_max_effort():
    gripper = core({"max_effort": 4.0})
    gripper.goal("g", 0.5, 9.0, 0.0)
    gripper.update(0.01, 0.01, 0.3, 1.0)
    assert gripper.cancel("g", 0.02) is True
    out = gripper.update(0.03, 0.01, 0.31, 1.0)
    assert (out.command, out.effort, out.events) == (0.3, 4.0, ())  # last measured position
    gripper.goal("h", 0.5, 9.0, 0.04)
    assert gripper.cancel("h", 0.05, position=0.33) is True
    assert gripper.update(0.06, 0.01, 0.33, 0.0).command == 0.33


def test_goal_refused_when_not_running_and_stopping_cancels_active_goal():
    gripper = GripperActionCore(gripper_action_config({"joint": "f"}, NS, POSITION_TYPE))
    with pytest.raises(RuntimeError, match=NOT_RUNNING):
        gripper.goal("g", 0.1, 1.0, 0.0)
    gripper.starting(0.0, 0.0)
    gripper.goal("g", 0.1, 1.0, 0.0)
    assert gripper.stopping(1.0) == "g"
    assert gripper.stopping(1.0) is None
    with pytest.raises(RuntimeError):
        gripper.update(1.0, 0.01, 0.0, 0.0)


def test_is_finite_goal():
    assert is_finite_goal(0.1, 0.0) and not is_finite_goal(math.nan, 1.0) and not is_finite_goal(0.1, math.inf)


# ------------------------------------------------------------------------------------------------ effort variant

EFFORT_GAINS = {"gains": {"finger": {"p": 10.0}}}


def test_effort_variant_max_effort_zero_gives_no_force():
    gripper = core(EFFORT_GAINS, EFFORT_TYPE)
    gripper.goal("g", 1.0, 0.0, 0.0)
    out = gripper.update(0.01, 0.01, 0.0, 0.0)
    assert out.command == 0.0 and out.effort == 0.0


def test_effort_variant_clamps_pid_to_abs_goal_max_effort():
    gripper = core(EFFORT_GAINS, EFFORT_TYPE)
    gripper.goal("g", 1.0, -3.0, 0.0)
    assert gripper.update(0.01, 0.01, 0.0, 0.0).command == 3.0  # 10 * 1.0 clamped to |-3|
    assert gripper.update(0.02, 0.01, 0.95, 0.0).command == pytest.approx(0.5)  # within the clamp
    gripper.goal("h", -1.0, 3.0, 0.03)
    out = gripper.update(0.04, 0.01, 0.0, 0.0)
    assert out.command == -3.0 and out.effort == -3.0


def test_effort_variant_derivative_acts_on_minus_velocity():
    gripper = core({"gains": {"finger": {"p": 0.0, "d": 2.0}}}, EFFORT_TYPE)
    gripper.goal("g", 0.0, 100.0, 0.0)
    assert gripper.update(0.01, 0.01, 0.5, 0.25).command == pytest.approx(-0.5)


def test_effort_variant_default_max_effort_after_starting_and_result_effort():
    gripper = core({"max_effort": 2.0, **EFFORT_GAINS}, EFFORT_TYPE, position=0.0)
    assert gripper.update(0.01, 0.01, -1.0, 0.0).command == 2.0  # holds 0.0 with the default 2.0
    gripper.goal("g", 0.0, 5.0, 0.02)
    (event,) = gripper.update(0.03, 0.01, 0.0, 0.0).events
    assert event.result.effort == 2.0


def test_starting_resets_the_pid():
    gripper = core({"gains": {"finger": {"p": 0.0, "i": 1.0, "i_clamp": 100.0}}}, EFFORT_TYPE)
    gripper.goal("g", 1.0, 100.0, 0.0)
    for step in range(1, 4):
        gripper.update(step * 0.5, 0.5, 0.0, 0.0)  # integral of 1.0 over 1.5 s
    assert gripper.update(2.0, 0.5, 0.0, 0.0).command == pytest.approx(2.0)
    gripper.stopping(2.0)
    gripper.starting(3.0, 0.0)
    gripper.goal("h", 1.0, 100.0, 3.0)
    assert gripper.update(3.5, 0.5, 0.0, 0.0).command == pytest.approx(0.5)
