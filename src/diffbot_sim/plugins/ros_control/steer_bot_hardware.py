"""``robotSimType steer_bot_hardware_gazebo/SteerBotHardwareGazebo``: a bicycle model's two joints mapped onto a
car's wheels and steering linkage (the mapping and its YAML: :mod:`diffbot_sim.control.steer_bot_hardware`).

Hardware handles, as upstream registers them (the robot's ``<transmission>``s are not read):

* ``rear_wheel`` (VelocityJointInterface) and ``front_steer`` (PositionJointInterface): the bicycle model the
  controller commands; ``rear_wheel`` reads the mean of the virtual rear wheels, ``front_steer`` its own
  command;
* the virtual rear wheels (velocity) and virtual front steers (position) with commands of their own that the
  hardware never applies, and the virtual front wheels (state only), all read from the physics.

Every physics step (writeSim) every virtual wheel is set to the ``rear_wheel`` command (Gazebo's SetVelocity:
the joint's velocity set before the step, the joint free during it, so friction acts on a free wheel: the four
wheels at one speed scrub in a turn through the wheels' own inertia, not through a motor of unlimited torque
that would overrule the steering) and each virtual steer is set to its linkage angle
(Gazebo's SetPosition, clamped to the joint's limits: here a position motor removing the whole error in one
step). The model's own ``rear_wheel``/``front_steer`` joints, if it has them, are not driven (free, as in
Gazebo). The e-stop is stored and has no effect (upstream's writeSim ignores it).
"""
import math
from dataclasses import dataclass

from diffbot_sim.control import steer_bot_hardware as sbh
from diffbot_sim.control.angles import shortest_angular_distance
from diffbot_sim.errors import ConfigError, PluginNotLoaded
from diffbot_sim.plugins.base import get_param, join
from diffbot_sim.plugins.joint_motors import UNLIMITED_EFFORT
from diffbot_sim.plugins.ros_control.hardware import KINEMATIC_POSITION_GAIN

SIM_TYPE = sbh.SIM_TYPE
VELOCITY, POSITION = "VelocityJointInterface", "PositionJointInterface"


@dataclass
class Handle:
    """One hardware handle: its buffers as the controllers and joint_state_controller see them."""

    name: str
    interface: str | None  # None: state only
    index: int | None = None  # PyBullet joint of a virtual joint; None for the bicycle model's two
    command: float = 0.0
    position: float = 0.0
    velocity: float = 0.0
    effort: float = 0.0
    method: str = "STEER_BOT"
    implicit: bool = False


class SteerBotHWSim:
    """SteerBotHardwareGazebo on one robot: the same calls as :class:`.hardware.RobotHWSim`."""

    #: writeSim has work every step (the wheels' speeds are set before each one)
    busy = True

    def __init__(self, ctx, ns, warnings):
        self.ctx, self.ns, self.estop = ctx, ns, False
        where = ns
        if get_param(join(ns, sbh.PARAM_NS), None) is None and get_param(join("/", sbh.PARAM_NS), None) is not None:
            where = "/"  # as the controllers are found anywhere when not under the namespace (robot_check loads at /)
            warnings.append(f"{SIM_TYPE}: its parameters are at /{sbh.PARAM_NS}, not under {ns} where Gazebo reads "
                            "them; used")
        try:
            self.cfg = sbh.steer_bot_config(get_param(join(where, sbh.PARAM_NS), None),
                                            get_param(join(where, "gains"), None), where)
        except ConfigError as err:
            raise PluginNotLoaded(f"{SIM_TYPE}: {err}; the hardware did not initialise (as in Gazebo: no "
                                  "controller manager)") from None
        cfg, robot = self.cfg, ctx.robot
        virtual = cfg.virtual_front_steers + cfg.virtual_rear_wheels + cfg.virtual_front_wheels
        missing = [j for j in virtual if j not in robot.joint_index]
        if missing:
            raise PluginNotLoaded(f"{SIM_TYPE}: virtual joint(s) {', '.join(missing)} of "
                                  f"{join(ns, sbh.PARAM_NS)} are not movable joints of the model")
        self.joints: dict[str, Handle] = {}  # upstream's registration order: steers, then wheels
        self._add(cfg.front_steer, POSITION)
        for name in cfg.virtual_front_steers:
            self._add(name, POSITION, robot.joint_index[name])
        self._add(cfg.rear_wheel, VELOCITY)
        for name in cfg.virtual_rear_wheels:
            self._add(name, VELOCITY, robot.joint_index[name])
        for name in cfg.virtual_front_wheels:
            self._add(name, None, robot.joint_index[name])
        self._read_order = [h for h in self.joints.values() if h.index is not None]
        self._read_idx = [h.index for h in self._read_order]
        self._wheel_idx = robot.indices(cfg.virtual_wheels)
        self._steer_idx = robot.indices(cfg.virtual_front_steers)
        self._steer_limits = [self._limits(name) for name in cfg.virtual_front_steers]
        self._pushed = None
        # the model's own bicycle joints are not driven (free, as in Gazebo: PyBullet's default motor would brake
        # them); the wheels are free too: SetVelocity sets their speed before each step, not a motor's
        free = [j for j in (cfg.rear_wheel, cfg.front_steer) if j in robot.joint_index]
        robot.free_joints(robot.indices(free) + self._wheel_idx)

    def _add(self, name, interface, index=None):
        self.joints[name] = Handle(name, interface, index)

    def _limits(self, name):
        joint = self.ctx.model.joints.get(name)
        if joint is not None and joint.type == "revolute" and joint.has_limit:
            return joint.lower, joint.upper
        return -math.inf, math.inf

    # -- what controllers see -----------------------------------------------------------------------------
    def names(self):
        return list(self.joints)

    def interface(self, joint):
        handle = self.joints.get(joint)
        return handle.interface if handle is not None else None

    def set_command(self, joint, value):
        self.joints[joint].command = value

    def positions(self, names):
        return [self.joints[n].position for n in names]

    def velocities(self, names):
        return [self.joints[n].velocity for n in names]

    def set_estop(self, active):
        self.estop = active

    def explicit_margin(self, joint, gains, loop):
        raise ConfigError(joint, None, f"a joint of a gazebo_ros_control hardware; {SIM_TYPE} has no PID "
                                       "effort joints")

    # -- readSim / writeSim -------------------------------------------------------------------------------
    def read(self):
        """readSim: the virtual joints from the physics (positions unwrapped), then the bicycle model's."""
        positions, velocities, efforts = self.ctx.robot.joint_states(self._read_idx)
        for handle, raw, velocity, effort in zip(self._read_order, positions, velocities, efforts):
            handle.position += shortest_angular_distance(handle.position, raw)
            handle.velocity, handle.effort = velocity, effort
        steer = self.joints[self.cfg.front_steer]
        right, left = (self.joints[n] for n in self.cfg.virtual_front_steers)
        steer.velocity = (right.velocity + left.velocity) / 2
        steer.effort = (right.effort + left.effort) / 2
        self._mirror()

    def _mirror(self):
        """What writeSim leaves in the bicycle model's buffers: the steer at its command, the wheel at the mean
        of the virtual rear wheels."""
        self.joints[self.cfg.front_steer].position = self.joints[self.cfg.front_steer].command
        wheel = self.joints[self.cfg.rear_wheel]
        right, left = (self.joints[n] for n in self.cfg.virtual_rear_wheels)
        wheel.position = 0.5 * (right.position + left.position)
        wheel.velocity = 0.5 * (right.velocity + left.velocity)

    def start(self):
        """initSim's buffers: every command 0; the positions as the physics has them."""
        for handle in self.joints.values():
            handle.command = 0.0
        self._pushed = None
        self.read()

    def write(self, dt):
        """writeSim, every physics step: the wheels at the rear wheel's command, the steers at the linkage's
        angles (clamped to their limits, as Gazebo's SetPosition clamps)."""
        robot = self.ctx.robot
        velocity = self.joints[self.cfg.rear_wheel].command
        angles = [min(max(a, lo), hi) for a, (lo, hi) in
                  zip(sbh.linkage_angles(self.joints[self.cfg.front_steer].command, self.cfg), self._steer_limits)]
        robot.set_joint_velocities(self._wheel_idx, [velocity] * len(self._wheel_idx))
        if angles != self._pushed:  # motor targets persist in PyBullet
            robot.set_positions(self._steer_idx, angles, [UNLIMITED_EFFORT] * len(angles), KINEMATIC_POSITION_GAIN)
            self._pushed = angles
        self._mirror()
