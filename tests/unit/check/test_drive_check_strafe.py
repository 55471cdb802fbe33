"""drive_check's sideways run (holonomic bases strafe between the straight run and the turn) and the tolerances
callers may tighten."""
import math

import pytest

from diffbot_sim.check import drive_check


def test_holonomic_bases_strafe():
    assert drive_check.holonomic("libgazebo_ros_control.so,libridgeback_ros_force_based_move.so,(simulator) ~x")
    assert drive_check.holonomic(["libgazebo_ros_planar_move.so"])
    assert drive_check.holonomic("libgazebo_ros_control.so, libgazebo_ros_planar_move.so")  # a list typed by hand
    assert not drive_check.holonomic("libgazebo_ros_diff_drive.so,libgazebo_ros_joint_state_publisher.so")
    assert not drive_check.holonomic("")
    assert drive_check.runs(True) == (drive_check.STRAIGHT_RUN, drive_check.STRAFE_RUN, drive_check.TURN_RUN)
    assert drive_check.runs(False) == (drive_check.STRAIGHT_RUN, drive_check.TURN_RUN)


def test_the_strafe_run_is_to_the_left_at_the_straight_speed():
    run = drive_check.STRAFE_RUN
    assert (run.linear_x, run.linear_y, run.angular_z, run.seconds) == (0.0, drive_check.SPEED, 0.0,
                                                                          drive_check.SECONDS)


def test_sideways_is_measured_in_the_start_heading():
    left, forward = drive_check.sideways((1.0, 1.0, math.pi / 2), (0.2, 1.05, math.pi / 2))
    assert left == pytest.approx(0.8)
    assert forward == pytest.approx(0.05)


def test_a_good_strafe_passes():
    yaw = 0.3
    end = (2.0 - 0.8 * math.sin(yaw), 0.8 * math.cos(yaw), yaw + 0.01)
    result = drive_check.strafe((0, 0, yaw), (-0.79 * math.sin(yaw), 0.79 * math.cos(yaw), yaw), (2.0, 0, yaw), end)
    assert result.passed, result.failures
    assert result.truth_left == pytest.approx(0.8) and result.odom_left == pytest.approx(0.79)


def test_a_short_strafe_fails_on_the_ground_truth_only():
    result = drive_check.strafe((0, 0, 0), (0, 0.8, 0), (0, 0, 0), (0, 0.587, 0))
    assert [f.split(":")[0] for f in result.failures] == ["ground truth"]
    assert "0.587 m to the left" in result.failures[0]


def test_a_strafe_the_wrong_way_or_diagonal_or_turning_fails():
    assert not drive_check.strafe((0, 0, 0), (0, -0.8, 0), (0, 0, 0), (0, -0.8, 0)).passed
    diagonal = drive_check.strafe((0, 0, 0), (0.2, 0.8, 0), (0, 0, 0), (0, 0.8, 0))
    assert diagonal.failures == ["odometry: drifted 0.200 m along its heading while moving sideways (limit 0.12 m)"]
    turned = drive_check.strafe((0, 0, 0), (0, 0.8, 0), (0, 0, 0), (0, 0.8, 0.2))
    assert turned.failures == ["ground truth: heading changed 0.200 rad (limit 0.1 rad)"]


def test_a_tighter_tolerance_for_bases_that_impose_their_velocity():
    tight = drive_check.HOLONOMIC_TOLERANCE
    assert drive_check.strafe((0, 0, 0), (0, 0.8, 0), (0, 0, 0), (0, 0.74, 0)).passed
    assert not drive_check.strafe((0, 0, 0), (0, 0.8, 0), (0, 0, 0), (0, 0.74, 0), tolerance=tight).passed
    assert drive_check.straight((0, 0, 0), (0.8, 0, 0), (0, 0, 0), (0.7, 0, 0)).passed
    assert not drive_check.straight((0, 0, 0), (0.8, 0, 0), (0, 0, 0), (0.7, 0, 0), tolerance=tight).passed
    turn = dict(truth_fraction=1 - tight, odom_fraction=1 - tight, tolerance=tight)
    assert drive_check.turn((0, 0, 0), (0, 0, 2.0), (0, 0, 0), (0, 0, 1.96), **turn).passed
    assert not drive_check.turn((0, 0, 0), (0, 0, 2.0), (0, 0, 0), (0, 0, 1.32), **turn).passed  # 0.66 of the turn
    assert not drive_check.turn((0, 0, 0), (0, 0, 2.0), (0, 0, 0), (0, 0, 2.2), **turn).passed
    assert drive_check.turn((0, 0, 0), (0, 0, 2.0), (0, 0, 0), (0, 0, 2.2)).passed
