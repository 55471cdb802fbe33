"""The controller_manager services, as the ``spawner``, ``unspawner`` and ``controller_manager`` nodes call
them (controller_manager_msgs; the ros_control plugin serves them in the simulator).

``<cm>`` is ``[--namespace/]controller_manager``, relative to the node's namespace unless absolute:
``<cm>/load_controller`` (LoadController: name), ``<cm>/switch_controller`` (SwitchController:
start_controllers, stop_controllers, strictness, start_asap, timeout), ``<cm>/unload_controller``
(UnloadController: name), ``<cm>/list_controllers``, ``<cm>/list_controller_types``,
``<cm>/reload_controller_libraries`` (ReloadControllerLibraries: force_kill).
"""
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

from diffbot_sim.gazebo import controller_cli

#: Errors a call to a controller_manager service can raise (gone, refused connection, shutdown).
CALL_ERRORS = (rospy.ServiceException, rospy.ROSException)


class ManagerClient:
    """The controller_manager services in one namespace (``--namespace``, or the node's namespace)."""

    def __init__(self, namespace=""):
        self.namespace = namespace

    def name(self, service):
        """The resolved name of ``<ns>/controller_manager/<service>``, for calls and messages."""
        return rospy.resolve_name(controller_cli.manager_service(self.namespace, service))

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
