"""gazebo_msgs of the /gazebo world API (``gazebo_ros_api_plugin``) to and from plain tuples (message modules
only; no rospy).

The API's decisions (:mod:`diffbot_sim.gazebo.world_api`) and the models (:mod:`diffbot_sim.simulator.
gazebo_models`) work on plain numbers: a pose is ``((x, y, z), (qx, qy, qz, qw))`` [m], a twist
``((vx, vy, vz), (wx, wy, wz))`` [m/s, rad/s], both in world axes unless a reference frame is named. These are
the only conversions between them and geometry_msgs/Pose, Twist and the gazebo_msgs states built of them.
ModelStates and LinkStates list every model (link) in one message, as gazebo_ros publishes them: ``name[i]``,
``pose[i]`` and ``twist[i]`` belong together.

gazebo_msgs is not a Debian package: it comes from the overlay (``overlay/gazebo_msgs``), so only the /gazebo
services import this module.
"""
from gazebo_msgs import msg as gmsg
from geometry_msgs.msg import Pose, Twist, Vector3
from std_msgs.msg import Header


def pose_tuple(msg):
    """A geometry_msgs/Pose as ``((x, y, z), (qx, qy, qz, qw))`` (not normalised: the caller checks it)."""
    p, q = msg.position, msg.orientation
    return (p.x, p.y, p.z), (q.x, q.y, q.z, q.w)


def twist_tuple(msg):
    """A geometry_msgs/Twist as ``((vx, vy, vz), (wx, wy, wz))``."""
    return (msg.linear.x, msg.linear.y, msg.linear.z), (msg.angular.x, msg.angular.y, msg.angular.z)


def pose_msg(pose):
    """geometry_msgs/Pose of ``((x, y, z), (qx, qy, qz, qw))``."""
    msg = Pose()
    (msg.position.x, msg.position.y, msg.position.z) = pose[0]
    (msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w) = pose[1]
    return msg


def twist_msg(twist):
    """geometry_msgs/Twist of ``(linear, angular)``."""
    msg = Twist()
    (msg.linear.x, msg.linear.y, msg.linear.z) = twist[0]
    (msg.angular.x, msg.angular.y, msg.angular.z) = twist[1]
    return msg


def vector3(values):
    """geometry_msgs/Vector3 of ``(x, y, z)`` (GetPhysicsProperties' gravity, m/s^2)."""
    return Vector3(*values)


def model_states(states):
    """gazebo_msgs/ModelStates of ``states``: ``(name, pose, linear, angular)`` in the order given."""
    return _filled(gmsg.ModelStates(), states)


def link_states(states):
    """gazebo_msgs/LinkStates of ``states``: ``(model::link, pose, linear, angular)`` in the order given."""
    return _filled(gmsg.LinkStates(), states)


def _filled(msg, states):
    """``msg`` (ModelStates or LinkStates: the same three lists) with one entry per state."""
    for name, pose, linear, angular in states:
        msg.name.append(name)
        msg.pose.append(pose_msg(pose))
        msg.twist.append(twist_msg((linear, angular)))
    return msg


def link_state(link_name, pose, twist, reference_frame):
    """gazebo_msgs/LinkState (GetLinkState's answer): ``pose`` and ``twist`` relative to ``reference_frame``."""
    return gmsg.LinkState(link_name=link_name, pose=pose_msg(pose), twist=twist_msg(twist),
                          reference_frame=reference_frame)


def state_header(seq, stamp, frame_id):
    """The std_msgs/Header of a GetModelState answer: its own count per model, sim time, the reference frame."""
    return Header(seq=seq, stamp=stamp, frame_id=frame_id)
