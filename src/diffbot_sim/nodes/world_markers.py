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
import time

from diffbot_sim.errors import DiffbotSimError
from diffbot_sim.nodes._entry import entry_point
from diffbot_sim.transforms import quaternion_from_yaw
from diffbot_sim.world.loading import robot_namespaces, simulator_world
from diffbot_sim.world.markers import CUBE, CYLINDER, MESH_RESOURCE, SPHERE, TRIANGLE_LIST, marker_specs

_KINDS = {CUBE: 1, SPHERE: 2, CYLINDER: 3, MESH_RESOURCE: 10, TRIANGLE_LIST: 11}  # Marker type constants


def make_marker_array(world, frame_id="world", warnings=None):
    """``world``'s static geometry as a visualization_msgs/MarkerArray in ``frame_id``.

    The first marker is a DELETEALL, so a node restarted with another world leaves no old shape in rviz.
    Marker ids count from 0 within each namespace (the body's name). Stamps are zero: the geometry holds at
    every time, and rviz then uses the latest transform instead of waiting for one at a given stamp.

    Args:
        world: a :class:`diffbot_sim.world.bodies.WorldDescription`.
        frame_id: the world's frame in TF.
        warnings: a list that gets one line per thing left out.

    Returns:
        visualization_msgs.msg.MarkerArray
    """
    from geometry_msgs.msg import Point
    from visualization_msgs.msg import Marker, MarkerArray

    array = MarkerArray()
    clear = Marker()
    clear.header.frame_id = frame_id
    clear.action = Marker.DELETEALL
    array.markers.append(clear)
    ids = {}
    for spec in marker_specs(world, warnings):
        m = Marker()
        m.header.frame_id = frame_id
        m.ns = spec.ns
        m.id = ids.get(spec.ns, 0)
        ids[spec.ns] = m.id + 1
        m.type = _KINDS[spec.kind]
        m.action = Marker.ADD
        (m.pose.position.x, m.pose.position.y, m.pose.position.z) = spec.pose[0]
        (m.pose.orientation.x, m.pose.orientation.y, m.pose.orientation.z, m.pose.orientation.w) = spec.pose[1]
        (m.scale.x, m.scale.y, m.scale.z) = spec.scale
        (m.color.r, m.color.g, m.color.b, m.color.a) = spec.color
        if spec.mesh:
            m.mesh_resource = spec.mesh
            m.mesh_use_embedded_materials = False
        if spec.kind == TRIANGLE_LIST:
            m.points = [Point(float(x), float(y), float(z)) for x, y, z in spec.points]
        m.frame_locked = False
        array.markers.append(m)
    return array


def odom_offset(source, x, y, yaw):
    """The pose of the odometry frame in the world, ``((x, y, z), (qx, qy, qz, qw))``: identity for
    ``world`` odometry (it reports the world pose), the spawn pose for ``encoder`` odometry (it starts at 0
    where the robot was spawned)."""
    if source != "encoder":
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)
    return (float(x), float(y), 0.0), quaternion_from_yaw(yaw)


def _wait(predicate, timeout, what):
    import rospy

    deadline = time.monotonic() + timeout
    while not rospy.is_shutdown():
        value = predicate()
        if value is not None:
            return value
        if time.monotonic() > deadline:
            raise DiffbotSimError(f"world_markers: no {what} after {timeout:g} s (is bullet_sim running?)")
        time.sleep(0.1)
    raise DiffbotSimError("world_markers: shut down while waiting for " + what)


def _odom_frames(sim, timeout):
    """``[(odometry frame, pose of it in the world)]`` for each robot of the simulator."""
    import rospy
    from nav_msgs.msg import Odometry

    out = []
    for ns in robot_namespaces(rospy.get_param(sim + "/robots", None)):
        private = sim + "/" + ns + "/" if ns else sim + "/"
        topic = _wait(lambda: rospy.get_param(private + "odom_topic", None), timeout,
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
    from geometry_msgs.msg import TransformStamped
    from visualization_msgs.msg import MarkerArray

    rospy.init_node("world_markers")
    sim = rospy.get_param("~sim", "/bullet_sim").rstrip("/")
    frame_id = rospy.get_param("~frame_id", "world")
    timeout = float(rospy.get_param("~timeout", 60.0))
    pub = rospy.Publisher("world_markers", MarkerArray, queue_size=1, latch=True)
    try:
        world = simulator_world(sim, rospy.get_param)
        warnings = []
        if world is not None:
            array = make_marker_array(world, frame_id, warnings)
            for text in warnings:
                rospy.logwarn("world_markers: " + text)
        else:
            array = make_marker_array(_Empty(), frame_id)
        pub.publish(array)
        rospy.loginfo(f"world_markers: {len(array.markers) - 1} markers in frame {frame_id}"
                      + (f" from {world.source}" if world is not None else " (no ~world: ground plane only)"))
        frames = _odom_frames(sim, timeout)
    except (DiffbotSimError, rospy.ROSException) as err:
        rospy.logfatal(str(err))
        return 1
    broadcaster = tf2_ros.StaticTransformBroadcaster()
    transforms = []
    for child, ((x, y, z), (qx, qy, qz, qw)) in frames:
        t = TransformStamped()
        t.header.frame_id = frame_id
        t.child_frame_id = child
        t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = x, y, z
        (t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z,
         t.transform.rotation.w) = qx, qy, qz, qw
        transforms.append(t)
    broadcaster.sendTransform(transforms)
    rospy.loginfo("world_markers: " + ", ".join(f"{frame_id} -> {t.child_frame_id}" for t in transforms))
    rospy.spin()
    return 0


class _Empty:
    """A world with nothing in it (no ``~world``): still publish, so rviz's display reports its topic."""

    bodies = ()

