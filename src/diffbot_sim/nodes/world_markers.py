"""``rosrun diffbot_sim world_markers``: the simulator's world for rviz, and where it sits against ``odom``.

Gazebo shows its world in its own window; rviz sees nothing of it, and in a Gazebo setup the world is not
in TF at all (``odom`` is the fixed frame). So that rviz can draw the walls a laser scan hits, this node
reads the same world file as ``bullet_sim`` (its ``~world`` parameter), publishes the static shapes once as
a latched MarkerArray in frame ``world``, and publishes ``world`` -> each robot's odometry frame on
``/tf_static``. It needs nothing from the simulator's code path: no hook in ``bullet_sim``.

``world`` -> odom: the simulator's odometry with ``odometry_source: world`` (Gazebo's default) *is* the
world pose, so the transform is the identity; with ``encoder`` odometry starts at the spawn pose, so the
transform is the spawn pose (x, y, yaw; the height a robot is raised onto is left out: odometry is planar).
Both come from the simulator's effective parameters (written back after it loaded the robots), and the
odometry frame's name from the header of the robot's first odometry message, so prefixed frames
(``robot1/odom``) come out as the simulator really publishes them.

Topics:
    ``world_markers`` (visualization_msgs/MarkerArray, latched): a DELETEALL, then one marker per static
        collision shape (box, cylinder, sphere, mesh; a map's walls as triangle lists), frame ``~frame_id``.
    ``/tf_static``: ``~frame_id`` -> each robot's odometry frame.

Parameters:
    ``~sim`` (str, ``/bullet_sim``): the simulator node, whose ``world``, ``map_wall_height``, ``robots``
        and effective parameters are read.
    ``~frame_id`` (str, ``world``): the frame of the markers and the parent of the static transforms.
    ``~timeout`` (float, 60 s wall): how long to wait for the simulator's effective parameters and first
        odometry before giving up (exit 1).

Exit status 1, with one line, on a world file that cannot be read or a simulator that never reports.
"""
import functools

from diffbot_sim.errors import DiffbotSimError
from diffbot_sim.nodes._entry import entry_point
from diffbot_sim.transforms import quaternion_from_yaw
from diffbot_sim.waiting import wait_for
from diffbot_sim.world.loading import robot_namespaces, simulator_world


def odom_offset(source, x, y, yaw):
    """The pose of the odometry frame in the world, ``((x, y, z), (qx, qy, qz, qw))``: identity for
    ``world`` odometry (it reports the world pose), the spawn pose for ``encoder`` odometry (it starts at 0
    where the robot was spawned)."""
    if source != "encoder":
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)
    return (float(x), float(y), 0.0), quaternion_from_yaw(yaw)


def _wait(predicate, timeout, what):
    """``predicate()``'s first value that is not None (an empty one counts), through ``waiting.wait_for`` as this
    node fails: one line naming itself, ended early by a ROS shutdown."""
    import rospy

    def present():
        value = predicate()
        return None if value is None else [value]
    return wait_for(present, timeout, what, 0.1, give_up=lambda: rospy.is_shutdown() and "shut down",
                    error=lambda message: DiffbotSimError(f"world_markers: {message} (is bullet_sim running?)"))[0]


def _odom_frames(sim, timeout):
    """``[(odometry frame, pose of it in the world)]`` for each robot of the simulator."""
    import rospy
    from nav_msgs.msg import Odometry

    out = []
    for ns in robot_namespaces(rospy.get_param(sim + "/robots", None)):
        private = sim + "/" + ns + "/" if ns else sim + "/"
        topic = _wait(functools.partial(rospy.get_param, private + "odom_topic", None), timeout,
                      f"parameter {private}odom_topic (the simulator's effective settings)")
        msg = rospy.wait_for_message(topic, Odometry, timeout=timeout)
        pose = odom_offset(rospy.get_param(private + "odometry_source", "world"),
                           rospy.get_param(private + "x", 0.0), rospy.get_param(private + "y", 0.0),
                           rospy.get_param(private + "yaw", 0.0))
        out.append((msg.header.frame_id, pose))
    return out


@entry_point
def main():
    """Entry point of ``rosrun diffbot_sim world_markers``."""
    import rospy
    import tf2_ros
    from visualization_msgs.msg import MarkerArray

    from diffbot_sim.messages.common import transform_stamped
    from diffbot_sim.messages.markers import marker_array

    rospy.init_node("world_markers")
    sim = rospy.get_param("~sim", "/bullet_sim").rstrip("/")
    frame_id = rospy.get_param("~frame_id", "world")
    timeout = float(rospy.get_param("~timeout", 60.0))
    pub = rospy.Publisher("world_markers", MarkerArray, queue_size=1, latch=True)
    try:
        world = simulator_world(sim, rospy.get_param)
        warnings = []
        if world is not None:
            array = marker_array(world, frame_id, warnings)
            for text in warnings:
                rospy.logwarn("world_markers: " + text)
        else:
            array = marker_array(_Empty(), frame_id)
        pub.publish(array)
        rospy.loginfo(f"world_markers: {len(array.markers) - 1} markers in frame {frame_id}"
                      + (f" from {world.source}" if world is not None else " (no ~world: ground plane only)"))
        frames = _odom_frames(sim, timeout)
    except (DiffbotSimError, rospy.ROSException) as err:
        rospy.logfatal(str(err))
        return 1
    broadcaster = tf2_ros.StaticTransformBroadcaster()
    transforms = [transform_stamped(frame_id, child, pose) for child, pose in frames]
    broadcaster.sendTransform(transforms)
    rospy.loginfo("world_markers: " + ", ".join(f"{frame_id} -> {t.child_frame_id}" for t in transforms))
    rospy.spin()
    return 0


class _Empty:
    """A world with nothing in it (no ``~world``): still publish, so rviz's display reports its topic."""

    bodies = ()

