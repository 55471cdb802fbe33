"""check.stillness: a body has settled when every value held within a band over a window of its own stamps (sim
time), not at one instant: an oscillation's turnaround, a slow creep and a window not yet covered are refused."""
import math
from types import SimpleNamespace

from diffbot_sim.check.stillness import held_still, pose_still
from diffbot_sim.transforms import rpy_quaternion


def samples(values_at, start=0.0, end=1.0, rate=100.0):
    count = int(round((end - start) * rate)) + 1
    return [(start + k / rate, values_at(start + k / rate)) for k in range(count)]


def test_jitter_within_the_band_is_still_and_the_last_values_come_back():
    still, last = held_still(samples(lambda t: [0.5 + 1e-4 * math.sin(40 * t)]), band=1e-3, window=0.3)
    assert still and last == [0.5 + 1e-4 * math.sin(40 * 1.0)]


def test_an_oscillation_is_not_still_even_at_its_turnaround():
    """+-5 mrad at 2 Hz: the last sample is at a turnaround (velocity 0), which a one-instant test takes for rest."""
    ringing = samples(lambda t: [0.005 * math.cos(2 * math.pi * 2 * t)], end=1.0)
    still, why = held_still(ringing, band=1e-3, window=0.3)
    assert not still and "value 0 moved" in why


def test_a_slow_creep_is_not_still():
    still, _ = held_still(samples(lambda t: [0.01 * t]), band=1e-3, window=0.3)  # 3 mrad over the window
    assert not still


def test_a_window_not_yet_covered_by_stamps_is_not_still():
    still, why = held_still(samples(lambda t: [0.0], start=0.9, end=1.0), band=1e-3, window=0.3)
    assert not still and "covered so far" in why
    assert held_still([], 1e-3, 0.3) == (False, "no samples yet")


def test_a_pose_still_across_the_yaw_wrap_is_still():
    """A body at rest facing -x reads yaw +pi and -pi by turns: that is no motion."""
    def odom(t, yaw):
        q = rpy_quaternion(0.0, 0.0, yaw)
        pose = SimpleNamespace(position=SimpleNamespace(x=1.0, y=2.0, z=0.0),
                               orientation=SimpleNamespace(x=q[0], y=q[1], z=q[2], w=q[3]))
        return SimpleNamespace(header=SimpleNamespace(stamp=SimpleNamespace(to_sec=lambda: t)),
                               pose=SimpleNamespace(pose=pose))
    messages = [odom(k * 0.01, math.pi - 1e-5 if k % 2 else -math.pi + 1e-5) for k in range(60)]
    assert pose_still(messages, band=1e-3, window=0.3) is messages[-1]
    moving = [odom(k * 0.01, 0.01 * k) for k in range(60)]
    assert pose_still(moving, band=1e-3, window=0.3) is None
