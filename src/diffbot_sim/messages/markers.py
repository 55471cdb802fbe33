"""A world's static shapes as the visualization_msgs/MarkerArray rviz draws (message modules only; no rospy).

The shapes and what is left out come from :func:`diffbot_sim.world.markers.marker_specs`; this module only
fills the message, for ``world_markers`` (Gazebo draws its world in its own window; rviz needs markers).
"""
from geometry_msgs.msg import Point
from visualization_msgs.msg import Marker, MarkerArray

from diffbot_sim.world.markers import CUBE, CYLINDER, MESH_RESOURCE, SPHERE, TRIANGLE_LIST, marker_specs

#: visualization_msgs/Marker's type constants of the spec kinds
MARKER_TYPES = {CUBE: Marker.CUBE, SPHERE: Marker.SPHERE, CYLINDER: Marker.CYLINDER,
                MESH_RESOURCE: Marker.MESH_RESOURCE, TRIANGLE_LIST: Marker.TRIANGLE_LIST}


def marker_array(world, frame_id="world", warnings=None):
    """``world``'s static geometry as a visualization_msgs/MarkerArray in ``frame_id``.

    The first marker is a DELETEALL, so a node restarted with another world leaves no old shape in rviz.
    Marker ids count from 0 within each namespace (the body's name). Stamps are zero: the geometry holds at
    every time, and rviz then uses the latest transform instead of waiting for one at a given stamp.

    Args:
        world: a :class:`diffbot_sim.world.bodies.WorldDescription` (anything with ``bodies``).
        frame_id: the world's frame in TF.
        warnings: a list that gets one line per thing left out.

    Returns:
        visualization_msgs.msg.MarkerArray
    """
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
        m.type = MARKER_TYPES[spec.kind]
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
