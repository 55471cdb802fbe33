"""The Kobuki base's bumper, cliff and wheel-drop events, decided as gazebo_ros_kobuki (kobuki_desktop, noetic
head f338488) decides them from its contact and ray sensors (pure).

* Bumper: each contact of the bumper's collision between 0.01 and 0.13 m above the model's origin is put on
  one of three 60-degree sectors by the direction from the robot toward it relative to the heading (the
  contact normal, inverted when the robot is the first collision): left (30, 90], centre [-30, 30],
  right [-90, -30); a sector pressed now and not before sends PRESSED, the reverse RELEASED.
* Cliff: a sensor whose first ray reads at least ``cliff_detection_threshold`` sends CLIFF once, below it FLOOR
  once; ``bottom`` is the distance back as the AD reading ``int(76123 · atan2(0.995, range))``.
* Wheel drop: a wheel's contact sensor without contact sends DROPPED once, with contact RAISED once.
"""
import math

LEFT, CENTER, RIGHT = 0, 1, 2  # BumperEvent / CliffEvent sensors; WheelDropEvent uses LEFT 0, RIGHT 1
RELEASED, PRESSED = 0, 1
FLOOR, CLIFF = 0, 1
RAISED, DROPPED = 0, 1
BUMPER_LOW, BUMPER_HIGH = 0.01, 0.13  # m above the model's origin
#: SensorState bits (kobuki_msgs): bumper right 1, centre 2, left 4; cliff the same; wheel drop right 1, left 2
BUMPER_BITS = {RIGHT: 1, CENTER: 2, LEFT: 4}
WHEEL_DROP_BITS = {0: 2, 1: 1}


def bumper_sectors(contacts, base_z, heading):
    """(left, centre, right) pressed for ``contacts``: [(contact z [m], normal x, normal y, robot is collision1)]
    in the world frame, for a model whose origin is at height ``base_z`` facing ``heading`` [rad]."""
    pressed = [False, False, False]
    for z, nx, ny, robot_first in contacts:
        if not BUMPER_LOW <= z - base_z <= BUMPER_HIGH:
            continue
        sign = -1.0 if robot_first else 1.0
        angle = math.atan2(sign * ny, sign * nx) - heading  # not wrapped, as upstream
        if math.pi / 6 < angle <= math.pi / 2:
            pressed[LEFT] = True
        elif -math.pi / 6 <= angle <= math.pi / 6:
            pressed[CENTER] = True
        elif -math.pi / 2 <= angle < -math.pi / 6:
            pressed[RIGHT] = True
    return tuple(pressed)


class Edges:
    """Which of several binary sensors changed since the last update: ``update(states)`` returns the
    [(index, True/False)] of those that did (upstream starts every bumper released and every cliff on floor)."""

    def __init__(self, count, initial=False):
        self.states = [initial] * count

    def update(self, states):
        changes = [(i, s) for i, (s, old) in enumerate(zip(states, self.states)) if s != old]
        self.states = list(states)
        return changes


def cliff_bottom(distance):
    """CliffEvent.bottom: the distance [m] as the cliff sensor's AD reading."""
    return int(76123.0 * math.atan2(0.995, distance))


def sensor_state_bits(bumpers, cliffs, dropped):
    """SensorState's (bumper, cliff, wheel_drop) bit fields from (left, centre, right) bumpers and cliffs and
    (left, right) dropped wheels."""
    bumper = sum(BUMPER_BITS[i] for i, on in enumerate(bumpers) if on)
    cliff = sum(BUMPER_BITS[i] for i, on in enumerate(cliffs) if on)
    drop = sum(WHEEL_DROP_BITS[i] for i, on in enumerate(dropped) if on)
    return bumper, cliff, drop
