"""controller_manager's command-line nodes (ROS 1 noetic semantics): ``spawner``, ``unspawner`` and
``controller_manager``, against the controller_manager services diffbot_sim's ros_control plugin serves.

Launch files written for Gazebo run ``<node pkg="controller_manager" type="spawner" args="joint_state_controller
diff_drive_controller"/>``; overlay/controller_manager's scripts run these nodes. Arguments are parsed by
:mod:`diffbot_sim.gazebo.cli`; here is only the ROS side.

Services called (controller_manager_msgs; ``<cm>`` is ``[--namespace/]controller_manager``, relative to the
node's namespace unless absolute): ``<cm>/load_controller`` (LoadController: name),
``<cm>/switch_controller`` (SwitchController: start_controllers, stop_controllers, strictness, start_asap,
timeout), ``<cm>/unload_controller`` (UnloadController: name), ``<cm>/list_controllers``,
``<cm>/list_controller_types``, ``<cm>/reload_controller_libraries`` (ReloadControllerLibraries: force_kill).

* ``spawner``: waits for load/switch/unload (``--timeout`` each; with sim time and no /clock yet it keeps
  waiting, as noetic), optionally for ``True`` on ``--wait-for``, loads every controller (a YAML file
  argument is uploaded where the controller manager reads it, and its top-level keys loaded), starts them
  in one STRICT switch unless ``--stopped``, spins; at shutdown stops and unloads what it loaded.
* ``unspawner NAME...``: stops the named running controllers (again every 3 s), restarts them at shutdown.
* ``controller_manager VERB NAME...``: one-shot calls, printing as noetic's script does.
"""
import sys
import threading
import time

import rospy
from controller_manager_msgs.srv import (
    ListControllers,
    ListControllersRequest,
    ListControllerTypes,
    ListControllerTypesRequest,
    LoadController,
    LoadControllerRequest,
    ReloadControllerLibraries,
    ReloadControllerLibrariesRequest,
    SwitchController,
    SwitchControllerRequest,
    UnloadController,
    UnloadControllerRequest,
)
from std_msgs.msg import Bool

from diffbot_sim.gazebo import cli as gazebo_cli
from diffbot_sim.gazebo.cli import CliError, UsageExit

#: Errors a call to a controller_manager service can raise (gone, refused connection, shutdown).
CALL_ERRORS = (rospy.ServiceException, rospy.ROSException)


def _parse(parse, prog, argv):
    """(parsed, None) or (None, exit status) after printing help or the one-line error."""
    argv = sys.argv if argv is None else argv
    try:
        return parse(argv[1:]), None
    except UsageExit as usage:
        if usage.text:
            # noetic prints help and usage on stdout, whatever the status
            sys.stdout.write(usage.text.rstrip("\n") + "\n")
        return None, usage.status
    except CliError as err:
        sys.stderr.write(f"{prog}: error: {err}\n")
        return None, 1


class ManagerClient:
    """The controller_manager services in one namespace (``--namespace``, or the node's namespace)."""

    def __init__(self, namespace=""):
        self.namespace = namespace

    def name(self, service):
        """The resolved name of ``<ns>/controller_manager/<service>``, for calls and messages."""
        return rospy.resolve_name(gazebo_cli.manager_service(self.namespace, service))

    def wait(self, service, timeout=None):
        """Wait for ``service``; raises rospy.ROSException after ``timeout`` s (None: forever)."""
        rospy.wait_for_service(self.name(service), timeout=timeout)

    def call(self, service, kind, request):
        return rospy.ServiceProxy(self.name(service), kind)(request)

    def load(self, name):
        return self.call("load_controller", LoadController, LoadControllerRequest(name=name)).ok

    def unload(self, name):
        return self.call("unload_controller", UnloadController, UnloadControllerRequest(name=name)).ok

    def switch(self, start=(), stop=(), strictness=SwitchControllerRequest.STRICT):
        request = SwitchControllerRequest(start_controllers=list(start), stop_controllers=list(stop),
                                          strictness=strictness, start_asap=False, timeout=0.0)
        return self.call("switch_controller", SwitchController, request).ok

    def controllers(self):
        return self.call("list_controllers", ListControllers, ListControllersRequest()).controller

    def types(self):
        return self.call("list_controller_types", ListControllerTypes, ListControllerTypesRequest()).types

    def reload_libraries(self, force_kill):
        request = ReloadControllerLibrariesRequest(force_kill=force_kill)
        return self.call("reload_controller_libraries", ReloadControllerLibraries, request).ok


# ------------------------------------------------------------------------------------------- spawner

def spawner_main(argv=None):
    """``rosrun controller_manager spawner [options] controller...``; returns the exit status."""
    args, status = _parse(gazebo_cli.parse_spawner_args, "spawner", argv)
    if args is None:
        return status
    try:
        controllers, files = gazebo_cli.expand_controllers(args.controllers)
    except CliError as err:
        sys.stderr.write(f"spawner: error: {err}\n")
        return 1
    rospy.init_node("spawner", anonymous=True)
    try:
        return Spawner(args, controllers, files).run()
    except rospy.ROSInterruptException:
        return 0


class Spawner:
    """One spawner's run: what it loaded, so that shutdown stops and unloads exactly that."""

    def __init__(self, args, controllers, files):
        self.args = args
        self.controllers = controllers
        self.files = files
        self.cm = ManagerClient(args.namespace)
        self.loaded = []

    def run(self):
        if not self._wait_for_services():
            return 1
        if self.args.wait_for and not self._wait_for_topic():
            return 0
        # Where the controller manager reads its controllers' configuration: --namespace, or this node's
        # namespace. (Noetic uploads to the node's namespace even with --namespace, where the manager then
        # finds nothing; where the two agree, this is the same.)
        prefix = gazebo_cli.manager_prefix(self.args.namespace)
        where = rospy.resolve_name(prefix) if prefix else rospy.get_namespace()
        for path, data in self.files:
            rospy.loginfo(f"Controller Spawner: uploading {path} to the parameter server under {where}")
            for name, value in gazebo_cli.flatten_params(data, prefix):
                rospy.set_param(name, value)
        rospy.on_shutdown(self.shutdown)
        for name in self.controllers:
            self._load(name)
        rospy.loginfo("Controller Spawner: Loaded controllers: %s" % ", ".join(self.loaded))
        if rospy.is_shutdown():
            return 0
        if not self.args.stopped and self.loaded:
            try:
                ok = self.cm.switch(start=self.loaded)
            except CALL_ERRORS as err:
                rospy.logerr(f"Failed to start controllers: {', '.join(self.loaded)}: "
                             f"{self.cm.name('switch_controller')}: {err}")
            else:
                if ok:
                    rospy.loginfo("Started controllers: %s" % ", ".join(self.loaded))
                else:
                    rospy.logerr(f"Failed to start controllers: {', '.join(self.loaded)} (see the simulator's "
                                 "log for the reason)")
        rospy.spin()
        return 0

    def _wait_for_services(self):
        """Wait for load, switch and unload (``--timeout`` each). False, with one error line, on timeout.

        As noetic: unload is waited for now though used at shutdown, to know early that the manager is
        complete; with /use_sim_time and no /clock yet the wait starts over (a paused or starting simulator).
        """
        timeout = self.args.timeout
        while True:
            try:
                for service in ("load_controller", "switch_controller", "unload_controller"):
                    rospy.loginfo("Controller Spawner: Waiting for service " + self.cm.name(service))
                    self.cm.wait(service, timeout)
                return True
            except rospy.ROSInterruptException:
                raise
            except rospy.ROSException:
                if rospy.get_param("/use_sim_time", False) and rospy.get_rostime() == rospy.Time(0):
                    rospy.loginfo("Waiting for /clock to be available...")
                    continue
                rospy.logerr(f"Controller Spawner couldn't find the expected controller_manager ROS interface: "
                             f"{self.cm.name(service)} did not appear within {timeout:g} s (is the robot "
                             "spawned, with a gazebo_ros_control plugin in that namespace?)")
                return False

    def _wait_for_topic(self):
        """Wait for ``True`` on ``--wait-for`` (std_msgs/Bool); False if ROS shut down first."""
        topic = self.args.wait_for
        last = [None]

        def on_msg(msg):
            last[0] = msg
            rospy.logdebug("Heard from wait-for topic: %s" % msg.data)

        sub = rospy.Subscriber(topic, Bool, on_msg)
        started = time.time()
        warned = False
        try:
            while last[0] is None or not last[0].data:
                time.sleep(0.01)
                if rospy.is_shutdown():
                    return False
                timeout = self.args.timeout
                if not warned and last[0] is None and timeout is not None and time.time() - started > timeout:
                    warned = True
                    rospy.logwarn(f'Controller Spawner hasn\'t heard anything from its "wait for" topic ({topic})')
        finally:
            sub.unregister()
        return True

    def _load(self, name):
        rospy.loginfo("Loading controller: " + name)
        try:
            ok = self.cm.load(name)
            reason = None
        except CALL_ERRORS as err:
            ok, reason = False, f"{self.cm.name('load_controller')}: {err}"
        if ok:
            self.loaded.append(name)
            return
        if reason is None:
            param = rospy.resolve_name(gazebo_cli.controller_type_param(self.args.namespace, name))
            try:
                kind = rospy.get_param(param)
            except KeyError:
                reason = (f"no parameter {param}: load the controller's configuration (rosparam load of its "
                          "YAML) before the spawner")
            else:
                reason = f"its type is '{kind}' ({param}); see the simulator's log for why it was refused"
        rospy.logerr(f"Failed to load {name}: {reason}")

    def shutdown(self):
        """on_shutdown hook: stop, then unload, what this spawner loaded (best effort, bounded by
        ``--shutdown-timeout`` when given; noetic ignores that flag, older spawners bounded the same work)."""
        if not self.loaded:
            return
        worker = threading.Thread(target=self._take_down, name="spawner-shutdown", daemon=True)
        worker.start()
        worker.join(self.args.shutdown_timeout)
        if worker.is_alive():
            rospy.logwarn(f"Controller Spawner: stopping and unloading did not finish within "
                          f"--shutdown-timeout={self.args.shutdown_timeout:g} s; leaving it")

    def _take_down(self):
        rospy.loginfo("Shutting down spawner. Stopping and unloading controllers...")
        try:
            rospy.loginfo("Stopping all controllers...")
            self.cm.switch(stop=self.loaded)
            rospy.loginfo("Unloading all loaded controllers...")
        except CALL_ERRORS as err:
            rospy.logwarn(f"Controller Spawner error while taking down controllers: {err}")
            return
        for name in reversed(self.loaded):
            try:
                rospy.loginfo(f"Trying to unload {name}")
                if self.cm.unload(name):
                    rospy.loginfo(f"Succeeded in unloading {name}")
                else:
                    rospy.logwarn(f"Controller Spawner could not unload {name}")
            except CALL_ERRORS as err:
                rospy.logwarn(f"Controller Spawner error while taking down controllers: {err}")
                return


# ------------------------------------------------------------------------------------------- unspawner

def unspawner_main(argv=None):
    """``rosrun controller_manager unspawner name...``: stop them until killed; returns the exit status."""
    names, status = _parse(gazebo_cli.parse_unspawner_args, "unspawner", argv)
    if names is None:
        return status
    rospy.init_node("unspawner", anonymous=True)
    cm = ManagerClient()
    inhibited = set()
    lock = threading.Lock()
    try:
        for service in ("switch_controller", "list_controllers"):
            cm.wait(service)
    except rospy.ROSInterruptException:
        return 0

    def stop_controllers(_event=None):
        with lock:
            try:
                running = {c.name for c in cm.controllers() if c.state == "running"}
                to_stop = sorted(set(names) & running)
                if to_stop:
                    rospy.loginfo("Inhibiting controllers: %s" % ", ".join(to_stop))
                    cm.switch(stop=to_stop, strictness=SwitchControllerRequest.BEST_EFFORT)
                    inhibited.update(to_stop)
            except CALL_ERRORS as err:
                rospy.logwarn(f"unspawner: could not stop {', '.join(names)}: {err}")

    stop_controllers()
    timer = rospy.Timer(rospy.Duration(gazebo_cli.UNSPAWNER_PERIOD), stop_controllers)

    def restart_controllers():
        timer.shutdown()
        with lock:
            if not inhibited:
                return
            try:
                cm.switch(start=sorted(inhibited), strictness=SwitchControllerRequest.BEST_EFFORT)
            except CALL_ERRORS as err:
                rospy.logwarn(f"unspawner: could not restart {', '.join(sorted(inhibited))}: {err}")

    rospy.on_shutdown(restart_controllers)
    rospy.spin()
    return 0


# ------------------------------------------------------------------------------------------- controller_manager

def controller_manager_main(argv=None):
    """``rosrun controller_manager controller_manager VERB [name...]``; 0 when every call succeeded, else 1
    (noetic always exits 0; it prints the same lines)."""
    command, status = _parse(gazebo_cli.parse_controller_manager_args, "controller_manager", argv)
    if command is None:
        return status
    rospy.init_node("controller_manager", anonymous=True)
    cm = ManagerClient()
    try:
        return 0 if _run_command(cm, command) else 1
    except rospy.ROSInterruptException:
        return 0
    except CALL_ERRORS as err:
        sys.stderr.write(f"controller_manager: error: {err}\n")
        return 1


def _out(*lines):
    for line in lines:
        print(line)


def _run_command(cm, command):
    verb, names = command.verb, command.names
    if verb == "list-types":
        cm.wait("list_controller_types")
        _out(*cm.types())
        return True
    if verb == "list":
        cm.wait("list_controllers")
        _out(*gazebo_cli.format_controller_list(cm.controllers()))
        return True
    if verb == "reload-libraries":
        return _reload_libraries(cm, command.restore)
    ok = True
    steps = {"load": ("load",), "unload": ("unload",), "start": ("start",), "stop": ("stop",),
             "spawn": ("load", "start"), "kill": ("stop", "unload")}[verb]
    for step in steps:
        for name in names:
            ok = _step(cm, step, name) and ok
    return ok


def _step(cm, step, name):
    if step == "load":
        cm.wait("load_controller")
        ok = cm.load(name)
        _out(gazebo_cli.format_load(ok, name))
        return ok
    if step == "unload":
        cm.wait("unload_controller")
        ok = cm.unload(name)
        _out(gazebo_cli.format_unload(ok, name))
        return ok
    cm.wait("switch_controller")
    start, stop = ([name], []) if step == "start" else ([], [name])
    ok = cm.switch(start=start, stop=stop)
    _out(*gazebo_cli.format_switch(ok, start, stop))
    return ok


def _reload_libraries(cm, restore):
    cm.wait("reload_controller_libraries")
    _out("Restore: " + str(restore))
    originally = cm.controllers() if restore else []
    ok = cm.reload_libraries(True)
    _out("Successfully reloaded libraries" if ok
         else "Failed to reload libraries. Do you still have controllers loaded?")
    if restore:
        for state in originally:
            cm.load(state.name)
        cm.switch(start=[s.name for s in originally if s.state == "running"],
                  strictness=SwitchControllerRequest.BEST_EFFORT)
        _out("Controllers restored to original state")
    return ok
