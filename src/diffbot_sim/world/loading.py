"""Which world file a world name means, and reading it (pure): an SDF ``.world`` through
:mod:`diffbot_sim.world.sdf_reader`, a map_server ``.yaml`` through :mod:`diffbot_sim.world.map_image`. The
simulator, ``world_markers`` and ``view_rviz`` read a world through this one module; the last two find it,
and the simulator's robots, from the running simulator's parameters (:func:`simulator_world`,
:func:`robot_namespaces`)."""
import os

from diffbot_sim.description.model_files import package_path
from diffbot_sim.errors import ModelError
from diffbot_sim.world.map_image import read_map
from diffbot_sim.world.model_paths import ros_package_model_paths
from diffbot_sim.world.sdf_reader import read_world


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
        return read_map(path, map_wall_height)
    return read_world(path, package_model_paths=ros_package_model_paths())


# -- the world of a running simulator, from its parameters (read by the caller: no rospy here) -----------

def simulator_world(sim, get_param):
    """The world a running ``bullet_sim`` at node name ``sim`` simulates, read as it reads it
    (:func:`load_world` of its ``world`` or ``world_name`` parameter, walls ``map_wall_height`` m high);
    None when it has no world. ``get_param(name, default)`` reads the parameter server
    (``rospy.get_param``), so ``world_markers`` and ``view_rviz`` draw exactly the simulated world.

    Raises:
        ModelError: a missing or malformed file, named.
    """
    name = get_param(sim + "/world", "") or get_param(sim + "/world_name", "")
    if not name:
        return None
    return load_world(name, float(get_param(sim + "/map_wall_height", 1.0)))


def robot_namespaces(robots):
    """The private sub-namespaces of a simulator's robots, from its ``robots`` parameter: ``[""]`` for the
    one robot of ``x, y, yaw`` (no ``~robots``), else each entry's ``name`` (entries are names or dicts)."""
    if robots is None:
        return [""]
    return [entry["name"] if isinstance(entry, dict) else str(entry) for entry in robots]
