"""``rosrun gazebo_ros spawn_model``: gazebo_ros's spawner of models, against diffbot_sim's world API.

Launch files written for Gazebo run ``<node pkg="gazebo_ros" type="spawn_model" args="-urdf -param
robot_description -model r1 -x 1 ..."/>``; overlay/gazebo_ros's ``spawn_model`` script runs this node. The
arguments mean what they mean in ROS 1 noetic (parsed by :mod:`diffbot_sim.gazebo.spawn_cli`); the node only
does the ROS side, in upstream's order:

1. ``-wait MODEL``: wait until MODEL is in ``<gazebo_ns>/model_states`` (checked at 10 Hz);
2. read the XML (``-file``, ``-param``, ``-stdin``, or the ``-database`` template) and check it parses;
3. call ``<gazebo_ns>/spawn_urdf_model`` or ``spawn_sdf_model`` (gazebo_msgs/SpawnModel: model_name,
   model_xml, robot_namespace, initial_pose, reference_frame), waiting for the service as long as it takes;
4. ``-J``: ``<gazebo_ns>/set_model_configuration`` (gazebo_msgs/SetModelConfiguration);
5. ``-unpause``: ``<gazebo_ns>/unpause_physics`` (std_srvs/Empty);
6. ``-b``: stay up; at shutdown ``<gazebo_ns>/delete_model`` (gazebo_msgs/DeleteModel).

Exit status: 0 once spawned (or, with ``-b``, at shutdown); 1 on a bad argument, unreadable XML or a
refused call (its status_message logged), one line naming the flag, file, parameter or service.
"""
import sys
import threading
import time

import rospy
from gazebo_msgs.msg import ModelStates
from gazebo_msgs.srv import (
    DeleteModel,
    DeleteModelRequest,
    SetModelConfiguration,
    SetModelConfigurationRequest,
    SpawnModel,
    SpawnModelRequest,
)
from geometry_msgs.msg import Pose
from std_srvs.srv import Empty, EmptyRequest

from diffbot_sim.gazebo import spawn_cli
from diffbot_sim.gazebo.cli import CliError, UsageExit

NODE_NAME = "spawn_model"
#: How often ``-wait`` checks for its model (s, wall time): upstream's 10 Hz.
WAIT_PERIOD = 0.1


class SpawnFailed(Exception):
    """A step failed; the message (one line) has been decided, the node exits 1."""


def main(argv=None):
    """Run the node; return the exit status."""
    argv = sys.argv if argv is None else argv
    try:
        # Upstream's -robot_namespace default: the node's namespace (ROS_NAMESPACE, __ns:=), known before init.
        args = spawn_cli.parse_spawn_args(argv[1:], default_robot_namespace=rospy.get_namespace())
    except UsageExit as usage:
        (sys.stdout if usage.status == 0 else sys.stderr).write(usage.text.rstrip("\n") + "\n")
        return usage.status
    except CliError as err:
        sys.stderr.write(f"{NODE_NAME}: error: {err}\n")
        return 1
    rospy.init_node(NODE_NAME, anonymous=True)
    try:
        return run(args)
    except SpawnFailed as err:
        rospy.logerr(f"{NODE_NAME}: {err}")
        return 1
    except rospy.ROSInterruptException:
        return 0


def run(args):
    """Spawn as ``args`` says; return the exit status (raises SpawnFailed with the message on failure)."""
    if args.wait and not _wait_for_model(args):
        return 0
    model_xml = _model_xml(args)
    _spawn(args, model_xml)
    if args.joints:
        _set_configuration(args)
    if args.unpause:
        _unpause(args)
    if args.bond:
        rospy.on_shutdown(lambda: _delete_model(args))
        rospy.loginfo(f"Waiting for shutdown to delete model {args.model}")
        rospy.spin()
    return 0


def _wait_for_model(args):
    """Block until ``args.wait`` is among the models of ``model_states``; False if ROS shut down first."""
    seen = threading.Event()

    def on_states(msg):
        if args.wait in msg.name:
            seen.set()

    sub = rospy.Subscriber(args.service("model_states"), ModelStates, on_states, queue_size=1)
    rospy.loginfo(f"Waiting for model {args.wait} before proceeding.")
    try:
        # 10 Hz in wall time: upstream's rospy.Rate runs on sim time, which stands still without /clock.
        while not rospy.is_shutdown() and not seen.wait(WAIT_PERIOD):
            pass
    finally:
        sub.unregister()
    return seen.is_set()


def _model_xml(args):
    """The model XML as ``args`` names its source, checked to parse (and package:// rewritten if asked)."""
    label = args.source_label
    try:
        if args.source == "file":
            rospy.loginfo(f"Loading model XML from file {args.source_value}")
            text = spawn_cli.read_model_file(args.source_value)
        elif args.source == "param":
            rospy.loginfo(f"Loading model XML from ros parameter {args.source_value}")
            name = rospy.resolve_name(args.source_value)
            try:
                text = rospy.get_param(name)
            except KeyError:
                raise CliError(f"{label}: parameter {name} is not set") from None
            spawn_cli.check_model_text(text, f"{label} (parameter {name})")
        elif args.source == "database":
            rospy.loginfo(f"Loading model XML for model://{args.source_value}")
            text = spawn_cli.database_xml(args.source_value)
        else:
            rospy.loginfo("Loading model XML from stdin")
            text = spawn_cli.check_model_text(sys.stdin.read(), "-stdin: standard input")
        return spawn_cli.prepare_model_xml(text, label, args.package_to_model)
    except CliError as err:
        raise SpawnFailed(str(err)) from None


def _proxy(args, name, kind):
    """A proxy of world API service ``name``, once it exists (waits as long as it takes, as upstream)."""
    service = args.service(name)
    rospy.loginfo(f"Waiting for service {service}")
    rospy.wait_for_service(service)
    return service, rospy.ServiceProxy(service, kind)


def _call(service, proxy, request):
    try:
        return proxy(request)
    except rospy.ServiceException as err:
        raise SpawnFailed(f"{service} call failed: {err}") from None


def _spawn(args, model_xml):
    service, spawn = _proxy(args, f"spawn_{args.fmt}_model", SpawnModel)
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = args.position
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = args.orientation
    request = SpawnModelRequest(model_name=args.model, model_xml=model_xml, robot_namespace=args.robot_namespace,
                                initial_pose=pose, reference_frame=args.reference_frame)
    rospy.loginfo(f"Calling service {service}")
    resp = _call(service, spawn, request)
    if not resp.success:
        raise SpawnFailed(f"{service} refused model '{args.model}' ({args.source_label}): {resp.status_message}")
    rospy.loginfo(f"Spawn status: {resp.status_message}")


#: Wall seconds upstream's spawn_model sleeps before set_model_configuration ("temporary hack",
#: gazebo_ros_pkgs issue 93): launch files are timed with it (a paused world is unpaused after it).
CONFIGURATION_DELAY = 1.0


def _set_configuration(args):
    service, configure = _proxy(args, "set_model_configuration", SetModelConfiguration)
    time.sleep(CONFIGURATION_DELAY)
    names = [name for name, _ in args.joints]
    request = SetModelConfigurationRequest(
        model_name=args.model, urdf_param_name=args.source_value if args.source == "param" else "",
        joint_names=names, joint_positions=[position for _, position in args.joints])
    resp = _call(service, configure, request)
    if not resp.success:
        raise SpawnFailed(f"{service} refused -J {', '.join(names)} of model '{args.model}': "
                          f"{resp.status_message}")
    rospy.loginfo(f"Set model configuration status: {resp.status_message}")


def _unpause(args):
    rospy.loginfo("Unpausing physics")
    service, unpause = _proxy(args, "unpause_physics", Empty)
    _call(service, unpause, EmptyRequest())


def _delete_model(args):
    """Shutdown hook of ``-b``: delete the model (best effort; the simulator may be gone already)."""
    service = args.service("delete_model")
    rospy.loginfo(f"Deleting model {args.model}")
    try:
        resp = rospy.ServiceProxy(service, DeleteModel)(DeleteModelRequest(model_name=args.model))
    except (rospy.ServiceException, rospy.ROSException) as err:
        rospy.logerr(f"{service} call failed: {err}")
        return
    if not resp.success:
        rospy.logerr(f"{service} refused to delete model '{args.model}': {resp.status_message}")
