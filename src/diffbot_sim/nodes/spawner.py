"""``rosrun controller_manager spawner``: controller_manager's spawner (ROS 1 noetic semantics), against the
controller_manager services diffbot_sim's ros_control plugin serves.

Launch files written for Gazebo run ``<node pkg="controller_manager" type="spawner" args="joint_state_controller
diff_drive_controller"/>``; overlay/controller_manager's ``spawner`` script runs this node. Arguments are
parsed by :mod:`diffbot_sim.gazebo.controller_cli`, the services called through
:mod:`diffbot_sim.nodes._manager_client`; here is only the ROS side.

The spawner waits for load/switch/unload (``--timeout`` each; with sim time and no /clock yet it keeps
waiting, as noetic), optionally for ``True`` on ``--wait-for``, loads every controller (a YAML file argument
is uploaded where the controller manager reads it, and its top-level keys loaded), starts them in one STRICT
switch unless ``--stopped``, spins; at shutdown it stops and unloads what it loaded.
"""
import sys
import threading
import time

import rospy
from std_msgs.msg import Bool

from diffbot_sim.gazebo import controller_cli
from diffbot_sim.gazebo.cli import CliError
from diffbot_sim.nodes._entry import entry_point
from diffbot_sim.nodes._manager_client import CALL_ERRORS, ManagerClient


@entry_point
def main(argv=None):
    """``rosrun controller_manager spawner [options] controller...``; returns the exit status."""
    args, status = controller_cli.parse_or_status(controller_cli.parse_spawner_args, "spawner", argv)
    if args is None:
        return status
    try:
        controllers, files = controller_cli.expand_controllers(args.controllers)
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
        prefix = controller_cli.manager_prefix(self.args.namespace)
        where = rospy.resolve_name(prefix) if prefix else rospy.get_namespace()
        for path, data in self.files:
            rospy.loginfo(f"Controller Spawner: uploading {path} to the parameter server under {where}")
            for name, value in controller_cli.flatten_params(data, prefix):
                rospy.set_param(name, value)
        rospy.on_shutdown(self.shutdown)
        for name in self.controllers:
            self._load(name)
        rospy.loginfo(f"Controller Spawner: Loaded controllers: {', '.join(self.loaded)}")
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
                    rospy.loginfo(f"Started controllers: {', '.join(self.loaded)}")
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
            rospy.logdebug(f"Heard from wait-for topic: {msg.data}")

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
            param = rospy.resolve_name(controller_cli.controller_type_param(self.args.namespace, name))
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


if __name__ == "__main__":
    sys.exit(main())
