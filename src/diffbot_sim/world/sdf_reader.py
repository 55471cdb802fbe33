"""Read a Gazebo-classic SDF world (``.world``) into a :class:`diffbot_sim.world.bodies.WorldDescription` (pure).

Why our own reader: ``pybullet.loadSDF`` has no ``<include>``, mishandles ``<static>true</static>``, turns
meshes into convex hulls and does not import jointless multi-link models; libsdformat is not on Debian's
Python. So we read the few elements that decide collisions ourselves and name everything else once in
``not_simulated`` so a user sees what the world asked for and did not get.

What is read (SDF 1.4 to 1.9, as Gazebo 11 reads them):

* ``<model>`` (inline, nested as ``outer::inner``) and ``<include>`` (``uri``; ``name``, ``pose`` and
  ``static`` override the included model's, an empty ``<pose/>`` resets it to zero; also inside a model).
  Each ``<link>`` becomes one :class:`~diffbot_sim.world.bodies.Body` named ``model::link``; joints between links
  are named in one warning per model and not simulated (the links move as separate bodies).
* ``<collision>`` geometry box, cylinder, sphere, plane (infinite), mesh; surface ``mu``/``mu2`` (ODE, else
  Bullet), contact ``kp``/``kd`` and ``laser_retro``. Of visuals only the colour is read, for cameras: the
  first ``<visual><material>`` of a link gives ``Body.color`` (its ``<diffuse>``, else ``<ambient>``, else a
  ``<script><name>`` of :data:`GAZEBO_COLORS`); the camera sees the collision geometry in that colour.
* Poses with SDF 1.7+ frame semantics (``relative_to`` naming a model, a link, ``model::link``, a ``<frame>``
  or a joint; 1.5/1.6's ``frame`` attribute is the same attribute before its rename), 1.8
  ``placement_frame``, 1.9 ``degrees`` and ``rotation_format="quat_xyzw"``.
* The first ``<state>``: its model (and nested model and link) poses replace the file's, as Gazebo's
  ``World::SetState`` does at start; its ``insertions`` add models and its ``deletions`` remove them.
* ``<physics>`` gravity, ``max_step_size`` and ``real_time_factor``.

``model://NAME`` is searched as Gazebo does: ``~/.gazebo/models``, each ``GAZEBO_MODEL_PATH`` entry, then the
directories ROS packages export to gazebo_ros (:func:`ros_package_model_paths`); the first match wins.
Gazebo's own ``ground_plane`` and ``sun`` are built in for when no directory has them. Nothing is ever
downloaded: a model that cannot be found is an error that names every directory searched.
"""
import math
import os
import xml.etree.ElementTree as ET

from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.transforms import compose, inverse, qnormalize, rpy_quaternion
from diffbot_sim.values import tag_number
from diffbot_sim.world.bodies import IDENTITY, Body, Shape, WorldDescription
from diffbot_sim.world.model_paths import env_model_paths

#: The SDF versions this reader knows; others are read as the nearest one (with a warning).
VERSIONS = ((1, 4), (1, 5), (1, 6), (1, 7), (1, 8), (1, 9))
#: The parser's own version: ``model.config`` entries newer than this are skipped, as libsdformat does.
PARSER_VERSION = VERSIONS[-1]

#: Mesh formats the physics layer can read (:mod:`diffbot_sim.description.meshes`).
MESH_EXTENSIONS = (".dae", ".stl", ".obj")

# Gazebo installs exactly these two models with itself "to make Gazebo run without an internet
# connection" (worlds.md 2.4). Written from the facts listed there: a static plane with ODE friction 100/50
# and a directional light.
_BUILTIN = {
    "ground_plane": """<sdf version="1.5"><model name="ground_plane"><static>true</static>
  <link name="link"><collision name="collision"><geometry><plane><normal>0 0 1</normal><size>100 100</size>
  </plane></geometry><surface><friction><ode><mu>100</mu><mu2>50</mu2></ode></friction></surface></collision>
  <visual name="visual"><material><script><name>Gazebo/Grey</name></script></material></visual>
  </link></model></sdf>""",
    "sun": """<sdf version="1.5"><light type="directional" name="sun"><cast_shadows>true</cast_shadows>
  <pose>0 0 10 0 0 0</pose><diffuse>0.8 0.8 0.8 1</diffuse><specular>0.2 0.2 0.2 1</specular>
  <direction>-0.5 0.1 -0.9</direction></light></sdf>""",
}

#: rgba of Gazebo's stock material scripts (gazebo.material's diffuse colours; Wood and Bricks are textures
#: there, here their average colour). Other script names leave a body uncoloured (PyBullet's default grey).
GAZEBO_COLORS = {
    "Gazebo/Red": (1.0, 0.0, 0.0, 1.0), "Gazebo/Green": (0.0, 1.0, 0.0, 1.0), "Gazebo/Blue": (0.0, 0.0, 1.0, 1.0),
    "Gazebo/Grey": (0.7, 0.7, 0.7, 1.0), "Gazebo/Gray": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/DarkGrey": (0.175, 0.175, 0.175, 1.0), "Gazebo/White": (1.0, 1.0, 1.0, 1.0),
    "Gazebo/Black": (0.0, 0.0, 0.0, 1.0), "Gazebo/Yellow": (1.0, 1.0, 0.0, 1.0),
    "Gazebo/Orange": (1.0, 0.5088, 0.0468, 1.0), "Gazebo/Purple": (1.0, 0.0, 1.0, 1.0),
    "Gazebo/Turquoise": (0.0, 1.0, 1.0, 1.0), "Gazebo/Wood": (0.56, 0.39, 0.22, 1.0),
    "Gazebo/Bricks": (0.6, 0.3, 0.22, 1.0),
}


# World children that change nothing our physics does: named once in ``not_simulated``.
_WORLD_NOT_SIMULATED = ("scene", "gui", "atmosphere", "magnetic_field", "spherical_coordinates", "wind",
                        "audio")


def _clean(pose):
    """Plain floats, -0.0 and rounding dust removed, so poses compare and print as the file wrote them."""
    (p, q) = pose
    tidy = lambda v: 0.0 if abs(v) < 1e-12 else float(v)  # noqa: E731
    return (tuple(tidy(v) for v in p), tuple(tidy(v) for v in q))


# ------------------------------------------------------------------------------------------ tree nodes

class _File:
    """One SDF file being read: its path (for messages and relative URIs) and its SDF version."""

    def __init__(self, path, version):
        self.path = path
        self.dir = os.path.dirname(path) if os.path.isabs(path) else os.getcwd()
        self.version = version


class _Scope:
    """A frame scope: the world or one model. Names in ``relative_to`` are looked up here."""

    def __init__(self, name, full, parent):
        self.name = name
        self.full = full
        self.parent = parent
        self.links = {}
        self.models = {}
        self.frames = {}  # name -> (pose, relative_to, attached_to, path)
        self.joints = {}  # name -> (pose, relative_to, child)


class _Model(_Scope):
    def __init__(self, name, full, parent, src, path):
        super().__init__(name, full, parent)
        self.src = src
        self.path = path
        self.static = False
        self.pose = IDENTITY
        self.relative_to = ""
        self.placement = ""


class _Link:
    def __init__(self, name, model, src, path):
        self.name = name
        self.model = model
        self.src = src
        self.path = path
        self.pose = IDENTITY
        self.relative_to = ""
        self.shapes = []
        self.mass = 1.0
        self.inertia = (1.0, 1.0, 1.0, 0.0, 0.0, 0.0)
        self.inertial_pose = IDENTITY
        self.color = None


# ------------------------------------------------------------------------------------------ XML helpers

def _parse_xml(path, text=None):
    """ElementTree root of ``path`` (or of ``text``, labelled ``path``); a ModelError names file and line."""
    try:
        if text is None:
            with open(path, "rb") as handle:
                text = handle.read()
        return ET.fromstring(text)
    except ET.ParseError as err:
        line, column = err.position
        detail = str(err).split(":")[0]
        raise ModelError(f"malformed XML at line {line}, column {column + 1} ({detail})", path) from None
    except OSError as err:
        raise ModelError(f"cannot read ({err.strerror or err})", path) from None


def _version(text):
    """``"1.6"`` -> (1, 6); None when it is not two dot-separated integers."""
    try:
        major, minor = (int(part) for part in (text or "").strip().split("."))
        return (major, minor)
    except ValueError:
        return None


def _text(el, tag, default=None):
    child = el.find(tag)
    if child is None or child.text is None or not child.text.strip():
        return default
    return child.text.strip()


def _bool(text):
    """SDF booleans: ``true``/``1`` (any case) are true; libsdformat reads ``True`` as true too."""
    return (text or "").strip().lower() in ("true", "1")


# ------------------------------------------------------------------------------------------ the reader

class _Reader:
    def __init__(self, model_paths, package_model_paths):
        self.search = []
        for path in list(model_paths) + list(package_model_paths or []):
            if path and path not in self.search:  # Gazebo's InsertUnique: first position wins
                self.search.append(path)
        self.world = None
        self.stack = []  # files being included, to catch include cycles
        self.top = []  # the world's models, in order
        self.scope = _Scope("", "", None)
        self.cache = {}
        self.active = set()
        self.override = {}
        self.poses = {}  # id(link or model) -> world pose a <state> set

    # -- messages
    def warn(self, message):
        if message not in self.world.warnings:
            self.world.warnings.append(message)

    def skip(self, what):
        if what not in self.world.not_simulated:
            self.world.not_simulated.append(what)

    # -- numbers
    def floats(self, text, count, src, path, what):
        parts = (text or "").split()
        try:
            values = tuple(float(v) for v in parts)
        except ValueError:
            values = ()
        if len(values) != count or not all(math.isfinite(v) for v in values):
            raise ModelError(f"{what} '{(text or '').strip()}' is not {count} finite number"
                             f"{'s' if count > 1 else ''}", src.path, path)
        return values

    def number(self, el, tag, default, src, path, positive=False):
        """The number in ``<tag>``, read as sdformat reads it (its leading number, the rest dropped with one
        warning)."""
        text = _text(el, tag)
        if text is None:
            return default
        notes = []
        try:
            value = tag_number(f"{src.path}: {path}/{tag}", text, notes)
        except ConfigError:
            raise ModelError(f"<{tag}> '{text}' is not 1 finite number", src.path, f"{path}/{tag}") from None
        for note in notes:
            self.warn(note)
        if positive and value <= 0:
            raise ModelError(f"<{tag}> {text} must be > 0", src.path, f"{path}/{tag}")
        return value

    def pose(self, el, src, path):
        """``<pose>`` element -> (pose, relative_to). An empty element is the identity, as in SDF."""
        rel = (el.get("relative_to") or el.get("frame") or "").strip()
        text = (el.text or "").strip()
        if not text:
            return IDENTITY, rel
        fmt = (el.get("rotation_format") or "euler_rpy").strip()
        if fmt == "quat_xyzw":
            v = self.floats(text, 7, src, path, "<pose> (quat_xyzw)")
            if sum(c * c for c in v[3:]) < 1e-12:
                raise ModelError("<pose> quaternion is zero", src.path, path)
            return ((v[0], v[1], v[2]), qnormalize(v[3:])), rel
        if fmt != "euler_rpy":
            raise ModelError(f"<pose rotation_format='{fmt}'> is not euler_rpy or quat_xyzw", src.path, path)
        v = self.floats(text, 6, src, path, "<pose>")
        angles = v[3:]
        if _bool(el.get("degrees")):
            angles = tuple(math.radians(a) for a in angles)
        return ((v[0], v[1], v[2]), rpy_quaternion(*angles)), rel

    def child_pose(self, el, src, path):
        pose_el = el.find("pose")
        if pose_el is None:
            return IDENTITY, ""
        return self.pose(pose_el, src, f"{path}/pose")

    # -- files
    def load(self, path, text=None, label=None):
        """Parse an SDF file -> (root, _File). Version outside 1.4-1.9: warned, read as the nearest."""
        label = label or path
        root = _parse_xml(label, text) if text is not None else _parse_xml(path)
        if root.tag != "sdf":
            raise ModelError(f"root element is <{root.tag}>, expected <sdf>", label, f"/{root.tag}")
        raw = root.get("version")
        version = _version(raw)
        if version is None:
            self.warn(f"{label}: <sdf version='{raw or ''}'> is not a version; read as SDF 1.7 (Gazebo 11's)")
            version = (1, 7)
        elif version not in VERSIONS:
            nearest = VERSIONS[0] if version < VERSIONS[0] else VERSIONS[-1]
            self.warn(f"{label}: SDF {raw} is not one of 1.4-1.9; read as SDF {nearest[0]}.{nearest[1]}")
            version = nearest
        return root, _File(label if text is not None else path, version)

    def model_file(self, directory, src, path):
        """The SDF file a model directory's model.config names (highest version <= 1.9; else the first)."""
        config = os.path.join(directory, "model.config")
        if not os.path.isfile(config):
            manifest = os.path.join(directory, "manifest.xml")
            if not os.path.isfile(manifest):
                raise ModelError(f"model directory {directory} has no model.config", src.path, path)
            self.warn(f"{manifest}: manifest.xml is deprecated in favour of model.config; read anyway")
            config = manifest
        root = _parse_xml(config)
        entries = [(e.get("version"), (e.text or "").strip()) for e in root.iter("sdf") if (e.text or "").strip()]
        if not entries:
            raise ModelError("names no <sdf> file", config, "/model/sdf")
        versioned = [(_version(v), name) for v, name in entries if _version(v) is not None]
        if versioned:
            usable = [item for item in versioned if item[0] <= PARSER_VERSION]
            newer = [name for v, name in versioned if v > PARSER_VERSION]
            if usable:
                if newer:
                    self.warn(f"{config}: {', '.join(newer)} need SDF > 1.9 and are ignored")
                chosen = max(usable, key=lambda item: item[0])[1]
            else:
                chosen = min(versioned, key=lambda item: item[0])[1]
                self.warn(f"{config}: every file needs SDF > 1.9; reading {chosen} as 1.9")
        else:
            chosen = entries[0][1]
        target = os.path.join(directory, chosen)
        if not os.path.isfile(target):
            raise ModelError(f"names {chosen}, which does not exist", config, "/model/sdf")
        return target

    def resolve_include(self, uri, src, path):
        """Include ``uri`` -> an SDF file path, or ``("builtin", name)``. Never a download."""
        searched = []
        if uri.startswith(("http://", "https://")):
            raise ModelError(f"<include> uri '{uri}' is a network address; models are never downloaded "
                             f"(put the model in GAZEBO_MODEL_PATH)", src.path, path)
        if uri.startswith("model://"):
            rest = uri[len("model://"):].strip("/")
            name = rest.split("/", 1)[0]
            for directory in self.search:
                candidate = os.path.join(directory, rest)
                searched.append(directory)
                if os.path.exists(candidate):
                    return self.sdf_of(candidate, src, path)
            if rest in _BUILTIN:
                return ("builtin", rest)
            where = ", ".join(searched) if searched else "(no directory)"
            raise ModelError(f"cannot resolve <include> uri '{uri}': no directory '{name}' in any of {where} "
                             f"(models are never downloaded)", src.path, path)
        literal = uri[len("file://"):] if uri.startswith("file://") else uri
        candidates = [literal] if os.path.isabs(literal) else [os.path.join(src.dir, literal)]
        if not os.path.isabs(literal):
            candidates += [os.path.join(d, literal) for d in self.search]
        for candidate in candidates:
            if os.path.exists(candidate):
                return self.sdf_of(candidate, src, path)
        raise ModelError(f"cannot resolve <include> uri '{uri}': tried {', '.join(candidates)} "
                         f"(models are never downloaded)", src.path, path)

    def sdf_of(self, candidate, src, path):
        return os.path.abspath(self.model_file(candidate, src, path) if os.path.isdir(candidate) else candidate)

    def mesh_path(self, uri, src, path):
        """Mesh ``uri`` -> an absolute path, or None (warned) when no file is there."""
        tried = []
        if uri.startswith(("model://", "package://")):
            rest = uri.split("://", 1)[1].lstrip("/")
            tried = [os.path.join(d, rest) for d in self.search]
            if uri.startswith("package://"):
                package, _, inner = rest.partition("/")
                try:
                    import rospkg  # lazy, optional: Gazebo itself only searches the model paths

                    tried.append(os.path.join(rospkg.RosPack().get_path(package), inner))
                except Exception:  # noqa: BLE001 - rospkg missing or the package unknown: keep searching
                    pass
        else:
            literal = uri[len("file://"):] if uri.startswith("file://") else uri
            if os.path.isabs(literal):
                tried = [literal]
            else:
                tried = [os.path.join(src.dir, literal)]
                tried += [os.path.join(d, literal) for d in
                          os.environ.get("GAZEBO_RESOURCE_PATH", "").split(":") if d]
        for candidate in tried:
            if os.path.isfile(candidate):
                return os.path.abspath(candidate)
        self.warn(f"{src.path}: {path}: mesh '{uri}' not found (tried {', '.join(tried) or 'nothing'}); "
                  f"collision skipped")
        return None

    # -- world
    def read(self, path):
        self.world = WorldDescription(name="", source=path)  # before load(): it may warn already
        root, src = self.load(path)
        worlds = root.findall("world")
        if not worlds:
            raise ModelError("no <world> element (is this a model file? spawn models instead)", path, "/sdf")
        world_el = worlds[0]
        name = world_el.get("name") or "default"
        wpath = f"/sdf/world[@name='{name}']"
        self.world.name = name
        if len(worlds) > 1:
            self.warn(f"{path}: {len(worlds)} <world> elements; only the first is read (as Gazebo does)")
        self.stack.append(os.path.abspath(path))
        states = []
        for el in world_el:
            tag = el.tag
            if tag == "model":
                self.add_top(self.model(el, self.scope, src, f"{wpath}/model[@name='{el.get('name')}']"))
            elif tag == "include":
                self.add_top(self.include(el, self.scope, src, f"{wpath}/include"))
            elif tag == "frame":
                self.frame(el, self.scope, src, wpath)
            elif tag == "state":
                states.append(el)
            elif tag == "light":
                self.skip(f"light {el.get('name', '')} ({el.get('type', 'point')})")
            elif tag == "plugin":
                self.skip(f"plugin {el.get('filename', el.get('name', ''))} in world")
            elif tag in ("actor", "road", "population"):
                self.skip(f"{tag} {el.get('name', '')}")
            elif tag in _WORLD_NOT_SIMULATED:
                self.skip(tag)
            elif tag not in ("physics", "gravity"):
                self.warn(f"{path}: {wpath}/{tag}: element not known to SDF worlds; ignored")
        self.physics(world_el, src, wpath)
        if states:
            if len(states) > 1:
                self.warn(f"{path}: {len(states)} <state> blocks; only the first applies (as in Gazebo)")
            self.state(states[0], src, f"{wpath}/state")
        self.emit()
        return self.world

    def add_top(self, model):
        if model is None:
            return
        if model.name in self.scope.models:
            self.warn(f"{model.src.path}: {model.path}: a second model named '{model.name}'; skipped")
            return
        self.scope.models[model.name] = model
        self.top.append(model)

    def physics(self, world_el, src, wpath):
        profiles = world_el.findall("physics")
        chosen = next((p for p in profiles if _bool(p.get("default"))), profiles[0] if profiles else None)
        for other in profiles:
            if other is not chosen:
                self.skip(f"physics profile {other.get('name', '')}")
        gravity_el = world_el.find("gravity")
        if chosen is not None:
            ppath = f"{wpath}/physics"
            kind = chosen.get("type", "ode")
            if kind != "ode":
                self.skip(f"physics type {kind} (Bullet is used whatever the file says)")
            for child in chosen:
                if child.tag == "max_step_size":
                    self.world.max_step_size = self.number(chosen, "max_step_size", None, src, ppath, True)
                elif child.tag == "real_time_factor":
                    self.world.real_time_factor = self.number(chosen, "real_time_factor", None, src, ppath)
                elif child.tag == "gravity":
                    if src.version >= (1, 6):
                        self.warn(f"{src.path}: {ppath}/gravity: SDF 1.6 moved gravity to <world>; ignored")
                    elif gravity_el is None:
                        gravity_el = child
                elif child.tag == "magnetic_field":
                    self.skip("magnetic_field")
                elif len(child):  # an engine block (ode, bullet, ...): name what it sets
                    for grandchild in child:
                        self.skip(f"physics {child.tag}/{grandchild.tag}")
                else:
                    self.skip(f"physics {child.tag}")
        if gravity_el is not None:
            self.world.gravity = self.floats(gravity_el.text, 3, src, f"{wpath}/gravity", "<gravity>")

    # -- models
    def include(self, el, parent, src, path):
        uri = _text(el, "uri")
        if uri is None:
            raise ModelError("<include> has no <uri>", src.path, path)
        path = f"{path}[uri='{uri}']"
        target = self.resolve_include(uri, src, path)
        if isinstance(target, tuple):
            root, isrc = self.load(f"<built-in {target[1]}>", text=_BUILTIN[target[1]])
        else:
            if target in self.stack:
                raise ModelError(f"<include> '{uri}' includes itself (through {' -> '.join(self.stack)})",
                                 src.path, path)
            root, isrc = self.load(target)
        top = next((c for c in root if c.tag in ("model", "light", "actor", "world")), None)
        name = _text(el, "name")
        if top is None or top.tag == "world":
            raise ModelError(f"<include> '{uri}': {isrc.path} holds no <model>, <light> or <actor>",
                             src.path, path)
        if top.tag == "light":
            self.skip(f"light {name or top.get('name', '')} ({top.get('type', 'point')})")
            return None
        if top.tag == "actor":
            self.skip(f"actor {name or top.get('name', '')}")
            return None
        pose = None
        if el.find("pose") is not None:
            pose = self.pose(el.find("pose"), src, f"{path}/pose")
        static = _text(el, "static")
        self.stack.append(isrc.path)
        try:
            model = self.model(top, parent, isrc, f"/sdf/model[@name='{top.get('name')}']", name=name, pose=pose,
                               static=None if static is None else _bool(static))
        finally:
            self.stack.pop()
        placement = _text(el, "placement_frame")
        if placement:
            model.placement = placement
        for plugin in el.findall("plugin"):
            self.skip(f"plugin {plugin.get('filename', plugin.get('name', ''))} in model {model.full}")
        return model

    def model(self, el, parent, src, path, name=None, pose=None, static=None):
        own = el.get("name")
        if not own:
            raise ModelError("<model> has no name", src.path, path)
        name = name or own
        full = f"{parent.full}::{name}" if parent.full else name
        model = _Model(name, full, parent, src, path)
        model.static = _bool(_text(el, "static", "false")) if static is None else static
        model.pose, model.relative_to = pose if pose is not None else self.child_pose(el, src, path)
        placement = _text(el, "placement_frame")  # not in the spec, but cheap to honour if written
        if placement:
            model.placement = placement
        for child in el:
            cpath = f"{path}/{child.tag}[@name='{child.get('name', '')}']"
            if child.tag == "link":
                link = self.link(child, model, src, cpath)
                model.links.setdefault(link.name, link)
            elif child.tag == "model":
                self.add_child(model, self.model(child, model, src, cpath))
            elif child.tag == "include":
                self.add_child(model, self.include(child, model, src, f"{path}/include"))
            elif child.tag == "frame":
                self.frame(child, model, src, path)
            elif child.tag == "joint":
                jpose, jrel = self.child_pose(child, src, cpath)
                model.joints[child.get("name", "")] = (jpose, jrel, _text(child, "child", ""))
            elif child.tag == "plugin":
                self.skip(f"plugin {child.get('filename', child.get('name', ''))} in model {full}")
            elif child.tag == "gripper":
                self.skip(f"gripper {child.get('name', '')} in model {full}")
        if model.joints:
            self.warn(f"{src.path}: model {full}: {len(model.joints)} joint(s) "
                      f"({', '.join(sorted(model.joints))}) not simulated; its links are separate bodies")
        return model

    def add_child(self, model, child):
        if child is None:
            return
        if child.name in model.models:
            self.warn(f"{child.src.path}: {child.path}: a second model named '{child.name}' in {model.full}; "
                      f"skipped")
            return
        model.models[child.name] = child

    def frame(self, el, scope, src, path):
        name = el.get("name", "")
        fpath = f"{path}/frame[@name='{name}']"
        pose, rel = self.child_pose(el, src, fpath)
        scope.frames[name] = (pose, rel, (el.get("attached_to") or "").strip(), fpath)

    def link(self, el, model, src, path):
        name = el.get("name")
        if not name:
            raise ModelError("<link> has no name", src.path, path)
        link = _Link(name, model, src, path)
        link.pose, link.relative_to = self.child_pose(el, src, path)
        inertial = el.find("inertial")
        if inertial is not None:
            ipath = f"{path}/inertial"
            link.mass = self.number(inertial, "mass", 1.0, src, ipath)  # <= 0: checked once static is known
            link.inertial_pose = self.child_pose(inertial, src, ipath)[0]
            tensor = inertial.find("inertia")
            if tensor is not None:
                tpath = f"{ipath}/inertia"
                link.inertia = tuple(self.number(tensor, key, default, src, tpath) for key, default in
                                     (("ixx", 1.0), ("iyy", 1.0), ("izz", 1.0), ("ixy", 0.0), ("ixz", 0.0),
                                      ("iyz", 0.0)))
        full = f"{model.full}::{name}"
        if _text(el, "gravity") is not None and not _bool(_text(el, "gravity")):
            self.skip(f"gravity off for link {full}")
        if _bool(_text(el, "kinematic")):
            self.skip(f"kinematic link {full} (simulated as a normal body)")
        for sensor in el.findall("sensor"):
            self.skip(f"sensor {sensor.get('name', '')} ({sensor.get('type', '')}) in link {full}")
        for light in el.findall("light"):
            self.skip(f"light {light.get('name', '')} ({light.get('type', 'point')}) in link {full}")
        for visual in el.findall("visual"):
            link.color = self.material(visual, src, f"{path}/visual[@name='{visual.get('name', '')}']")
            if link.color is not None:
                break
        for collision in el.findall("collision"):
            shape = self.collision(collision, src, f"{path}/collision[@name='{collision.get('name', '')}']")
            if shape is not None:
                link.shapes.append(shape)
        return link

    def material(self, el, src, path):
        """rgba of a ``<visual>``'s ``<material>``: ``<diffuse>``, else ``<ambient>``, else a known script name."""
        material = el.find("material")
        if material is None:
            return None
        for tag in ("diffuse", "ambient"):
            text = _text(material, tag)
            if text is not None:
                parts = text.split()
                values = self.floats(text, len(parts) if len(parts) in (3, 4) else 4, src,
                                     f"{path}/material/{tag}", f"<{tag}>")
                return tuple(min(max(v, 0.0), 1.0) for v in values) + ((1.0,) if len(values) == 3 else ())
        name = _text(material, "script/name")
        if name is not None:
            if name in GAZEBO_COLORS:
                return GAZEBO_COLORS[name]
            self.warn(f"{src.path}: {path}/material/script: '{name}' is not a colour this simulator knows; "
                      f"the camera sees it grey")
        return None

    def collision(self, el, src, path):
        geometry = el.find("geometry")
        kinds = list(geometry) if geometry is not None else []
        if not kinds:
            self.warn(f"{src.path}: {path}: no geometry; collision skipped")
            return None
        geom = kinds[0]
        gpath = f"{path}/geometry/{geom.tag}"
        shape = Shape(kind=geom.tag, name=el.get("name", ""))
        if geom.tag == "box":
            size = _text(geom, "size", "1 1 1")
            shape.size = self.floats(size, 3, src, f"{gpath}/size", "<size>")
        elif geom.tag == "cylinder":
            shape.size = (self.number(geom, "radius", 1.0, src, gpath, True),
                          self.number(geom, "length", 1.0, src, gpath, True))
        elif geom.tag == "sphere":
            shape.size = (self.number(geom, "radius", 1.0, src, gpath, True),)
        elif geom.tag == "plane":
            normal = self.floats(_text(geom, "normal", "0 0 1"), 3, src, f"{gpath}/normal", "<normal>")
            length = math.sqrt(sum(c * c for c in normal))
            if length == 0:
                raise ModelError("<normal> is the zero vector", src.path, f"{gpath}/normal")
            shape.size = tuple(c / length for c in normal)  # <size> is for the visual: the collision is infinite
        elif geom.tag == "mesh":
            uri = _text(geom, "uri")
            if uri is None:
                raise ModelError("<mesh> has no <uri>", src.path, gpath)
            if geom.find("submesh") is not None:
                self.warn(f"{src.path}: {gpath}/submesh: submesh is not supported; the whole mesh collides")
            shape.scale = self.floats(_text(geom, "scale", "1 1 1"), 3, src, f"{gpath}/scale", "<scale>")
            if os.path.splitext(uri)[1].lower() not in MESH_EXTENSIONS:
                self.warn(f"{src.path}: {gpath}: mesh '{uri}' is not .dae, .stl or .obj; collision skipped")
                return None
            shape.mesh = self.mesh_path(uri, src, gpath)
            if shape.mesh is None:
                return None
        else:
            self.warn(f"{src.path}: {gpath}: <{geom.tag}> geometry is not supported; collision skipped")
            return None
        shape.pose, rel = self.child_pose(el, src, path)
        if rel:
            self.warn(f"{src.path}: {path}/pose: relative_to '{rel}' on a collision is not supported; "
                      f"read relative to its link")
        shape.surface = self.surface(el, src, path)
        return shape

    def surface(self, el, src, path):
        found = {}
        spath = f"{path}/surface"
        for key, where in (("mu", "surface/friction/ode/mu"), ("mu2", "surface/friction/ode/mu2"),
                           ("kp", "surface/contact/ode/kp"), ("kd", "surface/contact/ode/kd"),
                           ("laser_retro", "laser_retro")):
            text = _text(el, where)
            if text is not None:
                found[key] = self.floats(text, 1, src, f"{path}/{where}", f"<{where.rsplit('/', 1)[-1]}>")[0]
        # Bullet's friction only where ODE's is not given: Gazebo's default engine reads the ODE values.
        for key, where in (("mu", "surface/friction/bullet/friction"), ("mu2", "surface/friction/bullet/friction2")):
            text = _text(el, where)
            if text is not None and key not in found:
                found[key] = self.floats(text, 1, src, f"{spath}/{where[8:]}", "<friction>")[0]
        return found

    # -- poses
    def world_pose(self, scope, name, src, path):
        """World pose of the frame ``name`` as seen from ``scope`` ('' = the scope's own frame)."""
        key = (id(scope), name)
        if key in self.cache:
            return self.cache[key]
        if key in self.active:
            raise ModelError(f"pose relative_to '{name}' is part of a cycle of frames", src.path, path)
        self.active.add(key)
        try:
            pose = self.resolve(scope, name, src, path)
        finally:
            self.active.discard(key)
        self.cache[key] = pose
        return pose

    def resolve(self, scope, name, src, path):
        if name == "" or (scope.parent is not None and name == "__model__"):
            return self.model_pose(scope) if scope.parent is not None else IDENTITY
        if scope.parent is None and name == "world":
            return IDENTITY
        if "::" in name:
            head, rest = name.split("::", 1)
            if head in scope.models:
                return self.world_pose(scope.models[head], rest, src, path)
        if name in scope.links:
            link = scope.links[name]
            return compose(self.world_pose(scope, link.relative_to, link.src, f"{link.path}/pose"), link.pose)
        if name in scope.models:
            return self.model_pose(scope.models[name])
        if name in scope.frames:
            pose, rel, attached, fpath = scope.frames[name]
            return compose(self.world_pose(scope, rel or attached, src, f"{fpath}/pose"), pose)
        if name in scope.joints:
            pose, rel, child = scope.joints[name]
            return compose(self.world_pose(scope, rel or child, src, path), pose)
        where = f"model {scope.full}" if scope.parent is not None else "the world"
        self.warn(f"{src.path}: {path}: relative_to '{name}' names no frame of {where}; its own frame is used")
        return self.world_pose(scope, "", src, path)

    def model_pose(self, model):
        if id(model) in self.override:
            return self.override[id(model)]
        key = (id(model), "__model__")
        if key in self.cache:
            return self.cache[key]
        if key in self.active:
            raise ModelError("model pose relative_to is part of a cycle of frames", model.src.path, model.path)
        self.active.add(key)
        try:
            pose = compose(self.world_pose(model.parent, model.relative_to, model.src, f"{model.path}/pose"),
                           model.pose)
            if model.placement:
                # The include pose places the placement frame, not the model frame: undo the frame's offset
                # in the model, found by resolving it with the model frame at the origin.
                sub = _Reader.__new__(_Reader)
                sub.__dict__.update(self.__dict__)
                sub.cache, sub.active, sub.override = {}, set(), {**self.override, id(model): IDENTITY}
                offset = sub.world_pose(model, model.placement, model.src, f"{model.path}/placement_frame")
                pose = compose(pose, inverse(offset))
        finally:
            self.active.discard(key)
        self.cache[key] = pose
        return pose

    # -- state
    def state(self, el, src, path):
        insertions = el.find("insertions")
        if insertions is not None:
            for model_el in insertions.findall("model"):
                mpath = f"{path}/insertions/model[@name='{model_el.get('name')}']"
                self.add_top(self.model(model_el, self.scope, src, mpath))
        deletions = el.find("deletions")
        if deletions is not None:
            for name_el in deletions.findall("name"):
                name = (name_el.text or "").strip()
                if name in self.scope.models:
                    del self.scope.models[name]
                    self.top = [m for m in self.top if m.name != name]
        for model_el in el.findall("model"):
            name = model_el.get("name", "")
            if name not in self.scope.models:
                self.warn(f"{src.path}: {path}/model[@name='{name}']: no model named '{name}' in the world; "
                          f"state entry skipped (as Gazebo does)")
                continue
            self.model_state(self.scope.models[name], model_el, src, f"{path}/model[@name='{name}']")

    def model_state(self, model, el, src, path):
        """Gazebo's Model::SetState: move the model rigidly to the state pose (zero when none is given),
        then put listed links at their own world poses, then nested models likewise."""
        pose_el = el.find("pose")
        target = self.pose(pose_el, src, f"{path}/pose")[0] if pose_el is not None else IDENTITY
        scale = _text(el, "scale")
        if scale is not None and self.floats(scale, 3, src, f"{path}/scale", "<scale>") != (1.0, 1.0, 1.0):
            self.warn(f"{src.path}: {path}/scale: model scale {scale} is not simulated; scale 1 used")
        delta = compose(target, inverse(self.current(model)))
        self.move(model, delta)
        for link_el in el.findall("link"):
            lname = link_el.get("name", "")
            link = model.links.get(lname.rsplit("::", 1)[-1])
            if link is None:
                self.warn(f"{src.path}: {path}/link[@name='{lname}']: no link '{lname}' in model {model.full}; "
                          f"skipped")
                continue
            if link_el.find("pose") is not None:
                self.poses[id(link)] = self.pose(link_el.find("pose"), src, f"{path}/link/pose")[0]
        for nested_el in el.findall("model"):
            nname = nested_el.get("name", "")
            nested = model.models.get(nname)
            if nested is None:
                self.warn(f"{src.path}: {path}/model[@name='{nname}']: no model '{nname}' in {model.full}; "
                          f"skipped")
                continue
            self.model_state(nested, nested_el, src, f"{path}/model[@name='{nname}']")

    def current(self, node):
        if id(node) in self.poses:
            return self.poses[id(node)]
        if isinstance(node, _Link):
            return compose(self.world_pose(node.model, node.relative_to, node.src, f"{node.path}/pose"),
                           node.pose)
        return self.model_pose(node)

    def move(self, model, delta):
        self.poses[id(model)] = compose(delta, self.current(model))
        for link in model.links.values():
            self.poses[id(link)] = compose(delta, self.current(link))
        for nested in model.models.values():
            self.move(nested, delta)

    # -- output
    def emit(self):
        poses = self.poses

        def walk(model, static, top):
            static = static or model.static
            for link in model.links.values():
                placed = compose(self.world_pose(model, link.relative_to, link.src, f"{link.path}/pose"), link.pose)
                pose = poses.get(id(link)) or placed
                # The top-level model's frame, moved with the link by a <state> (the model moves rigidly).
                in_model = compose(inverse(self.model_pose(top)), placed)
                if not static and any(s.kind == "plane" for s in link.shapes):
                    self.warn(f"{link.src.path}: {link.path}: a plane in a non-static model is not simulated")
                mass = link.mass
                if not static and mass <= 0:
                    self.warn(f"{link.src.path}: {link.path}/inertial/mass: {mass} is not > 0 in a non-static "
                              f"model; SDF's default 1 kg used")
                    mass = 1.0
                body = Body(name=f"{model.full}::{link.name}", model=model.full, pose=_clean(pose),
                            static=static, shapes=link.shapes, mass=mass, inertia=link.inertia,
                            inertial_pose=_clean(link.inertial_pose), color=link.color,
                            model_pose=_clean(compose(pose, inverse(in_model))))
                for shape in body.shapes:
                    shape.pose = _clean(shape.pose)
                self.world.bodies.append(body)
                if static and any(s.kind == "plane" for s in link.shapes):
                    self.world.has_ground = True
            for nested in model.models.values():
                walk(nested, static, top)

        for model in self.top:
            walk(model, False, model)


def read_world(path, model_paths=None, package_model_paths=None):
    """Read the Gazebo-classic world file ``path``.

    Args:
        path: the ``.world`` (SDF) file.
        model_paths: directories searched for ``model://NAME`` before ``package_model_paths``; None means
            Gazebo's list (``~/.gazebo/models`` then ``GAZEBO_MODEL_PATH``, :func:`env_model_paths`).
        package_model_paths: directories searched after those, e.g. :func:`ros_package_model_paths`.

    Returns:
        a :class:`~diffbot_sim.world.bodies.WorldDescription`: bodies in the order of the file, link-frame world
        poses (after the first ``<state>``), shapes posed in their link frames, mesh paths absolute.

    Raises:
        ModelError: a missing or malformed file (its line named), an include that cannot be resolved (the
            URI, the including file and every directory searched named), a value that is not a number,
            a cycle of frames.
    """
    path = os.path.abspath(path)
    if not os.path.isfile(path):
        raise ModelError("no such file", path)
    reader = _Reader(env_model_paths() if model_paths is None else model_paths, package_model_paths)
    return reader.read(path)
