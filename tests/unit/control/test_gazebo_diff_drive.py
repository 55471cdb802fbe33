"""control.gazebo_diff_drive: GazeboDiffDriveCore — refusal of non-finite commands, clamping, timeout brake,
acceleration ramp from the measured velocity, curvature kept under saturation; the plugin's step (a new
command at once, updates on the schedule, a stale command braked at its step) and its wheels."""
import math

import pytest

from diffbot_sim.control.gazebo_diff_drive import TWIST_FIELDS, DriveWheels, GazeboDiffDriveCore, non_finite_field
from diffbot_sim.control.kinematics import body_velocity

SEP, RAD, VMAX = 0.2, 0.032, 40.0  # the seed: max_linear = 1.28 m/s, max angular = 12.8 rad/s


def make(**kwargs):
    return GazeboDiffDriveCore(SEP, RAD, VMAX, **kwargs)


def body(targets):
    """Body (v, w) the wheel joint targets [rad/s] produce."""
    return body_velocity(targets[0] * RAD, targets[1] * RAD, SEP)


def test_command_to_wheel_targets():
    ctrl = make()
    assert ctrl.set_command(0.2, 1.0, 0.0) is True
    left, right = ctrl.update(0.01, 0.0, 0.0, 0.01)
    assert left == pytest.approx((0.2 - 0.1) / RAD)
    assert right == pytest.approx((0.2 + 0.1) / RAD)
    assert body((left, right)) == pytest.approx((0.2, 1.0))


@pytest.mark.parametrize("linear, angular", [(float("nan"), 0.0), (0.0, float("nan")), (float("inf"), 0.0),
                                             (0.0, -float("inf"))])
def test_non_finite_refused_and_command_unchanged(linear, angular):
    ctrl = make()
    ctrl.set_command(0.3, -0.5, 1.0)
    assert ctrl.set_command(linear, angular, 2.0) is False
    assert (ctrl.linear, ctrl.angular, ctrl.stamp) == (0.3, -0.5, 1.0)
    targets = ctrl.update(2.0, 0.0, 0.0, 0.01)
    assert all(math.isfinite(t) for t in targets)
    assert body(targets) == pytest.approx((0.3, -0.5))


def test_non_finite_field_names_first_bad():
    assert non_finite_field((0.0, 0.0, 0.0, 0.0, 0.0, 1.0)) is None
    assert non_finite_field((0.0, float("nan"), 0.0, 0.0, float("inf"), 0.0)) == "linear.y"
    assert non_finite_field((0.0,) * 5 + (float("-inf"),)) == "angular.z"
    assert TWIST_FIELDS[0] == "linear.x"


@pytest.mark.parametrize("linear, angular", [(1e308, 0.0), (-1e308, 0.0), (0.0, 1e308), (1e308, -1e308)])
def test_huge_command_clamped_to_finite_targets(linear, angular):
    ctrl = make()
    assert ctrl.set_command(linear, angular, 0.0) is True
    assert abs(ctrl.linear) <= VMAX * RAD
    assert abs(ctrl.angular) <= 2 * VMAX * RAD / SEP * (1 + 1e-12)  # one float rounding
    targets = ctrl.update(0.0, 0.0, 0.0, 0.01)
    assert all(math.isfinite(t) for t in targets)
    assert max(abs(t) for t in targets) <= VMAX + 1e-9
    assert max(abs(t) for t in targets) == pytest.approx(VMAX)  # saturated, not zeroed
    if linear:
        assert math.copysign(1.0, body(targets)[0]) == math.copysign(1.0, linear)


def test_timeout_holds_before_expiry_and_brakes_exactly_at_it():
    ctrl = make(cmd_vel_timeout=0.5)
    ctrl.set_command(0.2, 0.0, 10.0)
    assert ctrl.expiry() == pytest.approx(10.5)
    moving = (0.2 / RAD, 0.2 / RAD)
    for now in (10.0, 10.25, 10.499):
        assert ctrl.update(now, 6.0, 6.0, 0.01) == pytest.approx(moving)
    assert ctrl.update(10.5, 6.25, 6.25, 0.01) == (0.0, 0.0)
    assert ctrl.linear == 0.0 and ctrl.angular == 0.0


def test_timeout_brake_is_immediate_despite_acceleration_limit():
    ctrl = make(cmd_vel_timeout=0.2, max_wheel_acceleration=1.0)
    ctrl.set_command(0.3, 0.0, 0.0)
    assert ctrl.update(0.3, 9.0, 9.0, 0.01) == (0.0, 0.0)  # not 9 - a*dt/r


def test_timeout_brake_holds_on_following_updates_with_acceleration_limit():
    ctrl = make(cmd_vel_timeout=0.2, max_wheel_acceleration=1.0)
    ctrl.set_command(0.3, 0.0, 0.0)
    assert ctrl.update(0.2, 9.0, 9.0, 0.01) == (0.0, 0.0)
    # one control period later the wheels have not stopped yet; the safety stop must still command 0
    assert ctrl.update(0.21, 8.0, 8.0, 0.01) == (0.0, 0.0)


def test_new_command_after_timeout_drives_again():
    ctrl = make(cmd_vel_timeout=0.2)
    ctrl.set_command(0.3, 0.0, 0.0)
    assert ctrl.update(0.25, 0.0, 0.0, 0.01) == (0.0, 0.0)
    ctrl.set_command(-0.1, 0.0, 0.3)
    assert body(ctrl.update(0.35, 0.0, 0.0, 0.01)) == pytest.approx((-0.1, 0.0))


def test_zero_timeout_holds_forever():
    ctrl = make(cmd_vel_timeout=0.0)
    ctrl.set_command(0.2, 0.5, 0.0)
    assert ctrl.expiry() is None
    assert body(ctrl.update(1e6, 0.0, 0.0, 0.01)) == pytest.approx((0.2, 0.5))


def test_zero_command_never_expires():
    ctrl = make(cmd_vel_timeout=0.1)
    ctrl.set_command(0.0, 0.0, 0.0)
    assert ctrl.expiry() is None


def test_brake_resets_command():
    ctrl = make()
    ctrl.set_command(0.2, 0.5, 1.0)
    ctrl.brake()
    assert (ctrl.linear, ctrl.angular, ctrl.stamp) == (0.0, 0.0, None)
    assert ctrl.update(2.0, 0.0, 0.0, 0.01) == (0.0, 0.0)


def test_acceleration_ramp_limits_change_per_update():
    accel, dt = 1.8, 0.01
    step = accel * dt / RAD
    ctrl = make(max_wheel_acceleration=accel)
    ctrl.set_command(1.0, 0.0, 0.0)
    left, right = ctrl.update(0.0, 0.0, 0.0, dt)
    assert left == pytest.approx(step) and right == pytest.approx(step)
    # it ramps from the *measured* velocity, not from the previous target
    left, right = ctrl.update(0.01, 3.0, -1.0, dt)
    assert left == pytest.approx(3.0 + step)
    assert right == pytest.approx(-1.0 + step)
    # and never overshoots the target
    goal = 1.0 / RAD
    assert ctrl.update(0.02, goal - step / 3, goal - step / 3, dt) == pytest.approx((goal, goal))


def test_acceleration_ramp_down_when_reversing():
    accel, dt = 2.0, 0.02
    ctrl = make(max_wheel_acceleration=accel)
    ctrl.set_command(-0.5, 0.0, 0.0)
    left, right = ctrl.update(0.0, 10.0, 10.0, dt)
    assert left == pytest.approx(10.0 - accel * dt / RAD)
    assert right == pytest.approx(10.0 - accel * dt / RAD)


def test_no_acceleration_limit_jumps_to_target():
    ctrl = make(max_wheel_acceleration=0.0)
    ctrl.set_command(0.5, 0.0, 0.0)
    assert ctrl.update(0.0, -20.0, 30.0, 0.01) == pytest.approx((0.5 / RAD, 0.5 / RAD))


def test_curvature_kept_when_wheel_limit_saturates():
    # v and w are each within their own clamp, but the outer wheel would need 1.5 m/s > 1.28 m/s
    ctrl = make()
    ctrl.set_command(1.0, 5.0, 0.0)
    targets = ctrl.update(0.0, 0.0, 0.0, 0.01)
    assert max(abs(t) for t in targets) == pytest.approx(VMAX)
    v, w = body(targets)
    assert v < 1.0
    assert v / w == pytest.approx(1.0 / 5.0)  # same turning radius as commanded
    assert targets[1] / targets[0] == pytest.approx((1.0 + 0.5) / (1.0 - 0.5))


def test_curvature_kept_when_linear_speed_saturates():
    ctrl = make()
    ctrl.set_command(2.0, 1.0, 0.0)  # turning radius 2 m; 2 m/s > max_linear 1.28 m/s
    targets = ctrl.update(0.0, 0.0, 0.0, 0.01)
    assert max(abs(t) for t in targets) == pytest.approx(VMAX)
    v, w = body(targets)
    assert v / w == pytest.approx(2.0)


# -- the plugin's step: inbox, schedule, timeout between updates (what both front ends run) --------------------

class Wheels:
    """DriveWheels' interface: measured (left, right) velocities in, the targets set recorded."""

    def __init__(self, left=0.0, right=0.0):
        self.measured, self.set_to = (left, right), []

    def velocities(self):
        return self.measured

    def set(self, left, right):
        self.set_to.append((left, right))


def stepper(**kwargs):
    ctrl = make(update_rate=100.0, time_step=1 / 240, **kwargs)
    ctrl.start(0.0)
    return ctrl, Wheels()


def test_a_new_command_reaches_the_wheels_at_once_then_updates_follow_the_schedule():
    ctrl, wheels = stepper()
    assert ctrl.before_step(0.0, wheels) is None and len(wheels.set_to) == 1  # due at the start
    assert ctrl.before_step(1 / 240, wheels) is None and len(wheels.set_to) == 1  # not due until 0.01
    ctrl.inbox.put((0.2, 0.0))
    assert ctrl.before_step(2 / 240, wheels) == (0.2, 0.0)  # between updates, but new: applied now
    assert body(wheels.set_to[-1]) == pytest.approx((0.2, 0.0))
    assert ctrl.before_step(3 / 240, wheels) is None and len(wheels.set_to) == 3  # 0.0125 >= 0.01: due
    assert ctrl.next_update == pytest.approx(0.02)


def test_a_non_finite_command_is_not_applied_and_waits_for_the_schedule():
    ctrl, wheels = stepper()
    ctrl.before_step(0.0, wheels)
    ctrl.inbox.put((math.nan, 0.0))
    assert ctrl.before_step(1 / 240, wheels) is None and len(wheels.set_to) == 1


def test_a_stale_command_brakes_at_its_step_not_at_the_next_update():
    ctrl, wheels = stepper(cmd_vel_timeout=0.105, max_wheel_acceleration=1.0)
    ctrl.inbox.put((0.2, 0.0))
    ctrl.before_step(0.0, wheels)
    wheels.measured = (6.0, 6.0)
    step = 1
    while step * (1 / 240) < 0.105:
        ctrl.before_step(step / 240, wheels)
        step += 1
    count = len(wheels.set_to)
    ctrl.before_step(step / 240, wheels)  # 0.1083 s: stale, and no update is due before 0.11
    assert step / 240 < ctrl.next_update
    assert len(wheels.set_to) == count + 1 and wheels.set_to[-1] == (0.0, 0.0)


def test_reset_forgets_a_command_on_its_way_and_stops():
    ctrl, wheels = stepper()
    ctrl.inbox.put((0.2, 0.0))
    ctrl.before_step(0.0, wheels)
    ctrl.inbox.put((0.3, 0.0))
    ctrl.reset()
    ctrl.start(5.0)
    assert ctrl.before_step(5.0, wheels) is None
    assert wheels.set_to[-1] == (0.0, 0.0) and (ctrl.linear, ctrl.angular) == (0.0, 0.0)


def test_drive_wheels_average_each_side_and_set_every_wheel():
    class Body:
        def joint_states(self, indices):
            assert indices == [1, 2, 3, 4]
            return None, [1.0, 3.0, -2.0, -4.0], None

        def set_velocities(self, indices, velocities, forces):
            self.call = (indices, velocities, forces)
    robot = Body()
    wheels = DriveWheels(robot, [1, 2], [3, 4], [5.0, 5.0, 6.0, 6.0])
    assert wheels.velocities() == (2.0, -3.0)
    wheels.set(0.5, -0.5)
    assert robot.call == ([1, 2, 3, 4], [0.5, 0.5, -0.5, -0.5], [5.0, 5.0, 6.0, 6.0])
    wheels.brake()
    assert robot.call[1] == [0.0] * 4
