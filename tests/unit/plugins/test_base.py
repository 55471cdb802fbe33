"""plugins.base.Plugin: the publication schedule every publishing plugin inherits (``next_publish`` is the
next slot, ``take_due`` moves it on), and that a plugin which publishes nothing never asks for a step."""
import math

import pytest

from diffbot_sim.plugins.base import Plugin
from diffbot_sim.plugins.joint_motors import JointMotors


def test_next_publish_is_the_next_scheduled_slot():
    plugin = Plugin()
    assert plugin.next_publish() == math.inf  # nothing until started
    plugin.start(2.0)
    assert plugin.next_publish() == 2.0  # period 0: its first step
    assert plugin.take_due(2.0, 0.5) and plugin.next_publish() == 2.5
    assert not plugin.take_due(2.2, 0.5) and plugin.next_publish() == 2.5
    assert plugin.take_due(3.9, 0.5) and plugin.next_publish() == 4.4  # missed slots skipped, not burst
    plugin.start(0.0)  # a reset: sim time back to 0
    assert plugin.next_publish() == 0.0


class Periodic(Plugin):
    """A plugin publishing every ``period`` through ``take_due``, as the joint-state publisher and the sensors do;
    ``published`` lists the sim times it published at."""

    def __init__(self, period, sensor_timer):
        self.period, self.sensor_timer, self.published = period, sensor_timer, []

    def after_step(self, now, stamp=None, transforms=None):
        if self.take_due(now, self.period):
            self.published.append(round(now, 6))


def run(plugins, start, end, dt=1 / 240):
    """Step ``plugins`` from sim time ``start`` (exclusive) to ``end`` as the loop does (after_step after each
    step, at the sim time the step reached)."""
    steps = round((end - start) / dt)
    for k in range(1, steps + 1):
        for plugin in plugins:
            plugin.after_step(start + k * dt)


def test_after_a_start_the_odometry_comes_before_the_first_scan():
    """TurtleBot3: a 30 Hz diff drive (model plugin) and a 5 Hz laser (sensor). Before this rule both published at
    the first step, so a client's first scan could come before any odometry."""
    odom, laser = Periodic(1 / 30, False), Periodic(0.2, True)
    for plugin in (odom, laser):
        plugin.start(0.0)
    run([odom, laser], 0.0, 0.5)
    assert odom.published[0] == pytest.approx(1 / 30, abs=1 / 240)  # the first step at or after 1/30 s
    assert laser.published == pytest.approx([0.2, 0.4])  # the scan's first stamp is its period


def test_reset_simulation_restarts_both_and_reset_world_only_the_model_plugin():
    odom, laser = Periodic(1 / 30, False), Periodic(0.2, True)
    for plugin in (odom, laser):
        plugin.start(0.0)
    run([odom, laser], 0.0, 1.3)
    # reset_world at 1.3 s: sim time goes on; the model plugin restarts, the laser keeps its 0.2 s grid
    odom.published, laser.published = [], []
    for plugin in (odom, laser):
        plugin.start(1.3)
    run([odom, laser], 1.3, 1.7)
    assert odom.published[0] == pytest.approx(1.3 + 1 / 30, abs=1 / 240)
    assert laser.published == pytest.approx([1.4, 1.6])
    # reset_simulation: sim time back to 0; both start again, the laser first at 0.2 s
    odom.published, laser.published = [], []
    for plugin in (odom, laser):
        plugin.start(0.0)
    run([odom, laser], 0.0, 0.45)
    assert odom.published[0] == pytest.approx(1 / 30, abs=1 / 240)
    assert laser.published == pytest.approx([0.2, 0.4])


def test_a_sensor_spawned_late_publishes_at_its_first_step():
    laser = Periodic(0.2, True)
    laser.start(5.0)  # spawned at 5 s: Gazebo's sensor timer began at 0, so its update is overdue
    run([laser], 5.0, 5.45)
    assert laser.published == pytest.approx([5.0 + 1 / 240, 5.0 + 1 / 240 + 0.2, 5.0 + 1 / 240 + 0.4])


def test_joint_motors_publish_nothing():
    motors = JointMotors.__new__(JointMotors)  # no robot: only the schedule is asked
    motors.start(1.0)
    assert motors.next_publish() == math.inf
