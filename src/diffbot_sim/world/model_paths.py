"""Where Gazebo looks for ``model://`` URIs (pure): GAZEBO_MODEL_PATH, then the directories ROS packages export
to gazebo_ros (``<export><gazebo_ros gazebo_model_path="..."/>``), as gazebo_ros's setup does."""
import glob
import os
import xml.etree.ElementTree as ET


def env_model_paths():
    """Gazebo's own model search list: ``~/.gazebo/models``, then each ``GAZEBO_MODEL_PATH`` entry in order.

    When ``GAZEBO_MODEL_PATH`` is unset or empty Gazebo uses its compile-time default, the install's
    ``share/gazebo-<ver>/models``; we add any such directory that exists (none without Gazebo installed).
    """
    paths = [os.path.join(os.path.expanduser("~"), ".gazebo", "models")]
    entries = [p for p in os.environ.get("GAZEBO_MODEL_PATH", "").split(":") if p]
    if entries:
        paths += entries
    else:
        paths += sorted(glob.glob("/usr/share/gazebo-*/models"))
    return paths


#: ROS_PACKAGE_PATH -> its packages' model directories: read once per process, as gazebo_ros reads them once at
#: start-up (a walk of every package's manifest costs ~30 ms: every spawn_sdf_model paid it).
_PACKAGE_MODEL_PATHS: dict[str, list[str]] = {}


def ros_package_model_paths(rospack=None):
    """Model directories ROS packages export as ``<export><gazebo_ros gazebo_model_path="..."/></export>``.

    gazebo_ros's paths plugin asks ``rospack plugins --attrib=gazebo_model_path gazebo_ros``, which only
    looks at packages that depend directly on gazebo_ros. Those come first, in rospack's order. Then, our
    choice: every other package that exports the attribute without depending on gazebo_ros (this package
    does: it replaces Gazebo and so does not depend on it), so its example models resolve without Gazebo
    installed. An export is an explicit request, so honouring it cannot pick up anything unintended. This
    works the same whether gazebo_ros is installed or not: dependents are found from their manifests.

    ``${prefix}`` is the package directory (rospkg's ``Manifest.get_export``). When that directory does
    not hold the exported path but the manifest is a symbolic link (a catkin workspace whose package
    entries link to a source tree, as this repository's), the path is also tried next to the real manifest.

    Args:
        rospack: a ``rospkg.RosPack``; None: the packages of ``ROS_PACKAGE_PATH``, read once per process.

    Returns:
        directories, first to search first, without duplicates.
    """
    import rospkg  # lazy: the reader itself stays pure

    if rospack is None:
        key = os.environ.get("ROS_PACKAGE_PATH", "")
        if key not in _PACKAGE_MODEL_PATHS:
            _PACKAGE_MODEL_PATHS[key] = _exported_model_paths(rospkg.RosPack())
        return list(_PACKAGE_MODEL_PATHS[key])
    return _exported_model_paths(rospack)


def _exported_model_paths(rospack):
    """ros_package_model_paths' walk over ``rospack``'s packages (uncached)."""
    import rospkg

    direct, others = [], []
    for name in rospack.list():
        try:
            manifest = rospack.get_manifest(name)
            values = manifest.get_export("gazebo_ros", "gazebo_model_path")
        except (rospkg.ResourceNotFound, rospkg.InvalidManifest, ValueError):
            continue  # a broken package must not stop the world from loading (rospack skips it too)
        if not values:
            continue
        prefix = os.path.dirname(manifest.filename)  # rospkg names manifest.xml even for a package.xml
        real = os.path.dirname(os.path.realpath(os.path.join(prefix, "package.xml")))
        resolved = []
        for value in values:
            for part in value.split(":"):
                if part and not os.path.isdir(part) and part.startswith(prefix) and real != prefix:
                    alternative = real + part[len(prefix):]
                    if os.path.isdir(alternative):
                        part = alternative
                if part:
                    resolved.append(part)
        depends = any(d.name == "gazebo_ros" for d in manifest.depends) or _names_gazebo_ros(prefix)
        (direct if depends else others).extend(resolved)
    out = []
    for path in direct + others:
        if path not in out:
            out.append(path)
    return out


def _names_gazebo_ros(directory):
    """Whether the package in ``directory`` declares a dependency on gazebo_ros in its manifest.

    rospkg keeps only dependencies that rosdep or the package path knows, so without gazebo_ros installed
    ``Manifest.depends`` never lists it; the manifest itself still says it.
    """
    for name in ("package.xml", "manifest.xml"):
        try:
            root = ET.parse(os.path.join(directory, name)).getroot()
        except (OSError, ET.ParseError):
            continue
        for el in root:
            if el.tag.endswith("depend") and ((el.text or "").strip() == "gazebo_ros"
                                              or el.get("package") == "gazebo_ros"):
                return True
    return False
