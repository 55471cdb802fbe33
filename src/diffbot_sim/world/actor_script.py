"""Gazebo-classic 11 ``<actor>`` elements read into data, and their ``<script>`` played back (pure).

Reproduced from gazebo-classic's gazebo11 sources and the ignition-math6 they link (shared reference
fleets_and_actors.md part A, re-read at the sources named here):

Reading (``gazebo/physics/Actor.cc`` ``Load``/``LoadScript``; sdformat 9 with ``sdf/1.6/actor.sdf``):

* ``name`` is a required attribute: sdformat refuses the world without it, so :func:`read_actor` raises.
  ``<script>`` is required too, but sdformat then adds the default one (loop, no trajectories), so a
  missing script is only a note (ActorPlugin actors such as cafe.world's have none).
* Trajectories play in ascending ``id`` (ties keep file order). Gazebo keeps their animations in a map
  keyed by id, so two trajectories with the same id both play the waypoints of the later one.
* Waypoints go into a map keyed by time: file order is irrelevant and a repeated time keeps the last
  pose. The trajectory lasts until its last waypoint's time. Gazebo 11 *moves* the first waypoint to
  t = 0 (Gazebo 7 and older added an extra keyframe at 0 instead): waypoints at 2 s and 4 s play as 0 s and 4 s.
* Numbers are read as sdformat reads them (:func:`diffbot_sim.values.tag_number`): ``2.0s`` is 2 with
  one note; a text with no number is an error. ``tension`` outside 0..1 is used as written (sdformat 9
  does not enforce the schema's min/max; sdformat 10 does), with a note.

Playback (``Actor::Update`` with gazebo-classic PR 2773, ``common/Animation.cc`` ``PoseAnimation``,
ign-math6 ``Spline``, ``RotationSpline``, ``Quaternion::Slerp``/``Squad``):

* A new frame is computed at most every ``frame_period`` (1/30 s) of sim time; steps between frames hold
  the last frame. ``script time = sim - delay_start - play start``; before it reaches 0 nothing moves.
* At the end of the script: without ``loop`` the actor stops at its *last rendered* frame (a frame at or
  past the end is never drawn, so the last waypoint itself is not shown); with ``loop`` the time wraps
  and the play start moves to the wrap, so ``delay_start`` is waited again each cycle (period = length +
  delay), holding the first frame of the new cycle meanwhile.
* Trajectories play back to back. Position: a cubic Hermite spline per trajectory with Catmull-Rom
  tangents ``0.5 (1 - tension) (p[i+1] - p[i-1])`` (one-sided at open ends; when the first and last
  points agree within 1e-3 m the spline is closed and the end tangents wrap). The segment parameter is
  local in time, ``(t - t_k) / (t_{k+1} - t_k)``, so every waypoint is hit exactly at its time.
* Orientation: Shoemake squad with log/exp tangents (ign-math6 ``RotationSpline``), shortest path between
  the two keyframes but not for the tangents. Gazebo 11 uses squad for every segment; the "plain SLERP
  when the keyframes differ by < 0.16 rad" rule is gz-math PR 577 (open, never released). For yaw-only
  waypoints squad stays about z; across yaw +-pi its long-way tangents make the actor swing round, as in
  Gazebo. Tension does not affect rotation; heading is never derived from the direction of travel.

The pose returned is what Gazebo reports for the actor's model (``/gazebo/model_states``,
``get_model_state``): for an actor without a skeleton (links of its own, or a skin we do not animate) the
trajectory pose itself, in the world frame (the actor's ``<pose>`` only places it before the first
frame). With a skeleton Gazebo reports the trajectory pose composed with the animated root bone (its X
zeroed); we have no skeleton, so the trajectory pose is the actor's feet frame (actor.world's waypoints
sit at z = 0 and its skin stands on the ground).

Deliberately not reproduced: skeleton animation (``interpolate_x``, ``PoseAtX``, bone links); a
trajectory without waypoints (Gazebo gives it the length of the animation of its type, which we do not
read, and puts the actor at the world origin while it plays): here it lasts 0 s and holds the pose.
"""
import math
from bisect import bisect_left
from dataclasses import dataclass, field
from typing import Optional, Tuple
import xml.etree.ElementTree as ET

from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.transforms import qmul, qnormalize, rpy_quaternion
from diffbot_sim.values import check_bool, check_number, tag_number

Vec3 = Tuple[float, float, float]
Quat = Tuple[float, float, float, float]
Pose = Tuple[Vec3, Quat]
#: x, y, z (m), roll, pitch, yaw (rad), as SDF writes a ``<pose>``.
Pose6 = Tuple[float, float, float, float, float, float]
ZERO_POSE6: Pose6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

#: Actor::Update draws a new frame at most this often, in s of sim time ("do not refresh animation faster
#: than 30 Hz sim time").
FRAME_PERIOD = 1.0 / 30.0
#: ignition::math::equal's default tolerance: a keyframe time or spline parameter this close counts as equal.
_EQUAL = 1e-6
#: Vector3 and Quaternion ``operator==`` compare each component within this: the "closed spline" test.
_SAME_POINT = 1e-3


# ------------------------------------------------------------------------------------------ the data

@dataclass(frozen=True)
class Skin:
    """``<skin>``: the mesh drawn for the actor (``filename`` as written) and its uniform ``scale``."""

    filename: str
    scale: float = 1.0


@dataclass(frozen=True)
class Animation:
    """``<animation name>``: a skeleton animation file; ``interpolate_x`` ties its gait to distance."""

    name: str
    filename: str
    scale: float = 1.0
    interpolate_x: bool = False


@dataclass(frozen=True)
class Waypoint:
    """One keyframe: ``time`` s from the start of its trajectory, ``pose`` (x, y, z, roll, pitch, yaw)."""

    time: float
    pose: Pose6


@dataclass(frozen=True)
class Trajectory:
    """``<trajectory>`` as Gazebo plays it: ``waypoints`` are the keyframes (sorted, first at 0 s, repeated
    times collapsed) and ``duration`` s is the last waypoint's time as written."""

    id: int
    type: str
    tension: float = 0.0
    waypoints: Tuple[Waypoint, ...] = ()
    duration: float = 0.0


@dataclass(frozen=True)
class Script:
    """``<script>``: ``delay_start`` s; ``trajectories`` in the order they play (ascending id)."""

    loop: bool = True
    delay_start: float = 0.0
    auto_start: bool = True
    trajectories: Tuple[Trajectory, ...] = ()


@dataclass(frozen=True)
class PluginRef:
    """A ``<plugin>`` inside the actor: ``filename`` (e.g. ``libActorPlugin.so``), ``name`` and its element."""

    filename: str
    name: str
    element: ET.Element = field(compare=False, repr=False)


@dataclass(frozen=True)
class ActorDescription:
    """One ``<actor>``: its ``pose`` (x, y, z, roll, pitch, yaw; where it stands before the script moves
    it), ``skin`` (None without one), ``animations``, ``script`` and the ``plugins`` inside it."""

    name: str
    pose: Pose6 = ZERO_POSE6
    skin: Optional[Skin] = None
    animations: Tuple[Animation, ...] = ()
    script: Script = Script()
    plugins: Tuple[PluginRef, ...] = ()

    @property
    def world_pose(self) -> Pose:
        """``pose`` as ((x, y, z), (qx, qy, qz, qw))."""
        return pose6_to_pose(self.pose)

    def plugin(self, filename):
        """The first plugin whose file is ``filename`` (``libActorPlugin.so`` or ``ActorPlugin``), or None."""
        wanted = _plugin_stem(filename)
        return next((p for p in self.plugins if _plugin_stem(p.filename) == wanted), None)


def _plugin_stem(filename):
    """``/x/libActorPlugin.so`` and ``ActorPlugin`` name the same library, as Gazebo's plugin loader finds it."""
    stem = filename.strip().rsplit("/", 1)[-1]
    stem = stem[3:] if stem.startswith("lib") else stem
    return stem[:-3] if stem.endswith(".so") else stem


def pose6_to_pose(pose6):
    """(x, y, z, roll, pitch, yaw) -> ((x, y, z), (qx, qy, qz, qw)), the quaternion as ignition builds it."""
    x, y, z, roll, pitch, yaw = pose6
    return ((float(x), float(y), float(z)), rpy_quaternion(roll, pitch, yaw))


# ------------------------------------------------------------------------------------------ reading

def _number(text, where, notes, integer=False):
    """A tag's number as sdformat reads it; no leading number is a ModelError naming ``where``."""
    try:
        return tag_number(where, text, notes, integer=integer)
    except ConfigError:
        kind = "a whole number" if integer else "a number"
        raise ModelError(f"'{text.strip()}' is not {kind}", element=where) from None


def _child_number(el, tag, default, where, notes):
    child = el.find(tag)
    if child is None or not (child.text or "").strip():
        return default
    return _number(child.text, f"{where}/{tag}", notes)


def _child_bool(el, tag, default, where):
    child = el.find(tag)
    if child is None or not (child.text or "").strip():
        return default
    try:
        return check_bool(f"{where}/{tag}", child.text)
    except ConfigError:
        raise ModelError(f"'{child.text.strip()}' is not true/false/1/0", element=f"{where}/{tag}") from None


def _pose6(el, where):
    """A ``<pose>`` element's six numbers, strictly (as every pose in this project); empty or absent: zeros."""
    text = "" if el is None else (el.text or "").strip()
    if not text:
        return ZERO_POSE6
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        values = ()
    if len(values) != 6 or not all(math.isfinite(v) for v in values):
        raise ModelError(f"<pose> '{text}' is not 6 finite numbers", element=where)
    return values


def read_actor(element, path, notes):
    """The ``<actor>`` ``element`` (an ElementTree element) as an :class:`ActorDescription`.

    ``path`` names the element in messages (e.g. ``world.sdf: /sdf/world/actor[@name='a']``); what Gazebo
    tolerates but a user should know is appended to ``notes``, one line each.

    Raises:
        ModelError: no ``name``, a trajectory without ``id`` or ``type``, a number that is no number, a
            pose that is not 6 numbers, or a trajectory ending before 0 s (Gazebo finds nothing to play).
    """
    name = (element.get("name") or "").strip()
    if not name:
        raise ModelError("<actor> has no name attribute (sdformat requires one)", element=path)
    pose = _pose6(element.find("pose"), f"{path}/pose")
    skin = None
    skin_el = element.find("skin")
    if skin_el is not None:
        filename = (skin_el.findtext("filename") or "").strip()
        if filename:
            skin = Skin(filename, _child_number(skin_el, "scale", 1.0, f"{path}/skin", notes))
        else:
            notes.append(f"{path}/skin: no <filename>: Gazebo loads no skin")
    animations = tuple(a for a in (_animation(el, f"{path}/animation[{k}]", notes)
                                   for k, el in enumerate(element.findall("animation"), 1)) if a)
    plugins = tuple(PluginRef((el.get("filename") or "").strip(), (el.get("name") or "").strip(), el)
                    for el in element.findall("plugin"))
    script_el = element.find("script")
    if script_el is None:
        script = Script()
        if not plugins:
            notes.append(f"{path}: no <script>: sdformat adds the default one (no trajectory), so the actor "
                         "stays at its <pose>")
    else:
        script = _script(script_el, f"{path}/script", notes)
    return ActorDescription(name, pose, skin, animations, script, plugins)


def _animation(el, where, notes):
    name = (el.get("name") or "").strip()
    if not name:
        raise ModelError("<animation> has no name attribute (sdformat requires one)", element=where)
    filename = (el.findtext("filename") or "").strip()
    if not filename:
        notes.append(f"{where}: no <filename>: Gazebo drops animation '{name}'")
        return None
    return Animation(name, filename, _child_number(el, "scale", 1.0, where, notes),
                     _child_bool(el, "interpolate_x", False, where))


def _script(el, where, notes):
    loop = _child_bool(el, "loop", True, where)
    delay = _child_number(el, "delay_start", 0.0, where, notes)
    auto_start = _child_bool(el, "auto_start", True, where)
    read = [_trajectory(t, f"{where}/trajectory[{k}]", notes) for k, t in enumerate(el.findall("trajectory"), 1)]
    # Gazebo's `trajectories` map is keyed by id: the last trajectory of an id with waypoints is the one
    # every trajectory of that id plays (each keeps its own duration).
    played = {t.id: t.waypoints for t in read if t.waypoints}
    seen = set()
    for t in read:
        if t.id in seen:
            notes.append(f"{where}: two trajectories with id {t.id}: Gazebo plays the waypoints of the "
                         "last one for both")
        seen.add(t.id)
    ordered = sorted(read, key=lambda t: t.id)  # stable: equal ids keep file order, as Gazebo inserts them
    trajectories = tuple(Trajectory(t.id, t.type, t.tension, played.get(t.id, ()), t.duration) for t in ordered)
    return Script(loop, delay, auto_start, trajectories)


def _trajectory(el, where, notes):
    if el.get("id") is None or not el.get("type", "").strip():
        raise ModelError("<trajectory> needs both an id and a type attribute (sdformat requires them)",
                         element=where)
    ident = _number(el.get("id"), f"{where}/@id", notes, integer=True)
    tension = 0.0
    if el.get("tension") is not None and el.get("tension").strip():
        tension = _number(el.get("tension"), f"{where}/@tension", notes)
        if not 0.0 <= tension <= 1.0:
            notes.append(f"{where}: tension {tension:g} is outside SDF's 0..1; Gazebo 11 (sdformat 9) uses "
                         "it as written")
    points = {}
    for k, wp in enumerate(el.findall("waypoint"), 1):
        wpath = f"{where}/waypoint[{k}]"
        if wp.find("time") is None or wp.find("pose") is None:
            missing = "time" if wp.find("time") is None else "pose"
            notes.append(f"{wpath}: no <{missing}>: sdformat uses its default (0)")
        time = _child_number(wp, "time", 0.0, wpath, notes)
        if time in points:
            notes.append(f"{wpath}: a second waypoint at {time:g} s replaces the first, as in Gazebo")
        points[time] = _pose6(wp.find("pose"), f"{wpath}/pose")
    kind = el.get("type").strip()
    if not points:
        notes.append(f"{where}: no waypoints: Gazebo plays only the skeleton animation '{kind}' (not "
                     "simulated); it lasts 0 s here")
        return Trajectory(ident, kind, tension)
    times = sorted(points)
    if times[-1] < 0:
        raise ModelError(f"the last waypoint is at {times[-1]:g} s, before 0: Gazebo finds no trajectory "
                         "to play", element=where)
    if abs(times[0]) > _EQUAL:
        notes.append(f"{where}: the first waypoint (at {times[0]:g} s) is played at 0 s, as Gazebo 11 does")
    keys = [Waypoint(0.0 if i == 0 and abs(t) > _EQUAL else t, points[t]) for i, t in enumerate(times)]
    keys.sort(key=lambda w: w.time)  # a moved first waypoint can pass a negative second one (upper_bound)
    return Trajectory(ident, kind, tension, tuple(keys), times[-1])


# ------------------------------------------------------------------------------------------ quaternions
# (x, y, z, w) tuples, with ign-math6's exact formulas and thresholds: the interpolation must land where
# Gazebo's does, including its quirks.

def _qscale(q, s):
    return tuple(c * s for c in q)


def _qadd(a, b):
    return tuple(x + y for x, y in zip(a, b))


def _qinverse(q):
    """Quaternion::Inverse: conjugate over the squared norm (identity for a zero quaternion)."""
    norm2 = sum(c * c for c in q)
    if abs(norm2) <= _EQUAL:
        return (0.0, 0.0, 0.0, 1.0)
    return (-q[0] / norm2, -q[1] / norm2, -q[2] / norm2, q[3] / norm2)


def _qlog(q):
    """Quaternion::Log: angle * axis when sin(angle) >= 1e-3, else the vector part as it is."""
    x, y, z, w = q
    if abs(w) < 1.0:
        angle = math.acos(w)
        sin = math.sin(angle)
        if abs(sin) >= 1e-3:
            c = angle / sin
            return (c * x, c * y, c * z, 0.0)
    return (x, y, z, 0.0)


def _qexp(q):
    """Quaternion::Exp: (cos a, sin a * axis) for the vector part of length a."""
    x, y, z, _ = q
    angle = math.sqrt(x * x + y * y + z * z)
    sin = math.sin(angle)
    c = sin / angle if abs(sin) >= 1e-3 else 1.0
    return (c * x, c * y, c * z, math.cos(angle))


def slerp(t, p, q, shortest_path=False):
    """Quaternion::Slerp: spherical interpolation ``p`` -> ``q`` at ``t`` in 0..1; ``shortest_path`` flips
    ``q`` when the two are more than half a turn apart; near-equal (|cos| >= 0.999) ends are lerped."""
    cos = sum(a * b for a, b in zip(p, q))
    if cos < 0.0 and shortest_path:
        cos, q = -cos, _qscale(q, -1.0)
    if abs(cos) < 1.0 - 1e-3:
        sin = math.sqrt(1.0 - cos * cos)
        angle = math.atan2(sin, cos)
        return _qadd(_qscale(p, math.sin((1.0 - t) * angle) / sin), _qscale(q, math.sin(t * angle) / sin))
    mix = _qadd(_qscale(p, 1.0 - t), _qscale(q, t))
    norm = math.sqrt(sum(c * c for c in mix))
    return (0.0, 0.0, 0.0, 1.0) if abs(norm) <= _EQUAL else _qscale(mix, 1.0 / norm)


def squad(t, p, a, b, q, shortest_path=False):
    """Quaternion::Squad: Shoemake's spherical quadrangle through ``p``, ``q`` with inner points ``a``, ``b``."""
    return slerp(2.0 * t * (1.0 - t), slerp(t, p, q, shortest_path), slerp(t, a, b))


# ------------------------------------------------------------------------------------------ splines

class _PositionSpline:
    """ign-math6 ``Spline`` with auto-calculation off, ``Tension(tension)`` then ``RecalcTangents()``."""

    def __init__(self, points, tension):
        self.points = [tuple(float(c) for c in p) for p in points]
        n = len(self.points)
        self.tangents = [(0.0, 0.0, 0.0)] * n
        if n < 2:
            return
        pts = self.points
        closed = all(abs(a - b) <= _SAME_POINT for a, b in zip(pts[0], pts[-1]))
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
        if abs(t) <= _EQUAL:
            return self.points[index]
        if abs(t - 1.0) <= _EQUAL:
            return self.points[index + 1]
        t2, t3 = t * t, t * t * t
        h00, h10, h01, h11 = 2 * t3 - 3 * t2 + 1, t3 - 2 * t2 + t, -2 * t3 + 3 * t2, t3 - t2
        p0, p1, m0, m1 = self.points[index], self.points[index + 1], self.tangents[index], self.tangents[index + 1]
        return tuple(h00 * a + h10 * b + h01 * c + h11 * d for a, b, c, d in zip(p0, m0, p1, m1))


class _RotationSpline:
    """ign-math6 ``RotationSpline``: Shoemake's tangents ``p exp(-(log(p^-1 p[i+1]) + log(p^-1 p[i-1])) / 4)``
    (the point itself at open ends; wrapped when the first and last rotations agree within 1e-3)."""

    def __init__(self, rotations):
        self.points = [tuple(q) for q in rotations]
        n = len(self.points)
        self.tangents = list(self.points)
        if n < 2:
            return
        pts = self.points
        closed = all(abs(a - b) <= _SAME_POINT for a, b in zip(pts[0], pts[-1]))
        for i, p in enumerate(pts):
            inv = _qinverse(p)
            later = pts[i + 1] if i < n - 1 else (pts[1] if closed else p)
            earlier = pts[i - 1] if i > 0 else (pts[n - 2] if closed else p)
            pre_exp = _qscale(_qadd(_qlog(qmul(inv, later)), _qlog(qmul(inv, earlier))), -0.25)
            self.tangents[i] = qmul(p, _qexp(pre_exp))

    def interpolate(self, index, t):
        """RotationSpline::Interpolate(index, t), shortest path on (its default)."""
        if index + 1 >= len(self.points):
            return self.points[index]
        if abs(t) <= _EQUAL:
            return self.points[index]
        if abs(t - 1.0) <= _EQUAL:
            return self.points[index + 1]
        return squad(t, self.points[index], self.tangents[index], self.tangents[index + 1],
                     self.points[index + 1], shortest_path=True)


class _Track:
    """One trajectory's ``PoseAnimation`` (loop off): keyframe lookup by time, then the two splines."""

    def __init__(self, trajectory):
        self.times = [w.time for w in trajectory.waypoints]
        poses = [pose6_to_pose(w.pose) for w in trajectory.waypoints]
        self.poses = poses
        self.length = trajectory.duration
        self.position = _PositionSpline([p for p, _ in poses], trajectory.tension)
        self.rotation = _RotationSpline([q for _, q in poses])

    def pose_at(self, time):
        """Animation::SetTime (clamped to 0..length) then GetInterpolatedKeyFrame."""
        time = min(max(time, 0.0), self.length)
        i = bisect_left(self.times, time)  # first keyframe at or after `time`
        if i == len(self.times):  # past the last keyframe: blend towards the first, one length later
            t2, first = self.length + self.times[0], len(self.times) - 1
        else:
            t2, first = self.times[i], i - 1 if i > 0 and time < self.times[i] else i
        t1 = self.times[first]
        u = 0.0 if abs(t1 - t2) <= _EQUAL else (time - t1) / (t2 - t1)
        if abs(u) <= _EQUAL:
            return self.poses[first]
        return (self.position.interpolate(first, u), qnormalize(self.rotation.interpolate(first, u)))


# ------------------------------------------------------------------------------------------ playback

class ActorScript:
    """An actor's ``<script>`` played as ``Actor::Update`` plays it, one call per simulation step.

    ``frame_period`` s: at most one new frame per this much sim time, the steps in between holding the
    last frame (Gazebo: 1/30 s); 0 draws a frame at every call (for tests and smooth bodies).
    The object keeps Gazebo's state (play start, last frame), so call :meth:`pose_at` with non-decreasing
    sim times; a time earlier than the last call (a world reset) restarts the script.
    """

    def __init__(self, description, frame_period=FRAME_PERIOD):
        self.description = description
        self.frame_period = check_number("frame_period", frame_period, low=0.0)
        self.initial_pose = description.world_pose
        self._segments = []  # (start s, end s, _Track or None), back to back
        start = 0.0
        for trajectory in description.script.trajectories:
            track = _Track(trajectory) if trajectory.waypoints else None
            self._segments.append((start, start + trajectory.duration, track))
            start += trajectory.duration
        #: Total length of the script in s (sum of the trajectories' durations).
        self.script_length = start
        # Update returns at once when nothing is translated (and, ours, there is no skeleton).
        self._moves = any(track for _, _, track in self._segments)
        self._loaded_at = None
        self.reset(0.0)

    # -- Gazebo's Actor::Reset/Init, Play and Stop
    def reset(self, sim_time=0.0):
        """Actor::Reset + Init at ``sim_time``: back to the ``<pose>``, script from its start (playing at once
        when ``auto_start``)."""
        self._loaded_at = sim_time
        self._last_call = sim_time
        self._prev_frame = sim_time
        self._play_start = sim_time
        self.active = self.description.script.auto_start
        self._held = self.initial_pose
        #: Time into the current trajectory of the last frame drawn, s.
        self.script_time = 0.0

    def play(self, sim_time):
        """Actor::Play: (re)start the script at ``sim_time`` (what a plugin does when auto_start is false)."""
        self.active = True
        self._play_start = sim_time

    def stop(self):
        """Actor::Stop: hold the current pose until :meth:`play`."""
        self.active = False

    # -- the pose
    def trajectory_pose(self, script_time):
        """The pose at ``script_time`` s into the script (clamped to 0..length), with no frames, loop or
        delay: the first trajectory whose span holds the time, as Gazebo picks it. None when that
        trajectory has no waypoints or the script has none."""
        script_time = min(max(script_time, 0.0), self.script_length)
        for start, end, track in self._segments:
            if start <= script_time <= end:
                return track.pose_at(script_time - start) if track else None
        return None

    def pose_at(self, sim_time, play_start_time=None):
        """The actor's world pose ((x, y, z), (qx, qy, qz, qw)) at ``sim_time`` s.

        ``play_start_time``: the sim time Gazebo's ``Actor::Init`` ran (0.0 at construction: the world's
        start, for actors of the world file); with ``auto_start`` the script plays from then. A value other
        than the current one restarts the script from it (as :meth:`reset` does); None keeps the current.
        Before the first frame, while waiting for ``delay_start``, when not playing, or when the script has
        no waypoints, the pose is the last one shown: the ``<pose>`` until a frame has been drawn (Gazebo
        leaves the model where it was loaded).
        """
        if play_start_time is not None and play_start_time != self._loaded_at:
            self.reset(play_start_time)
        elif sim_time < self._last_call:
            self.reset(self._loaded_at)
        self._last_call = sim_time
        if not self.active or not self._moves:
            return self._held
        # common::Time differences are whole nanoseconds
        if round((sim_time - self._prev_frame) * 1e9) / 1e9 < self.frame_period:
            return self._held
        script_time = sim_time - self.description.script.delay_start - self._play_start
        if script_time < 0:
            return self._held
        if script_time >= self.script_length:
            if not self.description.script.loop:
                self.active = False  # PR 2773: stop, keeping the last frame
                return self._held
            script_time -= self.script_length
            self._play_start = sim_time - script_time
        segment = next((s for s in self._segments if s[0] <= script_time <= s[1]), None)
        if segment is None:  # Gazebo: "Trajectory not found" (a script of length 0)
            return self._held
        start, _, track = segment
        self._prev_frame = sim_time
        self.script_time = script_time - start
        if track is not None:
            self._held = track.pose_at(self.script_time)
        return self._held
