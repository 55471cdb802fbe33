"""The only place message objects are built (message modules only; no rospy).

The simulator publishes four messages per control period, thousands per wall second in fast mode, so its
builders reuse one message object each and serialize it with a few precompiled ``struct`` calls instead of
genpy's field-by-field code. That is safe because rospy serializes inside ``publish()`` on the caller's
thread, queued publisher or not (rospy/topics.py ``_PublisherImpl.publish``): once ``publish()`` returns,
the object may be refilled. The packed classes keep their genpy type and md5sum and write the very same
bytes (tests/unit/test_ros_msgs.py compares them with genpy's own ``serialize``); what never changes
(frames, joint names, covariance) is packed once per builder. The subclasses declare no ``__slots__`` on
purpose: genpy reads ``self.__slots__`` for the field list (printing, equality, keyword construction).
"""
import struct

from geometry_msgs.msg import TransformStamped, Twist, TwistStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState
from tf2_msgs.msg import TFMessage

_HEADER = struct.Struct("<3I")  # seq, stamp.secs, stamp.nsecs
_COUNT = struct.Struct("<I")
_POSE = struct.Struct("<7d")  # position xyz, orientation xyzw
_TWIST = struct.Struct("<6d")  # linear xyz, angular xyz


def _string(text):
    data = text.encode("utf-8")
    return _COUNT.pack(len(data)) + data


def covariance_diagonal(cov_x, cov_y, cov_yaw):
    """6x6 row-major covariance with x, y, yaw given; z, roll and pitch are unobserved (1e12)."""
    cov = [0.0] * 36
    for i, value in enumerate((cov_x, cov_y, 1e12, 1e12, 1e12, cov_yaw)):
        cov[i * 7] = value
    return cov


def diagonal(values):
    """6x6 row-major covariance with the six given values on its diagonal."""
    cov = [0.0] * 36
    for i, value in enumerate(values):
        cov[i * 7] = float(value)
    return cov


class PackedOdometry(Odometry):
    """nav_msgs/Odometry with frames and covariance packed once (same type, md5sum and bytes)."""


    def __init__(self, frame, child, covariance, twist_covariance=None):
        super().__init__()
        twist_covariance = covariance if twist_covariance is None else twist_covariance
        self.header.frame_id, self.child_frame_id = frame, child
        self.pose.covariance = list(covariance)
        self.twist.covariance = list(twist_covariance)
        self._frames = _string(frame) + _string(child)
        self._covariance = struct.pack("<36d", *covariance)
        self._twist_covariance = struct.pack("<36d", *twist_covariance)

    def serialize(self, buff):
        h, p, t = self.header, self.pose.pose, self.twist.twist
        buff.write(_HEADER.pack(h.seq, h.stamp.secs, h.stamp.nsecs))
        buff.write(self._frames)
        a, b = p.position, p.orientation
        buff.write(_POSE.pack(a.x, a.y, a.z, b.x, b.y, b.z, b.w))
        buff.write(self._covariance)
        a, b = t.linear, t.angular
        buff.write(_TWIST.pack(a.x, a.y, a.z, b.x, b.y, b.z))
        buff.write(self._twist_covariance)


class OdometryBuilder:
    """Odometry in ``frame`` for ``child``: pose in the odometry frame, twist in the child frame (signed)."""

    def __init__(self, frame, child, cov_x, cov_y, cov_yaw, pose_diagonal=None, twist_diagonal=None):
        """Covariance: x, y, yaw variances on both diagonals (gazebo_ros), or six-value ``pose_diagonal``
        and ``twist_diagonal`` (diff_drive_controller's parameters), which win when given."""
        self.frame, self.child = frame, child
        self.covariance = (diagonal(pose_diagonal) if pose_diagonal is not None
                           else covariance_diagonal(cov_x, cov_y, cov_yaw))
        twist = diagonal(twist_diagonal) if twist_diagonal is not None else self.covariance
        self.msg = PackedOdometry(frame, child, self.covariance, twist)

    def build(self, stamp, position, orientation, linear, angular):
        """The builder's message, refilled: publish it before the next build()."""
        msg = self.msg
        msg.header.stamp = stamp
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        p.x, p.y, p.z = position
        q.x, q.y, q.z, q.w = orientation
        v, w = msg.twist.twist.linear, msg.twist.twist.angular
        v.x, v.y, v.z = linear
        w.x, w.y, w.z = angular
        return msg


class PackedTransformStamped(TransformStamped):
    """geometry_msgs/TransformStamped with its two frames packed once."""


    def __init__(self, frame, child):
        super().__init__()
        self.header.frame_id, self.child_frame_id = frame, child
        self._frames = _string(frame) + _string(child)

    def serialize(self, buff):
        h, t = self.header, self.transform
        buff.write(_HEADER.pack(h.seq, h.stamp.secs, h.stamp.nsecs))
        buff.write(self._frames)
        a, b = t.translation, t.rotation
        buff.write(_POSE.pack(a.x, a.y, a.z, b.x, b.y, b.z, b.w))


class TransformBuilder:
    """One frame pair's transform, refilled per build (publish it before the next build)."""

    def __init__(self, frame, child):
        self.msg = PackedTransformStamped(frame, child)

    def build(self, stamp, position, orientation):
        msg = self.msg
        msg.header.stamp = stamp
        t, r = msg.transform.translation, msg.transform.rotation
        t.x, t.y, t.z = position
        r.x, r.y, r.z, r.w = orientation
        return msg


class PackedTFMessage(TFMessage):
    """tf2_msgs/TFMessage that lets each transform write itself (packed ones write in two calls)."""


    def serialize(self, buff):
        buff.write(_COUNT.pack(len(self.transforms)))
        for transform in self.transforms:
            transform.serialize(buff)


def tf_message(transforms):
    """All of a step's transforms in one TFMessage (one publish, not one per frame)."""
    return PackedTFMessage(transforms=list(transforms))


class PackedJointState(JointState):
    """sensor_msgs/JointState for a fixed list of joints, names packed once."""


    def __init__(self, names):
        super().__init__()
        self.name = list(names)
        self._names = _COUNT.pack(len(names)) + b"".join(_string(n) for n in names)
        self._array = struct.Struct(f"<I{len(names)}d")

    def serialize(self, buff):
        h, n, array = self.header, len(self.name), self._array
        if len(self.position) != n or len(self.velocity) != n or len(self.effort) != n:
            return JointState.serialize(self, buff)
        buff.write(_HEADER.pack(h.seq, h.stamp.secs, h.stamp.nsecs))
        buff.write(_string(h.frame_id))
        buff.write(self._names)
        buff.write(array.pack(n, *self.position))
        buff.write(array.pack(n, *self.velocity))
        buff.write(array.pack(n, *self.effort))


class JointStateBuilder:
    def __init__(self, names):
        self.msg = PackedJointState(names)

    def build(self, stamp, positions, velocities, efforts):
        msg = self.msg
        msg.header.stamp = stamp
        msg.position, msg.velocity, msg.effort = positions, velocities, efforts
        return msg


def imu(stamp, frame, orientation, angular_velocity, linear_acceleration, covariance=(0.0, 0.0, 0.0)):
    """sensor_msgs/Imu: orientation (x, y, z, w), angular velocity [rad/s] and linear acceleration
    [m/s^2] in ``frame``; ``covariance`` gives the three diagonals' value (orientation, rates, accel)."""
    msg = Imu()
    msg.header.stamp, msg.header.frame_id = stamp, frame
    q = msg.orientation
    q.x, q.y, q.z, q.w = orientation
    w, a = msg.angular_velocity, msg.linear_acceleration
    w.x, w.y, w.z = angular_velocity
    a.x, a.y, a.z = linear_acceleration
    for field_name, value in zip(("orientation_covariance", "angular_velocity_covariance",
                                  "linear_acceleration_covariance"), covariance):
        setattr(msg, field_name, [value, 0.0, 0.0, 0.0, value, 0.0, 0.0, 0.0, value])
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
