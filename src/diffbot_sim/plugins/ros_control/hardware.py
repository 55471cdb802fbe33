"""gazebo_ros_control's DefaultRobotHWSim: every ``<transmission>`` joint commanded as Gazebo commands it.

Each transmission joint with a Position, Velocity or Effort interface gets a command buffer (controllers
write it), its joint limits (URDF ``<limit>`` and ``<safety_controller>``, then ``<ns>/joint_limits/<joint>``;
:mod:`diffbot_sim.control.joint_limits`) and a control method (gazebo_ros_control's ``default_robot_hw_sim.cpp``):

* EFFORT: the command, limited, as the joint's torque, every physics step (zero until commanded);
* POSITION (no ``pid_gains``): Gazebo sets the joint's position (a kinematic set, clamped to its limits, the
  URDF velocity rate-limiting the command). Here: a position motor that removes the whole error in one step
  with an effort far above any model's (UNLIMITED_EFFORT), so the joint is where it was told, through the
  solver (contacts stay consistent);
* VELOCITY (no gains): a velocity motor capped at the URDF effort limit (ODE's ``vel``/``fmax``);
* POSITION_PID / VELOCITY_PID (``<ns>/gazebo_ros_control/pid_gains/<joint>`` with a ``p``): the PID's output,
  clamped to the effort limit, as the joint's torque every step, the position error taken as Gazebo takes it
  (shortest angle within the limits for revolute joints, shortest angle for continuous ones).

Where Gazebo's PID recipe is unstable at our step (gains tuned for 1 ms on light links; measured with
:func:`diffbot_sim.control.pid.explicit_loop_margin` against the inertia the joint moves), the joint runs the
implicit form of the same loop instead, with one warning naming it: PyBullet's position (velocity) motor,
which its solver holds at the target within the same effort limit, so the joint reaches and holds its target
under gravity. Limits are enforced every physics step (``period`` = the step), in upstream's order. The e-stop
(``eStopTopic``) freezes position commands at the measured positions and zeroes efforts and velocities.
``read`` gives what ``readSim`` gives: positions unwrapped for revolute and continuous joints, velocities, and
as effort the commanded torque (Gazebo's GetForce) for effort and PID joints, 0 for the motors Gazebo drives
kinematically (the implicit PID joints report the torque their motor applied).
"""
import math
from dataclasses import dataclass

from diffbot_sim.control.angles import shortest_angular_distance, shortest_angular_distance_with_limits
from diffbot_sim.control.joint_limits import JointLimitsInterfaceError, register_joint_limits
from diffbot_sim.control.pid import STABILITY_MARGIN, Pid, explicit_loop_margin, loop_verdict, pid_gains
from diffbot_sim.errors import ConfigError
from diffbot_sim.plugins.base import get_param, join
from diffbot_sim.plugins.joint_motors import UNLIMITED_EFFORT

EFFORT, POSITION, POSITION_PID, VELOCITY, VELOCITY_PID = (
    "EFFORT", "POSITION", "POSITION_PID", "VELOCITY", "VELOCITY_PID")
#: PyBullet's position gain for a POSITION joint: the motor removes the whole position error each step, the
#: nearest a constraint comes to Gazebo's SetPosition.
KINEMATIC_POSITION_GAIN = 1.0
_PI, _TWO_PI = math.pi, 2.0 * math.pi
_fmod, _isfinite = math.fmod, math.isfinite


@dataclass
class SimJoint:
    """One transmission joint of the hardware: its buffers and how it is driven."""

    name: str
    index: int  # PyBullet joint index
    interface: str  # PositionJointInterface, VelocityJointInterface or EffortJointInterface
    method: str  # EFFORT, POSITION, POSITION_PID, VELOCITY, VELOCITY_PID
    joint_type: str  # revolute, continuous, prismatic (or inferred from the limits)
    lower: float
    upper: float
    effort_limit: float  # N·m or N; inf without a limit
    velocity_limit: float  # rad/s or m/s; inf without a limit
    limit_handle: object = None
    pid: Pid | None = None  # explicit PID (None: no gains, or run as an implicit motor)
    implicit: bool = False  # a PID joint run as PyBullet's motor
    command: float = 0.0
    position: float | None = None  # unwrapped (readSim); None before the first read
    velocity: float = 0.0
    effort: float = 0.0
    frozen: float | None = None  # e-stop: the position held
    pushed: object = None  # the last motor setting given to PyBullet (skipped when unchanged)
    #: a controller whose own PID is unstable on this joint hands it targets instead of efforts: "position" or
    #: "velocity", driven by PyBullet's motor with at most ``target_force`` (None: the effort limit)
    target_mode: str | None = None
    target_force: float | None = None

    @property
    def motor_force(self):
        """The force cap of a PyBullet motor standing in for Gazebo's (finite)."""
        return min(self.effort_limit, UNLIMITED_EFFORT)

    @property
    def torque_driven(self):
        """Driven by a torque set every step (effort joints, explicit PIDs)."""
        return self.target_mode is None and (self.method == EFFORT or self.pid is not None)


class RobotHWSim:
    """The joints of one ``libgazebo_ros_control.so``; ``write`` applies the commands every physics step."""

    def __init__(self, ctx, ns, warnings):
        self.ctx = ctx
        self.ns = ns
        self.estop = False
        self.joints = {}  # name -> SimJoint, in transmission order
        model, robot = ctx.model, ctx.robot
        dt = ctx.cfg.time_step
        for other in model.other_transmissions:  # several joints, or an interface it has no handle for
            warnings.append(f"gazebo_ros_control: {other.warning}")
        for trans in model.transmissions:
            if trans.joint not in robot.joint_index:
                warnings.append(f"gazebo_ros_control: joint '{trans.joint}' of transmission '{trans.name}' is not "
                                "in the simulated model (a fixed joint?); it has no hardware handle")
                continue
            self.joints[trans.joint] = self._make_joint(trans, ns, warnings)
        self._check_stability(dt, warnings)
        robot.free_joints([j.index for j in self.joints.values() if j.torque_driven])
        self._order = list(self.joints.values())
        self._indices = [j.index for j in self._order]
        #: False once a write changed nothing the physics holds (every joint a PyBullet motor whose target is
        #: the controller's command, unclipped by its limits): until a command changes, the steps need no write
        self.busy = True

    def _make_joint(self, trans, ns, warnings):
        urdf_joint = self.ctx.model.joints.get(trans.joint)
        limits_params = get_param(join(ns, f"joint_limits/{trans.joint}"), None)
        try:
            limits = register_joint_limits(trans.joint, trans.interface, urdf_joint, limits_params, ns)
        except JointLimitsInterfaceError as err:
            raise ConfigError(join(ns, f"joint_limits/{trans.joint}"), limits_params, str(err)) from None
        method = {"EffortJointInterface": EFFORT, "PositionJointInterface": POSITION,
                  "VelocityJointInterface": VELOCITY}[trans.interface]
        pid = None
        if method != EFFORT:
            where = join(ns, f"gazebo_ros_control/pid_gains/{trans.joint}")
            gains = pid_gains(get_param(where, None), where)
            if gains is not None:
                method, pid = method + "_PID", Pid(gains)
        effort = limits.effort_limit if limits.effort_limit < 1e300 else math.inf
        velocity = (limits.limits.max_velocity if limits.limits is not None and limits.limits.has_velocity_limits
                    else math.inf)
        return SimJoint(trans.joint, self.ctx.robot.joint_index[trans.joint], trans.interface, method,
                        limits.joint_type, limits.lower, limits.upper, effort, velocity, limits.handle, pid)

    def _check_stability(self, dt, warnings):
        """Keep an explicit PID only where its discrete loop is well damped at our step (module docstring)."""
        pids = [j for j in self.joints.values() if j.pid is not None]
        if not pids:
            return
        inertias = self.ctx.robot.joint_inertias([j.index for j in pids])
        for joint, inertia in zip(pids, inertias):
            loop = "velocity" if joint.method == VELOCITY_PID else "position"
            margin = explicit_loop_margin(joint.pid.gains, dt, inertia, loop)
            if margin > STABILITY_MARGIN:
                gains = joint.pid.gains
                warnings.append(
                    f"{join(self.ns, 'gazebo_ros_control/pid_gains')}/{joint.name}: p={gains.p:g} d={gains.d:g} at a "
                    f"{dt * 1000:.2f} ms step is {loop_verdict(gains, margin, loop)} explicit loop on "
                    f"this joint (it moves {inertia:.3g} {'kg' if joint.joint_type == 'prismatic' else 'kg·m^2'}, "
                    f"{margin:.2g} of the stability bound); it runs as PyBullet's {loop} motor with the same "
                    f"effort limit instead")
                joint.pid, joint.implicit = None, True

    # -- what controllers see ---------------------------------------------------------------------------
    def names(self):
        return list(self.joints)

    def interface(self, joint):
        return self.joints[joint].interface if joint in self.joints else None

    def set_command(self, joint, value):
        """A controller's command (rad, m, rad/s, m/s, N·m or N, per the joint's interface)."""
        sim_joint = self.joints[joint]
        if value != sim_joint.command:
            sim_joint.command = value
            self.busy = True

    def explicit_margin(self, joint, gains, loop):
        """How much of its stability bound a controller's PID (``gains``, on ``loop`` "position" or
        "velocity") uses as an explicit force on ``joint`` at our step (see ``_check_stability``)."""
        inertia = self.ctx.robot.joint_inertias([self.joints[joint].index])[0]
        return explicit_loop_margin(gains, self.ctx.cfg.time_step, inertia, loop), inertia

    def drive_by_targets(self, joint, mode, force=None):
        """From now on ``set_command`` on ``joint`` gives a ``mode`` ("position" or "velocity") target that
        PyBullet's motor holds within ``force`` (default: the effort limit): for a controller whose own PID
        cannot run explicitly at our step."""
        sim_joint = self.joints[joint]
        sim_joint.target_mode, sim_joint.target_force, sim_joint.pushed = mode, force, None
        self.busy = True

    def set_target_force(self, joint, force):
        self.joints[joint].target_force = force
        self.busy = True

    def positions(self, names):
        return [self.joints[n].position for n in names]

    def velocities(self, names):
        return [self.joints[n].velocity for n in names]

    def set_estop(self, active):
        """eStopTopic: on the first active update, position commands freeze at the measured positions."""
        self.busy = True
        if active and not self.estop:
            for joint in self._order:
                joint.frozen = joint.position
        self.estop = active

    # -- readSim / writeSim -------------------------------------------------------------------------------
    # Both run every physics step for an effort arm: one pass over the joints each, the angle unwrapping
    # (``joint.position + shortest_angular_distance(joint.position, raw)``) written out with the same arithmetic.
    def read(self):
        """readSim: positions (unwrapped for revolute/continuous joints), velocities, efforts."""
        if not self._order:
            return
        positions, velocities, torques = self.ctx.robot.joint_states(self._indices)
        for joint, raw, velocity, torque in zip(self._order, positions, velocities, torques):
            previous = joint.position
            if previous is None or joint.joint_type == "prismatic":
                joint.position = raw
            else:
                delta = _fmod(raw - previous + _PI, _TWO_PI)
                joint.position = previous + (delta + _PI if delta <= 0.0 else delta - _PI)
            joint.velocity = velocity
            if joint.implicit or joint.target_mode is not None:
                joint.effort = torque
            elif not (joint.method == EFFORT or joint.pid is not None):  # not torque-driven
                joint.effort = 0.0

    def start(self):
        """Buffers as initSim leaves them: every command 0, PIDs reset; limit handles re-read positions."""
        self.read()
        self.busy = True
        for joint in self._order:
            joint.command, joint.frozen, joint.pushed = 0.0, None, None
            if joint.pid is not None:
                joint.pid.reset()
            if joint.limit_handle is not None:
                joint.limit_handle.reset(None)

    def write(self, dt):
        """writeSim, every physics step: each joint's command, limited, to the physics. Sets ``busy``: whether
        the next step needs a write too (a torque lasts one step; a limit still clipping a command moves its
        bound every step); a motor holding an unclipped command needs none until the command changes."""
        if not self._order:
            self.busy = False
            return
        robot = self.ctx.robot
        positions, velocities, _ = robot.joint_states(self._indices)
        torques, torque_idx = [], []
        busy = False
        estop = self.estop
        for joint, raw, velocity in zip(self._order, positions, velocities):
            previous = joint.position
            if previous is None or joint.joint_type == "prismatic":
                position = raw
            else:
                delta = _fmod(raw - previous + _PI, _TWO_PI)
                position = previous + (delta + _PI if delta <= 0.0 else delta - _PI)
            command = self._command(joint) if estop else joint.command
            mode = joint.target_mode
            if mode is not None:
                force = joint.motor_force if joint.target_force is None else joint.target_force
                setting: tuple = ("p" if mode == "position" else "v", command, force)
                if joint.pushed != setting:  # motor targets persist in PyBullet: given only when changed
                    if mode == "position":
                        robot.set_positions([joint.index], [command], [force])
                    else:
                        robot.set_velocities([joint.index], [command], [force])
                    joint.pushed = setting
                continue
            handle = joint.limit_handle
            if handle is not None:
                limited = handle.enforce(command, position, velocity, dt)
                if limited != command:
                    busy = True
                command = limited
            method = joint.method
            if method == EFFORT or joint.pid is not None:  # torque-driven
                busy = True
                effort = command if method == EFFORT else self._pid_effort(joint, command, position, velocity, dt)
                # _truncate, written out
                limit = joint.velocity_limit
                if velocity > limit and effort > 0 or velocity < -limit and effort < 0:
                    effort = 0.0
                else:
                    limit = joint.effort_limit
                    if _isfinite(limit):
                        effort = max(-limit, min(limit, effort))
                joint.effort = effort
                torques.append(effort)
                torque_idx.append(joint.index)
            elif method in (POSITION, POSITION_PID):
                setting = ("p", command)
                if joint.pushed != setting:
                    robot.set_positions([joint.index], [command],
                                        [joint.motor_force if joint.implicit else UNLIMITED_EFFORT],
                                        None if joint.implicit else KINEMATIC_POSITION_GAIN)
                    joint.pushed = setting
            else:
                setting = ("v", command)
                if joint.pushed != setting:
                    robot.set_velocities([joint.index], [command], [joint.motor_force])
                    joint.pushed = setting
        if torque_idx:
            robot.set_efforts(torque_idx, torques)
        self.busy = busy

    def _command(self, joint):
        if not self.estop:
            return joint.command
        if joint.method in (POSITION, POSITION_PID) or joint.target_mode == "position":
            return joint.frozen if joint.frozen is not None else joint.command
        return 0.0

    def _pid_effort(self, joint, command, position, velocity, dt):
        if joint.method == VELOCITY_PID:
            error = command - velocity
        elif joint.joint_type == "revolute":
            error = shortest_angular_distance_with_limits(position, command, joint.lower, joint.upper)[1]
        elif joint.joint_type == "continuous":
            error = shortest_angular_distance(position, command)
        else:
            error = command - position
        return joint.pid.compute(error, dt)


def _truncate(effort, velocity, joint):
    """Gazebo's Joint::CheckAndTruncateForce inside every SetForce: no push further while the joint is faster
    than its velocity limit, then clamped to the effort limit."""
    if velocity > joint.velocity_limit and effort > 0 or velocity < -joint.velocity_limit and effort < 0:
        return 0.0
    limit = joint.effort_limit
    return max(-limit, min(limit, effort)) if math.isfinite(limit) else effort
