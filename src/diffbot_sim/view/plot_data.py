"""What ``plot_run`` draws, from the messages of a run (pure: no rospy, no matplotlib).

A run is a list of ``(topic, message, t)`` records, ``t`` in sim seconds (a bag's record time, or the
receipt time of ``--live``). :func:`collect` sorts them into :class:`RunData` arrays by message *type*, so
namespaced robots and remapped topics work: Odometry in a frame named ``world`` is ground truth (the
simulator's ``~ground_truth``, like Gazebo's p3d), any other Odometry is the robot's odometry; Twist is the
command; LaserScan the scan; TFMessage the transforms. :func:`scan_in_odom` puts the last scan's points in
the odometry frame through the recorded TF tree, at the scan's stamp.

Ground truth is in the world frame and odometry in ``odom``. When ``/tf_static`` holds ``world -> odom``
(``view.launch``'s world_markers publishes it) the ground truth is drawn in ``odom`` through it; otherwise
in the world frame as it is, which equals ``odom`` for the default ``odometry_source: world``.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from diffbot_sim.transforms import compose, inverse, yaw_from_quaternion

IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


@dataclass
class RunData:
    """Arrays of one run. Times in s (sim), positions in m, speeds in m/s and rad/s.

    ``odom``/``truth``: (N, 6) rows of t, x, y, yaw, linear x, angular z. ``cmd``: (N, 3) rows of t, linear x,
    angular z. ``scan``: the last LaserScan (or None). ``odom_frame``, ``truth_frame``: their header frames.
    ``tf``: the recorded transforms (see :class:`TfTree`).
    """

    odom: np.ndarray
    truth: np.ndarray
    cmd: np.ndarray
    scan: object = None
    odom_frame: str = "odom"
    truth_frame: str = "world"
    tf: "TfTree | None" = None
    odom_topic: str = ""
    truth_topic: str = ""


def _pose(transform):
    t, r = transform.translation, transform.rotation
    return (t.x, t.y, t.z), (r.x, r.y, r.z, r.w)


class TfTree:
    """Transforms recorded from ``/tf`` and ``/tf_static``: static ones kept as the latest, dynamic ones as
    a time series per child frame, looked up at or before a time (no interpolation: odometry comes at
    50-100 Hz, a scan at 5-10 Hz, so the nearest earlier transform is at most 20 ms old)."""

    def __init__(self):
        self.static: dict[str, tuple[str, tuple]] = {}
        self.dynamic: dict[str, list[tuple[float, str, tuple]]] = {}

    def add(self, msg, static):
        """Record every transform of a tf2_msgs/TFMessage."""
        for t in msg.transforms:
            child, parent = t.child_frame_id.lstrip("/"), t.header.frame_id.lstrip("/")
            if static:
                self.static[child] = (parent, _pose(t.transform))
            else:
                self.dynamic.setdefault(child, []).append((t.header.stamp.to_sec(), parent, _pose(t.transform)))

    def parent(self, child, stamp):
        """``(parent, pose of child in parent)`` at ``stamp``, or None."""
        if child in self.static:
            return self.static[child]
        series = self.dynamic.get(child)
        if not series:
            return None
        best = None
        for t, parent, pose in series:
            if t <= stamp + 1e-9:
                best = (parent, pose)
            else:
                break
        return best if best is not None else (series[0][1], series[0][2])

    def lookup(self, target, source, stamp):
        """Pose of frame ``source`` in frame ``target`` at ``stamp``, or None when they are not connected.
        Both chains are walked up to the root and joined at their lowest common frame."""
        target, source = target.lstrip("/"), source.lstrip("/")

        def chain(frame):
            out = {frame: IDENTITY}
            pose = IDENTITY
            for _ in range(64):
                up = self.parent(frame, stamp)
                if up is None:
                    break
                frame, step = up[0], up[1]
                pose = compose(step, pose)
                out[frame] = pose
            return out
        from_source, from_target = chain(source), chain(target)
        for frame, source_in_frame in from_source.items():
            if frame in from_target:
                return compose(inverse(from_target[frame]), source_in_frame)
        return None


def collect(records):
    """Sort ``(topic, message, t)`` records into :class:`RunData` (see the module docstring).

    Raises:
        ValueError: no odometry at all (nothing to plot), naming the topics that were there.
    """
    odom, truth, cmd = [], [], []
    scan, tf = None, TfTree()
    frames = {"odom": "odom", "truth": "world"}
    topics = {"odom": "", "truth": ""}
    seen = set()
    for topic, msg, t in records:
        kind = getattr(msg, "_type", "")
        seen.add(f"{topic} ({kind})")
        if kind == "nav_msgs/Odometry":
            p, q, v = msg.pose.pose.position, msg.pose.pose.orientation, msg.twist.twist
            row = (msg.header.stamp.to_sec(), p.x, p.y, yaw_from_quaternion(q.x, q.y, q.z, q.w), v.linear.x,
                   v.angular.z)
            which = "truth" if msg.header.frame_id.lstrip("/") == "world" else "odom"
            if topics[which] and topics[which] != topic:
                continue  # a second robot or odometry source: the first one seen is the one drawn
            topics[which] = topic
            frames[which] = msg.header.frame_id.lstrip("/")
            (truth if which == "truth" else odom).append(row)
        elif kind == "geometry_msgs/Twist":
            cmd.append((t, msg.linear.x, msg.angular.z))
        elif kind == "geometry_msgs/TwistStamped":
            cmd.append((msg.header.stamp.to_sec(), msg.twist.linear.x, msg.twist.angular.z))
        elif kind == "sensor_msgs/LaserScan":
            scan = msg
        elif kind == "tf2_msgs/TFMessage":
            tf.add(msg, static=topic.endswith("tf_static"))
    if not odom and not truth:
        raise ValueError("no nav_msgs/Odometry in the run; topics: " + (", ".join(sorted(seen)) or "none"))
    return RunData(_array(odom, 6), _array(truth, 6), _array(cmd, 3), scan, frames["odom"], frames["truth"], tf,
                   topics["odom"], topics["truth"])


def _array(rows, width):
    return np.array(sorted(rows), dtype=float).reshape(-1, width)


def truth_in_odom(data):
    """Ground-truth x, y (N, 2) in the odometry frame, and how: ``"tf"`` through a recorded
    ``world -> odom`` transform, ``"as is"`` without one (world and odom coincide for world odometry)."""
    if not len(data.truth):
        return np.zeros((0, 2)), "none"
    offset = data.tf.lookup(data.odom_frame, data.truth_frame, data.truth[-1, 0]) if data.tf else None
    if offset is None:
        return data.truth[:, 1:3].copy(), "as is"
    out = [compose(offset, ((x, y, 0.0), (0.0, 0.0, 0.0, 1.0)))[0][:2] for x, y in data.truth[:, 1:3]]
    return np.array(out, dtype=float).reshape(-1, 2), "tf"


def scan_points(scan):
    """The finite ranges of a LaserScan as (N, 2) x, y in its own frame (REP 103: counter-clockwise)."""
    ranges = np.asarray(scan.ranges, dtype=float)
    angles = scan.angle_min + scan.angle_increment * np.arange(len(ranges))
    ok = np.isfinite(ranges) & (ranges >= scan.range_min) & (ranges <= scan.range_max)
    return np.stack([ranges[ok] * np.cos(angles[ok]), ranges[ok] * np.sin(angles[ok])], axis=1)


def scan_in_odom(data):
    """The last scan's points in the odometry frame (N, 2), or None when there is no scan or its frame is not
    connected to the odometry frame in the recorded TF."""
    if data.scan is None or data.tf is None:
        return None
    pose = data.tf.lookup(data.odom_frame, data.scan.header.frame_id, data.scan.header.stamp.to_sec())
    if pose is None:
        return None
    points = scan_points(data.scan)
    return np.array([compose(pose, ((x, y, 0.0), (0.0, 0.0, 0.0, 1.0)))[0][:2] for x, y in points],
                    dtype=float).reshape(-1, 2)


@dataclass
class Summary:
    """Figures printed under the plot: samples, duration (s), distance driven (m, odometry), final pose
    error against ground truth (m), or None without ground truth."""

    samples: int
    duration: float
    distance: float
    final_error: float | None = None
    notes: list[str] = field(default_factory=list)


def summarize(data):
    """Figures of a run for the plot's title line."""
    odom = data.odom if len(data.odom) else data.truth
    steps = np.diff(odom[:, 1:3], axis=0)
    distance = float(np.hypot(steps[:, 0], steps[:, 1]).sum()) if len(steps) else 0.0
    duration = float(odom[-1, 0] - odom[0, 0]) if len(odom) > 1 else 0.0
    error = None
    if len(data.odom) and len(data.truth):
        truth, _ = truth_in_odom(data)
        error = float(math.hypot(data.odom[-1, 1] - truth[-1, 0], data.odom[-1, 2] - truth[-1, 1]))
    return Summary(len(odom), duration, distance, error)
