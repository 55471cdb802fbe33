"""Model XML as gazebo_ros's spawn services edit it (pure): which kind a text is (URDF or SDF),
``package://`` resolved and the declaration and comments stripped from a URDF, a spawn request's
``robot_namespace`` injected into every plugin, a model renamed and an SDF model placed at its pose
(``gazebo_ros/src/gazebo_ros_api_plugin.cpp``, noetic-devel).

The functions edit the text in place (expat finds the byte offsets of the elements), so everything they do
not change stays byte-identical: comments, namespaces such as xmlns:xacro, formatting. Upstream re-prints
the whole document through TinyXML instead; no client can tell the difference in the result.
"""
import re
from xml.parsers import expat
from xml.sax.saxutils import escape

from diffbot_sim.gazebo.ignition import IDENTITY, unit_pose
from diffbot_sim.transforms import compose, quaternion_rpy
from diffbot_sim.world.sdf_elements import read_pose

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


def _read_pose(data, el, where):
    """An SDF ``<pose>`` element -> pose, read as every SDF pose is (:func:`diffbot_sim.world.sdf_elements.read_pose`:
    six numbers, SDF 1.9's ``degrees="true"`` and ``rotation_format="quat_xyzw"``, empty the identity)."""
    name_end = el.start + 1 + len(el.name.encode("utf-8"))
    attrs = {m.group(2).decode("utf-8"): m.group(4)[1:-1].decode("utf-8")
             for m in _ATTRIBUTE.finditer(data, name_end, el.tag_end)}
    return read_pose("".join(el.text), attrs, "model_xml", where)[0]


def sdf_model_at(xml, pose):
    """The text of the SDF's model element (see :func:`rename_model` for which) placed at ``pose``, for a
    world file: its first ``<pose>`` replaced by ``pose ∘ file_pose``.

    Upstream does not overwrite the model's own ``<pose>``: it composes it ON the requested pose (ignition
    ``model_pose + initial_pose``: the file's pose is read in the request's frame) and writes the result as
    a plain ``<pose>x y z roll pitch yaw</pose>`` (attributes such as ``relative_to`` dropped, as upstream's
    new element has none). The ``<pose>`` is read as every SDF pose is (an empty one is the identity); one
    that is not six numbers (seven with SDF 1.9 ``rotation_format="quat_xyzw"``; ``degrees="true"`` honoured)
    is a ModelError here; upstream logs and uses zeros. The ``<sdf version>`` of the original is not part of
    the returned text: the caller keeps it.
    """
    data, root = _scan(xml)
    target = _sdf_target(root)
    pose = unit_pose(pose)
    pose_el = target.child("pose")
    file_pose = IDENTITY
    if pose_el is not None:
        file_pose = _read_pose(data, pose_el, f"<{target.name}>/pose")
    (x, y, z), q = compose(pose, file_pose)
    text = " ".join(repr(float(v)) for v in (x, y, z) + quaternion_rpy(q))
    new = b"<pose>" + text.encode("ascii") + b"</pose>"
    edit = (pose_el.start, pose_el.end, new) if pose_el is not None else _append_child(target, new)
    start, end = target.start, target.end
    shifted = (edit[0] - start, edit[1] - start, edit[2])
    return _splice(data[start:end], [shifted]).decode("utf-8")


def sdf_model_frame(model_text):
    """(pose ((x, y, z), (qx, qy, qz, qw)), link names) of the SDF ``<model>`` element :func:`sdf_model_at`
    returned: for a model with nothing the physics holds, whose pose and links Gazebo still reports."""
    import xml.etree.ElementTree as ET

    root = ET.fromstring(model_text)
    pose_el = root.find("pose")
    pose = IDENTITY if pose_el is None else read_pose(pose_el.text, pose_el.attrib, "model_xml", "pose")[0]
    return pose, [link.get("name") for link in root.findall("link") if link.get("name")]
