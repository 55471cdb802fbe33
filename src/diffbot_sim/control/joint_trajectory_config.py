"""ros_controllers' joint_trajectory_controller (0.21.2, noetic-devel 678b92a): its parameters, checked (pure).

``jtc_config`` reads what ``JointTrajectoryController::init()`` and ``ClosedLoopHardwareInterfaceAdapter::init``
read (``joint_trajectory_controller_impl.h``, ``hardware_interface_adapter.h``, ``tolerances.h``), with their
defaults, into a frozen :class:`JtcConfig`: a wrong value raises ``ConfigError`` naming the full parameter; what
upstream logs while loading is kept in ``log``, and a controller upstream loads but would crash on starting says
so in ``start_crash``. The controller that runs on it is :mod:`diffbot_sim.control.joint_trajectory_controller`.
"""
from dataclasses import dataclass

from diffbot_sim.control.pid import PidGains, no_p_gain_message, pid_gains
from diffbot_sim.control.trajectory import SegmentTolerances, StateTolerances
from diffbot_sim.errors import ConfigError
from diffbot_sim.values import check_bool, check_mapping, check_number

CONTROLLER_TYPES = {
    "position_controllers/JointTrajectoryController": "position",
    "velocity_controllers/JointTrajectoryController": "velocity",
    "effort_controllers/JointTrajectoryController": "effort",
    # PosVel / PosVelAcc interfaces take the desired position (and velocity / acceleration) as they are.
    "pos_vel_controllers/JointTrajectoryController": "position",
    "pos_vel_acc_controllers/JointTrajectoryController": "position",
}

NO_GAINS_WARNING = "Failed to initialize PID gains from ROS parameter server."


@dataclass(frozen=True)
class JtcConfig:
    """A JointTrajectoryController's parameters, checked, with upstream's defaults.

    ``default_tolerances`` is one :class:`SegmentTolerances` per joint (``constraints/``). ``gains`` and
    ``velocity_ff`` are read for the velocity/effort variants only. ``log`` holds ``(level, text)`` lines
    upstream prints while loading; ``start_crash`` is set when upstream loads the controller but would crash
    on starting it (closed-loop variant without gains for a joint).
    """

    name: str
    controller_type: str
    variant: str
    joints: tuple[str, ...]
    wraparound: tuple[bool, ...]
    default_tolerances: tuple[SegmentTolerances, ...]
    state_publish_rate: float = 50.0
    action_monitor_rate: float = 20.0
    stop_trajectory_duration: float = 0.0
    allow_partial_joints_goal: bool = False
    gains: tuple[PidGains, ...] = ()
    velocity_ff: tuple[float, ...] = ()
    log: tuple[tuple[str, str], ...] = ()
    start_crash: str | None = None


def jtc_config(params, name, joints):
    """The :class:`JtcConfig` of the controller whose rosparam dict is ``params``.

    Args:
        params: ``rospy.get_param(name)``: ``type``, ``joints``, ``constraints``, ``gains``, ...
        name: the controller's full namespace (e.g. ``/arm_controller``), for messages.
        joints: the URDF's joints, name → (type, lower, upper); ``continuous`` joints wrap around.

    Raises:
        ConfigError: an unknown type, a missing/empty/non-string ``joints`` list, a joint the URDF lacks, or
            a parameter of the wrong kind, naming the full parameter.
    """
    if not isinstance(params, dict):
        raise ConfigError(name, params, "a dictionary of controller parameters")
    controller_type = params.get("type")
    if controller_type not in CONTROLLER_TYPES:
        raise ConfigError(f"{name}/type", controller_type, "one of " + ", ".join(CONTROLLER_TYPES))
    joint_names = _joint_names(params.get("joints"), f"{name}/joints", joints)
    constraints = check_mapping(f"{name}/constraints", params.get("constraints"))
    stopped_velocity = check_number(f"{name}/constraints/stopped_velocity_tolerance",
                                    constraints.get("stopped_velocity_tolerance", 0.01))
    goal_time = check_number(f"{name}/constraints/goal_time", constraints.get("goal_time", 0.0))
    tolerances = []
    for joint in joint_names:
        own = check_mapping(f"{name}/constraints/{joint}", constraints.get(joint))
        path = check_number(f"{name}/constraints/{joint}/trajectory", own.get("trajectory", 0.0))
        goal = check_number(f"{name}/constraints/{joint}/goal", own.get("goal", 0.0))
        tolerances.append(SegmentTolerances(StateTolerances(position=path),
                                            StateTolerances(position=goal, velocity=stopped_velocity), goal_time))
    variant = CONTROLLER_TYPES[controller_type]
    gains, velocity_ff, log, start_crash = (), (), (), None
    if variant != "position":
        gains, velocity_ff, log, start_crash = _closed_loop_gains(params, name, joint_names, controller_type)
    return JtcConfig(
        name=name, controller_type=controller_type, variant=variant, joints=joint_names,
        wraparound=tuple(joints[joint][0] == "continuous" for joint in joint_names),
        default_tolerances=tuple(tolerances),
        state_publish_rate=check_number(f"{name}/state_publish_rate", params.get("state_publish_rate", 50.0),
                                        low=0.0, low_open=True),
        action_monitor_rate=check_number(f"{name}/action_monitor_rate", params.get("action_monitor_rate", 20.0),
                                         low=0.0, low_open=True),
        stop_trajectory_duration=check_number(f"{name}/stop_trajectory_duration",
                                              params.get("stop_trajectory_duration", 0.0), low=0.0),
        allow_partial_joints_goal=check_bool(f"{name}/allow_partial_joints_goal",
                                             params.get("allow_partial_joints_goal", False)),
        gains=gains, velocity_ff=velocity_ff, log=log, start_crash=start_crash)


def _joint_names(value, label, urdf_joints):
    expected = "a non-empty list of joint names"
    if not isinstance(value, (list, tuple)) or not value or not all(isinstance(j, str) for j in value):
        raise ConfigError(label, value, expected)
    for joint in value:
        if joint not in urdf_joints:
            raise ConfigError(label, joint, "joints of robot_description (upstream: Could not find joint "
                                            f"'{joint}' in URDF model.)")
    return tuple(value)


def _closed_loop_gains(params, name, joint_names, controller_type):
    """``ClosedLoopHardwareInterfaceAdapter::init``: a PID per joint from ``gains/<joint>``, then
    ``velocity_ff/<joint>`` (default 0).

    Upstream stops at the first joint without ``p`` (ROS_ERROR + ROS_WARN, ``init`` returns false), but the
    controller ignores that result and loads. The later joints' PIDs are then null pointers, which
    ``starting()`` dereferences, and ``velocity_ff`` is left empty, which the first ``update()`` indexes:
    the process dies when the controller starts. That is reported in ``start_crash``.
    """
    all_gains = check_mapping(f"{name}/gains", params.get("gains"))
    feed_forward = check_mapping(f"{name}/velocity_ff", params.get("velocity_ff"))
    gains = []
    for joint in joint_names:
        namespace = f"{name}/gains/{joint}"
        joint_gains = pid_gains(all_gains.get(joint), namespace)
        if joint_gains is None:
            log = (("error", no_p_gain_message(namespace)), ("warn", NO_GAINS_WARNING))
            crash = (f"{name}: {controller_type} has no PID gains for joint '{joint}' ({namespace}/p); "
                     "ros_controllers loads it anyway and crashes the controller manager's process (Gazebo) "
                     "as soon as it starts (null PID / empty velocity_ff in HardwareInterfaceAdapter)")
            return tuple(gains), (), log, crash
        gains.append(joint_gains)
    velocity_ff = tuple(check_number(f"{name}/velocity_ff/{joint}", feed_forward.get(joint, 0.0))
                        for joint in joint_names)
    return tuple(gains), velocity_ff, (), None
