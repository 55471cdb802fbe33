"""``libgazebo_ros_control.so``: DefaultRobotHWSim's joints (:mod:`.hardware`) and the controller manager
(:mod:`.manager`) that runs the ros_controllers a robot's own launch file loads and spawns, one module per
controller type: ``diff_drive_controller/DiffDriveController`` (:mod:`.diff_drive`),
``joint_state_controller/JointStateController`` (:mod:`.joint_state`), the forward/group command and PID
controllers (:mod:`.forward_command`), ``*/JointTrajectoryController`` (:mod:`.joint_trajectory`) and
``*/GripperActionController`` (:mod:`.gripper_action`).

Plugin tags: ``robotNamespace`` (default: the spawner's ``/``; a ``~robots`` robot's own namespace replaces
it), ``robotSimType`` (DefaultRobotHWSim, SteerBotHardwareGazebo in :mod:`.steer_bot_hardware`, FrankaHWSim in
:mod:`.franka_hardware`; another is one warning and the default), ``controlPeriod`` (s; see
:mod:`.manager` for the default), ``eStopTopic`` (std_msgs/Bool), ``robotParam`` and ``legacyModeNS`` (accepted).
"""
import math

from std_msgs.msg import Bool

from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.plugins.base import Plugin, join
from diffbot_sim.plugins.ros_control.franka_hardware import FrankaHWSim
from diffbot_sim.plugins.ros_control.hardware import RobotHWSim
from diffbot_sim.plugins.ros_control.manager import KNOWN_TYPES, ControllerManager, ControllerManagerServices
from diffbot_sim.plugins.ros_control.steer_bot_hardware import SteerBotHWSim
from diffbot_sim.values import tag_number

DEFAULT_SIM_TYPE = "gazebo_ros_control/DefaultRobotHWSim"
#: robotSimType -> the hardware simulated for it (built as ``cls(ctx, ns, warnings)``); others: the default
HW_SIMS: dict[str, type[RobotHWSim] | type[SteerBotHWSim]] = {
    DEFAULT_SIM_TYPE: RobotHWSim, "steer_bot_hardware_gazebo/SteerBotHardwareGazebo": SteerBotHWSim,
    "franka_gazebo/FrankaHWSim": FrankaHWSim}


class RosControl(Plugin):
    filename = "libgazebo_ros_control.so"

    def __init__(self, ctx, path, ns, period, estop_topic, sim_type):
        self.ctx, self.path, self.ns, self.sim_type = ctx, path, ns, sim_type
        self.hw = HW_SIMS.get(sim_type, RobotHWSim)(ctx, ns, ctx.warnings)
        self.manager = ControllerManager(ctx, self.hw, ns, period)
        self._estop = None  # the latest e-stop message, applied on the loop
        self.estop_sub = (ctx.subscriber(join(ns, estop_topic), Bool, self._on_estop, queue_size=1)
                          if estop_topic else None)

    def _on_estop(self, msg):
        self._estop = bool(msg.data)
        self.ctx.sim.wake.set()

    def joints(self):
        """Every transmission joint: DefaultRobotHWSim writes a command to each on every step, zero until
        a controller sets one (an uncommanded velocity joint is held at rest, a position joint at 0)."""
        return set(self.hw.joints)

    def publishers(self):
        return self.manager.publishers()

    def next_control(self):
        """Every step while the hardware has work (torques, a limit still clipping, a new command); a robot whose
        joints are all PyBullet motors holding their targets has none until a controller's next update."""
        return self.ctx.sim.sim_time if self.hw.busy or self._estop is not None or self.manager.pending else math.inf

    def next_publish(self):
        return self.ctx.sim.sim_time if self.manager.step_due() else self.manager.next_update

    def before_step(self, now):
        if self.manager.pending:  # switches asked for while paused: at the first step after the unpause
            self.manager.run_pending(now)
        if self._estop is not None:
            active, self._estop = self._estop, None
            released = self.hw.estop and not active
            self.hw.set_estop(active)
            if released:
                self.manager.reset_controllers(now)
        self.hw.write(self.ctx.cfg.time_step)

    def after_step(self, now, stamp, transforms):
        self.manager.update(now, stamp, transforms)

    def start(self, now):
        self.hw.start()
        self.manager.start(now)

    def reset(self, now):
        """reset_world / reset_simulation: Gazebo keeps controllers running (their state survives); the
        hardware's commands start over."""
        self.hw.start()

    def summary(self):
        out = {"robot_namespace": self.ns, "control_period": self.manager.control_period,
               "robot_sim_type": self.sim_type}
        methods: dict[str, list[str]] = {}
        for joint in self.hw.joints.values():
            methods.setdefault(joint.method + ("(implicit)" if joint.implicit else ""), []).append(joint.name)
        for method, names in sorted(methods.items()):
            out[f"joints_{method.lower().replace('(implicit)', '_implicit')}"] = ",".join(names)
        out.update(self.manager.summary())
        return out


def create(ctx, element, path, params):
    tags = {child.tag: tag_value(child) for child in element}
    ns = ctx.plugin_namespace(tags.get("robotNamespace") or None, "/")
    if not ns.startswith("/"):
        ns = "/" + ns
    sim_type = tags.get("robotSimType") or DEFAULT_SIM_TYPE
    if sim_type not in HW_SIMS:
        ctx.warnings.append(f"{path}: robotSimType '{sim_type}' is not simulated; using {DEFAULT_SIM_TYPE}")
    period = None
    if tags.get("controlPeriod"):
        period = tag_number(f"<controlPeriod> of {path}", tags["controlPeriod"], ctx.warnings, low=0.0,
                            low_open=True)
        if period < ctx.cfg.time_step:
            ctx.warnings.append(f"{path}: <controlPeriod> {period:g} s is shorter than the physics step "
                                f"{ctx.cfg.time_step:g} s; controllers run every step")
        period = max(period, ctx.cfg.time_step)
    plugin = RosControl(ctx, path, ns, period, tags.get("eStopTopic"), sim_type)
    if ctx.cfg.autostart_controllers:
        plugin.manager.autostart(path)
    ControllerManagerServices(ctx, plugin.manager)
    return plugin


__all__ = ["RosControl", "create", "KNOWN_TYPES"]
