"""gazebo_ros's world API, its decisions only (pure: no rospy, no PyBullet): what the ROS 1 (noetic)
``gazebo_ros_api_plugin`` does to frames, twists, model XML, wrenches and physics properties, so the ROS node
that serves ``/gazebo/*`` answers as Gazebo classic did.

Every rule here was read in ``gazebo_ros/src/gazebo_ros_api_plugin.cpp`` (gazebo_ros_pkgs, noetic-devel),
with ignition-math's ``Pose3``/``Quaternion`` and Gazebo's ``Base::GetByName``, ``World::Step`` and
``ODELink::SetForce`` where the plugin leans on them. Where upstream has a bug that a client can see, the
function either mirrors it and says so (the point is to behave like Gazebo) or, where mirroring would only
hang or corrupt, does the sensible thing and says that instead; each docstring names which.

Conventions: a pose is ``((x, y, z), (qx, qy, qz, qw))``, a twist ``((vx, vy, vz), (wx, wy, wz))``, both in
WORLD axes unless a name says otherwise; times are sim seconds (floats).
"""
import math
import re
from xml.parsers import expat
from xml.sax.saxutils import escape

from diffbot_sim.transforms import compose, inverse, rotate, rpy_quaternion

IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))

# ------------------------------------------------------------------------------------------ frames

#: Reference-frame names every service (spawn, get/set model and link state, apply_body_wrench) takes for
#: the world, when no entity has that name: upstream tests an entity lookup first, then exactly these four.
WORLD_FRAMES = frozenset({"", "world", "map", "/map"})

#: Upstream's status_message when a reference frame is neither an entity nor a world name, per service.
FRAME_NOT_FOUND = {
    "spawn_model": "SpawnModel: reference reference_frame not found, did you forget to scope the link by "
                   "model name?",
    "get_model_state": "GetModelState: reference relative_entity_name not found, did you forget to scope the "
                       "body by model name?",
    "get_link_state": "GetLinkState: reference reference_frame not found, did you forget to scope the link by "
                      "model name?",
    "set_model_state": "SetModelState: specified reference frame entity does not exist",
    "set_link_state": "SetLinkState: failed",
    "apply_body_wrench": "ApplyBodyWrench: reference_frame not found",
}

#: ``world_state`` conventions: the exact inverse of ``relative_state``, or what each Set service does.
INVERSE, SET_MODEL_STATE, SET_LINK_STATE = "inverse", "set_model_state", "set_link_state"


def is_world_frame(name):
    """True for the names gazebo_ros reads as the inertial frame: "", "world", "map", "/map".

    The same four in every service (spawn, get/set model state, get/set link state, apply_body_wrench).
    Upstream looks the name up as an entity FIRST and only then compares it with these, so a model that is
    really called "map" or "world" is a frame there; a caller that wants that precedence looks its entities
    up before calling this.
    """
    return name in WORLD_FRAMES


def split_link_name(name):
    """``"model::link"`` -> ``("model", "link")``; a nested ``"a::b::c"`` -> ``("a::b", "c")``.

    Gazebo's scoped name of a link is its ancestors' names joined by ``::`` (the world left out), so the
    link is the last component and the model everything before it. Upstream also resolves a bare name
    (see :func:`find_entity`); this function is for callers that need the model part, so a bare name is a
    ValueError (with Gazebo's own hint about scoping).
    """
    model, sep, link = str(name).rpartition("::")
    if not sep:
        raise ValueError(f"'{name}' is not a scoped link name (model::link): did you forget to scope the link "
                         f"by model name?")
    if not model or not link or model.startswith("::") or model.endswith("::"):
        raise ValueError(f"'{name}' is not a scoped link name (model::link): a part is empty")
    return model, link


def find_entity(name, scoped_names):
    """The entity ``name`` resolves to, as Gazebo's ``World::EntityByName`` -> ``Base::GetByName`` does.

    ``scoped_names``: every entity's scoped name (models, nested models, links ...) in Gazebo's depth-first
    order (a model, then its children, in the order they were loaded). Upstream returns the first entity
    whose scoped name OR plain (last-component) name equals ``name``, so ``"base_link"`` alone finds the
    first model's base_link. Returns that scoped name, or None.
    """
    for scoped in scoped_names:
        if scoped == name or scoped.rpartition("::")[2] == name:
            return scoped
    return None


# ------------------------------------------------------------------------------------------ pose math

def _unrotate(q, v):
    """``v`` turned by the inverse of the unit quaternion ``q`` (ignition's RotateVectorReverse)."""
    return rotate((-q[0], -q[1], -q[2], q[3]), v)


def _unit(q):
    """``q`` normalised as ignition's ``Quaternion::Normalize``: a norm within 1e-6 of zero is identity."""
    m = max(abs(c) for c in q)
    if m == 0.0:
        return (0.0, 0.0, 0.0, 1.0)
    s = tuple(c / m for c in q)  # scaled first, so 1e200 components do not overflow the square
    n = m * math.sqrt(sum(c * c for c in s))
    if n <= 1e-6:
        return (0.0, 0.0, 0.0, 1.0)
    return tuple(c / n for c in q)


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _floats(v):
    return tuple(float(c) for c in v)


def _pose(pose):
    p, q = pose
    return _floats(p), _unit(_floats(q))


def quaternion_rpy(q):
    """(roll, pitch, yaw) of a quaternion (x, y, z, w), fixed axes as SDF and URDF write them
    (R = Rz(yaw) Ry(pitch) Rx(roll)); at pitch +-pi/2 yaw is 0 and roll carries the rest, as ignition's
    ``Quaternion::Euler`` (which Gazebo uses to write a spawned model's ``<pose>``) decides. Read from the
    rotation matrix, so pitch stays exact near +-pi/2 where ``asin`` would lose half the digits."""
    x, y, z, w = _unit(_floats(q))
    r00, r10, r20 = 1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)
    r21, r22 = 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)
    r11, r12 = 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)
    cos_pitch = math.hypot(r00, r10)
    pitch = math.atan2(-r20, cos_pitch)
    if cos_pitch < 1e-12:
        return math.atan2(-r12, r11), pitch, 0.0
    return math.atan2(r21, r22), pitch, math.atan2(r10, r00)


# ------------------------------------------------------------------------------------------ states

def relative_state(pose, twist, frame_pose, frame_twist):
    """What GetModelState (``relative_entity_name``) and GetLinkState (``reference_frame``) return for an
    entity at world ``pose``/``twist`` seen from the entity at ``frame_pose``/``frame_twist``.

    Pose: the entity's pose expressed in the frame (ignition ``entity_pose - frame_pose``; the quaternion
    comes back normalised). Twist, exactly as upstream: ``R_frameᵀ·(v − v_frame)`` and
    ``R_frameᵀ·(w − w_frame)``: world velocity differences turned into the frame's axes, WITHOUT the
    ``ω_frame × r`` transport term a rigid-body transform would add (a point at rest in the world, seen
    from a spinning frame, reports zero linear velocity).
    """
    pose, frame_pose = _pose(pose), _pose(frame_pose)
    qf = frame_pose[1]
    (v, w), (vf, wf) = (_floats(c) for c in twist), (_floats(c) for c in frame_twist)
    return compose(inverse(frame_pose), pose), (_unrotate(qf, _sub(v, vf)), _unrotate(qf, _sub(w, wf)))


def world_state(pose_in_frame, twist_in_frame, frame_pose, frame_twist, convention=INVERSE):
    """World pose and twist of a state given relative to a frame (SetModelState / SetLinkState with
    ``reference_frame``).

    The pose is always ``frame_pose ∘ pose_in_frame`` (ignition ``target_pose + frame_pose``). The twist
    depends on ``convention``, because upstream's two Set services disagree with each other and neither is
    the inverse of :func:`relative_state`:

    * ``INVERSE`` (default): the exact inverse of :func:`relative_state`, ``R_frame·v + v_frame`` and
      ``R_frame·w + w_frame``, so a state read with ``relative_state`` and written back lands where it was.
    * ``SET_MODEL_STATE``: what SetModelState does: ``R_frame·v`` and ``R_frame·w``; the frame's own velocity
      is NOT added ("velocities should be commanded in the requested reference frame": directions only).
    * ``SET_LINK_STATE``: what SetLinkState does: ``v − v_frame`` and ``w − w_frame``, NOT rotated (an
      upstream bug: the frame velocity is subtracted where it should be added, and the axes are the world's).
    """
    pose_in_frame, frame_pose = _pose(pose_in_frame), _pose(frame_pose)
    qf = frame_pose[1]
    (v, w), (vf, wf) = (_floats(c) for c in twist_in_frame), (_floats(c) for c in frame_twist)
    pose = compose(frame_pose, pose_in_frame)
    if convention == INVERSE:
        return pose, (_add(rotate(qf, v), vf), _add(rotate(qf, w), wf))
    if convention == SET_MODEL_STATE:
        return pose, (rotate(qf, v), rotate(qf, w))
    if convention == SET_LINK_STATE:
        return pose, (_sub(v, vf), _sub(w, wf))
    raise ValueError(f"world_state: convention '{convention}' is not one of "
                     f"{INVERSE!r}, {SET_MODEL_STATE!r}, {SET_LINK_STATE!r}")


def _finite(values, names, what):
    out = []
    for name, value in zip(names, values):
        value = float(value)
        if not math.isfinite(value):
            raise ValueError(f"{what}.{name} is {value!r}")
        out.append(value)
    return tuple(out)


def check_pose(pose, what):
    """``pose`` with finite numbers and a unit quaternion, or ValueError naming the field
    (``"initial_pose.position.x is nan"``).

    Upstream passes NaN and inf on to the physics (which then blows up); they are refused here. A zero (or
    near-zero: norm <= 1e-6) quaternion is accepted as the identity, as ignition's ``Quaternion::Normalize``
    makes it (SetModelState normalises explicitly "to eliminate invalid rotation (0, 0, 0, 0)"; spawn gets
    the same through ``Euler()``); any other quaternion is normalised.
    """
    p, q = pose
    position = _finite(p, ("position.x", "position.y", "position.z"), what)
    orientation = _finite(q, ("orientation.x", "orientation.y", "orientation.z", "orientation.w"), what)
    return position, _unit(orientation)


def check_twist(twist, what):
    """``twist`` as floats, or ValueError naming the first non-finite field (``"twist.angular.z is inf"``)."""
    v, w = twist
    return (_finite(v, ("linear.x", "linear.y", "linear.z"), what),
            _finite(w, ("angular.x", "angular.y", "angular.z"), what))


# ------------------------------------------------------------------------------------------ model XML
#
# The XML functions edit the text in place (expat finds the byte offsets of the elements), so everything
# they do not change stays byte-identical: comments, namespaces such as xmlns:xacro, formatting. Upstream
# re-prints the whole document through TinyXML instead; no client can tell the difference in the result.

_START_TAG = re.compile(rb'<[^\s/>]+(?:\s+[^\s=/>]+\s*=\s*(?:"[^"]*"|\'[^\']*\'))*\s*/?>')
_ATTRIBUTE = re.compile(rb'(\s+)([^\s=/>]+)(\s*=\s*)("[^"]*"|\'[^\']*\')')


class _Element:
    __slots__ = ("name", "start", "tag_end", "close", "end", "children", "text")

    def __init__(self, name, start, tag_end):
        self.name, self.start, self.tag_end = name, start, tag_end
        self.close = self.end = None  # start of the end tag, end of the element (both tag_end when empty)
        self.children, self.text = [], []

    @property
    def empty(self):
        return self.close == self.tag_end and self.end == self.tag_end

    def child(self, name):
        return next((c for c in self.children if c.name == name), None)

    def walk(self):
        yield self
        for child in self.children:
            yield from child.walk()


def _scan(xml):
    """(UTF-8 bytes of ``xml``, root _Element) or ValueError("model_xml is not valid XML: ..., line, column").

    Leading whitespace is skipped (upstream strips the declaration first, so whitespace before it is fine
    there; expat would refuse it)."""
    if not isinstance(xml, str):
        raise ValueError(f"model_xml is not text but {type(xml).__name__}")
    data = xml.encode("utf-8")
    skip = len(data) - len(data.lstrip())
    parser = expat.ParserCreate(encoding="UTF-8")  # the text is already decoded: ignore encoding="..."
    stack, top = [], []

    def start(name, _attrs):
        i = parser.CurrentByteIndex + skip
        match = _START_TAG.match(data, i)
        el = _Element(name, i, match.end() if match else data.index(b">", i) + 1)
        (stack[-1].children if stack else top).append(el)
        stack.append(el)

    def end(_name):
        el = stack.pop()
        if data[el.tag_end - 2:el.tag_end] == b"/>":
            el.close = el.end = el.tag_end
        else:
            el.close = parser.CurrentByteIndex + skip
            el.end = data.index(b">", el.close) + 1

    def text(chars):
        if stack:
            stack[-1].text.append(chars)

    parser.StartElementHandler, parser.EndElementHandler, parser.CharacterDataHandler = start, end, text
    try:
        parser.Parse(data[skip:], True)
    except expat.ExpatError as err:
        line = err.lineno + data[:skip].count(b"\n")
        raise ValueError(f"model_xml is not valid XML: {expat.ErrorString(err.code)}: line {line}, "
                         f"column {err.offset}") from None
    return data, top[0]


def _splice(data, edits):
    """``data`` with each (start, end, bytes) edit applied; an edit inside an earlier one is dropped."""
    out, at = [], 0
    for start, end, new in sorted(edits, key=lambda e: (e[0], e[1])):
        if start < at:
            continue
        out += [data[at:start], new]
        at = end
    out.append(data[at:])
    return b"".join(out)


def _set_attribute(data, el, attribute, value):
    """The edit that sets ``attribute`` of ``el``'s start tag to ``value`` (added after the tag name when
    the element has none)."""
    quoted = b'"' + escape(value, {'"': "&quot;"}).encode("utf-8") + b'"'
    name_end = el.start + 1 + len(el.name.encode("utf-8"))
    for match in _ATTRIBUTE.finditer(data, name_end, el.tag_end):
        if match.group(2).decode("utf-8") == attribute:
            return (match.start(4), match.end(4), quoted)
    return (name_end, name_end, b" " + attribute.encode("utf-8") + b"=" + quoted)


def _set_text(el, text):
    """The edit that makes ``text`` (escaped) the whole content of ``el``."""
    body = escape(text).encode("utf-8")
    if el.empty:
        return (el.tag_end - 2, el.tag_end, b">" + body + b"</" + el.name.encode("utf-8") + b">")
    return (el.tag_end, el.close, body)


def _append_child(el, xml_bytes):
    """The edit that adds ``xml_bytes`` as ``el``'s last child (upstream's ``LinkEndChild``)."""
    if el.empty:
        return (el.tag_end - 2, el.tag_end, b">" + xml_bytes + b"</" + el.name.encode("utf-8") + b">")
    return (el.close, el.close, xml_bytes)


def model_xml_kind(xml):
    """``"urdf"`` (root ``<robot>``) or ``"sdf"`` (root ``<sdf>``): the reader a spawn request needs.

    As upstream decides: its isURDF/isSDF look only at the root element, and spawn_sdf_model takes a URDF
    too. Raises ValueError("model_xml is not valid XML: <expat message>: line L, column C"), or for another
    root ValueError("model_xml: root element <foo> is neither <robot> (URDF) nor <sdf> (SDF)"); upstream
    answers the latter with "GazeboRosApiPlugin SpawnModel Failure: input model_xml not SDF or URDF, or
    cannot be converted to Gazebo compatible format.". A bare ``<model>`` root is refused, as upstream
    refuses it; the pre-SDF ``<gazebo>`` root that upstream still calls SDF is refused by name.
    """
    _, root = _scan(xml)
    if root.name == "robot":
        return "urdf"
    if root.name == "sdf":
        return "sdf"
    if root.name == "gazebo":
        raise ValueError("model_xml: root element <gazebo> is the pre-SDF Gazebo format, not read here; "
                         "write <sdf version=...> instead")
    raise ValueError(f"model_xml: root element <{root.name}> is neither <robot> (URDF) nor <sdf> (SDF)")


def prepare_urdf(xml, package_path):
    """What spawn_urdf_model does to the text before reading it: strip the XML declaration and comments,
    replace ``package://PKG`` with PKG's absolute directory; every other byte stays as it was.

    * Declaration: the first ``<?...?>`` (upstream removes exactly one processing instruction, the first).
    * Comments: every ``<!-- ... -->``, by plain text search as upstream does (so also inside CDATA). An
      unterminated ``<!--`` is a ValueError here; upstream loops forever on it.
    * ``package://PKG/``: the name runs up to the next ``/`` anywhere after the prefix, as upstream reads
      it; no ``/`` after a ``package://`` stops the replacing there (upstream logs "Malformed package
      name?" and leaves the rest). ``package_path(PKG)`` returns the directory; ``None``/``""`` or a raised
      LookupError (rospkg's not-found, as description.package_path raises it), ValueError or OSError means
      unknown: ValueError("urdf reference package name does not exist: PKG"), upstream's status_message
      word for word (upstream returns false there, so its caller sees a failed service call).
    """
    text = xml
    start, end = text.find("<?"), text.find("?>")
    if start != -1 and end != -1 and end > start:
        text = text[:start] + text[end + 2:]
    while True:
        start = text.find("<!--")
        if start == -1:
            break
        end = text.find("-->", start + 4)
        if end == -1:
            line = text.count("\n", 0, start) + 1
            raise ValueError(f"model_xml: comment opened at line {line} ('<!--') is never closed ('-->')")
        text = text[:start] + text[end + 3:]
    prefix = "package://"
    start = text.find(prefix)
    while start != -1:
        slash = text.find("/", start + len(prefix))
        if slash == -1:
            break
        name = text[start + len(prefix):slash]
        try:
            directory = package_path(name) if name else None
        except (LookupError, ValueError, OSError):
            directory = None
        if not directory:
            raise ValueError(f"urdf reference package name does not exist: {name}")
        directory = str(directory)
        directory = directory.rstrip("/") or "/"
        text = text[:start] + directory + text[slash:]
        start = text.find(prefix, start + len(directory))
    return text


def inject_robot_namespace(xml, namespace, replace_existing=False):
    """Give every ``<plugin>`` a ``<robotNamespace>namespace</robotNamespace>`` child, as spawn does when
    the request's robot_namespace is not empty.

    Upstream walks the whole document from the root (``<robot>`` for URDF, so ``<gazebo><plugin>`` and
    ``<gazebo reference="link"><sensor><plugin>`` alike; ``<sdf>`` for SDF, so every model, link, sensor
    and world plugin) and appends the element to each ``<plugin>`` that has NO ``<robotNamespace>`` child:
    a plugin's own ``<robotNamespace>`` wins over the request (its removal loop is dead code, and issue
    ros-simulation/gazebo_ros_pkgs#130 documents the add-if-unset behaviour). That is the default here;
    ``replace_existing=True`` instead overwrites existing ones. Note ``rosrun gazebo_ros spawn_model`` sends
    its own namespace ("/" at top level) unless told otherwise, so "/" is a namespace like any other.
    Everything else in the text stays byte-identical. Invalid XML: ValueError as :func:`model_xml_kind`.
    """
    if not namespace:
        return xml
    data, root = _scan(xml)
    element = b"<robotNamespace>" + escape(namespace).encode("utf-8") + b"</robotNamespace>"
    edits = []
    for el in root.walk():
        if el.name != "plugin":
            continue
        existing = [c for c in el.children if c.name == "robotNamespace"]
        if not existing:
            edits.append(_append_child(el, element))
        elif replace_existing:
            edits.append((existing[0].start, existing[0].end, element))
            edits.extend((extra.start, extra.end, b"") for extra in existing[1:])
    return _splice(data, edits).decode("utf-8") if edits else xml


def _sdf_target(root):
    """The element spawn names and places: ``<sdf>``'s first ``<model>``, else the first ``<include>`` of
    its ``<world>`` (upstream's updateSDFAttributes)."""
    if root.name != "sdf":
        raise ValueError(f"model_xml: root element <{root.name}> is not <sdf>")
    model = root.child("model")
    if model is not None:
        return model
    world = root.child("world")
    include = world.child("include") if world is not None else None
    if include is not None:
        return include
    others = ", ".join(f"<{c.name}>" for c in root.children) or "nothing"
    raise ValueError(f"model_xml: <sdf> holds no <model> (nor <world><include>) to spawn, only {others}")


def rename_model(xml, kind, name):
    """The model named ``name``, as spawn renames it: URDF ``<robot name=...>``; SDF ``<sdf>``'s first
    ``<model name=...>``, or for ``<sdf><world><include>`` the include's ``<name>`` (added if missing).

    Upstream appends the text to an existing ``<include><name>`` (giving "oldnew"); it is replaced here.
    An SDF without a model (upstream: a warning, then spawns under the old name, or a light) is a
    ValueError here. Everything else stays byte-identical.
    """
    data, root = _scan(xml)
    if kind == "urdf":
        if root.name != "robot":
            raise ValueError(f"model_xml: root element <{root.name}> is not <robot> (URDF)")
        edit = _set_attribute(data, root, "name", name)
    elif kind == "sdf":
        target = _sdf_target(root)
        if target.name == "model":
            edit = _set_attribute(data, target, "name", name)
        else:
            child = target.child("name")
            edit = _set_text(child, name) if child is not None else _append_child(
                target, b"<name>" + escape(name).encode("utf-8") + b"</name>")
    else:
        raise ValueError(f"rename_model: kind '{kind}' is neither 'urdf' nor 'sdf'")
    return _splice(data, [edit]).decode("utf-8")


def _read_pose(data, el):
    """An SDF ``<pose>`` element -> pose: six numbers (x y z roll pitch yaw) as Gazebo 11 reads them; SDF
    1.9's ``degrees="true"`` and ``rotation_format="quat_xyzw"`` (seven numbers) are honoured too."""
    text = "".join(el.text)
    name_end = el.start + 1 + len(el.name.encode("utf-8"))
    attrs = {m.group(2).decode("utf-8"): m.group(4)[1:-1].decode("utf-8")
             for m in _ATTRIBUTE.finditer(data, name_end, el.tag_end)}
    fmt = attrs.get("rotation_format", "euler_rpy")
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        values = None
    count = 7 if fmt == "quat_xyzw" else 6
    if fmt not in ("euler_rpy", "quat_xyzw") or values is None or len(values) != count \
            or not all(math.isfinite(v) for v in values):
        raise ValueError(f"model_xml: model <pose> '{text.strip()}' is not {count} finite numbers"
                         + (f" (rotation_format '{fmt}')" if fmt != "euler_rpy" else ""))
    if fmt == "quat_xyzw":
        return tuple(values[:3]), _unit(tuple(values[3:]))
    rpy = values[3:]
    if attrs.get("degrees", "false").strip().lower() in ("true", "1"):
        rpy = [math.radians(v) for v in rpy]
    return tuple(values[:3]), rpy_quaternion(*rpy)


def sdf_model_at(xml, pose):
    """The text of the SDF's model element (see :func:`rename_model` for which) placed at ``pose``, for a
    world file: its first ``<pose>`` replaced by ``pose ∘ file_pose``.

    Upstream does not overwrite the model's own ``<pose>``: it composes it ON the requested pose (ignition
    ``model_pose + initial_pose``: the file's pose is read in the request's frame) and writes the result as
    a plain ``<pose>x y z roll pitch yaw</pose>`` (attributes such as ``relative_to`` dropped, as upstream's
    new element has none). A ``<pose>`` that is not six numbers (seven with SDF 1.9
    ``rotation_format="quat_xyzw"``; ``degrees="true"`` honoured) is a ValueError here; upstream logs and
    uses zeros. The ``<sdf version>`` of the original is not part of the returned text: the caller keeps it.
    """
    data, root = _scan(xml)
    target = _sdf_target(root)
    pose = _pose(pose)
    pose_el = target.child("pose")
    file_pose = IDENTITY
    if pose_el is not None:
        file_pose = _read_pose(data, pose_el)
    (x, y, z), q = compose(pose, file_pose)
    text = " ".join(repr(float(v)) for v in (x, y, z) + quaternion_rpy(q))
    new = b"<pose>" + text.encode("ascii") + b"</pose>"
    if pose_el is not None:
        edit = (pose_el.start, pose_el.end, new)
    else:
        edit = _append_child(target, new)
    start, end = target.start, target.end
    shifted = (edit[0] - start, edit[1] - start, edit[2])
    return _splice(data[start:end], [shifted]).decode("utf-8")


# ------------------------------------------------------------------------------------------ wrenches

def wrench_to_world(force, torque, reference_point, frame_pose, body_pose=None):
    """(force, torque, point) to apply for an ApplyBodyWrench request, exactly as upstream computes it.

    Upstream first moves the wrench to the point: ``torque += reference_point × force`` (the point is a
    lever arm in the reference frame's axes, not a position). Then:

    * world frame (``frame_pose`` None: "", "world", "map", "/map"): force and that torque as they are.
    * an entity frame: ``tr = frame_pose - body_pose`` (the frame seen from the body); force ``R_tr·F``,
      torque ``R_tr·T + p_tr × (R_tr·F)``: the wrench expressed in the BODY's axes about the body origin.
      ``body_pose`` is required then.

    Either way upstream hands the result to ``Link::SetForce``/``SetTorque``, which in ODE are WORLD-axes
    force and torque at the link's CENTRE OF MASS. So with an entity frame the body-axes numbers are applied
    as world axes (upstream issue ros-simulation/gazebo_ros_pkgs#310, "Wrenches aren't transformed by
    reference frame"; it is only right while the body is aligned with the world). That is mirrored here.
    The returned point is always None: "at the link's centre of mass".
    """
    f, t, p = _floats(force), _floats(torque), _floats(reference_point)
    t = _add(t, _cross(p, f))
    if frame_pose is None:
        return f, t, None
    if body_pose is None:
        raise ValueError("wrench_to_world: body_pose is needed with a reference frame")
    tr_p, tr_q = compose(inverse(_pose(body_pose)), _pose(frame_pose))
    f = rotate(tr_q, f)
    t = _add(rotate(tr_q, t), _cross(tr_p, f))
    return f, t, None


def _ns(seconds):
    """Seconds -> integer nanoseconds, as ``ros::Time(double)`` stores them, so comparisons are exact."""
    return int(round(float(seconds) * 1e9))


class WrenchSchedule:
    """apply_body_wrench / clear_body_wrenches jobs, timed as gazebo_ros's ``wrenchBodySchedulerSlot``.

    A job: (body, force, torque, point) from ``start`` for ``duration``. Timing, as upstream:

    * ``start_time`` earlier than now (0, the unset value, included) means now.
    * at a step whose sim time is ``t`` the job applies if ``t >= start`` and (``duration < 0`` or
      ``t <= start + duration``); it is dropped once ``t > start + duration`` (never when ``duration < 0``).
    * Gazebo runs the slot at WorldUpdateBegin, after ``World::Step`` has already advanced sim time: ``t``
      is the time the coming step will REACH, while "now" at request time is the time already reached. So
      ``duration = 0`` with start "now" never applies (the srv file's "if duration < step size, apply wrench
      for one step size" is not what the code does: any ``0 <= duration < step`` starting now does nothing);
      a duration ``d`` starting now acts for ``floor(d / step)`` steps; a future start exactly on a step
      time with duration 0 acts for one step.
    * Each job calls ``SetForce``/``SetTorque``, which REPLACE the link's force and torque, so of several
      jobs active on one body the one added last wins; :meth:`active` returns only that one per body.

    Times are compared in integer nanoseconds, as ros::Time does. A body is a scoped name "model::link";
    :meth:`clear` matches it exactly, as upstream matches ``GetScopedName()``.
    """

    def __init__(self):
        self._jobs = []  # [body, force, torque, point, start_ns, end_ns or None (forever)]

    def __len__(self):
        return len(self._jobs)

    def add(self, body, force, torque, reference_point, start_time, duration, now):
        """Schedule a wrench. ``now``: the sim time already reached (the time a service call reads)."""
        for what, value in (("start_time", start_time), ("duration", duration), ("now", now)):
            if not math.isfinite(float(value)):
                raise ValueError(f"apply_body_wrench: {what} is {float(value)!r}")
        start = max(_ns(start_time), _ns(now))
        end = None if float(duration) < 0.0 else start + _ns(duration)
        point = None if reference_point is None else _floats(reference_point)
        self._jobs.append([body, _floats(force), _floats(torque), point, start, end])

    def active(self, now):
        """[(body, force, torque, point)] to apply during the coming step, at most one per body (the last
        added); jobs past their end are dropped. ``now``: the sim time this step will REACH (current sim
        time + step), which is what Gazebo's slot reads."""
        t = _ns(now)
        out, keep = {}, []
        for job in self._jobs:
            body, force, torque, point, start, end = job
            if t >= start and (end is None or t <= end):
                out[body] = (body, force, torque, point)
            if end is None or t <= end:
                keep.append(job)
        self._jobs = keep
        return list(out.values())

    def clear(self, body):
        """Drop every job on ``body`` (clear_body_wrenches); returns how many."""
        before = len(self._jobs)
        self._jobs = [job for job in self._jobs if job[0] != body]
        return before - len(self._jobs)

    def clear_model(self, model):
        """Drop every job on a link of ``model`` or of a model nested in it (delete_model); returns how
        many."""
        prefix = model + "::"
        before = len(self._jobs)
        self._jobs = [job for job in self._jobs if not job[0].startswith(prefix)]
        return before - len(self._jobs)

    def clear_all(self):
        """Drop every job (reset_simulation/reset_world keep them upstream; this is for shutting down)."""
        count, self._jobs = len(self._jobs), []
        return count


# ------------------------------------------------------------------------------------------ physics

#: PyBullet's default numSolverIterations (the installed client reports 50).
PYBULLET_SOLVER_ITERATIONS = 50


def physics_properties(time_step, real_time_factor, real_time, paused, gravity_z,
                       solver_iterations=PYBULLET_SOLVER_ITERATIONS):
    """GetPhysicsProperties' response fields, with an ``ode_config`` that says what PyBullet does.

    ``max_update_rate`` is Gazebo's real_time_update_rate: steps per wall second when paced
    (``real_time_factor / time_step``: 1000 for 1 ms steps at real time), 0 for "as fast as possible"
    (``real_time`` false). ``gravity``: (0, 0, gravity_z): only vertical gravity is simulated.

    ``ode_config`` (gazebo_msgs/ODEPhysics field names), Bullet's equivalent of each ODE quickstep setting:

    * auto_disable_bodies False: bodies never sleep (PyBullet only lets them with URDF_ENABLE_SLEEPING).
    * sor_pgs_precon_iters 0: Bullet's solver has no preconditioning pass (Gazebo's default is 0 too).
    * sor_pgs_iters ``solver_iterations``: PyBullet's numSolverIterations (sequential impulse, PGS-like).
    * sor_pgs_w 1.0: Bullet's SOR factor (btContactSolverInfo m_sor), no over-relaxation (Gazebo's 1.3).
    * sor_pgs_rms_error_tol 0.0: upstream never fills this field (always 0 from Gazebo); left so.
    * contact_surface_layer 1e-5 m: PyBullet's contactSlop (m_linearSlop), the penetration allowed before
      correction, which is what ODE's surface layer is (Gazebo's default 0.001).
    * contact_max_correcting_vel inf: Bullet does not cap the penetration-correcting velocity.
    * cfm 0.0: Bullet's global CFM (m_globalCfm).
    * erp 0.2: Bullet's ERP for contacts shallower than its split-impulse threshold (m_erp; deeper ones
      use split impulse with erp2 0.08), same as Gazebo's default.
    * max_contacts 4: Bullet keeps at most 4 contact points per body pair (its manifold size; Gazebo 20).
    """
    rate = real_time_factor / time_step if real_time else 0.0
    return {
        "time_step": float(time_step),
        "pause": bool(paused),
        "max_update_rate": float(rate),
        "gravity": (0.0, 0.0, float(gravity_z)),
        "ode_config": {
            "auto_disable_bodies": False,
            "sor_pgs_precon_iters": 0,
            "sor_pgs_iters": int(solver_iterations),
            "sor_pgs_w": 1.0,
            "sor_pgs_rms_error_tol": 0.0,
            "contact_surface_layer": 1e-5,
            "contact_max_correcting_vel": math.inf,
            "cfm": 0.0,
            "erp": 0.2,
            "max_contacts": 4,
        },
    }
