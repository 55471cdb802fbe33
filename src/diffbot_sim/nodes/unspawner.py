"""``rosrun controller_manager unspawner NAME...``: controller_manager's unspawner (ROS 1 noetic semantics):
stops the named running controllers (again every 3 s, in case a spawner started them meanwhile) and restarts
them at shutdown. overlay/controller_manager's ``unspawner`` script runs this node; arguments:
:mod:`diffbot_sim.gazebo.controller_cli`, services: :mod:`diffbot_sim.nodes._manager_client`.
"""
import sys
import threading

import rospy
from controller_manager_msgs.srv import SwitchControllerRequest

from diffbot_sim.gazebo import controller_cli
from diffbot_sim.nodes._entry import entry_point
from diffbot_sim.nodes._manager_client import CALL_ERRORS, ManagerClient


@entry_point
def main(argv=None):
    """``rosrun controller_manager unspawner name...``: stop them until killed; returns the exit status."""
    names, status = controller_cli.parse_or_status(controller_cli.parse_unspawner_args, "unspawner", argv)
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
                    rospy.loginfo(f"Inhibiting controllers: {', '.join(to_stop)}")
                    cm.switch(stop=to_stop, strictness=SwitchControllerRequest.BEST_EFFORT)
                    inhibited.update(to_stop)
            except CALL_ERRORS as err:
                rospy.logwarn(f"unspawner: could not stop {', '.join(names)}: {err}")

    stop_controllers()
    timer = rospy.Timer(rospy.Duration(controller_cli.UNSPAWNER_PERIOD), stop_controllers)

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


if __name__ == "__main__":
    sys.exit(main())
