"""Robot meshes as Gazebo classic reads them, rewritten as Wavefront .obj files PyBullet loads faithfully.

Pure (no rospy, no PyBullet): the caller passes the package resolver and the cache directory.

Why convert at all (measured on PyBullet 3.2.7): it builds collision shapes from .obj, binary .stl and
the .dae files its own COLLADA reader follows. An ASCII .stl, or a .dae using ``<polygons>`` or
``<instance_node>``, loads *silently* as a 2 mm placeholder ("cannot extract mesh" on stdout, which the
simulator hides). It also caches meshes per file name within a client. So every ``<mesh>`` of a
``<collision>`` or ``<visual>`` is read here, the way Gazebo classic reads it, and written once as an .obj
in metres whose name changes whenever its source does.

What Gazebo classic does, and so what this module does (gazebo/common/ColladaLoader.cc and issue
gazebosim/gazebo-classic#1305):

* COLLADA ``<asset><unit meter="s"/>``: every vertex, after its node transforms, is multiplied by ``s``.
* COLLADA ``<up_axis>``: **ignored** (issue #1305, open since 2014; RViz ignores it too), so ROS meshes
  are authored for a loader that ignores it. ``honour_up_axis=True`` applies it instead (Y_UP: +90 deg
  about x; X_UP: -90 deg about y), for meshes made for tools that do honour it.
* Node transforms: ``<matrix>``, ``<translate>``, ``<rotate>``, ``<scale>`` compose parent to child,
  in document order as the COLLADA spec says (Gazebo takes a ``<matrix>`` alone, else translate, rotates,
  scale in that order: the same result for what exporters write).
* STL and OBJ have no units: their numbers are metres.
* The URDF ``scale`` multiplies the result; it is left in the URDF for PyBullet to apply (see
  ``prepare_meshes``).

Converted files are cached under a key of (absolute path, size, mtime_ns, format version, up-axis rule),
so a second start only stats the source files. Cache writes go through a temporary file and ``os.replace``
so a crash or a second simulator never leaves a half-written .obj behind.
"""
import hashlib
import math
import os
import re
import tempfile
import xml.etree.ElementTree as ET
from urllib.parse import unquote

from diffbot_sim.description.mesh_formats import dae_up_axis, read_mesh, write_obj
from diffbot_sim.errors import ModelError

#: Bump when the converter's output changes, so older cache entries are not used.
CACHE_FORMAT = 1


def default_cache_dir():
    """``${ROS_HOME:-~/.ros}/diffbot_sim/mesh_cache``: where ROS tools keep per-user state already."""
    ros_home = os.environ.get("ROS_HOME") or os.path.join(os.path.expanduser("~"), ".ros")
    return os.path.join(ros_home, "diffbot_sim", "mesh_cache")


def _cache_target(cache_dir, path, stat, honour_up_axis):
    """Cache file name: the source's name, a hash of its path (for pruning) and a hash of the full key."""
    key = f"{CACHE_FORMAT}|{path}|{stat.st_size}|{stat.st_mtime_ns}|{int(honour_up_axis)}"
    stem = re.sub(r"[^A-Za-z0-9_.-]", "_", os.path.basename(path))[:60]
    path_hash = hashlib.sha1(path.encode("utf-8", "surrogateescape")).hexdigest()[:8]
    key_hash = hashlib.sha1(key.encode("utf-8", "surrogateescape")).hexdigest()[:12]
    return os.path.join(cache_dir, f"{stem}.{path_hash}.{key_hash}.obj"), f"{stem}.{path_hash}."


def convert_cached(path, cache_dir, honour_up_axis=False, reader=None):
    """Return the cached .obj for mesh file ``path``, converting it first when the cache has none.

    A hit costs one ``stat`` of the source and one of the cache file: no parsing. Entries of older
    versions of the same source are removed when a new one is written, so the cache does not grow with
    every edit of a mesh. The name changes with the content key, which also keeps PyBullet's own
    per-filename mesh cache from serving an old shape.

    Raises:
        ModelError: the source cannot be read or converted (from the readers), or the cache cannot be
            written (``source`` is then the cache directory).
    """
    try:
        stat = os.stat(path)
    except OSError as err:
        raise ModelError(f"cannot read ({err.strerror or err})", path) from None
    target, prefix = _cache_target(cache_dir, path, stat, honour_up_axis)
    if os.path.isfile(target):
        return target
    vertices, faces = (reader or read_mesh)(path, honour_up_axis)
    try:
        os.makedirs(cache_dir, exist_ok=True)
        handle, temporary = tempfile.mkstemp(prefix=".part-", suffix=".obj", dir=cache_dir)
        os.close(handle)
        try:
            write_obj(temporary, vertices, faces, comment=f"diffbot_sim mesh cache: {path} in metres")
            os.replace(temporary, target)
        except BaseException:
            if os.path.exists(temporary):
                os.remove(temporary)
            raise
    except OSError as err:
        raise ModelError(f"cannot write the mesh cache ({err.strerror or err})", cache_dir) from None
    for name in os.listdir(cache_dir):
        if name.startswith(prefix) and name.endswith(".obj") and os.path.join(cache_dir, name) != target:
            try:
                os.remove(os.path.join(cache_dir, name))
            except OSError:
                pass  # another process pruned it first
    return target


# ------------------------------------------------------------------------------------------------ URDF

def resolve_uri(uri, model_dir, resolve_package):
    """Mesh URI -> (absolute normalised path, None) or (None, why it cannot be resolved).

    ``package://pkg/rest`` through ``resolve_package``; ``file:///abs`` (percent-escapes decoded); a plain
    path, absolute or relative to ``model_dir`` (sdformat resolves relative URDF mesh paths against the
    model file's directory; a robot_description without a file has none). ``a/b/../c`` is normalised
    lexically: published models have such paths, and ``b`` need not exist for the file to be found.
    """
    uri = uri.strip()
    if uri.startswith("package://"):
        package, _, rest = uri[len("package://"):].partition("/")
        try:
            base = resolve_package(package)
        except LookupError:
            return None, f"names package '{package}', which is not found (is it on ROS_PACKAGE_PATH?)"
        path = os.path.join(base, rest)
    elif uri.startswith("file://"):
        path = unquote(uri[len("file://"):])
        if path.startswith("localhost/"):
            path = path[len("localhost"):]
    elif re.match(r"^[A-Za-z][A-Za-z0-9+.-]*://", uri):
        return None, f"has a URI scheme '{uri.split(':', 1)[0]}://' that is not supported (package:// and file:// are)"
    else:
        path = uri
    if not os.path.isabs(path):
        if model_dir is None:
            return None, "is a relative path and the model has no directory to resolve it against"
        path = os.path.join(model_dir, path)
    return os.path.normpath(path), None


def _parse_scale(text):
    """URDF ``scale`` -> (three floats, problem or None). urdfdom wants exactly three numbers."""
    parts = (text or "").split()
    try:
        values = [float(p) for p in parts]
    except ValueError:
        return (1.0, 1.0, 1.0), f"scale='{text}' is not three numbers; using 1 1 1"
    if len(values) == 3 and all(math.isfinite(v) and v != 0.0 for v in values):
        return tuple(values), None
    if len(values) == 1 and math.isfinite(values[0]) and values[0] != 0.0:
        return (values[0],) * 3, f"scale='{text}' has one number; using it on all three axes"
    if not parts:
        return (1.0, 1.0, 1.0), "scale='' is empty; using 1 1 1"
    return (1.0, 1.0, 1.0), f"scale='{text}' is not three non-zero numbers; using 1 1 1"


def _xml_parser():
    """ElementTree parser that keeps comments and processing instructions, so the text stays the model."""
    return ET.XMLParser(target=ET.TreeBuilder(insert_comments=True, insert_pis=True))


def prepare_meshes(urdf_text, source, model_dir, cache_dir, resolve_package, honour_up_axis=False):
    """Rewrite every link's ``<collision>``/``<visual>`` mesh to a cached .obj PyBullet reads as Gazebo would.

    The URDF ``scale`` attribute stays as written (PyBullet applies it to .obj meshes exactly as Gazebo
    applies it to the loaded mesh), so one converted file serves every scale a mesh is used at and the
    URDF keeps meaning what its author wrote. Only a ``scale`` urdfdom would reject is rewritten.

    Published mistakes are survived with one warning line each, never an exception:

    * ``<geometry>`` with several shapes: the first is kept, as urdfdom does; the others are removed.
    * ``scale=""`` (or one number, or garbage): ``1 1 1`` (one number: on all axes).
    * mesh file missing, package unknown, unsupported URI or unreadable file: that ``<collision>`` or
      ``<visual>`` is removed, so the rest of the link (and the model) still loads.
    * a .dae declaring Y_UP/X_UP while ``honour_up_axis`` is off: noted, since other tools would turn it.

    Args:
        urdf_text: the URDF (after xacro).
        source: the model file (or ``robot_description``), for error messages.
        model_dir: directory relative mesh paths are resolved against; None when the model has no file.
        cache_dir: where converted .obj files live (``default_cache_dir()`` for the user's).
        resolve_package: ``pkg -> path``; raises LookupError for an unknown package. Passed in so this
            module needs no rospkg.
        honour_up_axis: see ``read_dae``.

    Returns:
        (new URDF text, list of one-line warnings).

    Raises:
        ModelError: the URDF is not well-formed XML, or the cache directory cannot be written.
    """
    if "<mesh" not in urdf_text:
        return urdf_text, []
    try:
        root = ET.fromstring(urdf_text, parser=_xml_parser())
    except ET.ParseError as err:
        raise ModelError(f"malformed XML ({err})", source) from None
    warnings = []
    converted = {}  # path -> .obj path, or the ModelError that path gave: each file read once per call
    for link in root.findall("link"):
        name = link.get("name", "?")
        for element in [child for child in link if child.tag in ("collision", "visual")]:
            kind = element.tag
            geometry = element.find("geometry")
            if geometry is None:
                continue
            shapes = [child for child in geometry if isinstance(child.tag, str)]
            for extra in shapes[1:]:
                geometry.remove(extra)
                detail = f" filename='{extra.get('filename')}'" if extra.get("filename") is not None else ""
                warnings.append(f"link '{name}': {kind} <geometry> has more than one shape; <{extra.tag}{detail}> "
                                f"is ignored (urdfdom reads only the first, <{shapes[0].tag}>)")
            if not shapes or shapes[0].tag != "mesh":
                continue
            mesh = shapes[0]
            uri = mesh.get("filename", "")
            if not uri.strip():
                warnings.append(f"link '{name}': {kind} <mesh> has no filename; the link loads without that shape")
                link.remove(element)
                continue
            if mesh.get("scale") is not None:
                scale, problem = _parse_scale(mesh.get("scale"))
                if problem:
                    warnings.append(f"link '{name}': {kind} mesh '{uri}': {problem}")
                    mesh.set("scale", " ".join(repr(v) for v in scale))
            path, problem = resolve_uri(uri, model_dir, resolve_package)
            if path is not None and not os.path.isfile(path):
                problem = f"not found (looked at {path})"
            if problem is None:
                if path not in converted:
                    try:
                        converted[path] = convert_cached(path, cache_dir, honour_up_axis)
                    except ModelError as err:
                        if err.source == cache_dir:
                            raise
                        converted[path] = err
                    if (not honour_up_axis and path.lower().endswith(".dae")
                            and dae_up_axis(path) in ("Y_UP", "X_UP")):
                        warnings.append(f"mesh '{uri}' declares up_axis {dae_up_axis(path)}; ignored, as Gazebo "
                                        f"classic and RViz do (honour_up_axis turns it)")
                result = converted[path]
                if isinstance(result, ModelError):
                    problem = f"is unreadable ({result})"
                else:
                    mesh.set("filename", result)
                    continue
            warnings.append(f"link '{name}': {kind} mesh '{uri}' {problem}; the link loads without that shape")
            link.remove(element)
    text = ET.tostring(root, encoding="unicode")
    if urdf_text.lstrip().startswith("<?xml"):
        text = '<?xml version="1.0"?>\n' + text
    return text, warnings
