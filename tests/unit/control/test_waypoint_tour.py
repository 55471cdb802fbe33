"""The scripted drive: turn towards each waypoint, drive to it, stop when the list is done."""
import math

import pytest

from diffbot_sim.control.waypoint_tour import Tour, TourConfig


def test_turns_first_when_the_waypoint_is_behind():
    tour = Tour([(-1.0, 0.0)])
    linear, angular = tour.command(0.0, 0.0, 0.0)
    assert linear == 0.0 and angular == pytest.approx(1.0)  # the largest turn rate


def test_drives_towards_a_waypoint_ahead_and_steers():
    tour = Tour([(2.0, 0.1)])
    linear, angular = tour.command(0.0, 0.0, 0.0)
    assert linear == pytest.approx(0.3, abs=0.01) and 0.0 < angular < 0.2


def test_reaches_each_waypoint_in_turn_and_stops():
    tour = Tour([(1.0, 0.0), (1.0, 1.0)], TourConfig(tolerance=0.1))
    assert tour.command(0.95, 0.0, 0.0) != (0.0, 0.0) and tour.index == 1
    assert tour.command(1.0, 0.95, math.pi / 2) == (0.0, 0.0) and tour.done


def test_a_simulated_unicycle_completes_a_square():
    tour = Tour([(1, 0), (1, 1), (0, 1), (0, 0)])
    x = y = yaw = 0.0
    dt = 0.05
    for _ in range(2000):
        v, w = tour.command(x, y, yaw)
        if tour.done:
            break
        x, y, yaw = x + v * math.cos(yaw) * dt, y + v * math.sin(yaw) * dt, yaw + w * dt
    assert tour.done and math.hypot(x, y) < 0.15


def test_tours_without_a_config_do_not_share_one():
    """Each tour gets its own default TourConfig (TourConfig is mutable): tuning one tour leaves the next alone."""
    first, second = Tour([(1.0, 0.0)]), Tour([(1.0, 0.0)])
    first.config.speed = 0.05
    assert second.config.speed == TourConfig().speed
