"""plugins.base.Plugin: the publication schedule every publishing plugin inherits (``next_publish`` is the
next slot, ``take_due`` moves it on), and that a plugin which publishes nothing never asks for a step."""
import math

from diffbot_sim.plugins.base import Plugin
from diffbot_sim.plugins.joint_motors import JointMotors


def test_next_publish_is_the_next_scheduled_slot():
    plugin = Plugin()
    assert plugin.next_publish() == 0.0  # due at once until started
    plugin.start(2.0)
    assert plugin.next_publish() == 2.0
    assert plugin.take_due(2.0, 0.5) and plugin.next_publish() == 2.5
    assert not plugin.take_due(2.2, 0.5) and plugin.next_publish() == 2.5
    assert plugin.take_due(3.9, 0.5) and plugin.next_publish() == 4.4  # missed slots skipped, not burst
    plugin.start(0.0)  # a reset: sim time back to 0
    assert plugin.next_publish() == 0.0


def test_joint_motors_publish_nothing():
    motors = JointMotors.__new__(JointMotors)  # no robot: only the schedule is asked
    motors.start(1.0)
    assert motors.next_publish() == math.inf
