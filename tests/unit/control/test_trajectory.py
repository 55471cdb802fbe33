"""joint_trajectory_controller's trajectories: spline segments, message checks with upstream's texts, the
merge with the current trajectory (bridge, future start, wraparound, owners), holds and goal tolerances.

Times: segments are in the controller's time base (s); ``merge_trajectory`` takes ns as upstream's ros::Time.
"""
import math

import pytest

from diffbot_sim.control import trajectory as tr
from diffbot_sim.control.trajectory import (
    Segment,
    SegmentTolerances,
    SplineState,
    StateTolerances,
    TrajectoryError,
    TrajectoryPoint as P,
    hold_trajectory,
    merge_trajectory,
    resolve_goal_tolerances,
    sample,
)

S = 1_000_000_000  # ns per s


def approx(value, rel=1e-9, abs_=1e-9):
    return pytest.approx(value, rel=rel, abs=abs_)


# --- spline segments ---------------------------------------------------------------------------------------

def test_positions_only_is_linear():
    segment = Segment.spline(1.0, SplineState(0.0), 3.0, SplineState(4.0))
    assert segment.sample(2.0) == (approx(2.0), approx(2.0), 0.0)


def test_positions_and_velocities_give_a_cubic():
    segment = Segment.spline(0.0, SplineState(0.0, 0.0), 2.0, SplineState(1.0, 0.0))
    assert segment.sample(1.0) == (approx(0.5), approx(0.75), approx(0.0))  # 1.5 Δ/T at mid
    assert segment.sample(0.5) == (approx(0.15625), approx(0.5625), approx(0.75))


def test_positions_velocities_accelerations_give_a_quintic():
    segment = Segment.spline(0.0, SplineState(0.0, 0.0, 0.0), 1.0, SplineState(1.0, 0.0, 0.0))
    assert segment.sample(0.5) == (approx(0.5), approx(1.875), approx(0.0))  # 10t³-15t⁴+6t⁵
    assert segment.sample(0.25) == (approx(10 / 64 - 15 / 256 + 6 / 1024), approx(30 / 16 - 60 / 64 + 30 / 256),
                                    approx(60 / 4 - 180 / 16 + 120 / 64))


def test_the_lowest_common_specification_is_used():
    segment = Segment.spline(0.0, SplineState(0.0, 5.0, 1.0), 1.0, SplineState(1.0))
    assert segment.sample(0.5) == (approx(0.5), approx(1.0), 0.0)
    cubic = Segment.spline(0.0, SplineState(0.0, 0.0, 9.0), 1.0, SplineState(1.0, 0.0))
    assert cubic.sample(0.0).acceleration == approx(6.0)  # the start acceleration is not used


def test_endpoints_are_met_and_outside_the_span_the_end_state_is_at_rest():
    segment = Segment.spline(1.0, SplineState(2.0, 1.0, 0.5), 2.0, SplineState(3.0, -1.0, 2.0))
    assert segment.sample(1.0) == (approx(2.0), approx(1.0), approx(0.5))
    assert segment.sample(2.0) == (approx(3.0), approx(-1.0), approx(2.0))  # at the end: the polynomial
    assert segment.sample(0.5) == (2.0, 0.0, 0.0)
    assert segment.sample(2.5) == (approx(3.0), 0.0, 0.0)


def test_zero_duration_segments():
    assert Segment.spline(1.0, SplineState(2.0, 3.0), 1.0, SplineState(5.0, 0.0)).sample(1.0) == (2.0, 3.0, 0.0)
    assert Segment.spline(1.0, SplineState(2.0), 1.0, SplineState(5.0)).sample(1.0) == (2.0, 0.0, 0.0)
    assert Segment.spline(1.0, SplineState(2.0, 3.0, 4.0), 1.0, SplineState(5.0, 0.0, 0.0)).sample(1.0) == \
        (2.0, 3.0, 4.0)


def test_segment_errors():
    with pytest.raises(TrajectoryError, match="^Quintic spline segment can't be constructed: end_time < "):
        Segment.spline(2.0, SplineState(0.0), 1.0, SplineState(1.0))


def test_sample_finds_the_last_segment_started_and_reports_times_before_all():
    segments = (Segment.spline(1.0, SplineState(0.0), 2.0, SplineState(1.0)),
                Segment.spline(2.0, SplineState(1.0), 3.0, SplineState(3.0)))
    assert sample(segments, 0.5) == (None, (0.0, 0.0, 0.0))
    assert sample(segments, 2.0)[0] == 1
    assert sample(segments, 1.999)[0] == 0
    assert sample(segments, 9.0) == (1, (approx(3.0), 0.0, 0.0))


# --- building from a message -------------------------------------------------------------------------------

JOINTS = ("a", "b")
WRAP = (False, False)


def hold(positions, at=0.0):
    return hold_trajectory(at, positions, [0.0] * len(positions), 0.0)


def merge(points, current=None, names=JOINTS, stamp_ns=0, now_ns=10 * S, now_uptime_ns=1 * S, wrap=WRAP, **kw):
    current = hold([0.0] * len(JOINTS)) if current is None else current
    return merge_trajectory(current, JOINTS, wrap, list(names), points, stamp_ns, now_ns, now_uptime_ns, **kw)


@pytest.mark.parametrize("points, names, kw, text", [
    ([P([1, 2], time_from_start=1.0), P([1, 2], time_from_start=1.0)], JOINTS, {}, tr.NOT_INCREASING),
    ([P([1, 2], time_from_start=2.0), P([1, 2], time_from_start=1.0)], JOINTS, {}, tr.NOT_INCREASING),
    ([P([1], time_from_start=1.0)], ("a",), {}, tr.WRONG_JOINTS),
    ([P([1, 2], time_from_start=1.0)], ("a", "c"), {}, tr.WRONG_JOINTS),
    ([P([1], time_from_start=1.0)], ("c",), {"allow_partial_joints_goal": True}, tr.WRONG_JOINTS),
    ([P([1, 2], [1.0], time_from_start=1.0)], JOINTS, {}, tr.SIZE_MISMATCH),
    ([P([1, 2], [], [1, 2, 3], time_from_start=1.0)], JOINTS, {}, tr.SIZE_MISMATCH),
    ([P([1], time_from_start=1.0)], JOINTS, {}, tr.SIZE_MISMATCH),  # fewer positions than joints
    ([P([], time_from_start=1.0)], JOINTS, {}, tr.WRAP_SIZE_MISMATCH),
    ([P([1, 2], time_from_start=1.0), P([], time_from_start=2.0)], JOINTS, {},
     "Can't construct segment from ROS message: Start/end points data size mismatch."),
    ([P([1, 2], time_from_start=1.0), P([1, 2], [1], time_from_start=2.0)], JOINTS, {}, tr.SIZE_MISMATCH),
    ([], JOINTS, {}, "Trajectory message contains empty trajectory. Nothing to convert."),
])
def test_refused_messages_give_upstreams_text(points, names, kw, text):
    with pytest.raises(TrajectoryError) as info:
        merge(points, names=names, **kw)
    assert str(info.value) == text


def test_the_checks_run_in_upstreams_order():
    with pytest.raises(TrajectoryError, match="strictly increasing"):  # before the joints
        merge([P([1], time_from_start=2.0), P([1], time_from_start=1.0)], names=("zz",))
    with pytest.raises(TrajectoryError, match="expected joints"):  # before the point sizes
        merge([P([1, 2, 3], [1], time_from_start=1.0)], names=("a", "zz"))


def test_a_trajectory_entirely_in_the_past_is_refused_with_upstreams_text():
    points = [P([1, 2], time_from_start=0.5), P([1, 2], time_from_start=1.5)]
    with pytest.raises(TrajectoryError) as info:
        merge(points, stamp_ns=8 * S)
    assert str(info.value) == ("Dropping all 2 trajectory point(s), as they occur before the current time.\n"
                               "Last point is 0.500000s in the past.")
    with pytest.raises(TrajectoryError, match="Dropping all 1 "):  # a point exactly at "now" is dropped too
        merge([P([1, 2], time_from_start=2.0)], stamp_ns=8 * S)


def test_past_points_are_dropped_with_a_warning_but_a_leading_zero_point_silently():
    points = [P([0, 0], time_from_start=0.0), P([1, 2], time_from_start=1.0), P([2, 2], time_from_start=2.0)]
    assert merge(points).warning is None
    result = merge(points, stamp_ns=9 * S)  # now = 10 s: the points at 9 s and 10 s are gone
    assert result.warning == ("Dropping first 2 trajectory point(s) out of 3, as they occur before the current "
                              "time.\nFirst valid point will be reached in 1.000s.")
    assert sample(result.trajectory[0], 1.0 + 1.0)[1].position == approx(2.0)  # 11 s is uptime 2 s
    stamped = merge(points[:2], stamp_ns=10 * S)  # a t=0 point is dropped silently only without a stamp
    assert stamped.warning == ("Dropping first 1 trajectory point(s) out of 2, as they occur before the current "
                               "time.\nFirst valid point will be reached in 1.000s.")


def test_a_new_trajectory_starts_with_a_bridge_from_the_current_state():
    result = merge([P([1.0, 2.0], time_from_start=1.0), P([3.0, 2.0], time_from_start=2.0)]).trajectory
    first = result[0]
    assert [(s.start_time, s.end_time) for s in first] == [(0.0, 0.0), (1.0, 2.0), (2.0, 3.0)]
    assert sample(first, 1.0)[1] == (0.0, 1.0, 0.0)  # linear bridge to a position-only point: velocity jumps
    assert sample(first, 1.5)[1].position == approx(0.5)
    assert sample(first, 2.5)[1].position == approx(2.0)
    assert sample(result[1], 2.0)[1].position == approx(2.0)


@pytest.mark.parametrize("accelerations", [None, [0.5, 0.0]])
def test_segments_meet_at_the_knots(accelerations):
    extra = {} if accelerations is None else {"accelerations": accelerations}
    points = [P([1.0, 0.0], [0.5, 0.0], time_from_start=1.0, **extra),
              P([2.0, 0.0], [2.0, 0.0], time_from_start=2.0, **extra),
              P([0.0, 0.0], [0.0, 0.0], time_from_start=3.0, **extra)]
    joint = merge(points).trajectory[0]  # knots at uptime 2 and 3 s
    for knot, (position, velocity) in ((2.0, (1.0, 0.5)), (3.0, (2.0, 2.0))):
        before, after = sample(joint, knot - 1e-7)[1], sample(joint, knot)[1]
        assert after.position == approx(position) and after.velocity == approx(velocity)
        assert before.position == approx(position, abs_=1e-6) and before.velocity == approx(velocity, abs_=1e-5)
        if accelerations:
            assert before.acceleration == approx(after.acceleration, abs_=1e-4)


def moving_trajectory():
    """Joint a moves 0 → 2 rad between uptime 0 and 2 s with a smooth start/stop; b stays at 0."""
    return merge([P([1.0, 0.0], [1.0, 0.0], [0.0, 0.0], time_from_start=1.0),
                  P([2.0, 0.0], [0.0, 0.0], [0.0, 0.0], time_from_start=2.0)], now_uptime_ns=0,
                 current=hold([0.0, 0.0])).trajectory


@pytest.mark.parametrize("fields", [dict(velocities=[0.0, 0.0]), dict(velocities=[0.0, 0.0], accelerations=[0.0, 0.0])])
def test_replacing_mid_motion_does_not_jump(fields):
    old = moving_trajectory()
    now = 1.5
    before = sample(old[0], now)[1]
    assert before.velocity > 0.5  # really moving
    new = merge([P([-1.0, 0.0], time_from_start=1.0, **fields)], current=old, now_uptime_ns=int(now * S)).trajectory
    after = sample(new[0], now)[1]
    assert after.position == approx(before.position) and after.velocity == approx(before.velocity)
    just_after = sample(new[0], now + 1e-4)[1]
    assert just_after.position == approx(before.position, abs_=2e-4)
    assert sample(new[0], now + 1.0)[1].position == approx(-1.0)


def test_a_future_start_keeps_the_current_trajectory_until_then():
    old = moving_trajectory()
    # now: message time 10 s = uptime 0.5 s; the new trajectory starts at 11 s = uptime 1.5 s
    new = merge([P([5.0, 0.0], time_from_start=1.0)], current=old, stamp_ns=11 * S, now_uptime_ns=S // 2).trajectory
    for t in (0.5, 1.0, 1.4, 1.4999):
        assert sample(new[0], t)[1] == sample(old[0], t)[1]
    assert sample(new[0], 1.5)[1].position == approx(sample(old[0], 1.5)[1].position)
    assert sample(new[0], 2.5)[1].position == approx(5.0)
    assert sample(new[0], 2.0)[1].position == approx((sample(old[0], 1.5)[1].position + 5.0) / 2)


def test_continuous_joints_take_the_short_way_round():
    current = hold([3.0, 3.0])
    wrapped = merge([P([-3.0, -3.0], time_from_start=1.0), P([-2.9, -2.9], time_from_start=2.0)], current=current,
                    wrap=(True, False)).trajectory
    assert sample(wrapped[0], 2.0)[1].position == approx(2 * math.pi - 3.0)
    assert sample(wrapped[0], 3.0)[1].position == approx(2 * math.pi - 2.9)  # every point gets the offset
    assert sample(wrapped[1], 2.0)[1].position == approx(-3.0)


def test_a_half_turn_tie_goes_the_way_the_point_lies():
    assert tr.wraparound_offset(0.0, -math.pi, True) == 0.0
    assert tr.wraparound_offset(0.0, math.pi, True) == 0.0
    assert tr.wraparound_offset(4 * math.pi, 0.1, True) == approx(4 * math.pi)
    assert tr.wraparound_offset(0.0, 7.0, False) == 0.0


def test_segments_carry_the_owner_and_the_goals_tolerances():
    tolerances = (SegmentTolerances(StateTolerances(0.1)), SegmentTolerances(StateTolerances(0.2)))
    result = merge([P([1.0, 2.0], time_from_start=1.0), P([2.0, 2.0], time_from_start=2.0)], owner="g",
                   tolerances=tolerances).trajectory
    assert [(s.owner, s.tolerances.path.position) for s in result[1]] == [(None, 0.0), ("g", 0.2), ("g", 0.2)]
    topic = merge([P([1.0, 2.0], time_from_start=1.0)]).trajectory
    assert all(s.owner is None and s.tolerances == tr.NO_TOLERANCES for s in topic[0])


def test_partial_goals_leave_the_other_joints_trajectory_but_hand_it_to_the_new_owner():
    old = moving_trajectory()
    new = merge([P([5.0], time_from_start=1.0)], names=("b",), current=old, now_uptime_ns=S // 2, owner="g2",
                allow_partial_joints_goal=True).trajectory
    assert new[0][1:] == tuple(s.owned_by("g2") for s in old[0][1:])  # from the active segment on
    assert new[0][0] == old[0][0]
    assert [s.owner for s in new[1]] == [None, "g2"]  # b: its old hold segment keeps its owner, then the bridge
    assert sample(new[1], 1.5)[1].position == approx(5.0)


# --- holds and tolerances ----------------------------------------------------------------------------------

def test_hold_without_stop_duration_is_a_zero_length_segment_at_the_position():
    (segment,), = hold_trajectory(2.0, [1.5], [3.0], 0.0, owner="g")
    assert (segment.start_time, segment.duration, segment.owner) == (2.0, 0.0, "g")
    assert segment.sample(2.0) == (1.5, 0.0, 0.0) and segment.sample(5.0) == (1.5, 0.0, 0.0)


def test_hold_with_stop_duration_ramps_the_velocity_down():
    (segment,), = hold_trajectory(2.0, [1.0], [0.8], 0.5)
    assert (segment.start_time, segment.end_time) == (2.0, 2.5)
    assert segment.sample(2.0) == (approx(1.0), approx(0.8), approx(0.0))
    end = segment.sample(2.5)
    assert end.velocity == approx(0.0, abs_=1e-12)
    assert end.position == approx(1.0 + 0.3125 * 0.8 * 1.0)  # (p,v)→(p,−v) quintic over T=1 s: p + 5vT/16 at T/2
    assert 0.0 < segment.sample(2.25).velocity < 0.8


def test_goal_tolerances_override_rules():
    defaults = (SegmentTolerances(StateTolerances(0.1, 0.2, 0.3), StateTolerances(0.01, 0.01), 0.5),
                SegmentTolerances(StateTolerances(0.1), StateTolerances(0.02), 0.5))
    result = resolve_goal_tolerances(defaults, ("a", "b"), [("a", 0.5, -1.0, 0.0), ("zz", 9.0, 9.0, 9.0)],
                                     {"b": (-1.0, 0.3, 0.0)}, 0.0)
    assert result[0].path == StateTolerances(0.5, 0.0, 0.3)
    assert result[0].goal == defaults[0].goal
    assert result[1].goal == StateTolerances(0.0, 0.3, 0.0)
    assert result[1].goal_time == 0.5
    assert resolve_goal_tolerances(defaults, ("a", "b"), goal_time_tolerance=2.0)[0].goal_time == 2.0
    assert resolve_goal_tolerances(defaults, ("a", "b"), goal_time_tolerance=-1.0)[0].goal_time == 0.0


def test_a_tolerance_of_zero_is_not_checked():
    assert not StateTolerances(0.0, 0.0, 0.0).violated(100.0, 100.0, 100.0)
    assert StateTolerances(0.1).violated(-0.11, 0.0)
    assert not StateTolerances(0.1).violated(0.1, 5.0)
    assert StateTolerances(0.0, 0.1).violated(0.0, 0.2)
