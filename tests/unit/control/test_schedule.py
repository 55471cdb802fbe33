"""control.schedule: when a periodic update is next due, and when the first one comes after a start or a reset
(Gazebo's rules: a model plugin one period after its (re)start, a sensor on sim time from 0)."""
import math

import pytest

from diffbot_sim.control.schedule import first_due_model, first_due_sensor, next_due


def test_next_due_skips_missed_slots():
    assert next_due(0.2, 0.2, 0.2) == pytest.approx(0.4)
    assert next_due(0.2, 0.2, 1.05) == pytest.approx(1.25)  # fell behind: one period after now, no burst
    assert next_due(0.2, 0.0, 0.3) == 0.3  # every call


def test_a_model_plugin_first_updates_one_period_after_its_start():
    assert first_due_model(0.0, 1 / 30) == pytest.approx(1 / 30)  # gazebo_ros_diff_drive's 30 Hz odometry
    assert first_due_model(12.5, 0.01) == pytest.approx(12.51)  # spawned, or reset, at 12.5 s
    assert first_due_model(3.0, 0.0) == 3.0  # every step: its first step


def test_a_sensor_first_updates_at_its_period_on_sim_time():
    new = math.inf
    assert first_due_sensor(new, 0.2, 0.0) == 0.2  # a 5 Hz laser at the start: first scan at 0.2 s
    assert first_due_sensor(new, 0.005, 0.0) == 0.005  # a 200 Hz IMU sensor
    assert first_due_sensor(new, 0.2, 7.3) == 0.2  # spawned at 7.3 s: due at once (its timer began at 0)
    assert first_due_sensor(new, 0.0, 0.0) == 0.0  # every step


def test_reset_world_keeps_a_sensors_schedule_and_reset_simulation_restarts_it():
    assert first_due_sensor(7.4, 0.2, 7.3) == 7.4  # reset_world at 7.3 s (sim time goes on): unchanged
    assert first_due_sensor(7.4, 0.2, 7.2) == 7.4  # exactly one period ahead: still its own slot
    assert first_due_sensor(7.4, 0.2, 0.0) == 0.2  # reset_simulation: sim time back to 0, first scan at 0.2 s
    assert first_due_sensor(0.2, 0.2, 0.0) == 0.2  # reset before its first scan: the same slot
    assert first_due_sensor(7.3, 0.0, 0.0) == 0.0  # every step: the first step after the reset
