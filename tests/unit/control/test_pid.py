"""pid.py: control_toolbox::Pid (noetic 1.19) gains reading and computeCommand, hand-computed numbers."""
import math

import pytest

from diffbot_sim.control.pid import Pid, PidGains, boost_clamp, no_p_gain_message, pid_gains, pid_publish_state
from diffbot_sim.errors import ConfigError

NS = "/gazebo_ros_control/pid_gains/joint1"


# ---- parameters -------------------------------------------------------------------------------------------

def test_no_p_means_no_pid():
    assert pid_gains({"i": 1.0, "d": 2.0}, NS) is None
    assert pid_gains({}, NS) is None
    assert pid_gains(None, NS) is None
    assert no_p_gain_message(NS) == "No p gain specified for pid.  Namespace: " + NS


def test_defaults_and_ints_accepted():
    assert pid_gains({"p": 100}, NS) == PidGains(p=100.0, i=0.0, d=0.0, i_clamp_max=0.0, i_clamp_min=0.0,
                                                 antiwindup=False)


def test_i_clamp_is_symmetric_absolute():
    gains = pid_gains({"p": 1.0, "i": 0.5, "d": 0.1, "i_clamp": -3.0}, NS)
    assert (gains.p, gains.i, gains.d) == (1.0, 0.5, 0.1)
    assert (gains.i_clamp_min, gains.i_clamp_max) == (-3.0, 3.0)


def test_explicit_min_max_override_with_forced_signs():
    gains = pid_gains({"p": 1.0, "i_clamp": 3.0, "i_clamp_min": 2.0}, NS)
    assert (gains.i_clamp_min, gains.i_clamp_max) == (-2.0, 3.0)
    gains = pid_gains({"p": 1.0, "i_clamp": 3.0, "i_clamp_max": -5.0}, NS)
    assert (gains.i_clamp_min, gains.i_clamp_max) == (-3.0, 5.0)
    gains = pid_gains({"p": 1.0, "i_clamp_min": -1.0, "i_clamp_max": 4.0}, NS)
    assert (gains.i_clamp_min, gains.i_clamp_max) == (-1.0, 4.0)


def test_antiwindup_and_publish_state():
    assert pid_gains({"p": 1.0, "antiwindup": True}, NS).antiwindup is True
    assert pid_publish_state({"p": 1.0, "publish_state": True}, NS) is True
    assert pid_publish_state({"p": 1.0}, NS) is False


@pytest.mark.parametrize("key, value", [
    ("p", "high"), ("i", None), ("d", [1]), ("i_clamp", "x"), ("i_clamp_min", float("nan")),
    ("i_clamp_max", True), ("antiwindup", "maybe"), ("p", float("inf")),
])
def test_bad_values_name_the_parameter(key, value):
    params = {"p": 1.0, key: value}
    with pytest.raises(ConfigError) as err:
        pid_gains(params, NS)
    assert err.value.name == f"{NS}/{key}"


def test_bad_publish_state_and_namespace():
    with pytest.raises(ConfigError) as err:
        pid_publish_state({"publish_state": "perhaps"}, NS)
    assert err.value.name == f"{NS}/publish_state"
    with pytest.raises(ConfigError) as err:
        pid_gains(5.0, NS)
    assert err.value.name == NS


# ---- computeCommand ---------------------------------------------------------------------------------------

def test_proportional_only():
    pid = Pid(PidGains(p=2.0))
    assert pid.compute(0.5, 0.1) == pytest.approx(1.0)
    assert pid.compute(-0.25, 0.1) == pytest.approx(-0.5)


def test_first_call_after_reset_has_derivative_kick():
    # D = 0.5, error 2 over dt 0.1 from the (valid) last error 0: d = 0.5 * 20 = 10, plus p 1*2 = 12
    pid = Pid(PidGains(p=1.0, d=0.5))
    assert pid.compute(2.0, 0.1) == pytest.approx(12.0)
    # second call, error unchanged: no derivative
    assert pid.compute(2.0, 0.1) == pytest.approx(2.0)
    # error drops to 1 over 0.05 s: d = 0.5 * (-20) = -10, p = 1
    assert pid.compute(1.0, 0.05) == pytest.approx(-9.0)
    pid.reset()
    assert pid.compute(1.0, 0.1) == pytest.approx(1.0 + 0.5 * 10.0)


def test_integral_is_zero_with_default_i_clamp():
    pid = Pid(PidGains(p=0.0, i=10.0))
    assert pid.compute(1.0, 0.1) == 0.0
    assert pid.compute(1.0, 0.1) == 0.0
    assert pid.terms.i_error == pytest.approx(0.2)  # the error still accumulates


def test_integral_term_clamped_without_antiwindup():
    # I = 2, clamp 0.5: i_error 0.1, 0.2, 0.3 -> terms 0.2, 0.4, 0.6 -> 0.5; i_error keeps growing (windup)
    pid = Pid(PidGains(p=0.0, i=2.0, i_clamp_max=0.5, i_clamp_min=-0.5))
    assert pid.compute(1.0, 0.1) == pytest.approx(0.2)
    assert pid.compute(1.0, 0.1) == pytest.approx(0.4)
    assert pid.compute(1.0, 0.1) == pytest.approx(0.5)
    assert pid.terms.i_error == pytest.approx(0.3)
    # unwinding takes the stored excess: error -1 -> i_error 0.2 -> term 0.4 (still positive)
    assert pid.compute(-1.0, 0.1) == pytest.approx(0.4)


def test_antiwindup_clamps_the_error_integral():
    # I = 2, clamp 0.5 -> i_error within [-0.25, 0.25]: 0.1, 0.2, 0.25 ; then -1 -> 0.15 -> term 0.3
    pid = Pid(PidGains(p=0.0, i=2.0, i_clamp_max=0.5, i_clamp_min=-0.5, antiwindup=True))
    pid.compute(1.0, 0.1)
    pid.compute(1.0, 0.1)
    assert pid.compute(1.0, 0.1) == pytest.approx(0.5)
    assert pid.terms.i_error == pytest.approx(0.25)
    assert pid.compute(-1.0, 0.1) == pytest.approx(0.3)


def test_antiwindup_with_negative_i_gain_orders_the_bounds():
    # I = -2: bounds sorted(-0.5/-2, 0.5/-2) = [-0.25, 0.25]; i_error 0.3 -> 0.25, term -0.5
    pid = Pid(PidGains(p=0.0, i=-2.0, i_clamp_max=0.5, i_clamp_min=-0.5, antiwindup=True))
    assert pid.compute(3.0, 0.1) == pytest.approx(-0.5)
    assert pid.terms.i_error == pytest.approx(0.25)


def test_antiwindup_with_zero_i_gain_does_not_divide():
    pid = Pid(PidGains(p=1.0, i=0.0, i_clamp_max=1.0, i_clamp_min=-1.0, antiwindup=True))
    assert pid.compute(1.0, 0.1) == pytest.approx(1.0)


def test_explicit_error_dot():
    # P 1, D 0.5: e = 1, error_dot = -4 -> 1 - 2 = -1 ; the difference quotient is not used
    pid = Pid(PidGains(p=1.0, d=0.5))
    assert pid.compute(1.0, 0.1, error_dot=-4.0) == pytest.approx(-1.0)
    assert pid.terms.d_term == pytest.approx(-2.0)


def test_explicit_error_dot_does_not_move_last_error():
    # computeCommand(e, e_dot, dt) leaves p_error_last at 0: a later computeCommand(e, dt) derives from 0
    pid = Pid(PidGains(p=0.0, d=1.0))
    pid.compute(5.0, 0.1, error_dot=0.0)
    assert pid.compute(1.0, 0.5) == pytest.approx(2.0)


@pytest.mark.parametrize("error, dt", [(1.0, 0.0), (float("nan"), 0.1), (float("inf"), 0.1), (-math.inf, 0.1)])
def test_zero_dt_or_bad_error_returns_zero_without_state_change(error, dt):
    pid = Pid(PidGains(p=1.0, i=1.0, d=1.0, i_clamp_max=10.0, i_clamp_min=-10.0))
    pid.compute(1.0, 0.1)  # p 1, i 0.1, d 10
    before = pid.terms
    assert pid.compute(error, dt) == 0.0
    assert pid.terms == before
    # the next call derives from the last good error 1.0: p 2, i 0.1+0.2, d (2-1)/0.1 = 10
    assert pid.compute(2.0, 0.1) == pytest.approx(2.0 + 0.3 + 10.0)


def test_non_finite_error_dot_returns_zero():
    pid = Pid(PidGains(p=1.0, d=1.0))
    assert pid.compute(1.0, 0.1, error_dot=float("nan")) == 0.0
    assert pid.compute(1.0, 0.0, error_dot=1.0) == 0.0


def test_negative_dt_reuses_previous_error_dot_and_integrates():
    # first: e 1, dt 0.5 -> error_dot 2 (d term 2), i_error 0.5 (term clamped to 10: 0.5)
    pid = Pid(PidGains(p=0.0, i=1.0, d=1.0, i_clamp_max=10.0, i_clamp_min=-10.0))
    assert pid.compute(1.0, 0.5) == pytest.approx(2.5)
    # dt -0.5: error_dot stays 2, i_error 0.5 + (-0.5 * 3) = -1.0, last error not updated
    assert pid.compute(3.0, -0.5) == pytest.approx(2.0 - 1.0)
    # next positive step derives from the last error 1.0, not 3.0: (2 - 1)/0.5 = 2; i_error -1 + 1 = 0
    assert pid.compute(2.0, 0.5) == pytest.approx(2.0)


def test_terms_hold_the_pid_state_fields():
    pid = Pid(PidGains(p=2.0, i=1.0, d=0.5, i_clamp_max=1.0, i_clamp_min=-2.0))
    output = pid.compute(0.5, 0.2)
    terms = pid.terms
    assert terms.timestep == 0.2 and terms.error == 0.5 and terms.p_error == 0.5
    assert terms.error_dot == pytest.approx(2.5) and terms.d_error == pytest.approx(2.5)
    assert terms.p_term == pytest.approx(1.0)
    assert terms.i_error == pytest.approx(0.1) and terms.i_term == pytest.approx(0.1)
    assert terms.d_term == pytest.approx(1.25)
    assert (terms.i_max, terms.i_min) == (1.0, -2.0)
    assert terms.output == output == pytest.approx(2.35)


def test_reset_clears_integral_and_terms():
    pid = Pid(PidGains(p=0.0, i=1.0, i_clamp_max=5.0, i_clamp_min=-5.0))
    pid.compute(1.0, 1.0)
    pid.reset()
    assert pid.terms.i_error == 0.0 and pid.terms.output == 0.0
    assert pid.compute(1.0, 1.0) == pytest.approx(1.0)


def test_gains_can_change_without_reset():
    pid = Pid(PidGains(p=1.0, i=1.0, i_clamp_max=5.0, i_clamp_min=-5.0))
    pid.compute(1.0, 1.0)
    pid.gains = PidGains(p=3.0, i=2.0, i_clamp_max=5.0, i_clamp_min=-5.0)
    # i_error 2 -> term 4, p 3
    assert pid.compute(1.0, 1.0) == pytest.approx(7.0)


def test_velocity_pid_on_a_wheel():
    # HWSim VELOCITY_PID: error = cmd - vel every step; P 10, I 1 with i_clamp 0.05, 1 ms steps
    pid = Pid(pid_gains({"p": 10.0, "i": 1.0, "i_clamp": 0.05}, NS))
    efforts = [pid.compute(2.0 - velocity, 0.001) for velocity in (0.0, 1.0, 1.5)]
    assert efforts == pytest.approx([20.0 + 0.002, 10.0 + 0.003, 5.0 + 0.0035])


def test_boost_clamp_matches_boost_order():
    assert boost_clamp(5.0, -1.0, 1.0) == 1.0
    assert boost_clamp(-5.0, -1.0, 1.0) == -1.0
    assert boost_clamp(0.5, -1.0, 1.0) == 0.5
    # inverted bounds: below low -> low, otherwise above high -> high
    assert boost_clamp(0.0, 1.0, -1.0) == 1.0
    assert boost_clamp(2.0, 1.0, -1.0) == -1.0
