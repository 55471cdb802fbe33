"""An actor's trajectory as Gazebo 11 interpolates it between waypoints (pure): ``common/Animation.cc``
``PoseAnimation`` over ign-math6 ``Spline`` and ``RotationSpline``.

* Position: a cubic Hermite spline per trajectory with Catmull-Rom tangents ``0.5 (1 - tension) (p[i+1] -
  p[i-1])`` (one-sided at open ends; when the first and last points agree within 1e-3 m the spline is closed
  and the end tangents wrap). The segment parameter is local in time, ``(t - t_k) / (t_{k+1} - t_k)``, so
  every waypoint is hit exactly at its time.
* Orientation: Shoemake squad with log/exp tangents (ign-math6 ``RotationSpline``;
  :func:`diffbot_sim.transforms.squad`), shortest path between the two keyframes but not for the tangents.
  Gazebo 11 uses squad for every segment; the "plain SLERP when the keyframes differ by < 0.16 rad" rule is
  gz-math PR 577 (https://github.com/gazebosim/gz-math/pull/577: open, never released). For yaw-only
  waypoints squad stays about z; across yaw +-pi its long-way tangents make the actor swing round, as in
  Gazebo. Tension does not affect rotation; heading is never derived from the direction of travel.
"""
from bisect import bisect_left

from diffbot_sim.transforms import IGN_EQUAL, qnormalize, shoemake_tangent, squad
from diffbot_sim.world.actor_sdf import pose6_to_pose

#: Vector3 and Quaternion ``operator==`` compare each component within this: the "closed spline" test.
SAME_POINT = 1e-3


class PositionSpline:
    """ign-math6 ``Spline`` with auto-calculation off, ``Tension(tension)`` then ``RecalcTangents()``."""

    def __init__(self, points, tension):
        self.points = [tuple(float(c) for c in p) for p in points]
        n = len(self.points)
        self.tangents = [(0.0, 0.0, 0.0)] * n
        if n < 2:
            return
        pts = self.points
        closed = all(abs(a - b) <= SAME_POINT for a, b in zip(pts[0], pts[-1]))
        scale = 1.0 - tension

        def tangent(later, earlier):
            return tuple((a - b) * 0.5 * scale for a, b in zip(later, earlier))

        for i in range(n):
            if i == 0:
                self.tangents[i] = tangent(pts[1], pts[n - 2] if closed else pts[0])
            elif i == n - 1:
                self.tangents[i] = self.tangents[0] if closed else tangent(pts[i], pts[i - 1])
            else:
                self.tangents[i] = tangent(pts[i + 1], pts[i - 1])

    def interpolate(self, index, t):
        """Spline::Interpolate(index, t): the Hermite segment from point ``index`` at parameter ``t``."""
        if index >= len(self.points) - 1:  # "cannot blend to nothing": the point itself
            return self.points[index]
        if abs(t) <= IGN_EQUAL:
            return self.points[index]
        if abs(t - 1.0) <= IGN_EQUAL:
            return self.points[index + 1]
        t2, t3 = t * t, t * t * t
        h00, h10, h01, h11 = 2 * t3 - 3 * t2 + 1, t3 - 2 * t2 + t, -2 * t3 + 3 * t2, t3 - t2
        p0, p1, m0, m1 = self.points[index], self.points[index + 1], self.tangents[index], self.tangents[index + 1]
        return tuple(h00 * a + h10 * b + h01 * c + h11 * d for a, b, c, d in zip(p0, m0, p1, m1))


class RotationSpline:
    """ign-math6 ``RotationSpline``: Shoemake's tangents ``p exp(-(log(p^-1 p[i+1]) + log(p^-1 p[i-1])) / 4)``
    (the point itself at open ends; wrapped when the first and last rotations agree within 1e-3)."""

    def __init__(self, rotations):
        self.points = [tuple(q) for q in rotations]
        n = len(self.points)
        self.tangents = list(self.points)
        if n < 2:
            return
        pts = self.points
        closed = all(abs(a - b) <= SAME_POINT for a, b in zip(pts[0], pts[-1]))
        for i, p in enumerate(pts):
            later = pts[i + 1] if i < n - 1 else (pts[1] if closed else p)
            earlier = pts[i - 1] if i > 0 else (pts[n - 2] if closed else p)
            self.tangents[i] = shoemake_tangent(p, later, earlier)

    def interpolate(self, index, t):
        """RotationSpline::Interpolate(index, t), shortest path on (its default)."""
        if index + 1 >= len(self.points):
            return self.points[index]
        if abs(t) <= IGN_EQUAL:
            return self.points[index]
        if abs(t - 1.0) <= IGN_EQUAL:
            return self.points[index + 1]
        return squad(t, self.points[index], self.tangents[index], self.tangents[index + 1],
                     self.points[index + 1], shortest_path=True)


class PoseTrack:
    """One trajectory's ``PoseAnimation`` (loop off): keyframe lookup by time, then the two splines."""

    def __init__(self, trajectory):
        self.times = [w.time for w in trajectory.waypoints]
        poses = [pose6_to_pose(w.pose) for w in trajectory.waypoints]
        self.poses = poses
        self.length = trajectory.duration
        self.position = PositionSpline([p for p, _ in poses], trajectory.tension)
        self.rotation = RotationSpline([q for _, q in poses])

    def pose_at(self, time):
        """Animation::SetTime (clamped to 0..length) then GetInterpolatedKeyFrame."""
        time = min(max(time, 0.0), self.length)
        i = bisect_left(self.times, time)  # first keyframe at or after `time`
        if i == len(self.times):  # past the last keyframe: blend towards the first, one length later
            t2, first = self.length + self.times[0], len(self.times) - 1
        else:
            t2, first = self.times[i], i - 1 if i > 0 and time < self.times[i] else i
        t1 = self.times[first]
        u = 0.0 if abs(t1 - t2) <= IGN_EQUAL else (time - t1) / (t2 - t1)
        if abs(u) <= IGN_EQUAL:
            return self.poses[first]
        return (self.position.interpolate(first, u), qnormalize(self.rotation.interpolate(first, u)))
