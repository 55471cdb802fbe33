"""Whether a body has settled, judged by stamped samples: every value within a band over a window of sim time.

A "before" or "after" sample of a body must be taken once it holds still, and "still" is not one instant: one
message with a low velocity is also the turnaround of an oscillation, and a reading a fixed time after a
command is a guess about how long settling takes on this machine. ``held_still`` looks at the samples' own
stamps (sim time, as the simulator stamped them), so a test node that reads them late judges the same window.
Pure: no ROS; the suites and robot_check feed it what their callbacks kept.
"""
import math

from diffbot_sim.transforms import quaternion_rpy


def held_still(samples, band, window):
    """``samples``: [(stamp, [value, ...])] oldest first, stamped in sim time. Returns (True, the last values)
    when the samples of the last ``window`` s (with one at or before the window's start, so the window is
    covered) all lie within ``band`` (max - min) for every value; else (False, why not: how much sim time is
    covered so far, or which value moved how much)."""
    if not samples:
        return False, "no samples yet"
    last = samples[-1][0]
    start = last - window
    if samples[0][0] > start + 1e-9:
        return False, f"{last - samples[0][0]:.3f} s of sim time covered so far"
    begin = max(i for i, (stamp, _) in enumerate(samples) if stamp <= start + 1e-9)
    recent = [values for _, values in samples[begin:]]
    spreads = [max(column) - min(column) for column in zip(*recent)]
    widest = max(range(len(spreads)), key=spreads.__getitem__) if spreads else None
    if widest is not None and spreads[widest] > band:
        return False, f"value {widest} moved {spreads[widest]:.5f} over the last {window} s (band {band})"
    return True, list(samples[-1][1])


def pose_values(pose, heading=0.0):
    """[x, y, z, roll, pitch, yaw] of a geometry_msgs Pose for ``held_still``, the yaw taken about ``heading``
    (the last sample's: no jump where it wraps at +-pi; angles rather than quaternion components, which a
    publisher may flip in sign)."""
    p, q = pose.position, pose.orientation
    roll, pitch, yaw = quaternion_rpy((q.x, q.y, q.z, q.w))
    return [p.x, p.y, p.z, roll, pitch, math.remainder(yaw - heading, 2.0 * math.pi)]


def pose_still(messages, band, window):
    """The last of ``messages`` (stamped, with ``.pose.pose``: nav_msgs/Odometry, as ground truth comes) when
    the body's position (m) and orientation (rad) have held within ``band`` over the last ``window`` s of their
    stamps (``held_still``), else None."""
    if not messages:
        return None
    heading = pose_values(messages[-1].pose.pose)[5]
    samples = [(m.header.stamp.to_sec(), pose_values(m.pose.pose, heading)) for m in messages]
    return messages[-1] if held_still(samples, band, window)[0] else None
