"""A robot's model made ready to load, once for every front end: bullet_sim (``simulator/robots.py``), the
Gymnasium scene (``gym/scene.py``) and robot_check (``check/robot_report.py``) all read a model this way, so a
model means the same thing in each (pure: no PyBullet; placing it in a world is
:mod:`diffbot_sim.physics.robot_loading`).

The steps, in order: the model file through xacro (:mod:`.model_files`), the URDF parsed (:mod:`.urdf_model`),
its meshes converted and their URIs rewritten to the cache (:mod:`.meshes`), its ``<gazebo>`` plugins and
sensors read (:mod:`.plugin_tags`), and every transmission's joint looked up (a transmission naming a joint the
model lacks is an error naming the transmission, as gazebo_ros_control's loader refuses it).
"""
import os
from typing import NamedTuple

from diffbot_sim.description import meshes, xml_documents
from diffbot_sim.description.model_files import load_file, package_path, parse_args
from diffbot_sim.description.plugin_tags import NATIVE, Plugins, read_plugins
from diffbot_sim.description.urdf_model import RobotModel, parse_urdf


class PreparedModel(NamedTuple):
    """A model ready for ``physics.World.load_robot``.

    Attributes:
        source: the model file's path, or the parameter the URDF came from (error messages name it).
        text: the URDF, its mesh URIs rewritten to the converted-mesh cache (what PyBullet loads).
        model: the parsed RobotModel (of the text as written: mesh rewrites do not change it).
        plugins: its ``<gazebo>`` plugins and sensors (``plugin_tags.Plugins``).
        notes: one-line warnings of the mesh preparation (a missing mesh, a bad scale, ...).
    """

    source: str
    text: str
    model: RobotModel
    plugins: Plugins
    notes: list[str]


def read_model_file(path, model_args=""):
    """The URDF text of the model file ``path`` (``~`` expanded; a .xacro run with ``model_args``,
    ``"a:=1 b:=2"``) and its absolute path.

    Raises:
        ModelError: the file is missing or unreadable, or xacro fails (naming the file).
    """
    source = os.path.abspath(os.path.expanduser(path))
    return load_file(source, parse_args(model_args)), source


def prepare_model(text, source, known=NATIVE, known_sensors=(), cache_dir=None, resolve_package=package_path):
    """``text`` (URDF, after xacro) from ``source`` made ready to load.

    Args:
        known, known_sensors: the model and sensor plugin filenames the caller simulates (bullet_sim passes
            ``plugins.registry``'s; this layer does not import the plugins), as ``plugin_tags.read_plugins``.
        cache_dir: converted-mesh cache; None: the user's (``meshes.default_cache_dir()``).
        resolve_package: ``pkg -> path`` for ``package://`` meshes (LookupError when unknown).

    Relative mesh paths are resolved against the model file's directory (the working directory when the
    URDF came from a parameter).

    Raises:
        ModelError: the URDF is not a robot, a mesh cache that cannot be written, a transmission naming a
            joint the model lacks.
    """
    text = xml_documents.document_start(text)  # a robot_description with a blank line before <?xml
    model = parse_urdf(text, source)
    model_dir = os.path.dirname(source) if os.path.isfile(source) else os.getcwd()
    text, notes = meshes.prepare_meshes(text, source, model_dir, cache_dir or meshes.default_cache_dir(),
                                        resolve_package)
    found = read_plugins(model, known=known, known_sensors=known_sensors)
    for trans in model.transmissions:
        model.joint(trans.joint, f"/robot/transmission[@name='{trans.name}']")
    return PreparedModel(source, text, model, found, notes)
