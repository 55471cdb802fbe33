"""Pick and place with a mobile manipulator (pure): the steps of ``rosrun diffbot_sim pick_place`` and the
mathematics they need, for diffbot_arm (urdf/diffbot_arm.urdf.xacro) in worlds/pick_place.world.

* :func:`arm_geometry`: the arm's planar chain (shoulder pitch axis, upper arm, forearm, wrist-to-tool length)
  from the link origins the URDF gives with every joint at 0 (the arm straight up).
* :func:`top_down`: the shoulder pitch, elbow and wrist angles [rad] that put the tool centre point
  (``gripper_tcp_link``, between the finger pads) at a given distance ahead of the base and height above the
  ground, the fingers pointing straight down (pitch + elbow + wrist = pi), elbow bent forward. Closed-form
  two-link inverse kinematics; shoulder yaw stays 0 (the base turns to face the object).
* :func:`plan`: the sequence: drive to the pick table (closing on odometry), open, pregrasp above the box,
  grasp, close until the fingers stall on it, lift, back away, turn, drive to the place table, lower, open,
  retract, home. Every target comes from the scene's geometry (:class:`Scene`: where the box is and where it
  goes, the approach distance, the heights) and the arm's.
* :class:`BaseMotion`: the drive and turn steps as a controller of the base: pose (from /odom) in,
  (linear [m/s], angular [rad/s]) command out, until the base is within tolerance.
* :func:`gripper_outcome`: whether a gripper step did what it was for: an opening reached its goal; a closing
  *stalled on the object* (upstream's GripperActionController ends ABORTED with ``stalled`` when the fingers
  stop on something) with the fingers apart by about the object's width, not closed on nothing.
* For the MoveIt variant (``pick_place --moveit``): :data:`TABLES`, the world's tables as collision objects;
  :func:`top_down_pose`, the tool pose a 4-joint arm can take above a point (fingers down, turned towards it);
  :func:`moveit_steps`, the same sequence with the arm's steps as tool poses and the gripper's as finger targets.

Units: m, rad, s, N. Frames: the world's (z up); the base pose is base_footprint's (x, y, yaw).
"""
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

from diffbot_sim.errors import ConfigError
from diffbot_sim.transforms import wrap_angle

#: The arm joints the trajectory steps command, in this order (diffbot_arm's arm_controller).
ARM_JOINTS = ("shoulder_yaw_joint", "shoulder_pitch_joint", "elbow_joint", "wrist_joint")
#: The links whose origins (all joints at 0) give the planar chain: pitch axis, elbow axis, wrist axis, tool.
CHAIN_LINKS = ("upper_arm_link", "forearm_link", "wrist_link", "gripper_tcp_link")
HOME = (0.0, 0.0, 0.0, 0.0)

DRIVE, TURN, ARM, GRIPPER = "drive", "turn", "arm", "gripper"
OPEN, HOLD = "open", "hold"


@dataclass(frozen=True)
class ArmGeometry:
    """The arm as a planar chain in the base's x-z plane (base_footprint frame, shoulder yaw 0) [m]."""

    shoulder_x: float  # the shoulder pitch axis, ahead of base_footprint
    shoulder_z: float  # and above the ground
    upper: float  # shoulder pitch axis -> elbow axis
    fore: float  # elbow axis -> wrist axis
    hand: float  # wrist axis -> tool centre point


def arm_geometry(origins, links=CHAIN_LINKS):
    """:class:`ArmGeometry` from ``origins`` ({link: (x, y, z)} in base_footprint with every joint at 0, the
    arm straight up, e.g. check.arm_check.forward_kinematics of the URDF): the chain's links in order
    (pitch axis, elbow axis, wrist axis, tool centre point).

    Raises:
        ConfigError: a link missing, or a segment of no length.
    """
    points = []
    for link in links:
        if link not in origins:
            raise ConfigError(f"robot_description link {link}", None, "a link of the arm's chain")
        points.append(tuple(float(v) for v in origins[link][:3]))
    lengths = [math.dist(a, b) for a, b in zip(points, points[1:])]
    for link, length in zip(links[1:], lengths):
        if length <= 1e-6:
            raise ConfigError(f"robot_description link {link}", length, "a link away from the previous one")
    shoulder = points[0]
    return ArmGeometry(shoulder[0], shoulder[2], *lengths)


def top_down(arm: ArmGeometry, reach, height):
    """(shoulder_pitch, elbow, wrist) [rad] placing the tool centre point ``reach`` m ahead of base_footprint
    and ``height`` m above the ground with the fingers pointing down. The elbow bends forward (positive);
    pitch + elbow + wrist = pi.

    Raises:
        ValueError: the point is out of the arm's reach.
    """
    dx = reach - arm.shoulder_x  # the wrist axis is straight above the tool
    dz = height + arm.hand - arm.shoulder_z
    distance = math.hypot(dx, dz)
    cos_elbow = (distance ** 2 - arm.upper ** 2 - arm.fore ** 2) / (2.0 * arm.upper * arm.fore)
    if not -1.0 <= cos_elbow <= 1.0:
        raise ValueError(f"the point {reach:.3f} m ahead, {height:.3f} m up is out of the arm's reach "
                         f"({abs(arm.upper - arm.fore):.3f} to {arm.upper + arm.fore:.3f} m from the shoulder)")
    elbow = math.acos(cos_elbow)
    # angles from the vertical, positive tilting forward: the upper arm points at atan2(dx, dz) less the
    # angle the bent elbow adds
    pitch = math.atan2(dx, dz) - math.atan2(arm.fore * math.sin(elbow), arm.upper + arm.fore * math.cos(elbow))
    return pitch, elbow, math.pi - pitch - elbow


def tool_point(arm: ArmGeometry, pitch, elbow, wrist):
    """(reach, height) of the tool centre point for the planar angles (forward kinematics of :func:`top_down`)."""
    x = arm.shoulder_x + arm.upper * math.sin(pitch) + arm.fore * math.sin(pitch + elbow)
    z = arm.shoulder_z + arm.upper * math.cos(pitch) + arm.fore * math.cos(pitch + elbow)
    tip = pitch + elbow + wrist
    return x + arm.hand * math.sin(tip), z + arm.hand * math.cos(tip)


@dataclass(frozen=True)
class Scene:
    """Where the object is and where it goes (defaults: worlds/pick_place.world), and how the robot works there.

    ``pick`` / ``place``: the object's centre (x, y, z) [m] now and where it should end (resting on the place
    table); ``pick_heading`` / ``place_heading`` [rad]: the way the base faces each table (towards it).
    """

    pick: tuple[float, float, float] = (0.64, 0.0, 0.1425)
    place: tuple[float, float, float] = (-0.64, 0.0, 0.1425)
    pick_heading: float = 0.0
    place_heading: float = math.pi
    object_size: float = 0.045  # m across (the fingers close on it)
    standoff: float = 0.16  # m from base_footprint to the object's centre while grasping (table edge clear)
    grasp_above: float = 0.01  # m: tool centre above the object's centre (fingertips clear the table)
    pregrasp_lift: float = 0.06  # m above the grasp pose, before descending and after releasing
    carry_lift: float = 0.10  # m above the grasp pose while carrying
    back_off: float = 0.15  # m the base backs away from a table before turning
    open_width: float = 0.035  # gripper command [m] (left finger position) to open
    close_command: float = 0.0  # gripper command to close (the object stops the fingers first)
    grip_effort: float = 5.0  # N, the gripper goal's max_effort
    arm_move_time: float = 2.0  # s per arm motion (time_from_start of its one point)


class Step(NamedTuple):
    """One step: ``kind`` DRIVE (target: (x, y, direction +1 forward / -1 backward)), TURN (target: yaw),
    ARM (target: the four ARM_JOINTS positions, ``duration`` s) or GRIPPER (target: (position, max_effort),
    ``expect`` OPEN or HOLD)."""

    name: str
    kind: str
    target: tuple
    duration: float = 0.0
    expect: str = ""


def _ahead(point, heading, distance):
    return point[0] + distance * math.cos(heading), point[1] + distance * math.sin(heading)


def _arm_pose(arm, scene, height):
    pitch, elbow, wrist = top_down(arm, scene.standoff, height)
    return (0.0, pitch, elbow, wrist)


def _travel(start, goal, heading, name):
    """Turn towards ``goal`` (x, y), drive to it forward, then turn to ``heading``."""
    steps = []
    direction = math.atan2(goal[1] - start[1], goal[0] - start[0])
    if math.dist(start[:2], goal) > 1e-3:
        steps.append(Step(f"turn towards {name}", TURN, (direction,)))
        steps.append(Step(f"drive to {name}", DRIVE, (goal[0], goal[1], 1.0)))
    steps.append(Step(f"face {name}", TURN, (heading,)))
    return steps


def plan(scene: Scene, arm: ArmGeometry, start=(0.0, 0.0, 0.0)):
    """The steps, in order, from the base at ``start`` (x, y, yaw). Raises ValueError when a pose is out of
    the arm's reach."""
    grasp_z = scene.pick[2] + scene.grasp_above
    place_z = scene.place[2] + scene.grasp_above
    pick_base = _ahead(scene.pick, scene.pick_heading + math.pi, scene.standoff)
    place_base = _ahead(scene.place, scene.place_heading + math.pi, scene.standoff)
    pick_clear = _ahead(pick_base, scene.pick_heading + math.pi, scene.back_off)
    move = scene.arm_move_time
    steps = [Step("open the gripper", GRIPPER, (scene.open_width, scene.grip_effort), expect=OPEN)]
    steps += _travel(start, pick_base, scene.pick_heading, "the pick table")
    steps += [
        Step("pregrasp above the object", ARM, _arm_pose(arm, scene, grasp_z + scene.pregrasp_lift), move),
        Step("lower onto the object", ARM, _arm_pose(arm, scene, grasp_z), move * 0.75),
        Step("close on the object", GRIPPER, (scene.close_command, scene.grip_effort), expect=HOLD),
        Step("lift the object", ARM, _arm_pose(arm, scene, grasp_z + scene.carry_lift), move * 0.75),
        Step("back away from the pick table", DRIVE, (pick_clear[0], pick_clear[1], -1.0)),
    ]
    steps += _travel(pick_clear, place_base, scene.place_heading, "the place table")
    steps += [
        Step("lower onto the place table", ARM, _arm_pose(arm, scene, place_z), move),
        Step("release the object", GRIPPER, (scene.open_width, scene.grip_effort), expect=OPEN),
        Step("retract above the object", ARM, _arm_pose(arm, scene, place_z + scene.pregrasp_lift), move * 0.75),
        Step("home", ARM, HOME, move),
    ]
    return steps


@dataclass(frozen=True)
class MotionConfig:
    """How the base drives and turns in the DRIVE and TURN steps (slow and precise: it carries an object)."""

    speed: float = 0.15  # m/s cruising
    turn_rate: float = 0.8  # rad/s largest
    distance_gain: float = 1.0  # 1/s: speed per m still to go, near the goal
    heading_gain: float = 2.0  # 1/s: turn rate per rad of heading error
    min_speed: float = 0.008  # m/s, so the last millimetres are driven
    min_turn_rate: float = 0.04  # rad/s
    tolerance: float = 0.004  # m along the path
    yaw_tolerance: float = 0.01  # rad
    steer_distance: float = 0.05  # m: closer than this the heading is no longer steered towards the goal


class BaseMotion:
    """One DRIVE or TURN step as a controller: :meth:`command` from the base pose until :attr:`done`.

    DRIVE steers towards the goal point driving forward (``direction`` +1) or backward (-1), slows as it comes
    near and stops on it, backing up slowly if it went past (odometry may reach the controller late, e.g. in
    fast mode); it is done within ``tolerance`` along its heading. TURN turns in place the shorter way to the yaw
    and is done within ``yaw_tolerance``. A caller that stops the base and lets it settle asks a fresh motion
    whether it is still there (:func:`still_there`).
    """

    def __init__(self, step: Step, config: MotionConfig = MotionConfig()):
        if step.kind not in (DRIVE, TURN):
            raise ValueError(f"step {step.name!r} is not a base motion")
        self.step, self.config = step, config
        self.done = False

    def error(self, x, y, yaw):
        """What is left: m along the driving direction (negative: past the goal) or rad to turn."""
        if self.step.kind == TURN:
            return wrap_angle(self.step.target[0] - yaw)
        gx, gy, direction = self.step.target
        return direction * ((gx - x) * math.cos(yaw) + (gy - y) * math.sin(yaw))

    def command(self, x, y, yaw):
        """(linear, angular) for the pose (x, y, yaw); (0, 0) once done."""
        cfg = self.config
        if self.done:
            return 0.0, 0.0
        error = self.error(x, y, yaw)
        if self.step.kind == TURN:
            if abs(error) < cfg.yaw_tolerance:
                self.done = True
                return 0.0, 0.0
            rate = max(cfg.min_turn_rate, min(cfg.turn_rate, cfg.heading_gain * abs(error)))
            return 0.0, math.copysign(rate, error)
        if abs(error) < cfg.tolerance:
            self.done = True
            return 0.0, 0.0
        gx, gy, direction = self.step.target
        speed = max(cfg.min_speed, min(cfg.speed, cfg.distance_gain * abs(error)))
        angular = 0.0
        if error > cfg.steer_distance:  # steer while the goal is ahead and far enough to have a direction
            dx, dy = gx - x, gy - y
            bearing = math.atan2(dy, dx) if direction > 0 else math.atan2(-dy, -dx)
            angular = max(-cfg.turn_rate, min(cfg.turn_rate, cfg.heading_gain * wrap_angle(bearing - yaw)))
        return direction * math.copysign(speed, error), angular


def still_there(step: Step, x, y, yaw, config: MotionConfig = MotionConfig()):
    """Whether the base, stopped and settled at (x, y, yaw), is within the step's tolerance of its goal."""
    motion = BaseMotion(step, config)
    motion.command(x, y, yaw)
    return motion.done


def gripper_outcome(step: Step, status: str, position: float | None, reached_goal: bool, stalled: bool,
                    object_size: float, tolerance: float = 0.008):
    """(ok, reason) for a GRIPPER step's result: ``status`` "SUCCEEDED" / "ABORTED" / other, the result's
    ``position`` [m] (one finger's, so half the opening), ``reached_goal`` and ``stalled``.

    OPEN wants the goal reached. HOLD wants the fingers stopped on the object: stalled (or reached, should a
    goal be set to the object's width), with half the opening within ``tolerance`` of half the object's size.
    """
    if position is None or not math.isfinite(position):
        return False, f"{step.name}: no result ({status})"
    if step.expect == OPEN:
        return (status == "SUCCEEDED" and reached_goal,
                f"{step.name}: {status}, reached_goal={reached_goal}, finger at {position:.4f} m")
    held = abs(position - object_size / 2.0) <= tolerance
    stopped = stalled or reached_goal
    if held and stopped:
        return True, f"{step.name}: stalled on the object, finger at {position:.4f} m"
    if not held:
        return False, (f"{step.name}: the finger stopped at {position:.4f} m, not on a {object_size:.3f} m object "
                       f"(expected {object_size / 2.0:.4f} +- {tolerance:.3f} m): nothing grasped")
    return False, f"{step.name}: {status}, neither stalled nor at its goal"


def describe(steps: Sequence[Step]):
    """One line per step (for the log)."""
    lines = []
    for index, step in enumerate(steps, 1):
        target = ", ".join(v if isinstance(v, str) else f"{v:.3f}" for v in step.target)
        lines.append(f"{index:2d}. {step.name} ({step.kind}: {target})")
    return lines


#: The tables of worlds/pick_place.world as MoveIt collision boxes: (name, centre (x, y, z) [m], size (x, y, z) [m]).
#: Each is the solid block from the floor to its top surface (z 0.12): the arm never reaches under a table.
TABLES = (("pick_table", (0.75, 0.0, 0.06), (0.30, 0.40, 0.12)),
          ("place_table", (-0.75, 0.0, 0.06), (0.30, 0.40, 0.12)))


def top_down_pose(point, shoulder):
    """(x, y, z, qx, qy, qz, qw): gripper_tcp_link at ``point`` (x, y, z) with the fingers pointing straight down,
    turned about the vertical towards ``point`` from ``shoulder`` (x, y), the shoulder yaw axis: the orientation
    a 4-joint arm (yaw, then three pitch joints) has there, so that a 6-D pose goal is one it can reach.
    The rotation is Rz(yaw) Ry(pi)."""
    yaw = math.atan2(point[1] - shoulder[1], point[0] - shoulder[0])
    s, c = math.sin(yaw / 2.0), math.cos(yaw / 2.0)
    return (float(point[0]), float(point[1]), float(point[2]), -s, c, 0.0, 0.0)


def shoulder_xy(arm: ArmGeometry, x, y, yaw):
    """(x, y) of the shoulder yaw axis for the base at (x, y, yaw)."""
    return x + arm.shoulder_x * math.cos(yaw), y + arm.shoulder_x * math.sin(yaw)


#: MoveIt step kinds: the arm to a tool pose (target: a :func:`top_down_pose` point, z [m]), the arm to a named
#: pose of the SRDF (target: (name,)), the gripper to a left_finger_joint position (target: (position,)).
POSE, NAMED, FINGERS = "pose", "named", "fingers"


def moveit_steps(scene: Scene, start=(0.0, 0.0, 0.0)):
    """The pick-and-place of :func:`plan` for MoveIt: the same base motions; the arm's steps as tool points above
    the object (POSE: target (x, y, z) in the world; the caller turns it into :func:`top_down_pose` from where the
    base is then), the gripper's as finger positions (FINGERS), home as the SRDF's named pose (NAMED)."""
    grasp = (scene.pick[0], scene.pick[1], scene.pick[2] + scene.grasp_above)
    place = (scene.place[0], scene.place[1], scene.place[2] + scene.grasp_above)
    pick_base = _ahead(scene.pick, scene.pick_heading + math.pi, scene.standoff)
    place_base = _ahead(scene.place, scene.place_heading + math.pi, scene.standoff)
    pick_clear = _ahead(pick_base, scene.pick_heading + math.pi, scene.back_off)

    def above(point, lift):
        return (point[0], point[1], point[2] + lift)
    steps = [Step("open the gripper", FINGERS, (scene.open_width,), expect=OPEN)]
    steps += _travel(start, pick_base, scene.pick_heading, "the pick table")
    steps += [
        Step("pregrasp above the object", POSE, above(grasp, scene.pregrasp_lift)),
        Step("lower onto the object", POSE, grasp),
        Step("close on the object", FINGERS, (scene.close_command,), expect=HOLD),
        Step("lift the object", POSE, above(grasp, scene.carry_lift)),
        Step("back away from the pick table", DRIVE, (pick_clear[0], pick_clear[1], -1.0)),
    ]
    steps += _travel(pick_clear, place_base, scene.place_heading, "the place table")
    steps += [
        Step("above the place point", POSE, above(place, scene.pregrasp_lift)),
        Step("lower onto the place table", POSE, place),
        Step("release the object", FINGERS, (scene.open_width,), expect=OPEN),
        Step("retract above the object", POSE, above(place, scene.pregrasp_lift)),
        Step("home", NAMED, ("home",)),
    ]
    return steps
