"""Command lines of the Gazebo-era tools users' launch files run: gazebo_ros's ``spawn_model`` and
controller_manager's ``spawner``, ``unspawner`` and ``controller_manager`` (ROS 1 noetic semantics).

Why a module of its own: those tools are not Debian packages, so ``overlay/gazebo_ros`` and
``overlay/controller_manager`` ship stand-ins whose nodes (:mod:`diffbot_sim.nodes.spawn_model`,
:mod:`diffbot_sim.nodes.controller_spawner`) talk to the simulator. A launch file written for Gazebo passes
them the same arguments, so what those arguments mean must match noetic's scripts flag for flag; that is
pure logic, kept here without rospy so that it is unit-tested without a ROS master.

The facts followed (read from noetic's scripts, nothing copied):

* ``spawn_model`` parses with argparse (single-dash long flags, so argparse's prefix abbreviations apply as
  they do upstream); ``-urdf``/``-sdf`` and ``-file``/``-param``/``-database``/``-stdin`` are two required,
  mutually exclusive groups, ``-model`` is required; the pose is ``-x -y -z`` plus ``-R -P -Y`` turned into a
  quaternion as ``tf.transformations.quaternion_from_euler`` (static axes, 'sxyz'); ``-J`` is repeatable;
  ``-database NAME`` spawns an SDF 1.4 world that includes ``model://NAME``; ``-package_to_model`` rewrites
  ``<mesh filename="package://...">`` to ``model://``; the XML must parse before anything is sent.
* ``spawner``: controller names (or YAML files, whose top-level keys are the controllers and whose content
  goes onto the parameter server first), ``--stopped``, ``--wait-for``, ``--namespace``, ``--timeout``
  (default 30 s, <= 0 waits forever), ``--no-timeout``, ``--shutdown-timeout``.
* ``unspawner NAME...`` and ``controller_manager VERB NAME...`` with noetic's verbs, aliases and printouts.

Where upstream fails with a traceback (``-x abc``, ``-J joint abc``, an unset ``-param``), we give one line
naming the flag, the file or the parameter. ROS remapping arguments (``__name:=``, ``__log:=``, ``a:=b``,
which roslaunch appends) are dropped first, by ``rospy.myargv``'s rule: any argument containing ``:=``.
"""
import argparse
import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import List, Optional, Tuple
from urllib.parse import urlsplit, urlunsplit

import yaml

from diffbot_sim.errors import DiffbotSimError

#: rosgraph.names.REMAP: an argument containing it is a ROS remapping, not the program's.
REMAP = ":="

#: What ``-database NAME`` spawns: gazebo_ros's template, an SDF 1.4 world including the model by URI.
MODEL_DATABASE_TEMPLATE = """\
<sdf version="1.4">
    <world name="default">
        <include>
            <uri>model://{}</uri>
        </include>
    </world>
</sdf>"""

#: spawner's default wait for the controller_manager services (s), as noetic.
SPAWNER_TIMEOUT = 30.0

#: unspawner stops its controllers again this often (s), in case a spawner started them meanwhile.
UNSPAWNER_PERIOD = 3.0


class CliError(DiffbotSimError):
    """A bad command line; the message is one line naming the flag, file or parameter at fault."""


class UsageExit(Exception):
    """Not an error in the arguments as such: print ``text`` (help or usage) and exit with ``status``.

    ``-h`` exits 0 everywhere; noetic's unspawner exits 1 after its help, and ``controller_manager`` with an
    unknown verb prints its usage and exits 1.
    """

    def __init__(self, text, status=0):
        super().__init__(text)
        self.text = text
        self.status = status


def strip_remappings(argv):
    """``argv`` without ROS remapping arguments (``rospy.myargv``'s rule, done without rospy)."""
    return [arg for arg in argv if REMAP not in arg]


class _Parser(argparse.ArgumentParser):
    """argparse, but raising instead of printing and exiting, so a node decides how to report."""

    def error(self, message):
        raise CliError(f"{message} (see {self.prog} -h)")

    def print_help(self, file=None):
        raise UsageExit(self.format_help(), 0)

    def exit(self, status=0, message=None):
        raise UsageExit(message or "", status)


def _finite(flag, text, what):
    """``text`` as a finite float, else CliError naming ``flag`` (upstream: a traceback or NaN sent on)."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise CliError(f"{flag}: '{text}' is not a number ({what} expected)") from None
    if not math.isfinite(value):
        raise CliError(f"{flag}: '{text}' is not a finite number ({what} expected)")
    return value


# ------------------------------------------------------------------------------------------- spawn_model

@dataclass
class SpawnArgs:
    """A parsed ``spawn_model`` command line.

    ``fmt`` is ``urdf`` or ``sdf``; ``source`` one of ``file``, ``param``, ``database``, ``stdin`` with
    ``source_value`` its argument (None for stdin). Angles are radians, positions metres.
    """

    fmt: str
    source: str
    source_value: Optional[str]
    model: str
    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0
    joints: List[Tuple[str, float]] = field(default_factory=list)
    robot_namespace: str = "/"
    unpause: bool = False
    wait: Optional[str] = None
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
        """(x, y, z, w) from ``-R -P -Y``, as ``quaternion_from_euler(R, P, Y)`` gives it."""
        return quaternion_from_euler(self.roll, self.pitch, self.yaw)


def _spawn_parser():
    parser = _Parser(prog="spawn_model", description="Spawn a model in the simulator using the gazebo_ros API")
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
    pose = {key: _finite(f"-{key}", getattr(ns, key), what) for key, what in units.items()}
    joints = [(name, _finite(f"-J {name}", position, "a joint position")) for name, position in ns.joints]
    return SpawnArgs(
        fmt="urdf" if ns.urdf else "sdf", source=source,
        source_value=None if source == "stdin" else getattr(ns, source), model=ns.model,
        x=pose["x"], y=pose["y"], z=pose["z"], roll=pose["R"], pitch=pose["P"], yaw=pose["Y"], joints=joints,
        robot_namespace=default_robot_namespace if ns.robot_namespace is None else ns.robot_namespace,
        unpause=ns.unpause, wait=ns.wait, reference_frame=ns.reference_frame,
        gazebo_namespace=ns.gazebo_namespace, package_to_model=ns.package_to_model, bond=ns.bond)


def quaternion_from_euler(roll, pitch, yaw):
    """(x, y, z, w) of roll about x, then pitch about y, then yaw about z, all static axes.

    What ``tf.transformations.quaternion_from_euler(roll, pitch, yaw)`` (axes 'sxyz') returns, which is
    what spawn_model sends; tf is not a Debian Python package, so it is computed here.
    """
    hr, hp, hy = roll / 2.0, pitch / 2.0, yaw / 2.0
    cr, sr, cp, sp, cy, sy = math.cos(hr), math.sin(hr), math.cos(hp), math.sin(hp), math.cos(hy), math.sin(hy)
    return (sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


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


# ------------------------------------------------------------------------------------------- spawner

@dataclass
class SpawnerArgs:
    """A parsed ``spawner`` command line. ``timeout`` None waits forever; ``shutdown_timeout`` None: unbounded."""

    controllers: List[str]
    stopped: bool = False
    wait_for: Optional[str] = None
    namespace: str = ""
    timeout: Optional[float] = SPAWNER_TIMEOUT
    shutdown_timeout: Optional[float] = None


def _spawner_parser():
    parser = _Parser(prog="spawner", description="Controller spawner: loads and starts controllers, "
                     "stops and unloads them when killed")
    parser.add_argument("--stopped", action="store_true", help="loads controllers, but does not start them")
    parser.add_argument("--wait-for", metavar="topic",
                        help='does not load or start controllers until it hears "True" on a topic (std_msgs/Bool)')
    parser.add_argument("--namespace", metavar="ns", help="namespace of the controller_manager services")
    parser.add_argument("--timeout", metavar="T", default=str(SPAWNER_TIMEOUT),
                        help="how long to wait for controller_manager services when starting up [s] "
                             "(default: 30). <=0 waits indefinitely.")
    parser.add_argument("--no-timeout", action="store_true",
                        help="wait for controller_manager services indefinitely (same as `--timeout 0`)")
    parser.add_argument("--shutdown-timeout", metavar="T",
                        help="deprecated in noetic (no effect there); here: the longest the stop-and-unload "
                             "at shutdown may take [s]")
    parser.add_argument("controllers", metavar="controller", nargs="+",
                        help="controllers to load (or YAML files of controller configurations)")
    return parser


def parse_spawner_args(argv):
    """Parse ``spawner``'s arguments (``argv`` without the program name; remappings are dropped here).

    Raises:
        CliError: no controller, an unknown option, a timeout that is not a number.
        UsageExit: ``-h``.
    """
    ns = _spawner_parser().parse_args(strip_remappings(argv))
    timeout = _finite("--timeout", ns.timeout, "seconds")
    shutdown_timeout = None
    if ns.shutdown_timeout is not None:
        shutdown_timeout = _finite("--shutdown-timeout", ns.shutdown_timeout, "seconds")
        if shutdown_timeout <= 0:
            shutdown_timeout = None
    return SpawnerArgs(controllers=list(ns.controllers), stopped=ns.stopped, wait_for=ns.wait_for,
                       namespace=ns.namespace or "",
                       timeout=None if ns.no_timeout or timeout <= 0 else timeout,
                       shutdown_timeout=shutdown_timeout)


def manager_prefix(namespace):
    """The prefix of the controller_manager services: ``""`` (the node's namespace) or ``"ns/"``.

    Upstream appends ``/`` to a non-empty ``--namespace`` and prepends it to ``controller_manager/...``, so
    ``--namespace=/robot1`` gives ``/robot1/controller_manager/load_controller`` and ``robot1`` a name
    relative to the node's namespace.
    """
    if namespace and not namespace.endswith("/"):
        namespace += "/"
    return namespace


def manager_service(namespace, name):
    """``<ns>/controller_manager/<name>``, as a spawner with ``--namespace=namespace`` calls it."""
    return f"{manager_prefix(namespace)}controller_manager/{name}"


def controller_type_param(namespace, controller):
    """The parameter a controller's type is read from (``<ns>/<controller>/type``), for error messages.

    controller_manager reads a controller's configuration in its own namespace, which is ``--namespace``
    (or the node's namespace without it).
    """
    return f"{manager_prefix(namespace)}{controller}/type"


def read_controller_file(path):
    """A controller YAML file given to the spawner: (controller names, the parsed mapping).

    The noetic spawner treats an argument naming an existing path as such a file: it puts the file's content
    on the parameter server (merged key by key as ``rosparam.set_param`` does; the node uploads it where the
    controller manager reads it, see :mod:`diffbot_sim.nodes.controller_spawner`) and loads each top-level
    key as a controller. Raises CliError naming the file when it is not a YAML
    mapping.
    """
    try:
        with open(path, encoding="utf-8") as stream:
            data = yaml.safe_load(stream)
    except OSError as err:
        raise CliError(f"{path}: cannot be read: {err}") from None
    except yaml.YAMLError as err:
        detail = " ".join(str(err).split())
        raise CliError(f"{path}: invalid YAML: {detail}") from None
    if not isinstance(data, dict) or not data:
        raise CliError(f"{path}: expected a YAML mapping of controller names to their configuration")
    bad = [key for key in data if not isinstance(key, str)]
    if bad:
        raise CliError(f"{path}: controller names must be strings, not {bad[0]!r}")
    return list(data), data


def expand_controllers(names, exists=os.path.isfile, read=read_controller_file):
    """The spawner's arguments as (controller names to load, [(file, mapping) to upload first]).

    An argument naming an existing file is a YAML file (see :func:`read_controller_file`); any other is a
    controller name. Order is kept. (Noetic tests ``os.path.exists``, so a directory that happens to have a
    controller's name in the working directory crashes it; a file test avoids that.)
    """
    controllers, files = [], []
    for name in names:
        if exists(name):
            found, data = read(name)
            controllers.extend(found)
            files.append((name, data))
        else:
            controllers.append(name)
    return controllers, files


def flatten_params(data, prefix=""):
    """[(name, value)] leaves of a nested mapping, as ``rosparam.set_param_raw`` uploads it.

    A mapping merges key by key into what is already on the server (an update, not a replacement); lists
    and scalars are set whole. Names are relative (joined with ``/``) unless ``prefix`` is absolute.
    """
    leaves = []
    for key, value in data.items():
        name = f"{prefix.rstrip('/')}/{key}" if prefix else str(key)
        if isinstance(value, dict):
            leaves.extend(flatten_params(value, name))
        else:
            leaves.append((name, value))
    return leaves


# ------------------------------------------------------------------------------------------- unspawner

UNSPAWNER_HELP = """./unspawner name1 name2 name3

\tStops a set of controllers until killed.
\tUseful in roslaunch files to temporarily stop controllers"""


def parse_unspawner_args(argv):
    """The controllers ``unspawner`` stops; UsageExit(help, 1) without any or with ``-h``, as noetic."""
    names = strip_remappings(argv)
    if not names or names[0] in ("-h", "--help"):
        raise UsageExit(UNSPAWNER_HELP, 1)
    return list(dict.fromkeys(names))


# ------------------------------------------------------------------------------------------- controller_manager

CONTROLLER_MANAGER_USAGE = """Commands:
    load <name>          - Load the controller named <name>
    unload <name>        - Unload the controller named <name>
    start <name>         - Start the controller named <name>
    stop <name>          - Stop the controller named <name>
    spawn <name>         - Load and start the controller named <name>
    kill <name>          - Stop and unload the controller named <name>
    list                 - List active controllers
    list-types           - List controller Types
    reload-libraries     - Reloads all plugin controller libraries"""

#: controller_manager's verbs, their short aliases in noetic, and the canonical verb.
VERBS = {"load": "load", "unload": "unload", "start": "start", "stop": "stop", "spawn": "spawn", "sp": "spawn",
         "kill": "kill", "kl": "kill", "list": "list", "lc": "list", "list-types": "list-types",
         "lt": "list-types", "reload-libraries": "reload-libraries"}


@dataclass
class ManagerCommand:
    """A ``controller_manager`` command: the canonical verb, its controller names, ``--restore``."""

    verb: str
    names: List[str]
    restore: bool = False


def parse_controller_manager_args(argv):
    """Parse ``controller_manager VERB [NAME...]``.

    Raises:
        UsageExit: no verb (usage, status 0 as noetic) or an unknown one (usage, status 1).
    """
    args = strip_remappings(argv)
    if not args or args[0] in ("-h", "--help"):
        raise UsageExit(CONTROLLER_MANAGER_USAGE, 0)
    verb = VERBS.get(args[0])
    if verb is None:
        raise UsageExit(CONTROLLER_MANAGER_USAGE, 1)
    if verb == "reload-libraries":
        return ManagerCommand(verb, [], restore="--restore" in args[1:])
    return ManagerCommand(verb, args[1:])


def format_controller(state):
    """One line of ``controller_manager list``: ``'name' - 'hw_interface+...' ( state )``.

    ``state`` is a controller_manager_msgs/ControllerState (name, state, claimed_resources). Noetic joins the
    set of claimed hardware interfaces in set order; here sorted, so the line is stable.
    """
    interfaces = sorted({res.hardware_interface for res in state.claimed_resources})
    return "'%s' - '%s' ( %s )" % (state.name, "+".join(interfaces), state.state)


def format_controller_list(states):
    """``controller_manager list``'s printout (lines)."""
    if not states:
        return ["No controllers are loaded in mechanism control"]
    return [format_controller(state) for state in states]


def format_switch(ok, start, stop):
    """The lines ``controller_manager start/stop`` prints for a SwitchController answer."""
    if not ok:
        return [f"Error when starting {list(start)} and stopping {list(stop)}"]
    lines = []
    if start:
        lines.append(f"Started {list(start)} successfully")
    if stop:
        lines.append(f"Stopped {list(stop)} successfully")
    return lines


def format_load(ok, name):
    return f"Loaded '{name}'" if ok else f"Error when loading '{name}'"


def format_unload(ok, name):
    return f"Unloaded '{name}' successfully" if ok else f"Error when unloading '{name}'"
