"""gazebo_grasp_fix's decisions (pure): when an object held between fingers is attached to the palm, and when
it is let go.

Gazebo's ODE contacts cannot hold a grasped object reliably, so Gazebo arm models load ``libgazebo_grasp_fix.so``
(JenniferBuehler/gazebo-pkgs master d217a4c, gazebo_grasp_plugin 1.0.2; the ``noetic`` branch b6859e9 has the
same logic without the grasp-event publisher), which welds a gripped object to the palm link. Read from
``gazebo_grasp_plugin/src/GazeboGraspFix.cpp`` (``Load``, ``OnContact``, ``OnUpdate``, ``CheckGrip``) and
``src/GazeboGraspGripper.cpp`` (``Init``, ``HandleAttach``, ``HandleDetach``). Reproduced:

* Tags (:func:`grasp_fix_config`): one or more ``<arm>`` with ``<arm_name>``, ``<palm_link>`` and one or more
  ``<gripper_link>``; an incomplete arm, an arm whose palm link is missing or none of whose gripper links has a
  collision is skipped (a note); no usable arm leaves the plugin inactive. A repeated ``<arm_name>`` re-declares
  that arm: the later palm, the union of the gripper links. ``<forces_angle_tolerance>`` 120 deg,
  ``<update_rate>`` 5 (Hz, an int), ``<max_grip_count>`` 10, ``<grip_count_threshold>`` floor(max/2),
  ``<release_tolerance>`` 0.005 m, ``<disable_collisions_on_attach>`` false (only the exact texts "true" and
  "1" are true). ``<contact_topic>`` is documented upstream but never read.
* Contacts (``OnContact``): per physics step, each (object, gripper link) pair gives the mean force on the
  object and the mean contact point; the point and the object's frame origin are stored in the gripper link's
  frame. An update averages what arrived since the last one per (object, link).
* ``CheckGrip``: an object is gripped when two of its per-link mean forces (each >= 1e-4 N) make an angle
  greater than ``forces_angle_tolerance`` and the shorter is >= 0.3 of the longer. A tolerance below 90 deg
  never grips.
* Gripped: ``count = min(count + 1, max_grip_count)``; once ``count > grip_count_threshold`` (so at the
  threshold+1-th gripped update) an object not yet attached is attached to the arm with the most links in
  contact (ties: the first link name in sorted order), unless an involved arm already holds something (one
  object per arm). The contact points of that arm's links are remembered.
* Not gripped: ``count - 1`` (not below 0); an attached object whose count is ``<= threshold`` is released
  when, for any remembered link, the distance from the remembered contact point (moving with the link) to the
  object's frame origin differs from its distance at attachment by more than ``release_tolerance``. A release
  resets the count to 0.

Timing: upstream runs on WorldUpdateEnd, throttled by the **wall clock** to ``1/update_rate`` (so the grip
thresholds are wall-clock seconds, shorter in sim time when the simulation runs faster than real time); here the
caller decides the period (``config.update_period`` in sim or wall time) and passes the contacts gathered since
the previous call. Upstream's ``~/grasp_events`` Gazebo topic and the joint itself (a revolute joint with
limits [0, 0] between the palm link and the object's link at their current relative pose, and the object's
collide mode "none" / "all" with ``disable_collisions_on_attach``) are the caller's.
"""
import collections.abc
import math
import xml.etree.ElementTree as ET
from collections.abc import Hashable, Mapping, Sequence
from dataclasses import dataclass
from typing import NamedTuple

from diffbot_sim.errors import PluginNotLoaded
from diffbot_sim.transforms import qconj, rotate
from diffbot_sim.values import tag_number

PLUGIN_FILENAME = "libgazebo_grasp_fix.so"
#: CheckGrip's length ratio (fixed in OnUpdate): the weaker force must be at least this part of the stronger.
LENGTH_RATIO = 0.3
#: CheckGrip ignores force vectors shorter than this (N).
MIN_FORCE = 1e-4

Vec3 = tuple[float, float, float]
Pose = tuple[Vec3, tuple[float, float, float, float]]  # ((x, y, z), (qx, qy, qz, qw)), world frame


@dataclass(frozen=True)
class GraspArm:
    """One ``<arm>``: its name, the link an object is attached to, and the links whose contacts count."""

    name: str
    palm_link: str
    gripper_links: tuple[str, ...]


@dataclass(frozen=True)
class GraspFixConfig:
    """A gazebo_grasp_fix plugin, validated. ``forces_angle_tolerance`` is in rad (the tag is in degrees);
    ``release_tolerance`` in m; ``notes`` are ready-to-log lines (skipped arms, odd values)."""

    path: str
    arms: tuple[GraspArm, ...]
    forces_angle_tolerance: float = math.radians(120.0)
    update_rate: int = 5
    max_grip_count: int = 10
    grip_count_threshold: int = 5
    release_tolerance: float = 0.005
    disable_collisions_on_attach: bool = False
    notes: tuple[str, ...] = ()

    @property
    def update_period(self):
        """Seconds between updates (upstream: of wall time)."""
        return 1.0 / self.update_rate


def _children(source, tag):
    """The children named ``tag`` of an element, or the value(s) under ``tag`` of a mapping, in order."""
    if isinstance(source, ET.Element):
        return [child for child in source if child.tag == tag]
    value = source.get(tag) if isinstance(source, collections.abc.Mapping) else None
    if value is None:
        return []
    return list(value) if isinstance(value, (list, tuple)) else [value]


def _text(item):
    """A tag's text as sdformat gives it to ``Get<std::string>``: stripped."""
    if isinstance(item, ET.Element):
        return (item.text or "").strip()
    return "" if item is None else str(item).strip()


def grasp_fix_config(plugin, path, link_collisions: Mapping[str, int] | None = None) -> GraspFixConfig:
    """Read a gazebo_grasp_fix ``<plugin>``.

    Args:
        plugin: the ``<plugin>`` element, or a mapping of the same shape (``{"arm": [{"arm_name": ...,
            "palm_link": ..., "gripper_link": [...]}, ...], "update_rate": "10", ...}``).
        path: the plugin element's location, for messages.
        link_collisions: link name -> number of collision elements, for the model's links (after Gazebo's
            lumping). None: links are not checked.

    Raises:
        PluginNotLoaded: no ``<arm>``, or no arm usable (the notes on the skipped arms are in the message).
        ConfigError: a number tag without a leading number, or ``update_rate`` < 1.
    """
    notes: list[str] = []

    def number(tag, default, integer=False, **limits):
        items = _children(plugin, tag)
        if not items:
            return default
        return tag_number(f"<{tag}> of {path}", _text(items[0]), notes, integer=integer, **limits)

    angle = number("forces_angle_tolerance", 120.0)
    update_rate = number("update_rate", 5, integer=True, low=1)
    max_grip_count = number("max_grip_count", 10, integer=True)
    threshold = number("grip_count_threshold", max_grip_count // 2, integer=True)
    release_tolerance = number("release_tolerance", 0.005)
    disable = False
    items = _children(plugin, "disable_collisions_on_attach")
    if items:
        text = _text(items[0])
        disable = text in ("true", "1")
        if text not in ("true", "1", "false", "0"):
            notes.append(f"<disable_collisions_on_attach> of {path}: '{text}' is false (upstream takes only "
                         f"'true' and '1' as true)")
    if angle < 90.0:
        notes.append(f"<forces_angle_tolerance> of {path}: {angle:g} deg < 90: upstream's CheckGrip refuses it, "
                     "so nothing is ever gripped")
    if threshold >= max_grip_count:
        notes.append(f"<grip_count_threshold> of {path}: {threshold} >= max_grip_count {max_grip_count}: the "
                     "grip count never exceeds it, so nothing is ever attached")
    arms = _read_arms(plugin, path, link_collisions, notes)
    return GraspFixConfig(path=path, arms=arms, forces_angle_tolerance=math.radians(angle), update_rate=update_rate,
                          max_grip_count=max_grip_count, grip_count_threshold=threshold,
                          release_tolerance=release_tolerance, disable_collisions_on_attach=disable,
                          notes=tuple(notes))


def _read_arms(plugin, path, link_collisions, notes):
    """The usable arms, in declaration order, as ``Load`` + ``GazeboGraspGripper::Init`` accept them."""
    declared = _children(plugin, "arm")
    if not declared:
        raise PluginNotLoaded("GazeboGraspFix: Cannot load the GazeboGraspFix without any <arm> declarations",
                              element=path)
    arms: dict[str, GraspArm] = {}
    claimed: dict[str, str] = {}  # gripper link -> the first arm that listed it
    arm_notes_start = len(notes)
    for index, arm in enumerate(declared, 1):
        where = f"{path}/arm[{index}]"
        names, palms = _children(arm, "arm_name"), _children(arm, "palm_link")
        fingers = [_text(item) for item in _children(arm, "gripper_link")]
        if not (names and palms and fingers):
            notes.append(f"{where}: not all of <arm_name>, <palm_link> and <gripper_link> given: arm skipped")
            continue
        name, palm = _text(names[0]), _text(palms[0])
        previous = arms.get(name)
        if previous is not None:
            notes.append(f"{where}: arm '{name}' was already added: its palm is now '{palm}', its gripper links "
                         "the union of both declarations")
        links, added = (list(previous.gripper_links) if previous else []), []
        if link_collisions is not None and palm not in link_collisions:
            notes.append(f"{where}: palm link '{palm}' not found: arm '{name}' skipped")
            arms.pop(name, None)
            continue
        for link in fingers:
            if link_collisions is not None and link not in link_collisions:
                notes.append(f"{where}: gripper link '{link}' not found: skipped")
            elif link_collisions is not None and not link_collisions[link]:
                notes.append(f"{where}: gripper link '{link}' has no collision: its contacts cannot count")
            elif link not in links:
                links.append(link)
                added.append(link)
        if not links:
            notes.append(f"{where}: arm '{name}' has no gripper link with a collision: skipped")
            arms.pop(name, None)
            continue
        for link in added:
            if claimed.setdefault(link, name) != name:
                notes.append(f"{where}: gripper link '{link}' is already in arm '{claimed[link]}': its contacts "
                             f"count for '{claimed[link]}'")
        arms[name] = GraspArm(name, palm, tuple(links))
    if not arms:
        raise PluginNotLoaded("GazeboGraspFix: no arms were configured successfully. Plugin will not work ("
                              + "; ".join(notes[arm_notes_start:]) + ")", element=path)
    return tuple(arms.values())


class GraspContact(NamedTuple):
    """One physics step's contact between a gripper link and an object (a non-static body: upstream ignores
    contacts with static ones).

    ``point``: the mean of the pair's contact points (world, m). ``force``: the mean force on the object over
    those points (world axes, N; upstream has it in the object's link frame, which gives the same angles and
    lengths). ``object_position``: the object's link frame origin (world, m). ``link_pose``: the gripper
    link's world pose ``((x, y, z), (qx, qy, qz, qw))``. Build one from raw points with :func:`grasp_contact`.
    """

    link: str
    object: Hashable
    point: Vec3
    force: Vec3
    object_position: Vec3
    link_pose: Pose


def grasp_contact(link, obj, points: Sequence[Vec3], forces: Sequence[Vec3], object_position, link_pose):
    """A :class:`GraspContact` from one step's contact points of a pair and the force on the object at each:
    their means, as ``OnContact`` takes them."""
    if not points or len(points) != len(forces):
        raise ValueError("a grasp contact needs as many forces as points, and at least one")
    return GraspContact(link, obj, _mean(points), _mean(forces), tuple(object_position), link_pose)


def _mean(vectors):
    count = len(vectors)
    return tuple(sum(v[axis] for v in vectors) / count for axis in range(3))


def _norm(v):
    return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _to_local(pose, point):
    """``point`` (world) in the frame of ``pose``."""
    position, rotation = pose
    return rotate(qconj(rotation), _sub(point, position))


def _to_world(pose, point):
    position, rotation = pose
    turned = rotate(rotation, point)
    return (turned[0] + position[0], turned[1] + position[1], turned[2] + position[2])


def check_grip(forces: Sequence[Vec3], min_angle, length_ratio=LENGTH_RATIO):
    """``CheckGrip``: whether two of ``forces`` (each at least :data:`MIN_FORCE` long) make an angle greater
    than ``min_angle`` (rad) with the shorter at least ``length_ratio`` of the longer. ``min_angle`` < 90 deg
    is refused upstream (always False). The cosine is clipped to [-1, 1], where upstream's ``acos`` of a
    rounded-over dot product would give NaN and miss an exactly opposite pair."""
    if min_angle < math.pi / 2:
        return False
    for first in range(len(forces)):
        for second in range(first + 1, len(forces)):
            v1, v2 = forces[first], forces[second]
            l1, l2 = _norm(v1), _norm(v2)
            if l1 < MIN_FORCE or l2 < MIN_FORCE:
                continue
            cosine = (v1[0] * v2[0] + v1[1] * v2[1] + v1[2] * v2[2]) / (l1 * l2)
            if math.acos(max(-1.0, min(1.0, cosine))) > min_angle and min(l1, l2) / max(l1, l2) >= length_ratio:
                return True
    return False


class _LinkContact(NamedTuple):
    """One (object, gripper link)'s contacts over an update, averaged; points in the link's frame."""

    arm: str
    force: Vec3
    point_in_link: Vec3
    object_in_link: Vec3


class GraspFixCore:
    """The grasp state of one model: grip counts, which arm holds which object, and the contact points
    remembered at attachment. :meth:`update` returns the actions for the caller to carry out:
    ``("attach", arm, object, palm_link)`` and ``("detach", arm, object)``."""

    def __init__(self, config: GraspFixConfig):
        self.config = config
        self._arm_of_link: dict[str, str] = {}
        for arm in config.arms:
            for link in arm.gripper_links:
                self._arm_of_link.setdefault(link, arm.name)
        self._arms = {arm.name: arm for arm in config.arms}
        self.grip_counts: dict[Hashable, int] = {}
        self.attached: dict[str, Hashable] = {}  # arm -> object
        self._attach_points: dict[Hashable, dict[str, tuple[Vec3, Vec3]]] = {}

    def update(self, contacts: Sequence[GraspContact], link_poses: Mapping[str, Pose] | None = None,
               object_positions: Mapping[Hashable, Vec3] | None = None) -> list[tuple]:
        """One ``OnUpdate``.

        Args:
            contacts: the :class:`GraspContact` records gathered since the previous update (contacts of links
                that are no gripper link are ignored, as upstream's contact filter has only those).
            link_poses: current world pose of each gripper link, and object_positions: current world position
                of each object's link origin; looked up only for attached objects that may be released.

        Returns:
            the actions, attachments first (objects in sorted order), then releases.

        Raises:
            KeyError: a pose needed for a release check is missing.
        """
        per_object = self._average(contacts)
        actions, gripped = [], set()
        for obj in sorted(per_object, key=str):
            links = per_object[obj]
            forces = [links[link].force for link in sorted(links)]
            if not check_grip(forces, self.config.forces_angle_tolerance):
                continue
            gripped.add(obj)
            count = self.grip_counts.get(obj, 0)
            self.grip_counts[obj] = count = count + 1 if count < self.config.max_grip_count else count
            if count > self.config.grip_count_threshold:
                action = self._attach(obj, links)
                if action:
                    actions.append(action)
        actions += self._release(gripped, link_poses or {}, object_positions or {})
        return actions

    def _average(self, contacts):
        """{object: {link: _LinkContact}} of the gripper-link contacts."""
        sums: dict[Hashable, dict[str, list]] = {}
        for contact in contacts:
            arm = self._arm_of_link.get(contact.link)
            if arm is None:
                continue
            entry = sums.setdefault(contact.object, {}).setdefault(contact.link, [arm, [], [], []])
            entry[1].append(contact.force)
            entry[2].append(_to_local(contact.link_pose, contact.point))
            entry[3].append(_to_local(contact.link_pose, contact.object_position))
        return {obj: {link: _LinkContact(arm, _mean(forces), _mean(points), _mean(origins))
                      for link, (arm, forces, points, origins) in links.items()}
                for obj, links in sums.items()}

    def _attach(self, obj, links):
        """Attach ``obj`` to the arm with the most links touching it, unless an involved arm holds an object."""
        involved: dict[str, int] = {}
        best, best_count = None, 0
        for link in sorted(links):
            arm = links[link].arm
            involved[arm] = involved.get(arm, 0) + 1
            if involved[arm] > best_count:
                best, best_count = arm, involved[arm]
        if any(arm in self.attached for arm in involved):
            return None
        grasping = self._arms[best]
        self._attach_points[obj] = {link: (c.point_in_link, c.object_in_link) for link, c in links.items()
                                    if link in grasping.gripper_links}
        self.attached[best] = obj
        return ("attach", best, obj, grasping.palm_link)

    def _release(self, gripped, link_poses, object_positions):
        """Count down the objects not gripped now; release attached ones whose contact points moved."""
        holder = {}
        for arm in sorted(self.attached):
            holder[self.attached[arm]] = arm
        actions = []
        for obj in sorted(self.grip_counts, key=str):
            if obj in gripped:
                continue
            if self.grip_counts[obj] > 0:
                self.grip_counts[obj] -= 1
            arm = holder.get(obj)
            if arm is None or self.grip_counts[obj] > self.config.grip_count_threshold:
                continue
            points = self._attach_points.get(obj, {})
            moved = [self._moved(link, obj, point, origin, link_poses, object_positions)
                     for link, (point, origin) in points.items()]
            if any(moved):
                del self.attached[arm]
                del self._attach_points[obj]
                self.grip_counts[obj] = 0
                actions.append(("detach", arm, obj))
        return actions

    def _moved(self, link, obj, point_in_link, object_in_link, link_poses, object_positions):
        """Whether the remembered contact point of ``link`` is now farther from (or nearer to) the object's
        origin than at attachment by more than the release tolerance."""
        before = _norm(_sub(point_in_link, object_in_link))
        now = _norm(_sub(_to_world(link_poses[link], point_in_link), object_positions[obj]))
        return abs(before - now) > self.config.release_tolerance
