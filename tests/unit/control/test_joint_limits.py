"""joint_limits.py: joint_limits_interface as DefaultRobotHWSim uses it. Cases marked "upstream" follow
ros_control noetic-devel joint_limits_interface/test/{joint_limits_interface_test,joint_limits_rosparam_test}.cpp
and joint_limits_rosparam.yaml; the numbers elsewhere are hand-computed from the handles' formulas."""
import math

import pytest

from diffbot_sim.control.joint_limits import (
    DBL_MAX,
    EffortJointSaturation,
    EffortJointSoftLimits,
    JointLimits,
    JointLimitsInterfaceError,
    PositionJointSaturation,
    PositionJointSoftLimits,
    SoftJointLimits,
    VelocityJointSaturation,
    VelocityJointSoftLimits,
    apply_rosparam_limits,
    limits_from_urdf,
    make_limit_handle,
    register_joint_limits,
)
from diffbot_sim.description.urdf_model import Joint, SafetyController
from diffbot_sim.errors import ConfigError

EPS = 1e-12
PERIOD = 0.1
# upstream JointLimitsTest fixture
LIMITS = JointLimits(has_position_limits=True, min_position=-1.0, max_position=1.0, has_velocity_limits=True,
                     max_velocity=2.0, has_effort_limits=True, max_effort=8.0)
SOFT = SoftJointLimits(min_position=-0.8, max_position=0.8, k_position=20.0, k_velocity=40.0)
NS = "/arm/joint_limits/foo_joint"


def urdf_joint(jtype="revolute", has_limit=True, lower=-1.5, upper=2.0, velocity=3.0, effort=50.0, safety=None):
    return Joint("foo_joint", jtype, "base", "link", effort_limit=effort, velocity_limit=velocity,
                 has_limit=has_limit, lower=lower, upper=upper, safety=safety)


# ---- URDF -------------------------------------------------------------------------------------------------

def test_urdf_revolute_gets_position_velocity_effort():
    limits, soft = limits_from_urdf(urdf_joint())
    assert limits == JointLimits(has_position_limits=True, min_position=-1.5, max_position=2.0,
                                 has_velocity_limits=True, max_velocity=3.0, has_effort_limits=True,
                                 max_effort=50.0)
    assert soft is None


def test_urdf_continuous_wraps_and_prismatic_is_bounded():
    limits, _ = limits_from_urdf(urdf_joint("continuous", lower=-1.0, upper=1.0))
    assert limits.has_position_limits is False and limits.angle_wraparound is True
    assert limits.has_velocity_limits and limits.max_velocity == 3.0 and limits.max_effort == 50.0
    limits, _ = limits_from_urdf(urdf_joint("prismatic", lower=0.0, upper=0.04))
    assert (limits.has_position_limits, limits.min_position, limits.max_position) == (True, 0.0, 0.04)
    assert limits.angle_wraparound is False and limits.has_acceleration_limits is False


def test_urdf_without_limit_element_has_no_limits_but_keeps_soft():
    safety = SafetyController(k_velocity=10.0, k_position=15.0, soft_lower_limit=-1.0, soft_upper_limit=1.0)
    limits, soft = limits_from_urdf(urdf_joint("continuous", has_limit=False, velocity=None, effort=None,
                                               safety=safety))
    assert limits is None
    assert soft == SoftJointLimits(min_position=-1.0, max_position=1.0, k_position=15.0, k_velocity=10.0)


def test_urdf_limit_without_velocity_or_effort_attribute():
    limits, _ = limits_from_urdf(urdf_joint(velocity=None, effort=None))
    assert limits.has_velocity_limits is False and limits.has_effort_limits is False


# ---- rosparam (upstream joint_limits_rosparam_test GetJointLimits) ----------------------------------------

FOO = {"has_position_limits": True, "min_position": 0.0, "max_position": 1.0, "has_velocity_limits": True,
       "max_velocity": 2.0, "has_acceleration_limits": True, "max_acceleration": 5.0, "has_jerk_limits": True,
       "max_jerk": 100.0, "has_effort_limits": True, "max_effort": 20.0, "angle_wraparound": True,
       "has_soft_limits": True, "k_position": 10.0, "k_velocity": 20.0, "soft_lower_limit": 0.1,
       "soft_upper_limit": 0.9}
ANTIFOO = {"has_position_limits": False, "has_velocity_limits": False, "has_acceleration_limits": False,
           "has_jerk_limits": False, "has_effort_limits": False, "angle_wraparound": True}


def test_rosparam_absent_namespace():
    assert apply_rosparam_limits(None, None, NS) == (None, False)
    assert apply_rosparam_limits(LIMITS, None, NS) == (LIMITS, False)


def test_rosparam_full_specification():
    limits, found = apply_rosparam_limits(None, FOO, NS)
    assert found is True
    assert limits == JointLimits(True, 0.0, 1.0, True, 2.0, True, 5.0, True, 100.0, True, 20.0, False)


def test_rosparam_flags_without_values_set_nothing():
    flags = {"has_position_limits": True, "has_velocity_limits": True, "has_acceleration_limits": True,
             "has_jerk_limits": True, "has_effort_limits": True}
    assert apply_rosparam_limits(None, flags, NS) == (JointLimits(), True)


def test_rosparam_values_without_flags_set_nothing():
    values = {"min_position": 0.0, "max_position": 1.0, "max_velocity": 2.0, "max_acceleration": 5.0,
              "max_jerk": 100.0, "max_effort": 20.0}
    assert apply_rosparam_limits(None, values, NS) == (JointLimits(), True)


def test_rosparam_disables_set_values_and_reads_wraparound():
    limits, _ = apply_rosparam_limits(None, FOO, NS)
    limits, found = apply_rosparam_limits(limits, ANTIFOO, NS)
    assert found
    assert not (limits.has_position_limits or limits.has_velocity_limits or limits.has_acceleration_limits
                or limits.has_jerk_limits or limits.has_effort_limits)
    assert limits.angle_wraparound is True
    assert limits.max_velocity == 2.0  # the value stays, only the flag is cleared


def test_rosparam_incomplete_position_limits_not_loaded():
    limits, _ = apply_rosparam_limits(None, {"has_position_limits": True, "max_position": 1.0}, NS)
    assert limits.has_position_limits is False and limits.max_position == 0.0


def test_rosparam_overrides_one_field_of_urdf_limits():
    urdf, _ = limits_from_urdf(urdf_joint())
    limits, _ = apply_rosparam_limits(urdf, {"has_velocity_limits": True, "max_velocity": 0.5}, NS)
    assert limits.max_velocity == 0.5
    assert (limits.min_position, limits.max_position, limits.max_effort) == (-1.5, 2.0, 50.0)


@pytest.mark.parametrize("key, value", [
    ("has_position_limits", 1), ("has_velocity_limits", "yes"), ("min_position", "low"),
    ("max_velocity", None), ("max_effort", float("nan")), ("angle_wraparound", "true"),
])
def test_rosparam_bad_values_name_the_parameter(key, value):
    params = {"has_position_limits": key != "angle_wraparound", "min_position": 0.0, "max_position": 1.0,
              "has_velocity_limits": True, "max_velocity": 1.0, "has_effort_limits": True, "max_effort": 1.0}
    params[key] = value
    with pytest.raises(ConfigError) as err:
        apply_rosparam_limits(None, params, NS)
    assert err.value.name == f"{NS}/{key}"


def test_rosparam_namespace_not_a_dict():
    with pytest.raises(ConfigError) as err:
        apply_rosparam_limits(None, 3.0, NS)
    assert err.value.name == NS


# ---- handle construction (upstream HandleConstruction) ----------------------------------------------------

def test_handle_construction_refusals():
    with pytest.raises(JointLimitsInterfaceError, match="Cannot enforce limits for joint 'j1'. It has no "
                                                        "velocity limits specification."):
        PositionJointSoftLimits(JointLimits(), SOFT, "j1")
    with pytest.raises(JointLimitsInterfaceError, match="velocity"):
        EffortJointSoftLimits(JointLimits(has_effort_limits=True), SOFT)
    with pytest.raises(JointLimitsInterfaceError, match="no effort limits"):
        EffortJointSoftLimits(JointLimits(has_velocity_limits=True), SOFT)
    with pytest.raises(JointLimitsInterfaceError, match="no efforts limits"):
        EffortJointSaturation(JointLimits(has_velocity_limits=True))
    with pytest.raises(JointLimitsInterfaceError):
        VelocityJointSaturation(JointLimits())
    PositionJointSoftLimits(LIMITS, SOFT)
    EffortJointSoftLimits(LIMITS, SOFT)
    VelocityJointSaturation(LIMITS)
    VelocityJointSoftLimits(JointLimits(), SOFT)
    PositionJointSaturation(JointLimits())


# ---- PositionJointSoftLimits (upstream) -------------------------------------------------------------------

@pytest.mark.parametrize("command, expected", [
    (0.1, 0.1), (-0.1, -0.1), (0.2, 0.2), (-0.2, -0.2), (0.4, 0.2), (-0.4, -0.2),
])
def test_position_soft_velocity_bounds_upstream(command, expected):
    handle = PositionJointSoftLimits(LIMITS, SOFT)
    assert handle.enforce(command, 0.0, 0.0, PERIOD) == pytest.approx(expected, abs=EPS)


def test_position_soft_at_upper_soft_limit_upstream():
    handle = PositionJointSoftLimits(LIMITS, SOFT)
    assert handle.enforce(1.0, 0.8, 0.0, PERIOD) == pytest.approx(0.8, abs=EPS)  # no closer to the stop
    # away from it: v_min = clamp(-20 (0.8 + 0.8)) = -2 -> 0.8 - 0.2 = 0.6
    assert handle.enforce(0.0, 0.8, 0.0, PERIOD) == pytest.approx(0.6, abs=EPS)


def test_position_soft_beyond_soft_limit_pushes_back_upstream():
    handle = PositionJointSoftLimits(LIMITS, SOFT)
    # pos 0.9: v_max = clamp(-20 (0.9 - 0.8)) = -2, v_min = -2 -> the command must be 0.9 - 0.2 = 0.7
    assert handle.enforce(1.0, 0.9, 0.0, PERIOD) == pytest.approx(0.7, abs=EPS)
    handle = PositionJointSoftLimits(LIMITS, SOFT)
    assert handle.enforce(-1.0, -0.9, 0.0, PERIOD) == pytest.approx(-0.7, abs=EPS)


def test_position_soft_uses_previous_command_not_position():
    handle = PositionJointSoftLimits(LIMITS, SOFT)
    handle.enforce(0.2, 0.0, 0.0, PERIOD)
    # measured position ignored after the first call: from prev 0.2 another 0.2 step
    assert handle.enforce(1.0, -0.5, 0.0, PERIOD) == pytest.approx(0.4, abs=EPS)


def test_position_soft_pathological_soft_bounds_upstream():
    soft = SoftJointLimits(min_position=-1.5, max_position=1.5, k_position=20.0, k_velocity=40.0)
    assert PositionJointSoftLimits(LIMITS, soft).enforce(2.0, 1.0, 0.0, PERIOD) == pytest.approx(1.0, abs=EPS)
    assert PositionJointSoftLimits(LIMITS, soft).enforce(-2.0, -1.0, 0.0, PERIOD) == pytest.approx(-1.0, abs=EPS)


def test_position_soft_continuous_only_velocity():
    limits = JointLimits(has_velocity_limits=True, max_velocity=2.0, angle_wraparound=True)
    handle = PositionJointSoftLimits(limits, SOFT)
    assert handle.enforce(10.0, 5.0, 0.0, PERIOD) == pytest.approx(5.2, abs=EPS)


def test_position_soft_reset_upstream():
    handle = PositionJointSoftLimits(LIMITS, SOFT)
    handle.enforce(0.0, 0.0, 0.0, PERIOD)
    assert handle.enforce(1.0, 0.0, 0.0, PERIOD) == pytest.approx(0.2, abs=EPS)
    handle.reset()
    assert handle.enforce(0.8, 1.0, 0.0, PERIOD) == pytest.approx(0.8, abs=EPS)


# ---- PositionJointSaturation ------------------------------------------------------------------------------

def test_position_saturation_reset_upstream():
    handle = PositionJointSaturation(LIMITS)
    handle.enforce(0.0, 0.0, 0.0, PERIOD)
    assert handle.enforce(1.0, 0.0, 0.0, PERIOD) == pytest.approx(0.2, abs=EPS)
    handle.reset()
    assert handle.enforce(1.0, 1.0, 0.0, PERIOD) == pytest.approx(1.0, abs=EPS)


def test_position_saturation_rate_limit_and_hard_clamp():
    handle = PositionJointSaturation(LIMITS)
    # seeded at the measured 0.95: step 0.2 -> [0.75, 1.15] ∩ [-1, 1] -> 5.0 -> 1.0
    assert handle.enforce(5.0, 0.95, 0.0, PERIOD) == 1.0
    assert handle.enforce(-5.0, 0.95, 0.0, PERIOD) == pytest.approx(0.8, abs=EPS)
    handle.reset(position=-0.9)
    assert handle.enforce(-5.0, 0.0, 0.0, PERIOD) == -1.0


def test_position_saturation_beyond_hard_limit_snaps_to_it():
    # prev 2.0 beyond max 1.0: window [max(1.8, -1), min(2.2, 1)] = [1.8, 1.0] is inverted; std::min(std::max())
    # gives the upper bound 1.0 whatever the command (a jump larger than the rate limit)
    assert PositionJointSaturation(LIMITS).enforce(0.0, 2.0, 0.0, PERIOD) == 1.0
    assert PositionJointSaturation(LIMITS).enforce(-2.0, -2.0, 0.0, PERIOD) == -1.8


def test_position_saturation_without_velocity_limit_and_zero_velocity_freezes():
    no_velocity = JointLimits(has_position_limits=True, min_position=-1.0, max_position=1.0)
    assert PositionJointSaturation(no_velocity).enforce(0.9, -0.9, 0.0, PERIOD) == 0.9
    frozen = JointLimits(has_velocity_limits=True, max_velocity=0.0)
    assert PositionJointSaturation(frozen).enforce(3.0, 0.25, 0.0, PERIOD) == 0.25
    assert PositionJointSaturation(JointLimits()).enforce(1e300, 0.0, 0.0, PERIOD) == 1e300


def test_position_saturation_nan_command_reseeds():
    handle = PositionJointSaturation(LIMITS)
    assert math.isnan(handle.enforce(math.nan, 0.0, 0.0, PERIOD))
    assert handle.enforce(1.0, 0.5, 0.0, PERIOD) == pytest.approx(0.7, abs=EPS)


# ---- VelocityJointSaturation (upstream) -------------------------------------------------------------------

@pytest.mark.parametrize("command, expected", [(1.0, 1.0), (-1.0, -1.0), (2.0, 2.0), (-2.0, -2.0), (4.0, 2.0),
                                               (-4.0, -2.0)])
def test_velocity_saturation_bounds_upstream(command, expected):
    assert VelocityJointSaturation(LIMITS).enforce(command, 0.0, 0.0, PERIOD) == expected


def test_velocity_saturation_acceleration_upstream():
    limits = JointLimits(has_velocity_limits=True, max_velocity=2.0, has_acceleration_limits=True,
                         max_acceleration=20.0)
    handle = VelocityJointSaturation(limits)
    handle.enforce(1.0, 0.0, 0.0, 1000.0)
    assert handle.enforce(4.0, 0.0, 0.0, PERIOD) == pytest.approx(2.0, abs=EPS)
    handle.enforce(1.0, 0.0, 0.0, 1000.0)
    assert handle.enforce(-4.0, 0.0, 0.0, PERIOD) == pytest.approx(-1.0, abs=EPS)
    handle.enforce(-1.0, 0.0, 0.0, 1000.0)
    assert handle.enforce(4.0, 0.0, 0.0, PERIOD) == pytest.approx(1.0, abs=EPS)
    handle.enforce(-1.0, 0.0, 0.0, 1000.0)
    assert handle.enforce(-4.0, 0.0, 0.0, PERIOD) == pytest.approx(-2.0, abs=EPS)


def test_velocity_saturation_starts_from_zero_and_reset():
    limits = JointLimits(has_velocity_limits=True, max_velocity=5.0, has_acceleration_limits=True,
                         max_acceleration=10.0)
    handle = VelocityJointSaturation(limits)
    assert handle.enforce(5.0, 0.0, 3.0, PERIOD) == pytest.approx(1.0)  # from 0, not the measured 3
    assert handle.enforce(5.0, 0.0, 3.0, PERIOD) == pytest.approx(2.0)
    handle.reset()
    assert handle.enforce(5.0, 0.0, 3.0, PERIOD) == pytest.approx(1.0)


# ---- VelocityJointSoftLimits ------------------------------------------------------------------------------

def test_velocity_soft_limits():
    handle = VelocityJointSoftLimits(LIMITS, SOFT)
    # pos 0.7: v_max = clamp(-20 (0.7 - 0.8)) = 2 ; pos 0.75: 1.0 ; pos 0.9: -2 (pushed back)
    assert handle.enforce(3.0, 0.7, 0.0, PERIOD) == pytest.approx(2.0)
    assert handle.enforce(3.0, 0.75, 0.0, PERIOD) == pytest.approx(1.0)
    assert handle.enforce(0.0, 0.9, 0.0, PERIOD) == pytest.approx(-2.0)
    # lower side: pos -0.78 -> v_min = clamp(-20 (-0.78 + 0.8)) = -0.4
    assert handle.enforce(-3.0, -0.78, 0.0, PERIOD) == pytest.approx(-0.4)


def test_velocity_soft_limits_acceleration_and_no_velocity_limit():
    limits = JointLimits(has_acceleration_limits=True, max_acceleration=5.0)
    handle = VelocityJointSoftLimits(limits, SOFT)
    # no position or velocity limits: only the measured velocity 1.0 ± 0.5
    assert handle.enforce(100.0, 0.0, 1.0, PERIOD) == pytest.approx(1.5)
    assert handle.enforce(-100.0, 0.0, 1.0, PERIOD) == pytest.approx(0.5)
    assert VelocityJointSoftLimits(JointLimits(), SOFT).enforce(1e300, 0.0, 0.0, PERIOD) == 1e300


# ---- EffortJointSaturation --------------------------------------------------------------------------------

@pytest.mark.parametrize("command, position, velocity, expected", [
    (20.0, 0.0, 0.0, 8.0), (-20.0, 0.0, 0.0, -8.0), (3.0, 0.0, 0.0, 3.0),
    (5.0, 1.1, 0.0, 0.0), (-5.0, 1.1, 0.0, -5.0),      # above max: no more positive effort
    (-5.0, -1.1, 0.0, 0.0), (5.0, -1.1, 0.0, 5.0),     # below min: no more negative effort
    (5.0, 0.0, 2.5, 0.0), (-5.0, 0.0, 2.5, -5.0),      # too fast positive
    (-5.0, 0.0, -2.5, 0.0), (5.0, 0.0, -2.5, 5.0),     # too fast negative
    (5.0, 1.1, -2.5, 0.0), (-5.0, 1.1, -2.5, 0.0),     # both: the window closes to 0
])
def test_effort_saturation(command, position, velocity, expected):
    assert EffortJointSaturation(LIMITS).enforce(command, position, velocity, PERIOD) == expected


# ---- EffortJointSoftLimits --------------------------------------------------------------------------------

def test_effort_soft_limits():
    handle = EffortJointSoftLimits(LIMITS, SOFT)
    # pos 0, vel 0: v window [-2, 2] -> effort window [-8, 8] (40·2 = 80 clamped)
    assert handle.enforce(20.0, 0.0, 0.0, PERIOD) == 8.0
    # pos 0.79, vel 0.1: v_max = clamp(-20 (-0.01)) = 0.2 -> e_max = -40 (0.1 - 0.2) = 4
    assert handle.enforce(20.0, 0.79, 0.1, PERIOD) == pytest.approx(4.0)
    # pos 0.85, vel 0: v_max = clamp(-20·0.05) = -1 -> e_max = clamp(-40 (0 - (-1))) = -8: pushed back
    assert handle.enforce(20.0, 0.85, 0.0, PERIOD) == pytest.approx(-8.0)
    # pos -0.79, vel -0.1: v_min = clamp(-20 (0.01)) = -0.2 -> e_min = -40 (-0.1 + 0.2) = -4
    assert handle.enforce(-20.0, -0.79, -0.1, PERIOD) == pytest.approx(-4.0)
    # continuous: no position dependence, vel 1.9 -> e_max = -40 (1.9 - 2) = 4
    limits = JointLimits(has_velocity_limits=True, max_velocity=2.0, has_effort_limits=True, max_effort=8.0)
    assert EffortJointSoftLimits(limits, SOFT).enforce(20.0, 5.0, 1.9, PERIOD) == pytest.approx(4.0)


# ---- choice of handle (HWSim registerJointLimits) ---------------------------------------------------------

def test_make_limit_handle_choice():
    assert make_limit_handle("PositionJointInterface", None, SOFT) is None
    assert isinstance(make_limit_handle("PositionJointInterface", LIMITS, None), PositionJointSaturation)
    assert isinstance(make_limit_handle("hardware_interface/PositionJointInterface", LIMITS, SOFT),
                      PositionJointSoftLimits)
    assert isinstance(make_limit_handle("VelocityJointInterface", LIMITS, None), VelocityJointSaturation)
    assert isinstance(make_limit_handle("VelocityJointInterface", LIMITS, SOFT), VelocityJointSoftLimits)
    assert isinstance(make_limit_handle("EffortJointInterface", LIMITS, None), EffortJointSaturation)
    assert isinstance(make_limit_handle("EffortJointInterface", LIMITS, SOFT), EffortJointSoftLimits)
    with pytest.raises(ValueError):
        make_limit_handle("JointStateInterface", LIMITS, None)
    with pytest.raises(JointLimitsInterfaceError, match="'j'"):
        make_limit_handle("EffortJointInterface", JointLimits(), None, joint="j")


def test_register_joint_limits_from_urdf():
    reg = register_joint_limits("foo_joint", "EffortJointInterface", urdf_joint(), None, "/arm")
    assert (reg.joint_type, reg.lower, reg.upper, reg.effort_limit) == ("revolute", -1.5, 2.0, 50.0)
    assert isinstance(reg.handle, EffortJointSaturation)


def test_register_joint_limits_without_limits():
    reg = register_joint_limits("foo_joint", "PositionJointInterface", urdf_joint("continuous", has_limit=False),
                                None, "/arm")
    assert (reg.joint_type, reg.lower, reg.upper, reg.effort_limit) == ("continuous", -DBL_MAX, DBL_MAX, DBL_MAX)
    assert reg.handle is None and reg.limits is None
    reg = register_joint_limits("ghost", "PositionJointInterface", None, None, "/arm")
    assert reg.joint_type == "unknown" and reg.handle is None


def test_register_joint_limits_soft_needs_limits_and_infers_type():
    safety = SafetyController(k_velocity=10.0, k_position=15.0, soft_lower_limit=-1.0, soft_upper_limit=1.0)
    reg = register_joint_limits("foo_joint", "PositionJointInterface", urdf_joint(safety=safety), None, "/arm")
    assert isinstance(reg.handle, PositionJointSoftLimits)
    # no URDF joint: type from the rosparam limits
    params = {"has_position_limits": True, "min_position": -1.0, "max_position": 1.0}
    assert register_joint_limits("x", "PositionJointInterface", None, params, "/arm/").joint_type == "revolute"
    wrap = {"has_position_limits": False, "angle_wraparound": True}
    assert register_joint_limits("x", "PositionJointInterface", None, wrap, "/arm").joint_type == "continuous"
    vel = {"has_velocity_limits": True, "max_velocity": 1.0}
    reg = register_joint_limits("x", "VelocityJointInterface", None, vel, "/arm")
    assert reg.joint_type == "prismatic" and reg.effort_limit == DBL_MAX


def test_register_joint_limits_rosparam_error_names_full_path():
    with pytest.raises(ConfigError) as err:
        register_joint_limits("foo_joint", "PositionJointInterface", urdf_joint(),
                              {"has_velocity_limits": True, "max_velocity": "fast"}, "/arm/")
    assert err.value.name == "/arm/joint_limits/foo_joint/max_velocity"
