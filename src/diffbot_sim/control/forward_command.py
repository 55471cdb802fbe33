"""forward_command_controller and the ros_controllers typedefs and PID controllers built around it (ros-controls/
ros_controllers noetic-devel 678b92a, 0.21.2), pure: parameters, start values, commands and updates.

Sources: ``forward_command_controller/include/forward_command_controller/forward_command_controller.h`` and
``forward_joint_group_command_controller.h``; ``{position,velocity,effort}_controllers/src/*.cpp`` (the
``starting`` specialisations and the PID controllers); the ``*_plugins.xml`` files for the type names.

Reproduced:

* Forwarding types (:data:`FORWARD_TYPES`): the last accepted command is written to the joints every update.
  ``starting``: position types take the current positions, velocity/effort types 0. Group types take
  ``joints`` (a non-empty list; ``std_msgs/Float64MultiArray`` on ``command``, only ``data`` is used) and
  ignore a message of the wrong length with ``Dimension of command (N) does not match number of joints (M)!
  Not executing!``; single types take ``joint`` (``std_msgs/Float64``).
* PID types (:data:`PID_TYPES`): ``effort_controllers/JointPositionController`` and
  ``velocity_controllers/JointPositionController`` (``joint``, ``pid/``), ``effort_controllers/
  JointGroupPositionController`` (``joints``, ``<joint>/pid/``), ``effort_controllers/JointVelocityController``
  (``joint``, ``pid/``). A missing ``p`` makes upstream's ``init`` fail, so here it is a ConfigError. Position
  kinds clamp the command to the URDF limits of revolute/prismatic joints (start: the clamped current
  position), take the error with ``shortest_angular_distance_with_large_limits`` (revolute),
  ``shortest_angular_distance`` (continuous) or the difference (others), and output ``pid(error, period)``;
  ``starting`` resets the PIDs. The velocity kind outputs ``pid(command - velocity, period)`` from command 0.
  The single PID controllers publish ``control_msgs/JointControllerState`` on ``state`` at every 10th update
  (the 1st, 11th, ...): :attr:`PidPositionCore.state` is set on those updates, else None.

Not reproduced: ``setCommand(position, velocity)`` of the single position PID controllers (a C++ API, no
topic); the ROS plumbing (subscribers, publishers, realtime buffers).
"""
from collections.abc import Mapping
from dataclasses import dataclass

from diffbot_sim.control.angles import shortest_angular_distance, shortest_angular_distance_with_large_limits
from diffbot_sim.control.pid import Pid, PidGains, no_p_gain_message, pid_gains, pid_publish_state
from diffbot_sim.errors import ConfigError
from diffbot_sim.values import check_mapping

POSITION_INTERFACE = "PositionJointInterface"
VELOCITY_INTERFACE = "VelocityJointInterface"
EFFORT_INTERFACE = "EffortJointInterface"

#: forwarding type -> (claimed interface, what it forwards, single joint?)
FORWARD_TYPES = {
    "position_controllers/JointGroupPositionController": (POSITION_INTERFACE, "position", False),
    "velocity_controllers/JointGroupVelocityController": (VELOCITY_INTERFACE, "velocity", False),
    "effort_controllers/JointGroupEffortController": (EFFORT_INTERFACE, "effort", False),
    "position_controllers/JointPositionController": (POSITION_INTERFACE, "position", True),
    "velocity_controllers/JointVelocityController": (VELOCITY_INTERFACE, "velocity", True),
    "effort_controllers/JointEffortController": (EFFORT_INTERFACE, "effort", True),
}
#: PID type -> (claimed interface, what it controls, single joint?)
PID_TYPES = {
    "effort_controllers/JointPositionController": (EFFORT_INTERFACE, "pid_position", True),
    "effort_controllers/JointGroupPositionController": (EFFORT_INTERFACE, "pid_position", False),
    "velocity_controllers/JointPositionController": (VELOCITY_INTERFACE, "pid_position", True),
    "effort_controllers/JointVelocityController": (EFFORT_INTERFACE, "pid_velocity", True),
}
#: every controller type of this module -> the hardware interface it claims
CONTROLLER_TYPES = {name: spec[0] for name, spec in {**FORWARD_TYPES, **PID_TYPES}.items()}

#: how many updates apart the single PID controllers publish their state
STATE_DECIMATION = 10


@dataclass(frozen=True)
class JointSpec:
    """What the PID position controllers read from a joint's URDF: type, and limits (rad or m)."""

    name: str
    type: str
    lower: float = 0.0
    upper: float = 0.0


@dataclass(frozen=True)
class ForwardConfig:
    """One controller's checked parameters.

    ``kind`` is "position", "velocity", "effort" (forwarding), "pid_position" or "pid_velocity". ``single``:
    ``joint`` + ``std_msgs/Float64``; otherwise ``joints`` + ``std_msgs/Float64MultiArray``. ``specs`` (the
    URDF joints) and ``gains`` / ``pid_namespaces`` / ``publish_pid_state`` are set for the PID kinds only.
    """

    name: str
    controller_type: str
    interface: str
    kind: str
    single: bool
    joints: tuple[str, ...]
    specs: tuple[JointSpec, ...] = ()
    gains: tuple[PidGains, ...] = ()
    pid_namespaces: tuple[str, ...] = ()
    publish_pid_state: tuple[bool, ...] = ()


def forward_config(params, name, controller_type, joint_names_in_model):
    """The :class:`ForwardConfig` of the controller ``name`` (its namespace, e.g. ``/arm_controller``).

    Args:
        params: ``rospy.get_param(name)``.
        controller_type: one of :data:`CONTROLLER_TYPES`.
        joint_names_in_model: the joints the controller may claim: a collection of names, or a mapping
            name -> ``(type, lower, upper)`` (as jtc_config takes) or name -> ``urdf_model.Joint``. The PID
            position kinds need the mapping (URDF type and limits).

    Raises:
        ConfigError: naming the full parameter: unknown type; ``joint`` / ``joints`` missing, empty, not
            strings, or naming a joint not in the model; a PID namespace without ``p`` (upstream's init fails
            after ``No p gain specified for pid.  Namespace: <ns>``) or with bad gains.
    """
    ns = name.rstrip("/")
    if controller_type not in CONTROLLER_TYPES:
        raise ConfigError(f"{ns}/type", controller_type, "one of " + ", ".join(CONTROLLER_TYPES))
    if not isinstance(params, dict):
        raise ConfigError(ns, params, "a dictionary of controller parameters")
    interface, kind, single = {**FORWARD_TYPES, **PID_TYPES}[controller_type]
    joints = _joint_names(params, ns, single, joint_names_in_model)
    config = dict(name=ns, controller_type=controller_type, interface=interface, kind=kind, single=single,
                  joints=joints)
    if kind.startswith("pid_"):
        namespaces = tuple(f"{ns}/pid" if single else f"{ns}/{joint}/pid" for joint in joints)
        gains, publish = [], []
        for joint, pid_ns in zip(joints, namespaces):
            pid_params = params.get("pid") if single else check_mapping(f"{ns}/{joint}", params.get(joint)).get("pid")
            joint_gains = pid_gains(pid_params, pid_ns)
            if joint_gains is None:
                raise ConfigError(f"{pid_ns}/p", None, f"a P gain ({no_p_gain_message(pid_ns)}; the controller "
                                                       "does not load)")
            gains.append(joint_gains)
            publish.append(pid_publish_state(pid_params, pid_ns))
        config.update(gains=tuple(gains), pid_namespaces=namespaces, publish_pid_state=tuple(publish))
        if kind == "pid_position":
            config["specs"] = tuple(_joint_spec(joint, joint_names_in_model) for joint in joints)
    return ForwardConfig(**config)


def _joint_names(params, ns, single, model):
    """``joint`` (single) or ``joints`` (group), each checked against the model."""
    if single:
        label, value = f"{ns}/joint", params.get("joint")
        if not isinstance(value, str) or not value.strip():
            raise ConfigError(label, value, f"a joint name (upstream: No joint given (namespace: {ns}))")
        names = (value.strip(),)
    else:
        label, value = f"{ns}/joints", params.get("joints")
        if not isinstance(value, (list, tuple)) or not all(isinstance(j, str) and j.strip() for j in value):
            raise ConfigError(label, value, f"a list of joint names (upstream: Failed to getParam 'joints' "
                                            f"(namespace: {ns}).)")
        if not value:
            raise ConfigError(label, value, "a non-empty list of joint names (upstream: List of joint names is "
                                            "empty.)")
        names = tuple(j.strip() for j in value)
    for joint in names:
        if joint not in model:
            raise ConfigError(label, joint, "a joint of the robot with a command interface")
    return names


def _joint_spec(joint, model):
    """The URDF type and limits of ``joint`` from a mapping of (type, lower, upper) tuples or Joint objects."""
    if not isinstance(model, Mapping):
        raise ValueError("the PID position controllers need the model's joints as a mapping name -> "
                         "(type, lower, upper) or urdf_model.Joint")
    value = model[joint]
    if isinstance(value, (tuple, list)):
        joint_type, lower, upper = value
        return JointSpec(joint, joint_type, lower, upper)
    return JointSpec(joint, value.type, value.lower, value.upper)


def dimension_error(received, joints):
    """Upstream's ROS_ERROR for a Float64MultiArray of the wrong length (the message is then ignored)."""
    return f"Dimension of command ({received}) does not match number of joints ({joints})! Not executing!"


def _as_values(values, config):
    """A single controller's Float64 as a one-element list; a group's data as a list of floats."""
    if config.single and not isinstance(values, (list, tuple)):
        return [float(values)]
    return [float(v) for v in values]


class ForwardCommandCore:
    """ForwardCommandController / ForwardJointGroupCommandController: re-sends the last command."""

    def __init__(self, config: ForwardConfig):
        self.config = config
        self.commands = [0.0] * len(config.joints)

    def start(self, positions):
        """``starting``: position kinds hold the current ``positions``; velocity/effort kinds command 0."""
        if self.config.kind == "position":
            self.commands = [float(p) for p in positions]
        else:
            self.commands = [0.0] * len(self.config.joints)

    def command(self, values) -> str | None:
        """Take a ``command`` message's value(s); a wrong length returns upstream's error line and keeps the
        previous command (also accepted while stopped: ``start`` then overrides it, as upstream)."""
        values = _as_values(values, self.config)
        if len(values) != len(self.config.joints):
            return dimension_error(len(values), len(self.config.joints))
        self.commands = values
        return None

    def update(self, positions, velocities, period):
        """The commands to write to the joints this update (units of the claimed interface)."""
        return list(self.commands)


def position_error(spec: JointSpec, current, command):
    """The PID position controllers' error (rad or m) from ``current`` to the (clamped) ``command``."""
    if spec.type == "revolute":
        return shortest_angular_distance_with_large_limits(current, command, spec.lower, spec.upper)[1]
    if spec.type == "continuous":
        return shortest_angular_distance(current, command)
    return command - current


def clamp_to_urdf_limits(spec: JointSpec, command):
    """``enforceJointLimits``: revolute and prismatic commands clamped to [lower, upper] (upper checked
    first), others untouched."""
    if spec.type in ("revolute", "prismatic"):
        if command > spec.upper:
            return spec.upper
        if command < spec.lower:
            return spec.lower
    return command


@dataclass(frozen=True)
class JointControllerState:
    """``control_msgs/JointControllerState`` (without header): what the single PID controllers publish."""

    set_point: float
    process_value: float
    process_value_dot: float
    error: float
    time_step: float
    command: float
    p: float
    i: float
    d: float
    i_clamp: float
    antiwindup: bool


class PidPositionCore:
    """effort_controllers/JointPositionController, JointGroupPositionController and
    velocity_controllers/JointPositionController: PID from the position error to effort (or velocity)."""

    def __init__(self, config: ForwardConfig):
        self.config = config
        self.pids = [Pid(gains) for gains in config.gains]
        self.commands = [0.0] * len(config.joints)
        self.loop_count = 0
        self.state: JointControllerState | None = None

    def start(self, positions):
        """Hold the current positions (clamped to the URDF limits) and reset the PIDs."""
        self.commands = [clamp_to_urdf_limits(spec, float(p)) for spec, p in zip(self.config.specs, positions)]
        for pid in self.pids:
            pid.reset()

    command = ForwardCommandCore.command

    def update(self, positions, velocities, period):
        """Efforts (N·m or N; velocities for the velocity_controllers type), one per joint."""
        outputs = []
        errors = []
        for spec, pid, target, position in zip(self.config.specs, self.pids, self.commands, positions):
            target = clamp_to_urdf_limits(spec, target)
            error = position_error(spec, position, target)
            errors.append((target, error))
            outputs.append(pid.compute(error, period))
        self._note_state(errors, positions, velocities, period, outputs, with_velocity=True)
        return outputs

    def _note_state(self, errors, positions, velocities, period, outputs, with_velocity):
        """Set :attr:`state` on the updates a single controller publishes (loop_count % 10 == 0)."""
        self.state = None
        if self.config.single and self.loop_count % STATE_DECIMATION == 0:
            gains = self.pids[0].gains
            set_point, error = errors[0]
            self.state = JointControllerState(
                set_point=set_point, process_value=positions[0] if with_velocity else velocities[0],
                process_value_dot=velocities[0] if with_velocity else 0.0, error=error, time_step=period,
                command=outputs[0], p=gains.p, i=gains.i, d=gains.d, i_clamp=gains.i_clamp_max,
                antiwindup=gains.antiwindup)
        self.loop_count += 1


class PidVelocityCore(PidPositionCore):
    """effort_controllers/JointVelocityController: effort = PID(command - velocity), command 0 at start."""

    def start(self, positions):
        self.commands = [0.0] * len(self.config.joints)
        for pid in self.pids:
            pid.reset()

    def update(self, positions, velocities, period):
        error = self.commands[0] - velocities[0]
        output = self.pids[0].compute(error, period)
        self._note_state([(self.commands[0], error)], positions, velocities, period, [output],
                         with_velocity=False)
        return [output]


def make_core(config: ForwardConfig):
    """The core object for ``config``: ForwardCommandCore, PidPositionCore or PidVelocityCore."""
    if config.kind == "pid_position":
        return PidPositionCore(config)
    if config.kind == "pid_velocity":
        return PidVelocityCore(config)
    return ForwardCommandCore(config)
