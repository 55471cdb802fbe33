"""controller_manager for one ``libgazebo_ros_control.so``: the controller types simulated, loading from the
parameter server, switching and unloading (controller_manager's rules: :mod:`diffbot_sim.control.
controller_switching`), the update of running controllers, and its services
(``<robotNamespace>/controller_manager/{load,unload,switch}_controller``, ``list_controllers``,
``list_controller_types``, ``reload_controller_libraries``; controller_manager_msgs from the overlay), so a
user's ``rosrun controller_manager spawner`` drives the controllers here.

Controllers run every ``controlPeriod``; without one, those that close a loop in software (velocity/effort
trajectory controllers, PID controllers, the effort gripper) run every physics step, as at Gazebo's default
(``controlPeriod`` = the step), and the others every CONTROL_PERIOD: they hand targets to motors that hold
them between updates, so a slower update changes nothing but the CPU spent.
"""
import threading
from collections.abc import Callable

import rospy

from diffbot_sim.control import (
    ackermann_steering_controller as asc,
    controller_lookup,
    controller_switching as switching,
    diff_drive_config as ddc_cfg,
    forward_command as fwd,
    four_wheel_steering_controller as fws,
    gripper_action_controller as gac,
    joint_trajectory_config as jtc_cfg,
)
from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.plugins.base import get_param, join
from diffbot_sim.plugins.ros_control.ackermann_steering import AckermannSteeringController
from diffbot_sim.plugins.ros_control.controller import Controller
from diffbot_sim.plugins.ros_control.diff_drive import DiffDriveController
from diffbot_sim.plugins.ros_control.forward_command import ForwardCommandController
from diffbot_sim.plugins.ros_control.four_wheel_steering import FourWheelSteeringController
from diffbot_sim.plugins.ros_control.franka_gripper import FrankaGripperSim
from diffbot_sim.plugins.ros_control.franka_state import FrankaStateController
from diffbot_sim.plugins.ros_control.gripper_action import GripperActionController
from diffbot_sim.plugins.ros_control.joint_state import JointStateController
from diffbot_sim.plugins.ros_control.joint_trajectory import JointTrajectoryController

#: Update period [s] of controllers that only hand targets to motors, when the plugin gives no controlPeriod.
CONTROL_PERIOD = 0.01
JSC_TYPE = JointStateController.type


def _factories():
    """controller type -> ``factory(ctx, hw, full_name, params, manager_ns)``."""
    table: dict[str, Callable[..., Controller]] = {
        ddc_cfg.CONTROLLER_TYPE: lambda ctx, hw, name, params, ns: DiffDriveController(ctx, hw, name, params),
        JSC_TYPE: JointStateController,
        asc.CONTROLLER_TYPE: lambda ctx, hw, name, params, ns: AckermannSteeringController(ctx, hw, name, params),
        fws.CONTROLLER_TYPE: lambda ctx, hw, name, params, ns: FourWheelSteeringController(ctx, hw, name, params)}
    for kind in fwd.CONTROLLER_TYPES:
        table[kind] = lambda ctx, hw, name, params, ns: ForwardCommandController(ctx, hw, name, params)
    for kind in jtc_cfg.CONTROLLER_TYPES:
        table[kind] = lambda ctx, hw, name, params, ns: JointTrajectoryController(ctx, hw, name, params)
    for kind in (gac.POSITION_TYPE, gac.EFFORT_TYPE):
        table[kind] = lambda ctx, hw, name, params, ns: GripperActionController(ctx, hw, name, params)
    for cls in (FrankaStateController, FrankaGripperSim):  # franka_ros's, on robotSimType franka_gazebo/FrankaHWSim
        table[cls.type] = lambda ctx, hw, name, params, ns, cls=cls: cls(ctx, hw, name, params)
    return table


FACTORIES = _factories()
KNOWN_TYPES = frozenset(FACTORIES)


class ControllerManager:
    """The controllers of one hardware (RobotHWSim), loaded by name relative to ``ns``."""

    def __init__(self, ctx, hw, ns, period):
        self.ctx, self.hw, self.ns = ctx, hw, ns
        self.period = period  # None: Gazebo's default (see the module docstring)
        self.loaded = {}  # name -> controller (loaded, running or stopped)
        self.running = []  # in start order
        self.next_update = 0.0
        self.last_update = None
        self.last_step_update = None
        self._step_running, self._step_controllers = None, []  # see _every_step
        self.pending = []  # switches asked for while paused: (start, stop, strictness, PendingSwitch)
        attach = getattr(hw, "attach_manager", None)  # a robotSimType that acts on the controllers (FrankaHWSim)
        if attach is not None:
            attach(self)

    def full_name(self, name):
        return join(self.ns, name)

    # -- loading and switching (on the loop) --------------------------------------------------------------
    def load(self, name):
        """LoadController: build ``name`` from ``<ns>/<name>`` on the parameter server, stopped."""
        params = get_param(self.full_name(name), None)
        switching.check_load(name, self.loaded, params, KNOWN_TYPES)
        told = len(self.ctx.warnings)
        self._hw_loading(name)
        controller = FACTORIES[params["type"]](self.ctx, self.hw, self.full_name(name), params,
                                               self.ns.rstrip("/") or "/")
        for text in self.ctx.warnings[told:]:  # the start-up report is long gone: say it now
            rospy.logwarn(f"controller_manager {self.ns}: {text}")
        self.loaded[name] = controller
        return controller

    def switch(self, start, stop, strictness):
        """SwitchController: stop, then start. A controller that refuses to start (upstream's controller_manager
        would crash there) undoes the switch: the ones it stopped run again, so an arm is never left unheld."""
        claims = {n: c.joints() for n, c in self.loaded.items()}
        running = [n for n, c in self.loaded.items() if c in self.running]
        to_stop, to_start = switching.plan_switch(self.loaded, running, claims, start, stop, strictness)
        self._hw_switch("prepare_switch", to_start)
        now = self.ctx.sim.sim_time
        for name in to_stop:
            self._stop(name, now)
        self.hw.read()
        self._hw_switch("do_switch", to_start, to_stop)
        started = []
        try:
            for name in to_start:
                self.loaded[name].start(now)
                self.running.append(self.loaded[name])
                started.append(name)
        except Exception:
            for name in reversed(started):
                self._stop(name, now)
            self.hw.read()
            self._hw_switch("do_switch", to_stop, started)
            for name in to_stop:
                self.loaded[name].start(now)
                self.running.append(self.loaded[name])
            raise

    def switch_later(self, start, stop, strictness):
        """A switch asked for while physics is paused: upstream's realtime loop performs a switch at its next
        update and the service waits for it, so a spawner's switch waits for the first step after the unpause
        (a trajectory controller then starts from the pose ``spawn_model -J`` set while paused, not from the pose
        before it). Returns what the service waits on."""
        waiter = PendingSwitch()
        self.pending.append((start, stop, strictness, waiter))
        return waiter

    def run_pending(self, now):
        """The switches that waited for physics to run, performed before this step (the first after unpause)."""
        pending, self.pending = self.pending, []
        for start, stop, strictness, waiter in pending:
            try:
                self.switch(start, stop, strictness)
            except (switching.SwitchError, ConfigError, ModelError) as err:
                waiter.error = err
            waiter.done.set()

    def _hw_loading(self, name):
        """Tell a hardware that keeps per-controller state (FrankaHWSim: which joints a controller hands to PyBullet's
        motors) which controller the next calls come from."""
        loading = getattr(self.hw, "loading", None)
        if loading is not None:
            loading(name)

    def _hw_switch(self, hook, start, stop=()):
        """RobotHW's prepareSwitch (``prepare_switch``: may refuse with SwitchError) and doSwitch (``do_switch``) for a
        hardware that has them, with each controller's claims: {name: [(interface, [joints])]}."""
        method = getattr(self.hw, hook, None)
        if method is None:
            return
        def claims(names):
            return {n: [(self.loaded[n].interface, sorted(self.loaded[n].joints()))] for n in names
                    if self.loaded[n].interface}
        if hook == "prepare_switch":
            method(claims(start))
        else:
            method(claims(start), claims(stop))

    def _stop(self, name, now):
        controller = self.loaded[name]
        self.running.remove(controller)
        controller.stop(now)

    def unload(self, name):
        """UnloadController: a stopped controller goes, with its topics, services and actions."""
        switching.check_unload(name, self.loaded, [n for n, c in self.loaded.items() if c in self.running])
        controller = self.loaded.pop(name)
        for handle in controller.handles():
            self.ctx.release(handle)

    def autostart(self, path):
        """``~autostart_controllers``: every controller of a simulated type under the namespace starts at once,
        as if a spawner had named them all (our own launch files have no spawner)."""
        found = controller_lookup.find_controllers(get_param("/", {}), self.ns or "/")
        if not found:
            self.ctx.warnings.append(f"{path}: no controller found on the parameter server under {self.ns} (load "
                                     "your controller YAML with <rosparam command=\"load\"> before bullet_sim starts)")
        prefix = self.ns.rstrip("/") + "/"
        names = []
        for full, params in sorted(found.items()):
            kind = params.get("type")
            if kind not in KNOWN_TYPES:
                self.ctx.warnings.append(f"{full}: controller type {kind} is not simulated")
                continue
            name = full[len(prefix):] if full.startswith(prefix) else full
            self._hw_loading(name)
            controller = FACTORIES[kind](self.ctx, self.hw, full, params, self.ns.rstrip("/") or "/")
            self.loaded[name] = controller
            names.append(name)
        claims = {n: c.joints() for n, c in self.loaded.items()}
        try:
            switching.plan_switch(self.loaded, [], claims, names, [], switching.STRICT)
            self._hw_switch("prepare_switch", names)
        except switching.SwitchError as err:
            raise ModelError(str(err), self.ctx.model.source) from None
        self.hw.read()
        self._hw_switch("do_switch", names)
        for name in names:
            self.running.append(self.loaded[name])

    def states(self):
        """[(name, 'running' | 'stopped', type, {interface: [joints]})] for ListControllers."""
        out = []
        for name, controller in self.loaded.items():
            claimed: dict[str, list[str]] = {}
            if controller.type == JSC_TYPE:  # it reads every joint and claims none, as controller_manager lists it
                claimed["JointStateInterface"] = []
            for joint in sorted(controller.joints()):
                claimed.setdefault(controller.interface or self.hw.interface(joint) or "", []).append(joint)
            out.append((name, "running" if controller in self.running else "stopped", controller.type, claimed))
        return out

    # -- the update (on the loop) --------------------------------------------------------------------------
    def start(self, now):
        """The loop (re)starts at ``now``: running controllers start again (reset_world / reset_simulation do
        not stop controllers in Gazebo, but their time base restarts)."""
        self.next_update = now
        self.last_update = self.last_step_update = None
        self.hw.read()
        for controller in self.running:
            controller.start(now)

    def _every_step(self):
        """The running controllers that run at every physics step, found again only when the running set changed
        (the loop asks every step)."""
        if self.running != self._step_running:
            self._step_running = list(self.running)
            self._step_controllers = [c for c in self.running if self.period is None and getattr(c, "closed_loop",
                                                                                                  False)]
        return self._step_controllers

    def step_due(self):
        """Whether a controller runs at every physics step."""
        return bool(self._every_step())

    def update(self, now, stamp, transforms):
        """Run the controllers that are due at sim time ``now``."""
        slow_due = now + 1e-9 >= self.next_update
        every_step = self._every_step()
        if not slow_due and not every_step:
            return
        self.hw.read()
        if every_step:
            period = now - self.last_step_update if self.last_step_update is not None else self.ctx.cfg.time_step
            self.last_step_update = now
            for controller in every_step:
                controller.update(now, period, stamp, transforms)
        if slow_due:
            period = now - self.last_update if self.last_update is not None else self.control_period
            self.last_update = now
            self.next_update = self._next(now)
            for controller in self.running:
                if controller not in every_step:
                    controller.update(now, period, stamp, transforms)

    @property
    def control_period(self):
        return self.period if self.period is not None else CONTROL_PERIOD

    def _next(self, now):
        due = self.next_update + self.control_period
        return due if due >= now else now + self.control_period

    def reset_controllers(self, now):
        """The e-stop was released: every running controller is stopped and started again (upstream's
        ``reset_controllers``)."""
        for controller in self.running:
            controller.stop(now)
        self.hw.read()
        for controller in self.running:
            controller.start(now)

    def publishers(self):
        pubs = []
        for controller in self.running:
            pubs += controller.publishers()
        return pubs

    def summary(self):
        out = {}
        for controller in self.running:
            out.update(controller.summary())
        return out


class PendingSwitch:
    """A switch the loop performs later (``ControllerManager.switch_later``): ``done`` is set when it has run,
    ``error`` holds why it failed (None: it succeeded)."""

    def __init__(self):
        self.done = threading.Event()
        self.error = None


class ControllerManagerServices:
    """controller_manager's services in the plugin's namespace; each call runs on the simulator's loop."""

    def __init__(self, ctx, manager):
        try:
            from controller_manager_msgs import srv
        except ImportError:  # the overlay left out: no controller_manager_msgs to serve
            ctx.warnings.append("controller_manager_msgs is not built (overlay left out): no controller_manager "
                                "services; controllers start only with ~autostart_controllers")
            return
        self.ctx, self.manager, self.srv = ctx, manager, srv
        base = join(manager.ns, "controller_manager")
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
            rospy.logerr(f"controller_manager {self.manager.ns}: {what}: {err}")
            return False

    def _load(self, req):
        return self.srv.LoadControllerResponse(self._on_loop(lambda: self.manager.load(req.name), "load"))

    def _unload(self, req):
        return self.srv.UnloadControllerResponse(self._on_loop(lambda: self.manager.unload(req.name), "unload"))

    def _switch(self, req):
        args = (list(req.start_controllers), list(req.stop_controllers), req.strictness)
        if not self.ctx.sim.paused:
            return self.srv.SwitchControllerResponse(self._on_loop(lambda: self.manager.switch(*args), "switch"))
        waiter = self.ctx.sim.call(lambda: self.manager.switch_later(*args))
        while not waiter.done.wait(0.1):  # upstream's service polls until its realtime loop has switched
            if rospy.is_shutdown():
                return self.srv.SwitchControllerResponse(False)
        if waiter.error is not None:
            rospy.logerr(f"controller_manager {self.manager.ns}: switch: {waiter.error}")
        return self.srv.SwitchControllerResponse(waiter.error is None)

    def _list(self, _req):
        from controller_manager_msgs.msg import ControllerState, HardwareInterfaceResources

        states = self.ctx.sim.call(self.manager.states)
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
            if self.manager.loaded and not req.force_kill:
                raise switching.SwitchError("Controller manager: Cannot reload controller libraries because there "
                                            "are still controllers loaded (force_kill unset)")
            self.manager.switch([], list(self.manager.loaded), switching.BEST_EFFORT)
            for name in list(self.manager.loaded):
                self.manager.unload(name)
        return self.srv.ReloadControllerLibrariesResponse(self._on_loop(action, "reload libraries"))
