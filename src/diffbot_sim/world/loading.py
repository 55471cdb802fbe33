"""Which world file a world name means, and reading it (pure): an SDF ``.world`` through
:mod:`diffbot_sim.world.sdf_reader`, a map_server ``.yaml`` through :mod:`diffbot_sim.world.map_image`. The
simulator and ``world_markers`` read a world through this one module."""
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
