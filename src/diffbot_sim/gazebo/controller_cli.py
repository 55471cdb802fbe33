"""controller_manager's command lines (ROS 1 noetic semantics; pure, no rospy): ``spawner``,
``unspawner`` and ``controller_manager``, whose stand-ins in ``overlay/controller_manager`` run
:mod:`diffbot_sim.nodes.spawner`, :mod:`diffbot_sim.nodes.unspawner` and
:mod:`diffbot_sim.nodes.controller_manager_cli` against the services the ros_control plugin serves.

The facts followed (read from noetic's scripts, nothing copied):

* ``spawner``: controller names (or YAML files, whose top-level keys are the controllers and whose content
  goes onto the parameter server first), ``--stopped``, ``--wait-for``, ``--namespace``, ``--timeout``
  (default 30 s, <= 0 waits forever), ``--no-timeout``, ``--shutdown-timeout``.
* ``unspawner NAME...`` and ``controller_manager VERB NAME...`` with noetic's verbs, aliases and printouts.

Remapping arguments, one-line errors and help: :mod:`diffbot_sim.gazebo.cli`.
"""
import os
import sys
from dataclasses import dataclass

import yaml

from diffbot_sim.gazebo.cli import CliError, Parser, UsageExit, finite, strip_remappings

#: spawner's default wait for the controller_manager services (s), as noetic.
SPAWNER_TIMEOUT = 30.0

#: unspawner stops its controllers again this often (s), in case a spawner started them meanwhile.
UNSPAWNER_PERIOD = 3.0


def parse_or_status(parse, prog, argv):
    """Run ``parse`` on ``argv[1:]`` (``sys.argv`` when None): (parsed, None), or (None, exit status) after
    printing help or usage on stdout, as noetic does whatever the status, or the one-line error on stderr."""
    argv = sys.argv if argv is None else argv
    try:
        return parse(argv[1:]), None
    except UsageExit as usage:
        if usage.text:
            sys.stdout.write(usage.text.rstrip("\n") + "\n")
        return None, usage.status
    except CliError as err:
        sys.stderr.write(f"{prog}: error: {err}\n")
        return None, 1


@dataclass
class SpawnerArgs:
    """A parsed ``spawner`` command line. ``timeout`` None waits forever; ``shutdown_timeout`` None: unbounded."""

    controllers: list[str]
    stopped: bool = False
    wait_for: str | None = None
    namespace: str = ""
    timeout: float | None = SPAWNER_TIMEOUT
    shutdown_timeout: float | None = None


def _spawner_parser():
    parser = Parser(prog="spawner", description="Controller spawner: loads and starts controllers, "
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
    timeout = finite("--timeout", ns.timeout, "seconds")
    shutdown_timeout = None
    if ns.shutdown_timeout is not None:
        shutdown_timeout = finite("--shutdown-timeout", ns.shutdown_timeout, "seconds")
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
    controller manager reads it, see :mod:`diffbot_sim.nodes.spawner`) and loads each top-level
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
    names: list[str]
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
    return f"'{state.name}' - '{'+'.join(interfaces)}' ( {state.state} )"


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
