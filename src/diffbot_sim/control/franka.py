"""franka_gazebo's FrankaHWSim (franka_ros 0.10.1, ``franka_gazebo/src/franka_hw_sim.cpp``, ``joint.cpp``,
``controller_verifier.cpp``, ``include/franka_gazebo/statemachine.h``) as plain data and numbers: its
parameters read once (:func:`franka_hw_config`), the robot mode's state machine (:class:`RobotMode`), the check
of the controllers a switch starts (:func:`verify_switch`), the arm's kinematic chain from the URDF as its
``FrankaModelInterface`` builds it with KDL (:class:`Chain`: the flange pose, the zero Jacobian), and the
franka_hw state the ``FrankaStateInterface`` serves (:class:`FrankaState`, libfranka's ``RobotState``; 4x4
transforms as libfranka stores them: 16 numbers, column-major).

The gripper, franka_gazebo's FrankaGripperSim, is :mod:`diffbot_sim.control.franka_gripper`.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from diffbot_sim.control.pid import pid_gains
from diffbot_sim.errors import ConfigError
from diffbot_sim.transforms import rpy_matrix
from diffbot_sim.values import check_number

SIM_TYPE = "franka_gazebo/FrankaHWSim"
STATE_INTERFACE = "franka_hw/FrankaStateInterface"
MODEL_INTERFACE = "franka_hw/FrankaModelInterface"

IDENTITY16 = (1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0)
#: F_T_NE when the URDF has ``<arm_id>_hand`` and no ``F_T_NE`` parameter (guessEndEffector): the hand's TCP,
#: turned -45 degrees about z and 0.1034 m out from the flange.
HAND_F_T_NE = (0.7071, -0.7071, 0.0, 0.0, 0.7071, 0.7071, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.1034, 1.0)
#: libfranka's nominal collision thresholds FrankaHWSim falls back to (joint torques [N·m], Cartesian forces
#: [N] and torques [N·m] in the stiffness frame K).
DEFAULT_TORQUE_THRESHOLDS = (20.0, 20.0, 18.0, 18.0, 16.0, 14.0, 12.0)
DEFAULT_FORCE_THRESHOLDS = (20.0, 20.0, 20.0, 25.0, 25.0, 25.0)
#: Every parameter FrankaHWSim reads in the robot's namespace
PARAMETERS = ("arm_id", "tau_ext_lowpass_filter", "singularity_warning_threshold", "gravity_vector", "m_ee", "I_ee",
              "F_x_Cee", "F_T_NE", "NE_T_EE", "EE_T_K", "m_load", "I_load", "F_x_Cload",
              "lower_torque_thresholds_nominal", "upper_torque_thresholds_nominal", "lower_force_thresholds_nominal",
              "upper_force_thresholds_nominal", "motion_generators")
#: kDefaultTauExtLowpassFilter: the exponential filter's weight of a new sample (1: no filtering)
DEFAULT_TAU_EXT_LOWPASS_FILTER = 1.0

# the robot's modes (franka::RobotMode as franka_msgs/FrankaState numbers them)
IDLE, MOVE, USER_STOPPED = 1, 2, 5
MODE_NAMES = {IDLE: "Idle", MOVE: "Move", USER_STOPPED: "UserStopped"}
# a joint's control method, from the hardware interface a running controller claims it with
EFFORT, POSITION, VELOCITY = "EffortJointInterface", "PositionJointInterface", "VelocityJointInterface"
CONTROL_METHODS = (EFFORT, POSITION, VELOCITY)


def array_param(params, key, size, default, where):
    """A franka_hw array parameter: a string of ``size`` numbers separated by spaces (upstream's readArray), or
    a list of them. ``default`` when absent."""
    value = params.get(key, default)
    name = f"{where}/{key}"
    items = value.split() if isinstance(value, str) else value
    if not isinstance(items, (list, tuple)) or len(items) != size:
        raise ConfigError(name, value, f"{size} numbers separated by spaces")
    try:
        numbers = tuple(float(item) for item in items)
    except (TypeError, ValueError):
        raise ConfigError(name, value, f"{size} numbers separated by spaces") from None
    if not all(math.isfinite(n) for n in numbers):
        raise ConfigError(name, value, f"{size} finite numbers")
    return numbers


@dataclass
class FrankaHWConfig:
    """FrankaHWSim's parameters, read in the robot's namespace (``<robotNamespace>/...``) as initSim and
    readParameters read them."""

    arm_id: str
    arm_joints: list[str]  # <arm_id>_joint1..7
    finger_joints: list[str]  # the model's <arm_id>_finger_joint1/2 that have a transmission
    tau_ext_lowpass_filter: float
    singularity_warning_threshold: float
    gravity_vector: tuple | None  # None: the world's gravity
    m_ee: float
    I_ee: tuple  # libfranka's names, as the fields below
    F_x_Cee: tuple
    F_T_NE: tuple
    NE_T_EE: tuple
    EE_T_K: tuple
    m_load: float
    I_load: tuple
    F_x_Cload: tuple
    lower_torque_thresholds: tuple
    upper_torque_thresholds: tuple
    lower_force_thresholds: tuple
    upper_force_thresholds: tuple
    position_gains: dict[str, object]  # joint -> PidGains (motion_generators/position/gains/<joint>)
    velocity_gains: dict[str, object]  # joint -> PidGains (motion_generators/velocity/gains/<joint>)
    warnings: list[str] = field(default_factory=list)


def franka_hw_config(params, ns, robot_namespace, model_joints, hand_mass):
    """Read FrankaHWSim's parameters from ``params`` (the robot namespace ``ns`` as a dict).

    Args:
        robot_namespace: the plugin's robotNamespace without slashes (``arm_id``'s default, as upstream).
        model_joints: the URDF's joint names.
        hand_mass: the mass [kg] of ``<arm_id>_hand`` in the URDF, or None without such a link (m_ee's default).

    Raises:
        ConfigError: a parameter of the wrong type or size, or arm joints the URDF lacks, naming it.
    """
    where = ns.rstrip("/")  # a parameter's name is f"{where}/{key}"
    params = params if isinstance(params, dict) else {}
    warnings = []
    arm_id = params.get("arm_id", robot_namespace)
    if not isinstance(arm_id, str) or not arm_id:
        raise ConfigError(f"{where}/arm_id", arm_id, "the arm's name (e.g. panda)")
    if arm_id != robot_namespace:
        warnings.append(f"FrankaHWSim: Caution: Robot names differ! Read 'arm_id: {arm_id}' from parameter server "
                        f"but URDF defines '<robotNamespace>{robot_namespace}</robotNamespace>'. Will use "
                        f"'{arm_id}'!")
    arm_joints = [f"{arm_id}_joint{i}" for i in range(1, 8)]
    missing = [j for j in arm_joints if j not in model_joints]
    if missing:
        raise ConfigError(f"{where}/arm_id", arm_id, f"an arm whose joints {arm_id}_joint1..7 are in the URDF "
                          f"(missing: {', '.join(missing)})")
    filt = check_number(f"{where}/tau_ext_lowpass_filter",
                        params.get("tau_ext_lowpass_filter", DEFAULT_TAU_EXT_LOWPASS_FILTER), low=0.0, high=1.0)
    singular = check_number(f"{where}/singularity_warning_threshold",
                            params.get("singularity_warning_threshold", -1.0))
    gravity = (array_param(params, "gravity_vector", 3, None, where) if "gravity_vector" in params else None)
    has_hand = hand_mass is not None
    m_ee = check_number(f"{where}/m_ee", params.get("m_ee", hand_mass if has_hand else 0.0), low=0.0)
    motion = params.get("motion_generators") or {}
    gains = {}
    for kind in ("position", "velocity"):
        table = ((motion.get(kind) or {}).get("gains") or {}) if isinstance(motion, dict) else {}
        gains[kind] = {}
        for joint in arm_joints:
            found = pid_gains(table.get(joint), f"{where}/motion_generators/{kind}/gains/{joint}")
            if found is not None:
                gains[kind][joint] = found
        if kind == "position" and len(gains[kind]) < len(arm_joints):
            lacking = [j for j in arm_joints if j not in gains[kind]]
            warnings.append(f"FrankaHWSim: no p gain for {', '.join(lacking)} under "
                            f"{where}/motion_generators/position/gains: while no controller commands the arm, "
                            "those joints hold only against gravity (upstream's uninitialised PID gives 0)")
    return FrankaHWConfig(
        arm_id=arm_id, arm_joints=arm_joints,
        finger_joints=[j for j in (f"{arm_id}_finger_joint1", f"{arm_id}_finger_joint2") if j in model_joints],
        tau_ext_lowpass_filter=filt, singularity_warning_threshold=singular, gravity_vector=gravity,
        m_ee=m_ee, I_ee=array_param(params, "I_ee", 9, (0.0,) * 9, where),
        F_x_Cee=array_param(params, "F_x_Cee", 3, (0.0,) * 3, where),
        F_T_NE=array_param(params, "F_T_NE", 16, HAND_F_T_NE if has_hand else IDENTITY16, where),
        NE_T_EE=array_param(params, "NE_T_EE", 16, IDENTITY16, where),
        EE_T_K=array_param(params, "EE_T_K", 16, IDENTITY16, where),
        m_load=check_number(f"{where}/m_load", params.get("m_load", 0.0), low=0.0),
        I_load=array_param(params, "I_load", 9, (0.0,) * 9, where),
        F_x_Cload=array_param(params, "F_x_Cload", 3, (0.0,) * 3, where),
        lower_torque_thresholds=array_param(params, "lower_torque_thresholds_nominal", 7,
                                            DEFAULT_TORQUE_THRESHOLDS, where),
        upper_torque_thresholds=array_param(params, "upper_torque_thresholds_nominal", 7,
                                            DEFAULT_TORQUE_THRESHOLDS, where),
        lower_force_thresholds=array_param(params, "lower_force_thresholds_nominal", 6, DEFAULT_FORCE_THRESHOLDS,
                                           where),
        upper_force_thresholds=array_param(params, "upper_force_thresholds_nominal", 6, DEFAULT_FORCE_THRESHOLDS,
                                           where),
        position_gains=gains["position"], velocity_gains=gains["velocity"], warnings=warnings)


class RobotMode:
    """statemachine.h: Idle until a controller commands an arm joint (Move); a user stop (UserStopped) holds the
    arm where it is until released (Idle); error recovery from Idle starts moving again."""

    def __init__(self):
        self.mode = IDLE

    def switch_control(self, arm_controlled):
        """SwitchControl: a switch left ``arm_controlled`` (some arm joint has a control method). True when the
        mode changed."""
        if self.mode == IDLE and arm_controlled:
            self.mode = MOVE
            return True
        if self.mode == MOVE and not arm_controlled:
            self.mode = IDLE
            return True
        return False

    def user_stop(self, pressed):
        """UserStop: True when the stop was pressed now (the arm must hold where it is)."""
        if pressed and self.mode in (IDLE, MOVE):
            self.mode = USER_STOPPED
            return True
        if not pressed and self.mode == USER_STOPPED:
            self.mode = IDLE
        return False

    def error_recovery(self):
        if self.mode == IDLE:
            self.mode = MOVE


class SwitchRefused(Exception):
    """FrankaHWSim's prepareSwitch refused the controllers a switch would start."""


def verify_switch(claims, arm_joints, finger_joints):
    """ControllerVerifier::isValidController for each controller a switch starts: ``claims`` is {controller:
    [(interface, [joints])]}. A controller that claims joints by a command interface must claim the 7 arm
    joints (an arm controller) or both fingers by effort (the gripper).

    Raises:
        SwitchRefused: naming the controller, as controller_manager's "unfeasible" refusal.
    """
    arm, fingers = set(arm_joints), set(finger_joints)
    for name, resources in claims.items():
        commanding = [(iface, set(joints)) for iface, joints in resources if iface in CONTROL_METHODS]
        if not commanding:
            continue
        if any(len(joints) == 7 and joints <= arm for _, joints in commanding):
            continue
        if any(iface == EFFORT and joints == fingers and len(joints) == 2 for iface, joints in commanding):
            continue
        raise SwitchRefused(f"Could not switch controllers. The hardware interface combination for the requested "
                            f"controllers is unfeasible: FrankaHWSim takes a controller of all 7 arm joints or of "
                            f"both fingers by effort, and {name} claims "
                            + "; ".join(f"{sorted(j)} by {i}" for i, j in commanding))


# ---------------------------------------------------------------------------------------------- kinematics
def matrix(array16):
    """A libfranka transform (16 numbers, column-major) as a 4x4 matrix."""
    return np.array(array16, dtype=float).reshape(4, 4).T


def array16(m):
    """A 4x4 matrix as libfranka stores it (column-major)."""
    return tuple(float(v) for v in np.asarray(m).T.reshape(16))


def _origin(xyz, rpy):
    m = np.eye(4)
    m[:3, :3] = rpy_matrix(rpy)
    m[:3, 3] = xyz
    return m


class Chain:
    """The joints from ``root`` (a link) to ``tip`` (a link), as KDL's tree-to-chain walk takes them from the URDF:
    fixed joints as constant transforms, revolute and prismatic ones about their axes."""

    def __init__(self, model, root, tip):
        path, link = [], tip
        parents = {j.child: j for j in model.joints.values()}
        while link != root:
            joint = parents.get(link)
            if joint is None:
                raise ConfigError(f"FrankaModelInterface chain {root} -> {tip}", tip,
                                  f"a link below {root} in the URDF's tree")
            path.append(joint)
            link = joint.parent
        self.joints = list(reversed(path))
        self.movable = [j.name for j in self.joints if j.type != "fixed"]
        self._origins = [_origin(j.xyz, j.rpy) for j in self.joints]
        self._axes = [np.array(j.axis, dtype=float) / (np.linalg.norm(j.axis) or 1.0) for j in self.joints]

    def frames(self, positions):
        """([each movable joint's frame after its origin, as 4x4 in the root's frame], the tip's 4x4)."""
        pose = np.eye(4)
        frames = []
        for joint, origin, axis in zip(self.joints, self._origins, self._axes):
            pose = pose @ origin
            if joint.type == "fixed":
                continue
            frames.append((pose.copy(), axis))
            q = positions.get(joint.name, 0.0)
            step = np.eye(4)
            if joint.type == "prismatic":
                step[:3, 3] = axis * q
            else:
                step[:3, :3] = _axis_angle(axis, q)
            pose = pose @ step
        return frames, pose

    def pose(self, positions, tip_offset=None):
        """The tip's pose (4x4) in the root's frame, then ``tip_offset`` (4x4) applied."""
        tip = self.frames(positions)[1]
        return tip if tip_offset is None else tip @ tip_offset

    def zero_jacobian(self, positions, tip_offset=None):
        """The 6 x n geometric Jacobian of the point ``tip_offset`` puts on the tip, in the root's frame
        (linear rows first, as libfranka's zeroJacobian)."""
        frames, tip = self.frames(positions)
        point = (tip if tip_offset is None else tip @ tip_offset)[:3, 3]
        jac = np.zeros((6, len(frames)))
        for k, (frame, axis) in enumerate(frames):
            direction = frame[:3, :3] @ axis
            joint = [j for j in self.joints if j.type != "fixed"][k]
            if joint.type == "prismatic":
                jac[:3, k] = direction
            else:
                jac[:3, k] = np.cross(direction, point - frame[:3, 3])
                jac[3:, k] = direction
        return jac


def _axis_angle(axis, angle):
    x, y, z = axis
    c, s, t = math.cos(angle), math.sin(angle), 1.0 - math.cos(angle)
    return np.array([[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
                     [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
                     [t * x * z - s * y, t * y * z + s * x, t * z * z + c]])


def shift_inertia(inertia, mass, offset):
    """The inertia tensor (9 numbers, column-major) moved by ``offset`` (Steiner), as franka_hw_sim's
    shiftInertiaTensor."""
    r = np.array(offset, dtype=float)
    skew = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    shifted = np.array(inertia, dtype=float).reshape(3, 3).T - mass * skew @ skew
    return tuple(float(v) for v in shifted.T.reshape(9))


@dataclass
class FrankaState:
    """libfranka's RobotState as FrankaHWSim fills it (the fields franka_msgs/FrankaState carries; what it leaves
    at zero stays zero: elbow, O_T_EE_d/_c, errors)."""

    q: list[float] = field(default_factory=lambda: [0.0] * 7)
    q_d: list[float] = field(default_factory=lambda: [0.0] * 7)
    dq: list[float] = field(default_factory=lambda: [0.0] * 7)
    dq_d: list[float] = field(default_factory=lambda: [0.0] * 7)
    ddq_d: list[float] = field(default_factory=lambda: [0.0] * 7)
    tau_J: list[float] = field(default_factory=lambda: [0.0] * 7)
    dtau_J: list[float] = field(default_factory=lambda: [0.0] * 7)
    tau_J_d: list[float] = field(default_factory=lambda: [0.0] * 7)
    tau_ext_hat_filtered: list[float] = field(default_factory=lambda: [0.0] * 7)
    joint_contact: list[float] = field(default_factory=lambda: [0.0] * 7)
    joint_collision: list[float] = field(default_factory=lambda: [0.0] * 7)
    cartesian_contact: list[float] = field(default_factory=lambda: [0.0] * 6)
    cartesian_collision: list[float] = field(default_factory=lambda: [0.0] * 6)
    O_F_ext_hat_K: list[float] = field(default_factory=lambda: [0.0] * 6)
    K_F_ext_hat_K: list[float] = field(default_factory=lambda: [0.0] * 6)
    O_T_EE: tuple = (0.0,) * 16
    F_T_EE: tuple = IDENTITY16
    F_T_NE: tuple = IDENTITY16
    NE_T_EE: tuple = IDENTITY16
    EE_T_K: tuple = IDENTITY16
    m_ee: float = 0.0
    I_ee: tuple = (0.0,) * 9
    F_x_Cee: tuple = (0.0,) * 3
    m_load: float = 0.0
    I_load: tuple = (0.0,) * 9
    F_x_Cload: tuple = (0.0,) * 3
    m_total: float = 0.0
    I_total: tuple = (0.0,) * 9
    time: float = 0.0
    robot_mode: int = IDLE

    def update_dynamics(self):
        """updateRobotStateDynamics: the totals and F_T_EE after a change of end effector, load or frames."""
        self.m_total = self.m_ee + self.m_load
        self.F_T_EE = array16(matrix(self.F_T_NE) @ matrix(self.NE_T_EE))
        self.I_total = shift_inertia(self.I_ee, self.m_ee, self.F_x_Cload)

    def external(self, tau_ext, jacobian_o, jacobian_k, lower_force, upper_force):
        """The external wrench at K from the external joint torques: O_F_ext_hat_K and K_F_ext_hat_K by the
        pseudo-inverses of the transposed Jacobians, and the Cartesian contact/collision flags on K's."""
        tau = np.array(tau_ext, dtype=float)
        self.O_F_ext_hat_K = [float(v) for v in np.linalg.pinv(jacobian_o.T) @ tau]
        self.K_F_ext_hat_K = [float(v) for v in np.linalg.pinv(jacobian_k.T) @ tau]
        self.cartesian_contact = [float(abs(f) > t) for f, t in zip(self.K_F_ext_hat_K, lower_force)]
        self.cartesian_collision = [float(abs(f) > t) for f, t in zip(self.K_F_ext_hat_K, upper_force)]


def body_jacobian(zero_jacobian, pose):
    """A zero Jacobian expressed in the frame ``pose`` (4x4) of the point it moves (libfranka's bodyJacobian)."""
    rot = pose[:3, :3].T
    out = np.array(zero_jacobian)
    out[:3] = rot @ out[:3]
    out[3:] = rot @ out[3:]
    return out


def low_pass(previous, sample, weight):
    """tau_ext_hat_filtered's exponential moving average: ``weight`` of the new sample (1: none)."""
    return weight * sample + (1.0 - weight) * previous
