"""Contact sensor states (gazebo_ros_bumper's values) and the Kobuki's bumper, cliff and wheel-drop decisions."""
import math
from collections import namedtuple

import pytest

from diffbot_sim.sensors import kobuki_events as ev
from diffbot_sim.sensors.contact import contact_states

Point = namedtuple("Point", "other other_link position normal depth force")


def test_states_group_pairs_and_rotate_wrenches_into_the_link_frame():
    yaw = math.pi / 2  # the link faces +y: world -y is its -x... world +x is its -y
    q = (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
    points = [Point(7, -1, (1.0, 0.0, 0.1), (-1.0, 0.0, 0.0), 0.001, (-2.0, 0.0, 0.0)),
              Point(7, -1, (1.0, 0.1, 0.1), (-1.0, 0.0, 0.0), 0.002, (-3.0, 0.0, 0.0)),
              Point(9, 2, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 0.0, (0.0, 0.0, 5.0))]
    states = contact_states(points, "r::base::c", lambda body, _link: f"body{body}", (0.0, 0.0, 0.1), q)
    assert [s.collision2 for s in states] == ["body7", "body9"]
    first = states[0]
    assert first.depths == [0.001, 0.002] and first.positions[1] == (1.0, 0.1, 0.1)
    force, torque = first.wrenches[0]
    assert force == pytest.approx((0.0, 2.0, 0.0))  # world -x is the link's +y
    assert torque == pytest.approx((0.0, 0.0, 0.0))  # the force passes through the centre of mass
    assert first.total[0] == pytest.approx((0.0, 5.0, 0.0))
    assert first.wrenches[1][1] == pytest.approx((0.0, 0.0, 0.3))  # arm (1, 0.1, 0) x (-3, 0, 0), z unturned


def test_bumper_sectors_as_gazebo_ros_kobuki_splits_them():
    def hit(angle, z=0.05):  # the robot is collision1: the normal points from the obstacle toward the robot
        return (z, -math.cos(angle), -math.sin(angle), True)
    assert ev.bumper_sectors([hit(0.0)], 0.0, 0.0) == (False, True, False)
    assert ev.bumper_sectors([hit(math.radians(45))], 0.0, 0.0) == (True, False, False)
    assert ev.bumper_sectors([hit(math.radians(-60))], 0.0, 0.0) == (False, False, True)
    assert ev.bumper_sectors([hit(math.radians(120))], 0.0, 0.0) == (False, False, False)  # behind: no bumper
    assert ev.bumper_sectors([hit(0.0, z=0.2)], 0.0, 0.0) == (False, False, False)  # above the bumper
    assert ev.bumper_sectors([hit(math.pi / 2)], 0.0, math.pi / 2) == (False, True, False)  # heading +y


def test_edges_cliff_bottom_and_state_bits():
    edges = ev.Edges(3)
    assert edges.update((False, True, False)) == [(1, True)]
    assert edges.update((False, True, False)) == []
    assert edges.update((False, False, False)) == [(1, False)]
    assert ev.cliff_bottom(math.inf) == 0 and ev.cliff_bottom(0.03) == int(76123 * math.atan2(0.995, 0.03))
    assert ev.sensor_state_bits((True, True, False), (False, False, True), (True, False)) == (6, 1, 2)
