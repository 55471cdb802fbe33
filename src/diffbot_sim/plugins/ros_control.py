"""``libgazebo_ros_control.so``: DefaultRobotHWSim's joint motors, and the controllers the robot's own launch
file put on the parameter server, run as ros_controllers (noetic) runs them.

gazebo_ros_control itself only makes motors; a user's ``controller_manager spawner`` then starts the
controllers whose YAML was loaded with ``<rosparam command="load">``. The controller_manager package is not
in Debian, so this plugin plays both parts: it finds every controller under the robot's namespace (the
plugin's ``robotNamespace``, else the spawner's ``/``; if none is there, anywhere on the parameter server)
and starts the ones it knows:

* ``diff_drive_controller/DiffDriveController`` (:mod:`diffbot_sim.control.diff_drive_controller`):
  ``<controller>/cmd_vel`` in, ``<controller>/odom`` out, ``/tf`` when ``enable_odom_tf``,
  ``<controller>/cmd_vel_out`` when ``publish_cmd``; geometry from the URDF where the YAML gives none (first left/right joint origins, the
  first left wheel's cylinder or sphere collision);
* ``joint_state_controller/JointStateController``: ``joint_states`` in the controller manager's namespace,
  every transmission joint plus ``extra_joints``, at ``publish_rate``;
* ``velocity_controllers/JointVelocityController``, ``position_controllers/JointPositionController``,
  ``effort_controllers/JointEffortController``: ``<controller>/command`` (std_msgs/Float64) to its ``joint``.

Motors (DefaultRobotHWSim): a velocity joint reaches its command with at most its URDF effort limit
(unlimited without one: UNLIMITED_EFFORT); with ``<ns>/gazebo_ros_control/pid_gains/<joint>`` (p, i, d,
i_clamp) it becomes VELOCITY_PID: effort = PID(velocity error) every physics step, clamped to the limit,
where that loop is stable at our step (else an effort-limited velocity motor, with a warning).
Effort joints get zero until commanded. ``eStopTopic`` (std_msgs/Bool) forces velocity commands to 0.
Controllers update every ``controlPeriod`` (default CONTROL_PERIOD; Gazebo's default is the physics step).
"""
import math
import threading

import rospy
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from std_msgs.msg import Bool, Float64

from diffbot_sim.control import controller_lookup as controllers
from diffbot_sim.control import controller_switching as switching
from diffbot_sim.control import diff_drive_controller as ddc
from diffbot_sim.control.kinematics import quaternion_from_yaw
from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.plugins.base import Plugin, get_param, join, next_due
from diffbot_sim.plugins.joint_motors import effort_limit
from diffbot_sim.ros import messages as ros_msgs
from diffbot_sim.values import check_number, check_string, tag_number

#: Controller update period [s] when the plugin gives no ``controlPeriod``. Gazebo runs controllers at
#: every physics step (1 kHz in its default world); 100 Hz keeps real-time CPU low, and with velocity motors
#: the wheels hold their targets between updates (PID joints are still driven every step).
CONTROL_PERIOD = 0.01
#: Largest p·dt/inertia for which an explicit velocity PID is simulated as such (a first-order discrete loop
#: is stable below 2 and does not ring below 1; 0.5 leaves room for the I and D terms).
STABLE_LOOP_GAIN = 0.5
DEFAULT_SIM_TYPE = "gazebo_ros_control/DefaultRobotHWSim"
JSC_TYPE = "joint_state_controller/JointStateController"
JOINT_COMMAND_TYPES = {"velocity_controllers/JointVelocityController": "VelocityJointInterface",
                       "position_controllers/JointPositionController": "PositionJointInterface",
                       "effort_controllers/JointEffortController": "EffortJointInterface"}
KNOWN_TYPES = frozenset([ddc.CONTROLLER_TYPE, JSC_TYPE, *JOINT_COMMAND_TYPES])


def loop_gain(p, dt, inertia):
    """p·dt/inertia: how far one step of an explicit velocity P loop overshoots (stable below 2)."""
    return p * dt / max(inertia, 1e-12)


class Pid:
    """A PID on velocity error (control_toolbox semantics: i_clamp bounds the integral term)."""

    def __init__(self, p=0.0, i=0.0, d=0.0, i_clamp=0.0):
        self.p, self.i, self.d = p, i, d
        self.i_clamp = abs(i_clamp)
        self.integral = 0.0
        self.last_error = None

    def update(self, error, dt):
        if dt <= 0:
            return 0.0
        self.integral += error * dt
        i_term = self.i * self.integral
        if self.i_clamp:
            i_term = max(-self.i_clamp, min(self.i_clamp, i_term))
            if self.i:
                self.integral = i_term / self.i
        d_term = 0.0 if self.last_error is None else self.d * (error - self.last_error) / dt
        self.last_error = error
        return self.p * error + i_term + d_term

    def reset(self):
        self.integral, self.last_error = 0.0, None


class RosControl(Plugin):
    filename = "libgazebo_ros_control.so"

    def __init__(self, ctx, path, ns, control_period, estop_topic, sim_type):
        self.ctx = ctx
        self.path = path
        self.ns = ns
        self.period = control_period
        self.sim_type = sim_type
        model, robot = ctx.model, ctx.robot
        self.interfaces = {t.joint: t.interface for t in model.transmissions}
        self.commands = {}  # joint -> latest command from a controller
        self.pids = {}
        gains = get_param(join(ns, "gazebo_ros_control/pid_gains"), {})
        for joint, values in (gains.items() if isinstance(gains, dict) else ()):
            if joint in self.interfaces and isinstance(values, dict):
                try:
                    self.pids[joint] = Pid(*(float(values.get(k, 0.0)) for k in ("p", "i", "d", "i_clamp")))
                except (TypeError, ValueError):
                    ctx.warnings.append(f"{join(ns, 'gazebo_ros_control/pid_gains')}/{joint}: not numbers; "
                                        "the joint keeps a velocity motor")
        self.index = {j: robot.indices([j])[0] for j in self.interfaces if j in robot.joint_index}
        self._check_pid_stability(ns)
        self.pid_limits = {j: effort_limit(model, j) for j in self.pids}  # read once, used every step
        free = [self.index[j] for j, iface in self.interfaces.items()
                if j in self.index and (iface == "EffortJointInterface" or j in self.pids)]
        robot.free_joints(free)
        self.estop = False
        self.estop_sub = (ctx.subscriber(join(ns, estop_topic), Bool, self._on_estop, queue_size=1)
                          if estop_topic else None)
        self.controllers = []  # the running ones, updated every control period in start order
        self.loaded = {}  # controller name (relative to ns) -> runner: loaded, running or stopped
        self.next_control = 0.0
        self.last_pid_time = None

    def _check_pid_stability(self, ns):
        """Keep the explicit PID only where its discrete loop is stable at our step.

        Gains tuned for Gazebo's 1 ms step often are not at 1/240 s: measured on the PID fixture, p = 5 on a
        1.9e-4 kg·m^2 wheel oscillates at +-85 rad/s. A loop gain p·dt/I above STABLE_LOOP_GAIN gets the
        implicit form of the same loop instead: PyBullet's velocity motor, which the solver keeps at the
        commanded velocity within the same effort limit (one warning names the joint)."""
        dt = self.ctx.cfg.time_step
        for joint in list(self.pids):
            if joint not in self.index:
                continue
            inertia = self.ctx.robot.smallest_inertia(self.index[joint])
            gain = loop_gain(self.pids[joint].p, dt, inertia)
            if gain > STABLE_LOOP_GAIN:
                self.ctx.warnings.append(
                    f"{join(ns, 'gazebo_ros_control/pid_gains')}/{joint}: p={self.pids[joint].p:g} at a "
                    f"{dt * 1000:.2f} ms step is an unstable loop on this joint (inertia {inertia:.2g} kg·m^2, "
                    f"loop gain {gain:.3g}); it runs as an effort-limited velocity motor instead")
                del self.pids[joint]

    def _on_estop(self, msg):
        self.estop = bool(msg.data)
        self.ctx.sim.wake.set()

    # -- hardware -----------------------------------------------------------------------------------
    def write(self, joint, value):
        """A controller's command for ``joint`` (applied to the motor now, or by the PID every step)."""
        self.commands[joint] = value
        if joint in self.pids or joint not in self.index:
            return
        iface, robot = self.interfaces[joint], self.ctx.robot
        force = effort_limit(self.ctx.model, joint)
        idx = [self.index[joint]]
        if iface == "VelocityJointInterface":
            robot.set_velocities(idx, [0.0 if self.estop else value], [force])
        elif iface == "PositionJointInterface":
            robot.set_positions(idx, [value], [force])
        else:
            robot.set_efforts(idx, [max(-force, min(force, value))])

    def joints(self):
        """Every transmission joint: DefaultRobotHWSim writes a command to each on every update, zero until
        a controller sets one (an uncommanded velocity joint is held at rest, as in Gazebo)."""
        return set(self.index)

    def publishers(self):
        pubs = []
        for controller in self.controllers:
            pubs += controller.publishers()
        return pubs

    def next_due(self):
        return self.ctx.sim.sim_time if self.pids else math.inf

    def next_publish(self):
        return self.next_control

    def before_step(self, now):
        if not self.pids:
            return
        robot = self.ctx.robot
        names = list(self.pids)
        _, velocities, _ = robot.joint_states([self.index[j] for j in names])
        dt = self.ctx.cfg.time_step
        efforts = []
        for joint, velocity in zip(names, velocities):
            target = 0.0 if self.estop else self.commands.get(joint, 0.0)
            limit = self.pid_limits[joint]
            efforts.append(max(-limit, min(limit, self.pids[joint].update(target - velocity, dt))))
        robot.set_efforts([self.index[j] for j in names], efforts)

    def after_step(self, now, stamp, transforms):
        if now + 1e-9 < self.next_control:
            return
        self.next_control = next_due(self.next_control, self.period, now)
        for controller in self.controllers:
            controller.update(now, stamp, transforms)

    def start(self, now):
        self.next_control = now
        for pid in self.pids.values():
            pid.reset()
        for joint, iface in self.interfaces.items():
            if joint in self.index and iface != "PositionJointInterface":
                self.write(joint, 0.0)
        for controller in self.controllers:
            controller.start(now)

    def reset(self, now):
        for joint in list(self.commands):
            self.write(joint, 0.0)
        self.start(now)

    # -- controller_manager (its services call these on the loop's thread) --------------------------
    def full_name(self, name):
        return join(self.ns, name)

    def load(self, name):
        """LoadController: build ``name`` from ``<ns>/<name>`` on the parameter server, stopped."""
        params = get_param(self.full_name(name), None)
        switching.check_load(name, self.loaded, params, KNOWN_TYPES)
        runner = make_runner(self.ctx, self, self.full_name(name), params)
        self.loaded[name] = runner
        return runner

    def _running(self):
        return [name for name, runner in self.loaded.items() if runner in self.controllers]

    def switch(self, start, stop, strictness):
        """SwitchController: stop, then start (controller_manager's rules,
        :mod:`diffbot_sim.control.controller_switching`)."""
        claims = {n: r.joints() for n, r in self.loaded.items()}
        to_stop, to_start = switching.plan_switch(self.loaded, self._running(), claims, start, stop, strictness)
        for name in to_stop:
            runner = self.loaded[name]
            self.controllers.remove(runner)
            runner.stop()
        for name in to_start:
            runner = self.loaded[name]
            runner.start(self.ctx.sim.sim_time)
            self.controllers.append(runner)

    def unload(self, name):
        """UnloadController: a stopped controller goes, with its topics."""
        switching.check_unload(name, self.loaded, self._running())
        runner = self.loaded.pop(name)
        for handle in runner.handles():
            self.ctx.release(handle)

    def states(self):
        """[(name, 'running' | 'stopped', type, {interface: [joints]})] for ListControllers."""
        out = []
        for name, runner in self.loaded.items():
            claimed = {}
            if runner.type == JSC_TYPE:  # it reads every joint and claims none, as controller_manager lists it
                claimed["JointStateInterface"] = []
            for joint in sorted(runner.joints()):
                claimed.setdefault(self.interfaces.get(joint, ""), []).append(joint)
            out.append((name, "running" if runner in self.controllers else "stopped", runner.type, claimed))
        return out

    def summary(self):
        out = {"robot_namespace": self.ns, "control_period": self.period, "robot_sim_type": self.sim_type}
        if self.pids:
            out["pid_joints"] = ",".join(sorted(self.pids))
        for controller in self.controllers:
            out.update(controller.summary())
        return out


class DiffDriveControllerRunner:
    """One DiffDriveController on the hardware of a RosControl plugin."""

    type = ddc.CONTROLLER_TYPE

    def __init__(self, ctx, hw, name, params, manager_ns):
        self.ctx, self.hw, self.name = ctx, hw, name
        model = ctx.model
        cfg = ddc.ddc_config(params, name)
        for warning in cfg.warnings:
            ctx.warnings.append(warning)
        if cfg.unknown_keys:
            ctx.warnings.append(f"{name}: parameters DiffDriveController does not read, ignored: "
                                f"{', '.join(cfg.unknown_keys)}")
        for joint in cfg.joints:
            model.joint(joint, name)
            if joint not in hw.interfaces:
                raise ModelError(f"controller {name} names wheel joint '{joint}', which has no transmission "
                                 "(gazebo_ros_control has no handle for it)", model.source)
        separation = radius = None
        if cfg.wheel_separation is None:
            separation = model.wheel_separation(cfg.left_wheels[0], cfg.right_wheels[0], name)
        if cfg.wheel_radius is None:
            radius = model.wheel_radius(cfg.left_wheels[0], name)
        self.core = ddc.DiffDriveControllerCore(cfg, separation, radius)
        self.cfg = cfg
        self.left_idx = ctx.robot.indices(list(cfg.left_wheels))
        self.right_idx = ctx.robot.indices(list(cfg.right_wheels))
        self.odom_frame = ctx.frame(cfg.odom_frame_id)
        self.base_frame = ctx.frame(cfg.base_frame_id)
        self._lock = threading.Lock()
        self._pending = None
        self.sub = ctx.subscriber(join(name, "cmd_vel"), Twist, self._on_twist, queue_size=1)
        self.odom_pub = ctx.publisher(join(name, "odom"), Odometry)
        self.cmd_out_pub = ctx.publisher(join(name, "cmd_vel_out"), TwistStamped) if cfg.publish_cmd else None
        self.odom_builder = ros_msgs.OdometryBuilder(self.odom_frame, self.base_frame, 0, 0, 0,
                                                     pose_diagonal=cfg.pose_covariance_diagonal,
                                                     twist_diagonal=cfg.twist_covariance_diagonal)
        self.tf_builder = ros_msgs.TransformBuilder(self.odom_frame, self.base_frame)

    def _on_twist(self, msg):
        count = self.sub.get_num_connections()
        with self._lock:
            self._pending = (msg.linear.x, msg.angular.z, count)

    def joints(self):
        return set(self.cfg.joints)

    def publishers(self):
        return [p for p in (self.odom_pub, self.cmd_out_pub) if p is not None]

    def handles(self):
        return [self.sub] + self.publishers()

    def start(self, now):
        self.core.starting(now)

    def stop(self):
        """diff_drive_controller's stopping(): the wheels are braked."""
        for joint in self.cfg.joints:
            self.hw.write(joint, 0.0)

    def update(self, now, stamp, transforms):
        if self._pending is not None:
            with self._lock:
                (linear, angular, count), self._pending = self._pending, None
            why = self.core.set_command(linear, angular, now, count)
            if why is not None:
                self.ctx.sim.warn(f"ddc:{self.name}", f"{self.name}: {why}")
        robot = self.ctx.robot
        positions, _, _ = robot.joint_states(self.left_idx + self.right_idx)
        n = len(self.left_idx)
        step = self.core.update(now, positions[:n], positions[n:], self.hw.period)
        for joint in self.cfg.left_wheels:
            self.hw.write(joint, step.left)
        for joint in self.cfg.right_wheels:
            self.hw.write(joint, step.right)
        if step.publish_odom:
            x, y, yaw = self.core.pose
            linear, angular = self.core.velocity
            orientation = quaternion_from_yaw(yaw)
            if self.odom_pub.get_num_connections():
                self.odom_pub.publish(self.odom_builder.build(stamp, (x, y, 0.0), orientation, (linear, 0.0, 0.0),
                                                              (0.0, 0.0, angular)))
            if self.cfg.enable_odom_tf:
                transforms.append(self.tf_builder.build(stamp, (x, y, 0.0), orientation))
        if self.cmd_out_pub is not None and not step.skipped and self.cmd_out_pub.get_num_connections():
            lin, ang = self.core.last_command
            self.cmd_out_pub.publish(ros_msgs.twist_stamped(stamp, lin, ang))

    def summary(self):
        return {f"{self.name}/wheel_separation": self.core.separation,
                f"{self.name}/wheel_radius": self.core.left_radius,
                "cmd_vel_topic": self.sub.resolved_name, "odom_topic": self.odom_pub.resolved_name}


class JointStateControllerRunner:
    """joint_state_controller/JointStateController: every transmission joint plus ``extra_joints``."""

    type = JSC_TYPE

    def __init__(self, ctx, hw, name, params, manager_ns):
        self.ctx, self.hw, self.name = ctx, hw, name
        rate = params.get("publish_rate")
        if rate is None:
            ctx.warnings.append(f"{name}: no publish_rate (JointStateController requires one); using 50 Hz")
            rate = 50.0
        rate = check_number(f"{name}/publish_rate", rate, low=0.0, low_open=True)
        self.period = 1.0 / rate
        self.joints_ = [j for j in hw.interfaces if j in hw.index]
        self.extra = []
        for item in params.get("extra_joints", []) or []:
            entry = item if isinstance(item, dict) else {"name": item}
            if isinstance(entry.get("name"), str):
                self.extra.append((entry["name"], float(entry.get("position", 0.0)),
                                   float(entry.get("velocity", 0.0)), float(entry.get("effort", 0.0))))
        self.pub = ctx.publisher(join(manager_ns, "joint_states"), JointState)
        self.builder = ros_msgs.JointStateBuilder(self.joints_ + [e[0] for e in self.extra])
        self.next = 0.0

    def joints(self):
        return set()

    def publishers(self):
        return [self.pub]

    def handles(self):
        return [self.pub]

    def start(self, now):
        self.next = now

    def stop(self):
        pass

    def update(self, now, stamp, transforms):
        if now + 1e-9 < self.next:  # a controller, not a Plugin: its own schedule
            return
        self.next = next_due(self.next, self.period, now)
        if not self.pub.get_num_connections():
            return
        positions, velocities, efforts = self.ctx.robot.joint_states([self.hw.index[j] for j in self.joints_])
        for _, p, v, e in self.extra:
            positions.append(p)
            velocities.append(v)
            efforts.append(e)
        self.pub.publish(self.builder.build(stamp, positions, velocities, efforts))

    def summary(self):
        return {f"{self.name}/topic": self.pub.resolved_name}


class JointCommandRunner:
    """velocity/position/effort ``Joint*Controller``: ``<controller>/command`` -> its joint."""

    def __init__(self, ctx, hw, name, params, manager_ns, interface):
        self.ctx, self.hw, self.name = ctx, hw, name
        self.type = params.get("type")
        self.joint = check_string(f"{name}/joint", params.get("joint"))
        ctx.model.joint(self.joint, name)
        if hw.interfaces.get(self.joint) != interface:
            raise ModelError(f"controller {name} needs joint '{self.joint}' with a {interface} transmission",
                             ctx.model.source)
        self.value = None
        self.sub = ctx.subscriber(join(name, "command"), Float64, self._on_command, queue_size=1)

    def _on_command(self, msg):
        if math.isfinite(msg.data):
            self.value = msg.data
            self.ctx.sim.wake.set()
        else:
            self.ctx.sim.warn(f"cmd:{self.name}", f"{self.name}: ignored a non-finite command")

    def joints(self):
        return {self.joint}

    def publishers(self):
        return []

    def handles(self):
        return [self.sub]

    def start(self, now):
        pass

    def stop(self):
        pass

    def update(self, now, stamp, transforms):
        if self.value is not None:
            self.hw.write(self.joint, self.value)
            self.value = None

    def summary(self):
        return {f"{self.name}/command": self.sub.resolved_name}


def find_controllers(ns):
    """{controller namespace: its parameter dict} of every controller under ``ns`` on the parameter server,
    else anywhere on it (:func:`diffbot_sim.control.controller_lookup.find_controllers`)."""
    return controllers.find_controllers(get_param("/", {}), ns or "/")


def create(ctx, element, path, params):
    tags = {child.tag: tag_value(child) for child in element}
    ns = ctx.plugin_namespace(tags.get("robotNamespace") or None, "/")
    if not ns.startswith("/"):
        ns = "/" + ns
    sim_type = tags.get("robotSimType") or DEFAULT_SIM_TYPE
    if sim_type != DEFAULT_SIM_TYPE:
        ctx.warnings.append(f"{path}: robotSimType '{sim_type}' is not simulated; using {DEFAULT_SIM_TYPE}")
    period = CONTROL_PERIOD
    if tags.get("controlPeriod"):
        period = tag_number(f"<controlPeriod> of {path}", tags["controlPeriod"], ctx.warnings, low=0.0,
                            low_open=True)
        period = max(period, ctx.cfg.time_step)
    hw = RosControl(ctx, path, ns, period, tags.get("eStopTopic"), sim_type)
    if ctx.cfg.autostart_controllers:
        _start_all(ctx, hw, path, ns)
    ControllerManagerServices(ctx, hw)
    return hw


def make_runner(ctx, hw, name, cparams):
    """The runner of controller ``name`` (its full parameter namespace) of a simulated type."""
    kind = cparams.get("type")
    manager_ns = name.rsplit("/", 1)[0] or "/"
    if kind == ddc.CONTROLLER_TYPE:
        return DiffDriveControllerRunner(ctx, hw, name, cparams, manager_ns)
    if kind == JSC_TYPE:
        return JointStateControllerRunner(ctx, hw, name, cparams, manager_ns)
    return JointCommandRunner(ctx, hw, name, cparams, manager_ns, JOINT_COMMAND_TYPES[kind])


def _start_all(ctx, hw, path, ns):
    """``~autostart_controllers``: every controller of a simulated type found under the namespace starts at
    once, as if a spawner had named them all (our own launch files have no spawner)."""
    controllers = find_controllers(ns)
    if not controllers:
        ctx.warnings.append(f"{path}: no controller found on the parameter server under {ns} (load your "
                            "controller YAML with <rosparam command=\"load\"> before bullet_sim starts)")
    owned = {}
    for name, cparams in sorted(controllers.items()):
        kind = cparams.get("type")
        if kind not in KNOWN_TYPES:
            ctx.warnings.append(f"{name}: controller type {kind} is not simulated")
            continue
        runner = make_runner(ctx, hw, name, cparams)
        for joint in runner.joints():
            if joint in owned:
                raise ModelError(f"controllers {owned[joint]} and {name} both command joint '{joint}'",
                                 ctx.model.source)
            owned[joint] = name
        relative = name[len(ns.rstrip("/")) + 1:] if name.startswith(ns.rstrip("/") + "/") else name
        hw.loaded[relative] = runner
        hw.controllers.append(runner)


class ControllerManagerServices:
    """controller_manager's services in the plugin's namespace (``<robotNamespace>/controller_manager/...``),
    with controller_manager_msgs' types, so ``rosrun controller_manager spawner`` drives our controllers.
    Each call runs on the simulator's loop (the only thread that touches controllers and physics)."""

    def __init__(self, ctx, hw):
        try:
            from controller_manager_msgs import srv
        except ImportError:  # the overlay left out: no controller_manager_msgs to serve
            ctx.warnings.append("controller_manager_msgs is not built (overlay left out): no controller_manager "
                                "services; controllers start only with ~autostart_controllers")
            return
        self.ctx, self.hw, self.srv = ctx, hw, srv
        base = join(hw.ns, "controller_manager")
        for name, kind, handler in (("load_controller", srv.LoadController, self._load),
                                    ("unload_controller", srv.UnloadController, self._unload),
                                    ("switch_controller", srv.SwitchController, self._switch),
                                    ("list_controllers", srv.ListControllers, self._list),
                                    ("list_controller_types", srv.ListControllerTypes, self._types),
                                    ("reload_controller_libraries", srv.ReloadControllerLibraries,
                                     self._reload)):
            ctx.service(join(base, name), kind, handler)

    def _on_loop(self, action, what):
        """Run ``action`` on the loop; True, or False with the reason logged as controller_manager does."""
        try:
            self.ctx.sim.call(action)
            return True
        except (switching.SwitchError, ConfigError, ModelError) as err:
            rospy.logerr(f"controller_manager {self.hw.ns}: {what}: {err}")
            return False

    def _load(self, req):
        return self.srv.LoadControllerResponse(self._on_loop(lambda: self.hw.load(req.name), "load"))

    def _unload(self, req):
        return self.srv.UnloadControllerResponse(self._on_loop(lambda: self.hw.unload(req.name), "unload"))

    def _switch(self, req):
        ok = self._on_loop(lambda: self.hw.switch(list(req.start_controllers), list(req.stop_controllers),
                                                  req.strictness), "switch")
        return self.srv.SwitchControllerResponse(ok)

    def _list(self, _req):
        from controller_manager_msgs.msg import ControllerState, HardwareInterfaceResources

        states = self.ctx.sim.call(self.hw.states)
        out = [ControllerState(name=name, state=state, type=kind,
                               claimed_resources=[HardwareInterfaceResources(f"hardware_interface::{iface}",
                                                                             joints)
                                                  for iface, joints in claimed.items() if iface])
               for name, state, kind, claimed in states]
        return self.srv.ListControllersResponse(out)

    def _types(self, _req):
        kinds = sorted(KNOWN_TYPES)
        return self.srv.ListControllerTypesResponse(kinds, ["controller_interface::ControllerBase"] * len(kinds))

    def _reload(self, req):
        def action():
            if self.hw.loaded and not req.force_kill:
                raise switching.SwitchError("Controller manager: Cannot reload controller libraries because there "
                                            "are still controllers loaded (force_kill unset)")
            self.hw.switch([], list(self.hw.loaded), switching.BEST_EFFORT)
            for name in list(self.hw.loaded):
                self.hw.unload(name)
        return self.srv.ReloadControllerLibrariesResponse(self._on_loop(action, "reload libraries"))
