"""One SDF element's values, read as Gazebo classic (libsdformat) reads them (pure): numbers, poses, a
visual's colour, a collision's shape and surface. Nothing here needs the names and frames of the rest of the
world; :mod:`diffbot_sim.world.sdf_reader` resolves those.

Numbers: a tag's leading number, the rest dropped with one warning (sdformat's ``std::stod``), non-finite
values refused with the file and element named. Poses (:func:`read_pose`, the one reader of an SDF ``<pose>``:
worlds, actors, spawned models): SDF 1.9 ``degrees`` and ``rotation_format="quat_xyzw"``, ``relative_to``
(1.5/1.6's ``frame`` is the same attribute before its rename) returned for the caller to resolve, an empty
``<pose/>`` the identity. Collisions: box, cylinder, sphere, plane (infinite), mesh; surface
``mu``/``mu2`` (ODE, else Bullet), contact ``kp``/``kd`` and ``laser_retro``. Of visuals only the colour:
``<diffuse>``, else ``<ambient>``, else a ``<script><name>`` of :data:`GAZEBO_COLORS`.
"""
import math
import os

from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.transforms import qnormalize, rpy_quaternion
from diffbot_sim.values import tag_number
from diffbot_sim.world.bodies import IDENTITY, Shape

#: Mesh formats the physics layer can read (:mod:`diffbot_sim.description.meshes`).
MESH_EXTENSIONS = (".dae", ".stl", ".obj")

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


def _finite_numbers(text, count, what, source, element):
    """Exactly ``count`` finite numbers in ``text`` (a tuple), else ModelError naming ``what``."""
    parts = (text or "").split()
    try:
        values = tuple(float(v) for v in parts)
    except ValueError:
        values = ()
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise ModelError(f"{what} '{(text or '').strip()}' is not {count} finite number"
                         f"{'s' if count > 1 else ''}", source, element)
    return values


def pose_numbers(text, attributes, source=None, element=None):
    """The numbers of an SDF ``<pose>`` whose text is ``text`` and attributes ``attributes`` (a dict), read
    strictly (every pose of this project is read here): None for an empty element (SDF's default, the
    identity); else (x, y, z, roll, pitch, yaw) [m, rad] (SDF 1.9 ``degrees="true"``: the angles converted), or
    with ``rotation_format="quat_xyzw"`` (x, y, z, qx, qy, qz, qw) as written.

    Raises:
        ModelError: not 6 (or 7) finite numbers, an unknown ``rotation_format``, a zero quaternion; naming
            ``source`` and ``element``.
    """
    text = (text or "").strip()
    if not text:
        return None
    fmt = (attributes.get("rotation_format") or "euler_rpy").strip()
    if fmt == "quat_xyzw":
        values = _finite_numbers(text, 7, "<pose> (quat_xyzw)", source, element)
        if sum(c * c for c in values[3:]) < 1e-12:
            raise ModelError("<pose> quaternion is zero", source, element)
        return values
    if fmt != "euler_rpy":
        raise ModelError(f"<pose rotation_format='{fmt}'> is not euler_rpy or quat_xyzw", source, element)
    values = _finite_numbers(text, 6, "<pose>", source, element)
    if sdf_bool(attributes.get("degrees")):
        values = values[:3] + tuple(math.radians(a) for a in values[3:])
    return values


def read_pose(text, attributes, source=None, element=None):
    """An SDF ``<pose>`` (text and attributes, as :func:`pose_numbers` reads them) -> (pose ((x, y, z),
    (qx, qy, qz, qw)), relative_to): an empty element is the identity, as in SDF; ``relative_to`` (1.5/1.6's
    ``frame`` is the same attribute before its rename) is returned for the caller to resolve ("" if none).

    Raises:
        ModelError: as :func:`pose_numbers`.
    """
    relative_to = (attributes.get("relative_to") or attributes.get("frame") or "").strip()
    values = pose_numbers(text, attributes, source, element)
    if values is None:
        return IDENTITY, relative_to
    if len(values) == 7:
        return ((values[0], values[1], values[2]), qnormalize(values[3:])), relative_to
    return ((values[0], values[1], values[2]), rpy_quaternion(*values[3:])), relative_to


def text_of(el, tag, default=None):
    """The stripped text of ``el``'s child ``tag`` (a path such as ``script/name`` works), or ``default``
    when it is missing or blank."""
    child = el.find(tag)
    if child is None or child.text is None or not child.text.strip():
        return default
    return child.text.strip()


def sdf_bool(text):
    """SDF booleans: ``true``/``1`` (any case) are true; libsdformat reads ``True`` as true too."""
    return (text or "").strip().lower() in ("true", "1")


class ElementReader:
    """Reads elements of the SDF files of one world: ``files`` (a :class:`~diffbot_sim.world.sdf_files.SdfFiles`)
    finds meshes, ``warn(text)`` takes a warning for the world's report. ``src`` arguments are the
    :class:`~diffbot_sim.world.sdf_files.SdfFile` being read, ``path`` the element's path, for messages."""

    def __init__(self, files, warn):
        self.files = files
        self.warn = warn

    def floats(self, text, count, src, path, what):
        """Exactly ``count`` finite numbers in ``text`` (a tuple), else ModelError naming ``what``."""
        return _finite_numbers(text, count, what, src.path, path)

    def number(self, el, tag, default, src, path, positive=False):
        """The number in ``<tag>``, read as sdformat reads it (its leading number, the rest dropped with one
        warning)."""
        text = text_of(el, tag)
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
        """``<pose>`` element -> (pose, relative_to) (:func:`read_pose`)."""
        return read_pose(el.text, el.attrib, src.path, path)

    def child_pose(self, el, src, path):
        """(pose, relative_to) of ``el``'s ``<pose>`` child; the identity without one."""
        pose_el = el.find("pose")
        if pose_el is None:
            return IDENTITY, ""
        return self.pose(pose_el, src, f"{path}/pose")

    # -- geometry
    def material(self, el, src, path):
        """rgba of a ``<visual>``'s ``<material>``: ``<diffuse>``, else ``<ambient>``, else a known script name."""
        material = el.find("material")
        if material is None:
            return None
        for tag in ("diffuse", "ambient"):
            text = text_of(material, tag)
            if text is not None:
                parts = text.split()
                values = self.floats(text, len(parts) if len(parts) in (3, 4) else 4, src,
                                     f"{path}/material/{tag}", f"<{tag}>")
                return tuple(min(max(v, 0.0), 1.0) for v in values) + ((1.0,) if len(values) == 3 else ())
        name = text_of(material, "script/name")
        if name is not None:
            if name in GAZEBO_COLORS:
                return GAZEBO_COLORS[name]
            self.warn(f"{src.path}: {path}/material/script: '{name}' is not a colour this simulator knows; "
                      f"the camera sees it grey")
        return None

    def collision(self, el, src, path):
        """A ``<collision>`` as a :class:`~diffbot_sim.world.bodies.Shape` posed in its link's frame, or None
        (warned) for geometry that cannot collide here: none, unsupported, or a mesh that is not found."""
        geometry = el.find("geometry")
        kinds = list(geometry) if geometry is not None else []
        if not kinds:
            self.warn(f"{src.path}: {path}: no geometry; collision skipped")
            return None
        geom = kinds[0]
        gpath = f"{path}/geometry/{geom.tag}"
        shape = Shape(kind=geom.tag, name=el.get("name", ""))
        if geom.tag == "box":
            size = text_of(geom, "size", "1 1 1")
            shape.size = self.floats(size, 3, src, f"{gpath}/size", "<size>")
        elif geom.tag == "cylinder":
            shape.size = (self.number(geom, "radius", 1.0, src, gpath, True),
                          self.number(geom, "length", 1.0, src, gpath, True))
        elif geom.tag == "sphere":
            shape.size = (self.number(geom, "radius", 1.0, src, gpath, True),)
        elif geom.tag == "plane":
            normal = self.floats(text_of(geom, "normal", "0 0 1"), 3, src, f"{gpath}/normal", "<normal>")
            length = math.sqrt(sum(c * c for c in normal))
            if length == 0:
                raise ModelError("<normal> is the zero vector", src.path, f"{gpath}/normal")
            shape.size = tuple(c / length for c in normal)  # <size> is for the visual: the collision is infinite
        elif geom.tag == "mesh":
            uri = text_of(geom, "uri")
            if uri is None:
                raise ModelError("<mesh> has no <uri>", src.path, gpath)
            if geom.find("submesh") is not None:
                self.warn(f"{src.path}: {gpath}/submesh: submesh is not supported; the whole mesh collides")
            shape.scale = self.floats(text_of(geom, "scale", "1 1 1"), 3, src, f"{gpath}/scale", "<scale>")
            if os.path.splitext(uri)[1].lower() not in MESH_EXTENSIONS:
                self.warn(f"{src.path}: {gpath}: mesh '{uri}' is not .dae, .stl or .obj; collision skipped")
                return None
            shape.mesh = self.files.mesh_path(uri, src, gpath)
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
        """A collision's surface numbers: {mu, mu2, kp, kd, laser_retro} as far as the file gives them."""
        found = {}
        spath = f"{path}/surface"
        for key, where in (("mu", "surface/friction/ode/mu"), ("mu2", "surface/friction/ode/mu2"),
                           ("kp", "surface/contact/ode/kp"), ("kd", "surface/contact/ode/kd"),
                           ("laser_retro", "laser_retro")):
            text = text_of(el, where)
            if text is not None:
                found[key] = self.floats(text, 1, src, f"{path}/{where}", f"<{where.rsplit('/', 1)[-1]}>")[0]
        # Bullet's friction only where ODE's is not given: Gazebo's default engine reads the ODE values.
        for key, where in (("mu", "surface/friction/bullet/friction"), ("mu2", "surface/friction/bullet/friction2")):
            text = text_of(el, where)
            if text is not None and key not in found:
                found[key] = self.floats(text, 1, src, f"{spath}/{where[8:]}", "<friction>")[0]
        return found
