"""``rosrun controller_manager controller_manager VERB NAME...``: controller_manager's command-line tool
(ROS 1 noetic semantics): one-shot calls of the controller_manager services (load, unload, start, stop,
spawn, kill, list, list-types, reload-libraries), printing as noetic's script does.
overlay/controller_manager's ``controller_manager`` script runs this node; arguments and printouts:
:mod:`diffbot_sim.gazebo.controller_cli`, services: :mod:`diffbot_sim.nodes._manager_client`.
"""
import sys

import rospy
from controller_manager_msgs.srv import SwitchControllerRequest

from diffbot_sim.gazebo import controller_cli
from diffbot_sim.nodes._entry import entry_point
from diffbot_sim.nodes._manager_client import CALL_ERRORS, ManagerClient


@entry_point
def main(argv=None):
    """``rosrun controller_manager controller_manager VERB [name...]``; 0 when every call succeeded, else 1
    (noetic always exits 0; it prints the same lines)."""
    command, status = controller_cli.parse_or_status(controller_cli.parse_controller_manager_args,
                                                     "controller_manager", argv)
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
        _out(*controller_cli.format_controller_list(cm.controllers()))
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
        _out(controller_cli.format_load(ok, name))
        return ok
    if step == "unload":
        cm.wait("unload_controller")
        ok = cm.unload(name)
        _out(controller_cli.format_unload(ok, name))
        return ok
    cm.wait("switch_controller")
    start, stop = ([name], []) if step == "start" else ([], [name])
    ok = cm.switch(start=start, stop=stop)
    _out(*controller_cli.format_switch(ok, start, stop))
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


if __name__ == "__main__":
    sys.exit(main())
