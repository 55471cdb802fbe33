"""franka_gazebo's FrankaGripperSim (franka_ros 0.10.1, ``franka_gazebo/src/franka_gripper_sim.cpp`` and its
header) without ROS: the two finger joints driven by effort through a PID each, in one of four states, and the
goals of its actions (homing, move, grasp, stop, and control_msgs' gripper command) carried out as upstream's
blocking callbacks carry them out, here as jobs the update advances.

States (upstream's): IDLE (each finger tracks the other's position at zero speed: a mimicked pair, damped),
MOVING (both fingers track a width moving at the goal's speed; reaching the width within the tolerance ends in
IDLE), GRASPING (the same towards fully closed or fully open, with the grasp's force), HOLDING (each finger
tracks the other and pushes with half the force). MOVING and GRASPING end when the fingers' summed speed stays
at or below ``grasp/resting_threshold`` for ``grasp/consecutive_samples`` updates: a grasp then HOLDs, a move
blocked by an object goes IDLE.

Goals as upstream answers them: ``move`` succeeds with ``success`` whether the width is within
``move/width_tolerance`` when the fingers stopped; ``grasp`` is aborted unless the gripper ends HOLDING, else
succeeds with ``success`` whether the width is within the goal's epsilon (if not, the gripper goes IDLE);
``homing`` closes and opens fully at 0.02 m/s; ``stop`` interrupts every goal and goes IDLE; a gripper command's
position is half the width (MoveIt commands one finger) and it moves (``max_effort`` ~0 or opening) or grasps.
"""
import math
from dataclasses import dataclass

from diffbot_sim.control.pid import Pid, PidGains, pid_gains
from diffbot_sim.errors import ConfigError
from diffbot_sim.values import check_number

CONTROLLER_TYPE = "franka_gazebo/FrankaGripperSim"
IDLE, HOLDING, MOVING, GRASPING = "IDLE", "HOLDING", "MOVING", "GRASPING"
MAX_FINGER_WIDTH = 0.08  # kMaxFingerWidth [m]
DEFAULT_MOVE_WIDTH_TOLERANCE = 0.001  # [m]
DEFAULT_GRIPPER_ACTION_WIDTH_TOLERANCE = 0.005  # [m]
DEFAULT_GRIPPER_ACTION_SPEED = 0.1  # [m/s]
GRASP_RESTING_THRESHOLD = 0.003  # [m/s]
GRASP_CONSECUTIVE_SAMPLES = 10
HOMING_SPEED = 0.02  # [m/s]
MINIMUM_GRASP_FORCE = 1e-4  # [N]: a gripper command with less moves instead of grasping


@dataclass(frozen=True)
class GripperConfig:
    arm_id: str
    finger1: str
    finger2: str
    move_width_tolerance: float
    gripper_action_width_tolerance: float
    gripper_action_speed: float
    resting_threshold: float
    consecutive_samples: int
    gains1: PidGains  # finger1/gains
    gains2: PidGains


def gripper_config(params, name, model_joints):
    """FrankaGripperSim::init's parameters (``<name>/...``).

    Raises:
        ConfigError: no ``arm_id``, finger joints the model lacks, no finger gains, a bad number; naming it.
    """
    arm_id = params.get("arm_id")
    if not isinstance(arm_id, str) or not arm_id:
        raise ConfigError(f"{name}/arm_id", arm_id, "the arm's name (FrankaGripperSim requires it)")
    fingers = [f"{arm_id}_finger_joint1", f"{arm_id}_finger_joint2"]
    for joint in fingers:
        if joint not in model_joints:
            raise ConfigError(f"{name}/arm_id", arm_id, f"an arm with finger joints {fingers[0]} and {fingers[1]} "
                              f"(the model has no {joint})")
    gains = []
    for key in ("finger1", "finger2"):
        where = f"{name}/{key}/gains"
        found = pid_gains((params.get(key) or {}).get("gains") if isinstance(params.get(key), dict) else None, where)
        if found is None:
            raise ConfigError(where, None, "PID gains with a p (FrankaGripperSim's init fails without them)")
        gains.append(found)

    def number(path, default, **limits):
        section, key = path.split("/")
        value = (params.get(section) or {}).get(key, default) if isinstance(params.get(section), dict) else default
        return check_number(f"{name}/{path}", value, **limits)
    return GripperConfig(
        arm_id, fingers[0], fingers[1],
        number("move/width_tolerance", DEFAULT_MOVE_WIDTH_TOLERANCE, low=0.0),
        number("gripper_action/width_tolerance", DEFAULT_GRIPPER_ACTION_WIDTH_TOLERANCE, low=0.0),
        number("gripper_action/speed", DEFAULT_GRIPPER_ACTION_SPEED, low=0.0),
        number("grasp/resting_threshold", GRASP_RESTING_THRESHOLD, low=0.0),
        int(number("grasp/consecutive_samples", GRASP_CONSECUTIVE_SAMPLES, low=1)),
        gains[0], gains[1])


@dataclass
class Target:
    """Upstream's Config: what the fingers are driven to."""

    width: float = 0.0
    speed: float = 0.0
    force: float = 0.0
    inner: float = 0.0
    outer: float = 0.0


@dataclass
class Finished:
    """A goal's end: ``outcome`` "succeeded" or "aborted" (actionlib's), with the result's fields."""

    goal_id: str
    kind: str  # homing, move, grasp, stop, gripper_action
    outcome: str
    success: bool
    error: str = ""
    width: float = 0.0  # the width [m] when it ended (the gripper command's result position)


@dataclass
class Job:
    goal_id: str
    kind: str
    width: float = 0.0
    speed: float = 0.0
    force: float = 0.0
    inner: float = 0.0
    outer: float = 0.0
    phase: str = ""  # what the job waits for: move, grasp, homing_close, homing_open
    waiting_from: str = IDLE  # the state it waits to leave (waitUntilStateChange)


class FrankaGripperCore:
    """The gripper's state, its two PIDs and the goal being carried out."""

    def __init__(self, cfg: GripperConfig):
        self.cfg = cfg
        self.pid1, self.pid2 = Pid(cfg.gains1), Pid(cfg.gains2)
        self.state, self.target = IDLE, Target()
        self.job: Job | None = None
        self._resting = 0
        self._finished: list[Finished] = []

    def starting(self):
        self.state, self.target = IDLE, Target()
        self.pid1.reset()
        self.pid2.reset()

    # -- goals ------------------------------------------------------------------------------------------------
    def _interrupt(self, text):
        if self.job is not None:
            self._finish(self.job, "aborted", False, text)

    def _finish(self, job, outcome, success, error="", width=0.0):
        self._finished.append(Finished(job.goal_id, job.kind, outcome, success, error, width))
        if job is self.job:
            self.job = None

    def _transition(self, state, target):
        self.state, self.target = state, target
        if self.job is not None:
            self.job.waiting_from = state

    def _move(self, job, width, speed):
        tol = self.cfg.move_width_tolerance
        job.phase = job.phase or "move"
        self._transition(MOVING, Target(width, speed, 0.0, tol, tol))

    def _grasp(self, job, width, speed, force, inner, outer, current):
        direction = math.copysign(1.0, width - current)
        job.width, job.inner, job.outer, job.phase = width, inner, outer, "grasp"
        self._transition(GRASPING, Target(0.0 if width < current else MAX_FINGER_WIDTH, speed, direction * force,
                                          inner, outer))

    def homing(self, goal_id):
        self._interrupt("Command interrupted, because new homing action called")
        self.job = Job(goal_id, "homing", phase="homing_close")
        tol = self.cfg.move_width_tolerance
        self._transition(MOVING, Target(0.0, HOMING_SPEED, 0.0, tol, tol))

    def move(self, goal_id, width, speed):
        """A move goal; its refusal text, or None when started."""
        if speed < 0:
            return "Only positive speeds allowed"
        if not math.isfinite(width) or width < 0 or width > MAX_FINGER_WIDTH:
            return f"Target width has to lie between 0 .. {MAX_FINGER_WIDTH:f}"
        self._interrupt("Command interrupted, because new move action called")
        self.job = Job(goal_id, "move", width=width, speed=speed)
        self._move(self.job, width, speed)
        return None

    def grasp(self, goal_id, width, speed, force, inner, outer, current):
        if not width < MAX_FINGER_WIDTH or width < 0:
            return f"Can only grasp inside finger width from [0 .. {MAX_FINGER_WIDTH:f}["
        if speed < 0:
            return "Only positive speeds allowed"
        self._interrupt("Command interrupted, because new grasp action called")
        self.job = Job(goal_id, "grasp")
        self._grasp(self.job, width, speed, force, inner, outer, current)
        return None

    def gripper_command(self, goal_id, position, max_effort, current):
        """control_msgs' GripperCommand: ``position`` is one finger's, so the width is twice it."""
        width = position * 2.0
        if width > MAX_FINGER_WIDTH or width < 0.0:
            return (f"Commanding out of range position! max_position = {MAX_FINGER_WIDTH / 2:f}, commanded position "
                    f"= {position:f}. Be aware that you command the position of each finger which is half of the "
                    "total opening width!")
        self._interrupt("Command interrupted, because new gripper command called")
        self.job = Job(goal_id, "gripper_action", width=width)
        tol = self.cfg.gripper_action_width_tolerance
        if abs(max_effort) < MINIMUM_GRASP_FORCE or width > current:
            self._move(self.job, width, self.cfg.gripper_action_speed)
        else:
            self._grasp(self.job, width, self.cfg.gripper_action_speed, max_effort, tol, tol, current)
        return None

    def stop(self, goal_id):
        """Stop: every goal interrupted, the fingers IDLE where they are; succeeds at once."""
        self._interrupt("Command interrupted, because stop action was called")
        self._transition(IDLE, Target(self.target.width, 0.0, 0.0, self.target.inner, self.target.outer))
        self._finished.append(Finished(goal_id, "stop", "succeeded", True))

    def cancel(self, goal_id):
        """A goal canceled by its client: the gripper goes IDLE (upstream's preempt callbacks)."""
        if self.job is not None and self.job.goal_id == goal_id:
            self.job = None
            self.state = IDLE
            return True
        return False

    def take_finished(self):
        out, self._finished = self._finished, []
        return out

    # -- the update ---------------------------------------------------------------------------------------------
    def update(self, dt, positions, velocities):
        """One control period: the two finger efforts [N], and the job advanced when the state changed."""
        (q1, q2), (v1, v2) = positions, velocities
        width = q1 + q2
        before = self.state
        efforts = self._control(dt, q1, q2, v1, v2, width)
        if self.state != before or (self.job is not None and self.job.waiting_from != self.state):
            self._advance(width)
        return efforts

    def _control(self, dt, q1, q2, v1, v2, width):
        target = self.target
        if self.state == IDLE:
            return (self.pid1.compute(q2 - q1, dt, -v1), self.pid2.compute(q1 - q2, dt, -v2))
        speed = target.speed * math.copysign(1.0, target.width - width)
        w1, w2 = q1 + 0.5 * speed * dt, q2 + 0.5 * speed * dt
        force = 0.0
        if self.state == HOLDING:
            w1, w2, force = q2, q1, target.force / 2.0
        efforts = (self.pid1.compute(w1 - q1, dt, 0.5 * speed - v1) + force,
                   self.pid2.compute(w2 - q2, dt, 0.5 * speed - v2) + force)
        if self.state == MOVING and target.width - target.inner < width < target.width + target.outer:
            self.state, self.target = IDLE, Target(target.width, 0.0, 0.0, target.inner, target.outer)
            return efforts
        if self.state in (GRASPING, MOVING):
            self._resting = self._resting + 1 if abs(v1 + v2) <= self.cfg.resting_threshold else 0
            if self._resting >= self.cfg.consecutive_samples:
                self._resting = 0
                if self.state == GRASPING:
                    self.state, self.target = HOLDING, Target(width, 0.0, target.force, target.inner, target.outer)
                else:
                    self.state, self.target = IDLE, Target(width, 0.0, 0.0, target.inner, target.outer)
        return efforts

    def _advance(self, width):
        """The job's wait (waitUntilStateChange) ended: what its callback does next."""
        job = self.job
        if job is None:
            return
        state = self.state
        if job.phase == "homing_close":
            job.phase = "homing_open"
            tol = self.cfg.move_width_tolerance
            self._transition(MOVING, Target(MAX_FINGER_WIDTH, HOMING_SPEED, 0.0, tol, tol))
        elif job.phase == "homing_open":
            if state != IDLE:
                self._finish(job, "aborted", False, "Unexpected state transistion: The gripper not in IDLE as "
                             "expected", width)
            else:
                self._finish(job, "succeeded", True, "", width)
        elif job.phase == "move":
            if state != IDLE:
                self._finish(job, "aborted", False, "Unexpected state transistion: The gripper not in IDLE as "
                             "expected", width)
            elif job.kind == "gripper_action":
                self._finish(job, "succeeded", True, "", width)  # move() returned true: reached_goal
            else:
                tol = self.cfg.move_width_tolerance
                self._finish(job, "succeeded", job.width - tol < width < job.width + tol, "", width)
        elif job.phase == "grasp":
            if state != HOLDING:
                self._finish(job, "aborted", False, "Unexpected state transistion: The gripper not in HOLDING as "
                             "expected", width)
                return
            ok = job.width - job.inner < width < job.width + job.outer
            error = "" if ok else (
                f"When the gripper stopped (below speed of {self.cfg.resting_threshold:f} m/s the width between the "
                f"fingers was not at {job.width:f}m (-{job.inner:f}m/+{job.outer:f}m) but at {width:f}m")
            if not ok:
                self.state = IDLE
            self._finish(job, "succeeded", ok, error if job.kind == "grasp" else "", width)
