"""gazebo_ros's ``spawn_model`` command line (ROS 1 noetic semantics; pure, no rospy): what
:mod:`diffbot_sim.nodes.spawn_model` (``overlay/gazebo_ros``'s stand-in) is asked to spawn, and the model XML
it sends.

The facts followed (read from noetic's script, nothing copied): argparse with single-dash long flags (so
argparse's prefix abbreviations apply as they do upstream); ``-urdf``/``-sdf`` and
``-file``/``-param``/``-database``/``-stdin`` are two required, mutually exclusive groups, ``-model`` is
required; the pose is ``-x -y -z`` plus ``-R -P -Y`` turned into a quaternion as
``tf.transformations.quaternion_from_euler`` (static axes, 'sxyz'); ``-J`` is repeatable; ``-database NAME``
spawns an SDF 1.4 world that includes ``model://NAME``; ``-package_to_model`` rewrites
``<mesh filename="package://...">`` to ``model://``; the XML must parse before anything is sent. Remapping
arguments, one-line errors and help: :mod:`diffbot_sim.gazebo.cli`.
"""
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from urllib.parse import urlsplit, urlunsplit

from diffbot_sim.gazebo.cli import CliError, Parser, finite, strip_remappings
from diffbot_sim.transforms import rpy_quaternion

#: What ``-database NAME`` spawns: gazebo_ros's template, an SDF 1.4 world including the model by URI.
MODEL_DATABASE_TEMPLATE = """\
<sdf version="1.4">
    <world name="default">
        <include>
            <uri>model://{}</uri>
        </include>
    </world>
</sdf>"""


@dataclass
class SpawnArgs:
    """A parsed ``spawn_model`` command line.

    ``fmt`` is ``urdf`` or ``sdf``; ``source`` one of ``file``, ``param``, ``database``, ``stdin`` with
    ``source_value`` its argument (None for stdin). Angles are radians, positions metres.
    """

    fmt: str
    source: str
    source_value: str | None
    model: str
    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0
    joints: list[tuple[str, float]] = field(default_factory=list)
    robot_namespace: str = "/"
    unpause: bool = False
    wait: str | None = None
    reference_frame: str = ""
    gazebo_namespace: str = "/gazebo"
    package_to_model: bool = False
    bond: bool = False

    def service(self, name):
        """The world API service ``name`` under ``-gazebo_namespace`` (``/gazebo/spawn_urdf_model``).

        Upstream joins ``gazebo_namespace + '/' + name``; a trailing slash (``-gazebo_namespace /gazebo/``,
        as its help text spells the default) is dropped so the name has no ``//``.
        """
        return f"{self.gazebo_namespace.rstrip('/')}/{name}"

    @property
    def spawn_service(self):
        return self.service(f"spawn_{self.fmt}_model")

    @property
    def source_label(self):
        """How error messages name where the XML came from: ``-file robot.urdf``, ``-param robot_description``."""
        return f"-{self.source}" if self.source_value is None else f"-{self.source} {self.source_value}"

    @property
    def position(self):
        return (self.x, self.y, self.z)

    @property
    def orientation(self):
        """(x, y, z, w) from ``-R -P -Y``, as ``tf.transformations.quaternion_from_euler(R, P, Y)`` gives it
        (tf is not a Debian Python package; :func:`diffbot_sim.transforms.rpy_quaternion` is the same)."""
        return rpy_quaternion(self.roll, self.pitch, self.yaw)


def _spawn_parser():
    parser = Parser(prog="spawn_model", description="Spawn a model in the simulator using the gazebo_ros API")
    fmt = parser.add_mutually_exclusive_group(required=True)
    fmt.add_argument("-urdf", action="store_true", help="incoming XML is in URDF format")
    fmt.add_argument("-sdf", action="store_true", help="incoming XML is in SDF format")
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("-file", metavar="FILE_NAME", help="load model XML from file")
    source.add_argument("-param", metavar="PARAM_NAME", help="load model XML from ROS parameter")
    source.add_argument("-database", metavar="MODEL_NAME",
                        help="load model XML from the model MODEL_NAME (model://MODEL_NAME, GAZEBO_MODEL_PATH)")
    source.add_argument("-stdin", action="store_true", help="load model XML from stdin")
    parser.add_argument("-model", required=True, metavar="MODEL_NAME", help="name of model to spawn")
    parser.add_argument("-reference_frame", default="",
                        help="model/body the initial pose is relative to; empty or 'world': the world frame")
    parser.add_argument("-gazebo_namespace", default="/gazebo",
                        help="ROS namespace of the simulator's gazebo_ros interfaces (default /gazebo)")
    parser.add_argument("-robot_namespace", default=None,
                        help="ROS namespace of the model's plugins (default: this node's namespace)")
    parser.add_argument("-unpause", action="store_true", help="unpause physics after spawning the model")
    parser.add_argument("-wait", metavar="MODEL_NAME", help="wait for MODEL_NAME to exist before spawning")
    for flag, help_text in (("-x", "x of initial position, meters"), ("-y", "y of initial position, meters"),
                            ("-z", "z of initial position, meters"), ("-R", "roll of initial orientation, radians"),
                            ("-P", "pitch of initial orientation, radians"),
                            ("-Y", "yaw of initial orientation, radians")):
        parser.add_argument(flag, default="0", help=help_text)
    parser.add_argument("-J", dest="joints", default=[], action="append", nargs=2,
                        metavar=("JOINT_NAME", "JOINT_POSITION"),
                        help="initialize the specified joint at the specified position (repeatable)")
    parser.add_argument("-package_to_model", action="store_true",
                        help='convert URDF <mesh filename="package://..."> to "model://..."')
    parser.add_argument("-b", dest="bond", action="store_true",
                        help="bond to the simulator: delete the model when this program is interrupted")
    return parser


def parse_spawn_args(argv, default_robot_namespace="/"):
    """Parse ``spawn_model``'s arguments (``argv`` without the program name; remappings are dropped here).

    Args:
        default_robot_namespace: ``-robot_namespace``'s default; upstream's is ``rospy.get_namespace()``,
            the node's namespace, which the node passes in.

    Raises:
        CliError: one line naming the flag (missing group, conflicting flags, a pose that is not a finite
            number, an empty ``-model``).
        UsageExit: ``-h``.
    """
    ns = _spawn_parser().parse_args(strip_remappings(argv))
    source = next(name for name in ("file", "param", "database", "stdin") if getattr(ns, name))
    if not ns.model:
        raise CliError("-model: the model needs a name (see spawn_model -h)")
    units = {"x": "a position in meters", "y": "a position in meters", "z": "a position in meters",
             "R": "an angle in radians", "P": "an angle in radians", "Y": "an angle in radians"}
    pose = {key: finite(f"-{key}", getattr(ns, key), what) for key, what in units.items()}
    joints = [(name, finite(f"-J {name}", position, "a joint position")) for name, position in ns.joints]
    return SpawnArgs(
        fmt="urdf" if ns.urdf else "sdf", source=source,
        source_value=None if source == "stdin" else getattr(ns, source), model=ns.model,
        x=pose["x"], y=pose["y"], z=pose["z"], roll=pose["R"], pitch=pose["P"], yaw=pose["Y"], joints=joints,
        robot_namespace=default_robot_namespace if ns.robot_namespace is None else ns.robot_namespace,
        unpause=ns.unpause, wait=ns.wait, reference_frame=ns.reference_frame,
        gazebo_namespace=ns.gazebo_namespace, package_to_model=ns.package_to_model, bond=ns.bond)


def database_xml(model_name):
    """The SDF ``-database NAME`` spawns: a world including ``model://NAME`` (gazebo_ros's template)."""
    return MODEL_DATABASE_TEMPLATE.format(model_name)


def read_model_file(path):
    """The text of ``-file path``; CliError naming the file when it is missing, not a file, unreadable or empty."""
    label = f"-file {path}"
    if not os.path.exists(path):
        raise CliError(f"{label}: no such file")
    if not os.path.isfile(path):
        raise CliError(f"{label}: not a file")
    try:
        with open(path, encoding="utf-8") as stream:
            text = stream.read()
    except (OSError, UnicodeDecodeError) as err:
        raise CliError(f"{label}: cannot be read: {err}") from None
    if not text.strip():
        raise CliError(f"{label}: the file is empty")
    return text


def check_model_text(text, source_label):
    """``text`` when it is non-empty text, else CliError naming the source (a parameter that is no string)."""
    if not isinstance(text, str):
        raise CliError(f"{source_label}: holds a {type(text).__name__}, not model XML text")
    if not text.strip():
        raise CliError(f"{source_label}: is empty")
    return text


def package_to_model(root):
    """Rewrite every ``<mesh filename="package://P/...">`` under ``root`` to ``model://P/...`` in place.

    As spawn_model's ``-package_to_model``: only ``mesh`` elements with a ``filename`` attribute (URDF's
    spelling; SDF's ``<uri>`` is left alone), only the ``package`` scheme, the rest of the URI unchanged.
    Returns how many were rewritten.
    """
    count = 0
    for mesh in root.iterfind(".//mesh"):
        filename = mesh.get("filename")
        if filename is None:
            continue
        url = urlsplit(filename)
        if url.scheme == "package":
            mesh.set("filename", urlunsplit(("model",) + tuple(url[1:])))
            count += 1
    return count


def prepare_model_xml(text, source_label, rewrite_package_uris=False):
    """The XML to send: ``text`` checked to parse, and with ``-package_to_model`` its mesh URIs rewritten.

    Upstream refuses XML that does not parse before calling the simulator; so do we, naming the source
    (``-param robot_description: invalid XML: mismatched tag: line 12, column 4``). Upstream re-serialises
    the parsed tree every time; here only a rewritten tree is (ElementTree drops comments and the XML
    declaration, so untouched XML goes through byte for byte; the parsed content is the same either way).
    """
    check_model_text(text, source_label)
    try:
        root = ET.fromstring(text)
    except ET.ParseError as err:
        raise CliError(f"{source_label}: invalid XML: {err}") from None
    if rewrite_package_uris and package_to_model(root):
        return ET.tostring(root, encoding="unicode")
    return text
