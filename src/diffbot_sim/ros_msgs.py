"""The only place message objects are built (message modules only; no rospy).

Each call returns a new message: rospy's queued publishers serialize on another thread later, so a message
object must never be refilled after ``publish()``. What is constant (frames, names, covariance) is computed
once by the builder. Stamps are passed in (sim time, as a genpy/rospy Time).
"""
from geometry_msgs.msg import TransformStamped, Twist, TwistStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage


def covariance_diagonal(cov_x, cov_y, cov_yaw):
    """6x6 row-major covariance with x, y, yaw given; z, roll and pitch are unobserved (1e12)."""
    cov = [0.0] * 36
    for i, value in enumerate((cov_x, cov_y, 1e12, 1e12, 1e12, cov_yaw)):
        cov[i * 7] = value
    return cov


class OdometryBuilder:
    """Odometry in ``frame`` for ``child``: pose in the odometry frame, twist in the child frame (signed)."""

    def __init__(self, frame, child, cov_x, cov_y, cov_yaw):
        self.frame, self.child = frame, child
        self.covariance = covariance_diagonal(cov_x, cov_y, cov_yaw)

    def build(self, stamp, position, orientation, linear, angular):
        msg = Odometry()
        msg.header.stamp = stamp
        msg.header.frame_id = self.frame
        msg.child_frame_id = self.child
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        p.x, p.y, p.z = position
        q.x, q.y, q.z, q.w = orientation
        v, w = msg.twist.twist.linear, msg.twist.twist.angular
        v.x, v.y, v.z = linear
        w.x, w.y, w.z = angular
        msg.pose.covariance = self.covariance
        msg.twist.covariance = self.covariance
        return msg


def transform(stamp, frame, child, position, orientation):
    msg = TransformStamped()
    msg.header.stamp = stamp
    msg.header.frame_id = frame
    msg.child_frame_id = child
    t, r = msg.transform.translation, msg.transform.rotation
    t.x, t.y, t.z = position
    r.x, r.y, r.z, r.w = orientation
    return msg


def tf_message(transforms):
    """All of a step's transforms in one TFMessage (one publish, not one per frame)."""
    return TFMessage(transforms=list(transforms))


def joint_state(stamp, names, positions, velocities, efforts):
    msg = JointState()
    msg.header.stamp = stamp
    msg.name = names
    msg.position = positions
    msg.velocity = velocities
    msg.effort = efforts
    return msg


def clock(stamp):
    return Clock(clock=stamp)


def twist(linear, angular):
    """A planar body command: linear.x [m/s], angular.z [rad/s]."""
    msg = Twist()
    msg.linear.x = linear
    msg.angular.z = angular
    return msg


def twist_stamped(stamp, linear, angular):
    msg = TwistStamped()
    msg.header.stamp = stamp
    msg.twist = twist(linear, angular)
    return msg


def twist_values(twist):
    """The six Twist fields in controller.TWIST_FIELDS order."""
    return (twist.linear.x, twist.linear.y, twist.linear.z, twist.angular.x, twist.angular.y, twist.angular.z)
