"""robot_check's view of a robot's transmission joints (pure): how DefaultRobotHWSim drives each, its limits,
the controller that commands it, and the small moves that judge an arm by its body.

* :func:`joint_infos`: for every ``<transmission>`` joint, its interface and control method (with or without
  ``<ns>/gazebo_ros_control/pid_gains/<joint>``), the limits gazebo_ros_control enforces (URDF ``<limit>``, then
  ``<ns>/joint_limits/<joint>`` from the YAMLs: :func:`diffbot_sim.control.joint_limits.register_joint_limits`),
  the controller of the user's YAML that claims it, and its role: a drive wheel, a mimic joint (a mimic-joint
  plugin or URDF ``<mimic>`` moves it), or an arm joint (everything else).
* :func:`plan_moves`: per controller of arm joints, the targets of a small move (:data:`STEP_ANGLE` rad or
  :data:`STEP_SLIDE` m, away from the nearer limit) and the way to send them (a FollowJointTrajectory goal, a
  GripperCommand goal or a command topic). Joints without such a controller are listed as not moved.
* :func:`judge_move`: whether the joints went where they were sent (joint_states) and every link Gazebo keeps is
  where joint_states + the URDF put it (ground truth, :func:`diffbot_sim.check.arm_check.pose_errors`).
"""
import math
from dataclasses import dataclass, field

from diffbot_sim.control.joint_limits import JointLimitsInterfaceError, register_joint_limits
from diffbot_sim.control.pid import pid_gains
from diffbot_sim.errors import ConfigError

MIMIC_PLUGINS = ("libroboticsgroup_gazebo_mimic_joint_plugin.so",
                 "libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so")
STEP_ANGLE = 0.2  # rad: how far a revolute or continuous arm joint is moved
STEP_SLIDE = 0.02  # m: how far a prismatic one is moved
#: A joint counts as moved when it went within this much of its target: rad (m for prismatic joints).
MOVE_TOLERANCE = {"angle": 0.05, "slide": 0.005}
#: The body agrees with joint_states + the URDF within these (m, rad) for every link Gazebo keeps.
BODY_DISTANCE, BODY_ANGLE = 0.005, 0.02
TRAJECTORY, GRIPPER, POSITION_TOPIC = "trajectory", "gripper", "position command"
_POSITION_FORWARD = ("position_controllers/JointPositionController",
                     "position_controllers/JointGroupPositionController",
                     "effort_controllers/JointPositionController", "effort_controllers/JointGroupPositionController",
                     "velocity_controllers/JointPositionController")


@dataclass
class JointInfo:
    """One transmission joint as the simulator drives it. Limits in rad (m), rad/s (m/s), N·m (N); inf: none."""

    name: str
    type: str
    interface: str
    method: str  # e.g. "position, PID from pid_gains"
    lower: float = -math.inf
    upper: float = math.inf
    velocity: float = math.inf
    effort: float = math.inf
    controller: str = ""  # the controller's name in the robot's namespace, "" when none claims the joint
    controller_type: str = ""
    role: str = ""  # "drive wheel", "mimic of <joint> (...)" or "" for an arm joint

    @property
    def arm(self):
        return not self.role

    @property
    def slide(self):
        return self.type == "prismatic"


def _subtree(tree, path):
    node = tree
    for part in [p for p in path.split("/") if p]:
        node = node.get(part) if isinstance(node, dict) else None
    return node


def _claimed(params):
    """The joints a controller's parameters name (``joint``, ``joints``, a diff drive's wheels)."""
    out = []
    for key in ("joint", "joints", "left_wheel", "right_wheel"):
        value = params.get(key)
        out += [value] if isinstance(value, str) else [v for v in value if isinstance(v, str)] \
            if isinstance(value, list) else []
    return out


def joint_infos(model, tree, ns, controllers, wheels=(), mimic_plugins=()):
    """:class:`JointInfo` of every transmission joint of ``model``.

    Args:
        tree: the YAMLs' parameters as one nested dict (as loaded at ``/``).
        ns: the gazebo_ros_control plugin's namespace.
        controllers: {controller namespace: parameters} found under ``ns`` (controller_lookup).
        wheels: joints a drive turns. mimic_plugins: [(master, mimic joint)] of the mimic-joint plugins.

    Raises:
        ConfigError: a bad rosparam limit or gain, naming the parameter (bullet_sim refuses it too).
    """
    prefix = "/" + ns.strip("/") if ns.strip("/") else ""
    owner = {}
    for name, params in sorted(controllers.items()):
        for joint in _claimed(params):
            owner.setdefault(joint, (name[len(prefix):].lstrip("/") if name.startswith(prefix + "/") else name,
                                     str(params.get("type", ""))))
    plugin_mimics = dict((mimic, master) for master, mimic in mimic_plugins)
    out = []
    for trans in model.transmissions:
        joint = model.joints.get(trans.joint)
        where = f"{prefix}/joint_limits/{trans.joint}"
        try:
            limits = register_joint_limits(trans.joint, trans.interface, joint, _subtree(tree, where), ns)
        except JointLimitsInterfaceError as err:
            raise ConfigError(where, _subtree(tree, where), str(err)) from None
        method = trans.interface.replace("JointInterface", "").lower()
        if method in ("position", "velocity"):
            gains_at = f"{prefix}/gazebo_ros_control/pid_gains/{trans.joint}"
            gains = pid_gains(_subtree(tree, gains_at), gains_at)
            method += f", pid_gains p {gains.p:g}" if gains is not None else ", no pid_gains"
        velocity = (limits.limits.max_velocity if limits.limits is not None and limits.limits.has_velocity_limits
                    else math.inf)
        name, kind = owner.get(trans.joint, ("", ""))
        if trans.joint in wheels:
            role = "drive wheel"
        elif trans.joint in plugin_mimics:
            role = f"mimic of {plugin_mimics[trans.joint]} (plugin)"
        elif joint is not None and joint.mimic is not None and not name:
            role = f"mimic of {joint.mimic.joint} (URDF)"
        else:
            role = ""
        out.append(JointInfo(trans.joint, limits.joint_type, trans.interface, method,
                             limits.lower if limits.lower > -1e300 else -math.inf,
                             limits.upper if limits.upper < 1e300 else math.inf, velocity,
                             limits.effort_limit if limits.effort_limit < 1e300 else math.inf, name, kind, role))
    return out


def _number(value, unit):
    return "none" if not math.isfinite(value) else f"{value:g} {unit}"


def format_joints(joints):
    """Lines: one per transmission joint (interface, limits, controller, role)."""
    if not joints:
        return []
    lines = [f"joints with a transmission: {len(joints)}"]
    for j in joints:
        length, speed, force = ("m", "m/s", "N") if j.slide else ("rad", "rad/s", "N·m")
        span = (f"[{j.lower:g}, {j.upper:g}] {length}" if math.isfinite(j.lower) and math.isfinite(j.upper)
                else "no position limits")
        controller = f"{j.controller} ({j.controller_type})" if j.controller else "no controller"
        role = f"; {j.role}" if j.role else ""
        lines.append(f"  {j.name}: {j.type}, {j.interface} ({j.method}), {span}, {_number(j.velocity, speed)}, "
                     f"{_number(j.effort, force)}; {controller}{role}")
    return lines


# ------------------------------------------------------------------------------------------------ moving

@dataclass
class Move:
    """One controller's small move: how it is sent, its joints (all it commands) and their targets."""

    controller: str
    controller_type: str
    how: str  # TRAJECTORY, GRIPPER or POSITION_TOPIC
    joints: list[str]
    targets: list[float]
    moved: list[str]  # the joints this move judges (arm joints of the controller)


def send_kind(controller_type):
    if controller_type.endswith("/JointTrajectoryController"):
        return TRAJECTORY
    if controller_type.endswith("/GripperActionController"):
        return GRIPPER
    if controller_type in _POSITION_FORWARD:
        return POSITION_TOPIC
    return None


def step_target(info, position):
    """Where a small move takes the joint from ``position``: the step away from the nearer limit, at most a
    third of the range."""
    step = STEP_SLIDE if info.slide else STEP_ANGLE
    if math.isfinite(info.lower) and math.isfinite(info.upper):
        step = min(step, (info.upper - info.lower) / 3.0)
        if position + step > info.upper - 1e-3:
            return position - step
        if position - step < info.lower + 1e-3:
            return position + step
        return position + step if info.upper - position >= position - info.lower else position - step
    return position + step


def plan_moves(joints, positions, controller_joints):
    """(moves, not moved) for the arm joints of ``joints`` at ``positions`` ({joint: value}).

    ``controller_joints``: {controller: [every joint it commands, in its order]} (from its parameters).
    Returns the moves, and [(joint, why)] for arm joints no move covers.
    """
    moves, skipped = [], []
    by_controller = {}
    for info in joints:
        if not info.arm:
            continue
        how = send_kind(info.controller_type) if info.controller else None
        if how is None:
            skipped.append((info.name, "no controller" if not info.controller
                            else f"{info.controller_type} is not moved by robot_check"))
        elif info.name not in positions:
            skipped.append((info.name, "not in joint_states"))
        else:
            by_controller.setdefault(info.controller, []).append(info)
    for controller, infos in by_controller.items():
        names = controller_joints.get(controller) or [i.name for i in infos]
        if any(n not in positions for n in names):
            skipped += [(i.name, f"{controller}'s joints are not all in joint_states") for i in infos]
            continue
        targets = {n: positions[n] for n in names}
        for info in infos:
            targets[info.name] = step_target(info, positions[info.name])
        moves.append(Move(controller, infos[0].controller_type, send_kind(infos[0].controller_type), list(names),
                          [targets[n] for n in names], [i.name for i in infos]))
    return moves, skipped


@dataclass
class MoveResult:
    """How one move went: the joints' motion (joint_states) and the body (ground truth)."""

    move: Move
    phase: str  # "out" or "back"
    reached: dict[str, float]  # joint -> position after the move
    wanted: dict[str, float]
    slides: dict[str, bool]
    worst_link: str = ""
    distance: float = 0.0  # m
    angle: float = 0.0  # rad
    answer: str = ""  # what the controller answered (goal status), "" for a topic
    failures: list[str] = field(default_factory=list)

    @property
    def passed(self):
        return not self.failures


def judge_move(move, phase, wanted, reached, slides, errors, answer=""):
    """A :class:`MoveResult`: each moved joint within MOVE_TOLERANCE of ``wanted``, every link's pose error
    (``errors``: {link: PoseError}) within BODY_DISTANCE / BODY_ANGLE."""
    result = MoveResult(move, phase, dict(reached), dict(wanted), dict(slides), answer=answer)
    for joint in move.moved:
        tolerance = MOVE_TOLERANCE["slide" if slides.get(joint) else "angle"]
        got = reached.get(joint)
        if got is None or not math.isfinite(got) or abs(got - wanted[joint]) > tolerance:
            result.failures.append(f"{joint} at {got if got is None else round(got, 4)}, sent to "
                                   f"{wanted[joint]:.4f} (joint_states)")
    if errors:
        link, worst = max(errors.items(), key=lambda item: item[1].distance)
        result.worst_link, result.distance = link, worst.distance
        result.angle = max(e.angle for e in errors.values())
        if worst.distance > BODY_DISTANCE:
            result.failures.append(f"link {link} is {worst.distance * 1000:.1f} mm from where joint_states + the "
                                   "URDF put it (ground truth)")
        if result.angle > BODY_ANGLE:
            turned = max(errors.items(), key=lambda item: item[1].angle)[0]
            result.failures.append(f"link {turned} is turned {result.angle:.3f} rad from where joint_states + "
                                   "the URDF put it (ground truth)")
    else:
        result.failures.append("no link's ground truth could be read")
    return result


def format_moves(results, skipped):
    """Lines for the arm check."""
    lines = []
    for r in results:
        steps = ", ".join(f"{j} {r.wanted[j]:+.3f} (at {r.reached.get(j, math.nan):+.3f})" for j in r.move.moved)
        answer = f", {r.answer}" if r.answer else ""
        lines.append(f"  {r.move.controller} {r.phase}: {steps}{answer}; worst link {r.worst_link or '?'} "
                     f"{r.distance * 1000:.1f} mm, {r.angle:.3f} rad: {'PASS' if r.passed else 'FAIL'}")
        lines.extend(f"    {text}" for text in r.failures)
    for joint, why in skipped:
        lines.append(f"  {joint}: not moved ({why})")
    return lines


def controller_joints(controllers, ns) -> dict[str, list[str]]:
    """{controller name relative to ``ns``: the joints it commands, in its order}."""
    prefix = "/" + ns.strip("/") if ns.strip("/") else ""
    out = {}
    for name, params in controllers.items():
        short = name[len(prefix):].lstrip("/") if name.startswith(prefix + "/") else name
        out[short] = _claimed(params)
    return out


def mimic_pairs(plugins) -> list[tuple[str, str]]:
    """[(master, mimic joint)] of the mimic-joint plugins among ``plugins`` ([(filename, {tag: text})])."""
    return [(tags.get("joint", ""), tags.get("mimicJoint", "")) for filename, tags in plugins
            if filename in MIMIC_PLUGINS]


def max_effort_for(info: JointInfo | None, params):
    """The GripperCommand max_effort robot_check sends: the controller's ``max_effort`` if set, else the
    joint's effort limit (an effort gripper with 0 does not move), else 10."""
    value = params.get("max_effort") if isinstance(params, dict) else None
    if isinstance(value, (int, float)) and value:
        return abs(float(value))
    if info is not None and math.isfinite(info.effort):
        return info.effort
    return 10.0
