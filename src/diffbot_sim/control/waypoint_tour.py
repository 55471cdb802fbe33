"""Driving a robot through a list of waypoints (pure): the scripted drive of ``slam.launch`` (``drive:=tour``),
which maps a world without a person at the keys.

Turn in place towards the next waypoint, then drive to it, steering; a waypoint is reached within
``tolerance``. Pose in, (linear, angular) command out; the caller passes the time and the pose.
"""
import math
from collections.abc import Sequence
from dataclasses import dataclass

from diffbot_sim.transforms import wrap_angle


@dataclass
class TourConfig:
    """How the tour drives (defaults suit the seed robot with the navigation stack's limits)."""

    speed: float = 0.3  # m/s cruising
    turn_rate: float = 1.0  # rad/s largest turn rate
    tolerance: float = 0.15  # m: a waypoint is reached this close
    turn_first: float = 0.35  # rad: a heading error above this is turned away in place first
    heading_gain: float = 2.0  # 1/s: turn rate per rad of heading error


class Tour:
    """Where the robot is in its list of waypoints and what it should do now."""

    def __init__(self, waypoints: Sequence[tuple[float, float]], config: TourConfig | None = None):
        self.waypoints: list[tuple[float, float]] = [(float(x), float(y)) for x, y in waypoints]
        self.config = config if config is not None else TourConfig()
        self.index = 0

    @property
    def done(self):
        return self.index >= len(self.waypoints)

    def command(self, x, y, yaw):
        """The (linear [m/s], angular [rad/s]) command from pose (x, y, yaw); (0, 0) once the tour is done."""
        cfg = self.config
        while not self.done:
            tx, ty = self.waypoints[self.index]
            distance = math.hypot(tx - x, ty - y)
            if distance > cfg.tolerance:
                break
            self.index += 1
        if self.done:
            return 0.0, 0.0
        error = wrap_angle(math.atan2(ty - y, tx - x) - yaw)
        angular = max(-cfg.turn_rate, min(cfg.turn_rate, cfg.heading_gain * error))
        if abs(error) > cfg.turn_first:
            return 0.0, angular
        linear = min(cfg.speed, 0.8 * distance + 0.05) * math.cos(error)
        return linear, angular
