"""control.pick_place: the arm's chain from link origins, top-down inverse kinematics, the steps of the
sequence with their targets from the scene, the base motions closing on a pose, the gripper outcomes."""
import math

import pytest

from diffbot_sim.control import pick_place as pp
from diffbot_sim.errors import ConfigError

# diffbot_arm with every joint at 0 (base_footprint frame, from its URDF): pitch axis, elbow, wrist, tool
ORIGINS = {"upper_arm_link": (-0.03, 0.0, 0.216), "forearm_link": (-0.03, 0.0, 0.356),
           "wrist_link": (-0.03, 0.0, 0.476), "gripper_tcp_link": (-0.03, 0.0, 0.5435)}
ARM = pp.arm_geometry(ORIGINS)


def test_arm_geometry_from_the_link_origins():
    assert ARM.shoulder_x == pytest.approx(-0.03)
    assert ARM.shoulder_z == pytest.approx(0.216)
    assert (ARM.upper, ARM.fore, ARM.hand) == pytest.approx((0.14, 0.12, 0.0675))


def test_arm_geometry_names_a_missing_or_degenerate_link():
    with pytest.raises(ConfigError, match="wrist_link"):
        pp.arm_geometry({k: v for k, v in ORIGINS.items() if k != "wrist_link"})
    with pytest.raises(ConfigError, match="forearm_link"):
        pp.arm_geometry(dict(ORIGINS, forearm_link=ORIGINS["upper_arm_link"]))


def test_top_down_matches_the_worlds_grasp_angles():
    # worlds/pick_place.world's comment: tool 1 cm above the box centre (z 0.1525), 0.16 m ahead of the base
    assert pp.top_down(ARM, 0.16, 0.1525) == pytest.approx((0.87, 1.51, 0.77), abs=0.005)
    assert pp.top_down(ARM, 0.16, 0.2125) == pytest.approx((0.62, 1.39, 1.14), abs=0.005)
    assert pp.top_down(ARM, 0.16, 0.2525) == pytest.approx((0.53, 1.18, 1.43), abs=0.005)


@pytest.mark.parametrize("reach, height", [(0.16, 0.15), (0.2, 0.25), (0.05, 0.35), (0.1, 0.2)])
def test_top_down_points_the_tool_down_at_the_point(reach, height):
    pitch, elbow, wrist = pp.top_down(ARM, reach, height)
    assert pitch + elbow + wrist == pytest.approx(math.pi)
    assert elbow > 0  # bent forward
    assert pp.tool_point(ARM, pitch, elbow, wrist) == pytest.approx((reach, height), abs=1e-9)


def test_top_down_refuses_a_point_out_of_reach():
    with pytest.raises(ValueError, match="out of the arm's reach"):
        pp.top_down(ARM, 0.6, 0.15)


def test_plan_drives_to_the_table_picks_carries_and_places():
    steps = pp.plan(pp.Scene(), ARM)
    kinds = [s.kind for s in steps]
    assert kinds[0] == pp.GRIPPER and steps[0].expect == pp.OPEN
    close = next(i for i, s in enumerate(steps) if s.expect == pp.HOLD)
    release = next(i for i, s in enumerate(steps) if i > close and s.kind == pp.GRIPPER)
    assert steps[release].expect == pp.OPEN
    # the base reaches the pick table before the grasp, and the place table only while carrying
    drives = [i for i, s in enumerate(steps) if s.kind == pp.DRIVE]
    assert drives[0] < close < drives[1] < drives[-1] < release
    assert steps[drives[0]].target == pytest.approx((0.48, 0.0, 1.0))
    assert steps[drives[1]].target == pytest.approx((0.33, 0.0, -1.0))  # backs away before turning
    assert steps[drives[-1]].target == pytest.approx((-0.48, 0.0, 1.0))
    assert steps[-1].target == pp.HOME


def test_plan_arm_targets_come_from_the_scene():
    scene = pp.Scene()
    steps = pp.plan(scene, ARM)
    grasp = next(s for s in steps if s.name == "lower onto the object")
    lift = next(s for s in steps if s.name == "lift the object")
    place = next(s for s in steps if s.name == "lower onto the place table")
    assert pp.tool_point(ARM, *grasp.target[1:]) == pytest.approx((0.16, 0.1525))
    assert pp.tool_point(ARM, *lift.target[1:])[1] == pytest.approx(0.1525 + scene.carry_lift)
    assert grasp.target[0] == 0.0 and place.target == pytest.approx(grasp.target)
    # a higher place table: the placing pose is higher by as much
    higher = pp.plan(pp.Scene(place=(-0.64, 0.0, 0.2025)), ARM)
    place = next(s for s in higher if s.name == "lower onto the place table")
    assert pp.tool_point(ARM, *place.target[1:])[1] == pytest.approx(0.2125)


def test_plan_turns_towards_a_table_off_the_axis():
    steps = pp.plan(pp.Scene(pick=(0.5, 0.5, 0.1425), pick_heading=math.pi / 2), ARM)
    turn, drive, face = steps[1:4]
    assert drive.target == pytest.approx((0.5, 0.34, 1.0))
    assert turn.target[0] == pytest.approx(math.atan2(0.34, 0.5))
    assert face.target[0] == pytest.approx(math.pi / 2)


def simulate(motion, pose, dt=0.02, limit=2000):
    """A unicycle following the motion's commands until it is done."""
    x, y, yaw = pose
    for _ in range(limit):
        v, w = motion.command(x, y, yaw)
        if motion.done:
            return x, y, yaw
        x, y, yaw = x + v * math.cos(yaw) * dt, y + v * math.sin(yaw) * dt, yaw + w * dt
    raise AssertionError("the motion never finished")


def test_drive_stops_on_the_goal_forward_and_backward():
    cfg = pp.MotionConfig()
    x, y, _ = simulate(pp.BaseMotion(pp.Step("in", pp.DRIVE, (0.48, 0.0, 1.0))), (0.0, 0.0, 0.0))
    assert x == pytest.approx(0.48, abs=cfg.tolerance) and y == pytest.approx(0.0, abs=1e-6)
    x, y, yaw = simulate(pp.BaseMotion(pp.Step("back", pp.DRIVE, (0.33, 0.0, -1.0))), (0.48, 0.0, 0.0))
    assert x == pytest.approx(0.33, abs=cfg.tolerance) and yaw == pytest.approx(0.0)


def test_drive_steers_onto_the_goal_and_never_exceeds_its_speed():
    motion = pp.BaseMotion(pp.Step("in", pp.DRIVE, (1.0, 0.1, 1.0)))
    v, w = motion.command(0.0, 0.0, 0.0)
    assert 0 < v <= pp.MotionConfig().speed and w > 0
    x, y, _ = simulate(pp.BaseMotion(pp.Step("in", pp.DRIVE, (1.0, 0.1, 1.0))), (0.0, 0.0, 0.0))
    assert math.dist((x, y), (1.0, 0.1)) < 0.01


def test_drive_slows_near_the_goal_and_backs_up_when_past_it():
    motion = pp.BaseMotion(pp.Step("in", pp.DRIVE, (0.48, 0.0, 1.0)))
    far, near = motion.command(0.0, 0.0, 0.0)[0], motion.command(0.47, 0.0, 0.0)[0]
    assert near < far and near >= pp.MotionConfig().min_speed
    past = motion.command(0.50, 0.0, 0.0)
    assert -0.03 < past[0] < 0.0 and past[1] == 0.0  # slowly back, no steering so close
    assert motion.command(0.481, 0.0, 0.0) == (0.0, 0.0) and motion.done
    assert motion.command(0.0, 0.0, 0.0) == (0.0, 0.0)  # stays done
    backward = pp.BaseMotion(pp.Step("back", pp.DRIVE, (0.33, 0.0, -1.0)))
    assert backward.command(0.30, 0.0, 0.0)[0] > 0.0  # reversing past its goal: forward again


def test_still_there_after_settling():
    step = pp.Step("in", pp.DRIVE, (0.48, 0.0, 1.0))
    assert pp.still_there(step, 0.482, 0.0, 0.0)
    assert not pp.still_there(step, 0.495, 0.0, 0.0)
    assert pp.still_there(pp.Step("face", pp.TURN, (math.pi,)), 0.0, 0.0, -math.pi + 0.005)


def test_turn_goes_the_short_way_and_stops_within_tolerance():
    motion = pp.BaseMotion(pp.Step("turn", pp.TURN, (math.pi,)))
    assert motion.command(0.0, 0.0, -3.0)[1] < 0  # -3.0 -> pi: 0.14 rad the negative way
    _, _, yaw = simulate(pp.BaseMotion(pp.Step("turn", pp.TURN, (math.pi,))), (0.3, 0.0, 0.0))
    assert abs(math.remainder(yaw - math.pi, 2 * math.pi)) < pp.MotionConfig().yaw_tolerance


def test_base_motion_refuses_other_steps():
    with pytest.raises(ValueError):
        pp.BaseMotion(pp.Step("open", pp.GRIPPER, (0.035, 5.0), expect=pp.OPEN))


OPEN_STEP = pp.Step("open", pp.GRIPPER, (0.035, 5.0), expect=pp.OPEN)
HOLD_STEP = pp.Step("close", pp.GRIPPER, (0.0, 5.0), expect=pp.HOLD)


def test_gripper_open_needs_the_goal_reached():
    assert pp.gripper_outcome(OPEN_STEP, "SUCCEEDED", 0.0345, True, False, 0.045)[0]
    assert not pp.gripper_outcome(OPEN_STEP, "ABORTED", 0.02, False, True, 0.045)[0]


def test_gripper_hold_needs_a_stall_on_the_object():
    assert pp.gripper_outcome(HOLD_STEP, "ABORTED", 0.0233, False, True, 0.045)[0]
    ok, reason = pp.gripper_outcome(HOLD_STEP, "SUCCEEDED", 0.0005, True, False, 0.045)
    assert not ok and "nothing grasped" in reason  # closed on nothing
    ok, reason = pp.gripper_outcome(HOLD_STEP, "ABORTED", 0.035, False, True, 0.045)
    assert not ok and "nothing grasped" in reason  # did not close (no force)
    assert not pp.gripper_outcome(HOLD_STEP, "ABORTED", 0.0225, False, False, 0.045)[0]
    assert not pp.gripper_outcome(HOLD_STEP, "LOST", None, False, False, 0.045)[0]


def test_describe_lists_every_step():
    steps = pp.plan(pp.Scene(), ARM)
    lines = pp.describe(steps)
    assert len(lines) == len(steps) and lines[0].startswith(" 1. open the gripper")


def _rotate(q, v):
    x, y, z, w = q
    # v' = q v q*, written out for a unit quaternion
    tx, ty, tz = 2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])
    return (v[0] + w * tx + y * tz - z * ty, v[1] + w * ty + z * tx - x * tz, v[2] + w * tz + x * ty - y * tx)


@pytest.mark.parametrize("point, shoulder", [((0.64, 0.0, 0.15), (0.45, 0.0)), ((-0.5, 0.3, 0.2), (-0.3, 0.0)),
                                             ((0.1, -0.4, 0.3), (0.0, 0.0))])
def test_top_down_pose_points_the_fingers_down_and_faces_the_point(point, shoulder):
    x, y, z, *q = pp.top_down_pose(point, shoulder)
    assert (x, y, z) == point
    assert math.isclose(sum(c * c for c in q), 1.0)
    down = _rotate(q, (0.0, 0.0, 1.0))  # the tool's z axis, along the fingers
    assert down == pytest.approx((0.0, 0.0, -1.0), abs=1e-9)
    forward = _rotate(q, (1.0, 0.0, 0.0))  # Rz(yaw) Ry(pi) turns x to (-cos yaw, -sin yaw, 0)
    yaw = math.atan2(point[1] - shoulder[1], point[0] - shoulder[0])
    assert forward == pytest.approx((-math.cos(yaw), -math.sin(yaw), 0.0), abs=1e-9)


def test_shoulder_xy_follows_the_base():
    arm = pp.ArmGeometry(-0.03, 0.2, 0.14, 0.12, 0.0675)
    assert pp.shoulder_xy(arm, 1.0, 2.0, 0.0) == pytest.approx((0.97, 2.0))
    assert pp.shoulder_xy(arm, 1.0, 2.0, math.pi / 2) == pytest.approx((1.0, 1.97))


def test_moveit_steps_pick_above_the_object_and_place_on_the_other_table():
    scene = pp.Scene()
    steps = pp.moveit_steps(scene)
    kinds = [s.kind for s in steps]
    assert kinds[0] == pp.FINGERS and steps[0].expect == pp.OPEN
    assert steps[-1] == pp.Step("home", pp.NAMED, ("home",))
    poses = [s for s in steps if s.kind == pp.POSE]
    grasp = next(s for s in poses if s.name == "lower onto the object")
    assert grasp.target == pytest.approx((scene.pick[0], scene.pick[1], scene.pick[2] + scene.grasp_above))
    place = next(s for s in poses if s.name == "lower onto the place table")
    assert place.target == pytest.approx((scene.place[0], scene.place[1], scene.place[2] + scene.grasp_above))
    hold = next(s for s in steps if s.expect == pp.HOLD)
    assert kinds.index(pp.FINGERS, 1) == steps.index(hold)
    # the base motions are the plain variant's
    arm = pp.ArmGeometry(-0.03, 0.216, 0.14, 0.12, 0.0675)
    plain = [s for s in pp.plan(scene, arm) if s.kind in (pp.DRIVE, pp.TURN)]
    assert [s for s in steps if s.kind in (pp.DRIVE, pp.TURN)] == plain
    assert all(line for line in pp.describe(steps))


def test_tables_cover_the_worlds_table_tops():
    for _, centre, size in pp.TABLES:
        assert centre[2] + size[2] / 2 == pytest.approx(0.12)  # the top surface of both tables
    assert {name for name, _, _ in pp.TABLES} == {"pick_table", "place_table"}
