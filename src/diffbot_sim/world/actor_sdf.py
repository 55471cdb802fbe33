"""Gazebo-classic 11 ``<actor>`` elements read into data (pure), as ``gazebo/physics/Actor.cc``
``Load``/``LoadScript`` reads them (sdformat 9 with ``sdf/1.6/actor.sdf``):

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

The script is played by :mod:`diffbot_sim.world.actor_script`; ``libActorPlugin.so``'s walk by
:mod:`diffbot_sim.world.actor_walk`.
"""
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.transforms import IGN_EQUAL, quaternion_rpy, rpy_quaternion
from diffbot_sim.values import check_bool, tag_number
from diffbot_sim.world.sdf_elements import pose_numbers

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]
Pose = tuple[Vec3, Quat]
#: x, y, z (m), roll, pitch, yaw (rad), as SDF writes a ``<pose>``.
Pose6 = tuple[float, float, float, float, float, float]
ZERO_POSE6: Pose6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


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
    waypoints: tuple[Waypoint, ...] = ()
    duration: float = 0.0


@dataclass(frozen=True)
class Script:
    """``<script>``: ``delay_start`` s; ``trajectories`` in the order they play (ascending id)."""

    loop: bool = True
    delay_start: float = 0.0
    auto_start: bool = True
    trajectories: tuple[Trajectory, ...] = ()


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
    skin: Skin | None = None
    animations: tuple[Animation, ...] = ()
    script: Script = Script()
    plugins: tuple[PluginRef, ...] = ()

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
    """A ``<pose>`` element's six numbers (x y z roll pitch yaw), read as every SDF pose is
    (:func:`~diffbot_sim.world.sdf_elements.pose_numbers`); empty or absent: zeros."""
    values = None if el is None else pose_numbers(el.text, el.attrib, element=where)
    if values is None:
        return ZERO_POSE6
    if len(values) == 7:  # rotation_format="quat_xyzw"
        return values[:3] + quaternion_rpy(values[3:])
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
    if abs(times[0]) > IGN_EQUAL:
        notes.append(f"{where}: the first waypoint (at {times[0]:g} s) is played at 0 s, as Gazebo 11 does")
    keys = [Waypoint(0.0 if i == 0 and abs(t) > IGN_EQUAL else t, points[t]) for i, t in enumerate(times)]
    keys.sort(key=lambda w: w.time)  # a moved first waypoint can pass a negative second one (upper_bound)
    return Trajectory(ident, kind, tension, tuple(keys), times[-1])
