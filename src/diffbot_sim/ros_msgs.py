"""The only place message objects are built (message modules only; no rospy).

Builders fill message objects the caller owns and re-uses, so the simulator allocates nothing per publish.
Stamps are passed in (sim time, as a genpy/rospy Time).
"""
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage


def new_odometry(frame, child, cov_x, cov_y, cov_yaw):
    """An Odometry with frames and covariance diagonals set once. z, roll, pitch are unobserved: 1e12."""
    msg = Odometry()
    msg.header.frame_id = frame
    msg.child_frame_id = child
    diagonal = (cov_x, cov_y, 1e12, 1e12, 1e12, cov_yaw)
    cov = [0.0] * 36
    for i, value in enumerate(diagonal):
        cov[i * 7] = value
    msg.pose.covariance = list(cov)
    msg.twist.covariance = list(cov)
    return msg


def fill_odometry(msg, stamp, position, orientation, linear, angular):
    """Pose in the odometry frame; twist in the child (base) frame, signed."""
    msg.header.stamp = stamp
    p, q = msg.pose.pose.position, msg.pose.pose.orientation
    p.x, p.y, p.z = position
    q.x, q.y, q.z, q.w = orientation
    v, w = msg.twist.twist.linear, msg.twist.twist.angular
    v.x, v.y, v.z = linear
    w.x, w.y, w.z = angular
    return msg


def new_transform(frame, child):
    msg = TransformStamped()
    msg.header.frame_id = frame
    msg.child_frame_id = child
    return msg


def fill_transform(msg, stamp, position, orientation):
    msg.header.stamp = stamp
    t, r = msg.transform.translation, msg.transform.rotation
    t.x, t.y, t.z = position
    r.x, r.y, r.z, r.w = orientation
    return msg


def tf_message(transforms):
    """All of a step's transforms in one TFMessage (one publish, not one per frame)."""
    return TFMessage(transforms=list(transforms))


def new_joint_state(names):
    msg = JointState()
    msg.name = list(names)
    return msg


def fill_joint_state(msg, stamp, positions, velocities, efforts):
    msg.header.stamp = stamp
    msg.position = positions
    msg.velocity = velocities
    msg.effort = efforts
    return msg


def clock(stamp):
    return Clock(clock=stamp)


def twist_values(twist):
    """The six Twist fields in controller.TWIST_FIELDS order."""
    return (twist.linear.x, twist.linear.y, twist.linear.z, twist.angular.x, twist.angular.y, twist.angular.z)
