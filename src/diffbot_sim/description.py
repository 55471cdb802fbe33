"""Turn a model file (URDF or xacro) into URDF text, and resolve mesh URIs for PyBullet.

xacro 1.13.3 (the ROS 1 one) runs in-process through its API, so ``$(find pkg)`` works through rospkg and
``$(arg name)`` through the mappings we pass; nothing is shelled out. xacro and rospkg are imported
lazily so the rest of the package stays importable without them.
"""
import os
import xml.etree.ElementTree as ET

from diffbot_sim import xacro_compat
from diffbot_sim.errors import ModelError


def parse_args(text):
    """``"a:=1 b:=x"`` -> {"a": "1", "b": "x"} (xacro's command-line mapping syntax)."""
    mappings = {}
    for token in text.split():
        name, sep, value = token.partition(":=")
        if not sep or not name:
            raise ModelError(f"xacro argument '{token}' is not name:=value", "~model_args")
        mappings[name] = value
    return mappings


def load_file(path, args=None):
    """Read ``path``; run xacro on it when it is a .xacro file. Returns URDF text.

    xacro is 1.13.3 patched by ``xacro_compat`` (noetic's ``xacro.``/``python.``/``math.`` symbols, safe
    ``load_yaml``, noetic's macro defaults, ``$(dirname)``), so noetic descriptions load as they do in ROS.

    Raises:
        ModelError: the file is missing or unreadable, xacro fails, or the installed xacro is not the
            1.13.x the compatibility layer patches (the message names the file).
    """
    if not os.path.isfile(path):
        raise ModelError("no such file", path)
    if not path.endswith(".xacro"):
        try:
            with open(path, encoding="utf-8") as handle:
                return handle.read()
        except (OSError, UnicodeDecodeError) as err:
            raise ModelError(f"cannot read ({err})", path) from None
    xacro = xacro_compat.apply()  # lazy import of xacro: only xacro files need it; idempotent

    try:
        doc = xacro.process_file(path, mappings=dict(args or {}))
        return doc.toprettyxml(indent="  ")
    except Exception as err:  # noqa: BLE001 - xacro raises XacroException, ExpatError, IOError, NameError...
        detail = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise ModelError(f"xacro failed: {detail}", path) from None
    finally:
        # xacro 1.13 keeps processing state in module globals; leave them clean for the next call.
        for name in ("filestack", "macrostack"):
            if hasattr(xacro, name):
                setattr(xacro, name, None if name == "filestack" else [])
        if hasattr(xacro, "all_includes"):
            xacro.all_includes = []


def package_path(package):
    """rospkg's path of ROS package ``package``, for ``package://`` URIs.

    Raises:
        LookupError: no such package on ROS_PACKAGE_PATH.
    """
    import rospkg  # lazy

    try:
        return rospkg.RosPack().get_path(package)
    except rospkg.ResourceNotFound as err:
        raise LookupError(package) from err


def resolve_uri(uri, source):
    """``package://pkg/path`` (via rospkg) or ``file://path`` -> an absolute file path PyBullet can open."""
    if uri.startswith("package://"):
        package, _, rest = uri[len("package://"):].partition("/")
        import rospkg  # lazy

        try:
            return os.path.join(rospkg.RosPack().get_path(package), rest)
        except rospkg.ResourceNotFound:
            raise ModelError(f"mesh '{uri}': package '{package}' not found (is it on ROS_PACKAGE_PATH?)",
                             source) from None
    if uri.startswith("file://"):
        return uri[len("file://"):]
    return uri


def resolve_meshes(text, source):
    """Rewrite every ``<mesh filename=...>`` with a package:// or file:// URI to a plain path."""
    if "package://" not in text and "file://" not in text:
        return text
    root = ET.fromstring(text)
    for mesh in root.iter("mesh"):
        uri = mesh.get("filename", "")
        if uri.startswith(("package://", "file://")):
            mesh.set("filename", resolve_uri(uri, source))
    return ET.tostring(root, encoding="unicode")


def resolve_world_path(name, package_root=None):
    """The world file ``name`` names: a path as given (absolute, or relative to the working directory),
    else, as gzserver does, relative to each GAZEBO_RESOURCE_PATH directory, then to this package (which
    ships ``worlds/empty.world``, empty_world.launch's default; ``package_root`` defaults to rospkg's path of
    diffbot_sim).

    Raises:
        ModelError: naming the world and every directory searched.
    """
    path = os.path.abspath(os.path.expanduser(name))
    if os.path.isfile(path) or os.path.isabs(os.path.expanduser(name)):
        return path
    package_root = package_root or package_path("diffbot_sim")
    dirs = [d for d in os.environ.get("GAZEBO_RESOURCE_PATH", "").split(":") if d] + [package_root]
    for directory in dirs:
        candidate = os.path.join(directory, name)
        if os.path.isfile(candidate):
            return candidate
    raise ModelError(f"no such world file (searched the working directory, GAZEBO_RESOURCE_PATH and "
                     f"{package_root})", name)


def load_world(name, map_wall_height):
    """The world ``name`` names (:func:`resolve_world_path`): an SDF ``.world``, or a map_server ``.yaml``
    whose occupied cells become walls ``map_wall_height`` m high; a WorldDescription. The simulator and
    ``world_markers`` read the same file through this one function.

    Raises:
        ModelError: a missing or malformed file, named.
    """
    path = resolve_world_path(name)
    if path.endswith((".yaml", ".yml")):
        from diffbot_sim.world_map import read_map
        return read_map(path, map_wall_height)
    from diffbot_sim.world_sdf import read_world, ros_package_model_paths
    return read_world(path, package_model_paths=ros_package_model_paths())
