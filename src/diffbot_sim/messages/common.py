"""The common_msgs (geometry, nav, sensor), tf2_msgs and rosgraph_msgs messages the plugins and the loop
publish, built from plain numbers (message modules only; no rospy).

The simulator publishes four messages per control period, thousands per wall second in fast mode, so its
builders reuse one message object each and serialize it with a few precompiled ``struct`` calls instead of
genpy's field-by-field code. That is safe because rospy serializes inside ``publish()`` on the caller's
thread, queued publisher or not (rospy/topics.py ``_PublisherImpl.publish``): once ``publish()`` returns,
the object may be refilled. The packed classes keep their genpy type and md5sum and write the very same
bytes (tests/unit/messages/test_common.py compares them with genpy's own ``serialize``); what never changes
(frames, joint names, covariance) is packed once per builder. The subclasses declare no ``__slots__`` on
purpose: genpy reads ``self.__slots__`` for the field list (printing, equality, keyword construction).
"""
import struct

import numpy as np
from geometry_msgs.msg import Point32, TransformStamped, Twist, TwistStamped, Vector3Stamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import (
    CameraInfo,
    ChannelFloat32,
    Image,
    Imu,
    JointState,
    LaserScan,
    NavSatFix,
    PointCloud,
    PointCloud2,
    PointField,
    Range,
)
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
        _fill_motion(msg, position, orientation, linear, angular)
        return msg


def _fill_motion(msg, position, orientation, linear, angular):
    """An Odometry's pose (x, y, z; qx, qy, qz, qw) and twist (linear, angular)."""
    p, q = msg.pose.pose.position, msg.pose.pose.orientation
    p.x, p.y, p.z = position
    q.x, q.y, q.z, q.w = orientation
    v, w = msg.twist.twist.linear, msg.twist.twist.angular
    v.x, v.y, v.z = linear
    w.x, w.y, w.z = angular


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




class ImageBuilder:
    """sensor_msgs/Image of a fixed size and encoding in ``frame``; ``build`` refills its data (bytes)."""

    def __init__(self, frame, width, height, encoding, bytes_per_pixel):
        self.msg = Image(height=height, width=width, encoding=encoding, is_bigendian=0,
                         step=width * bytes_per_pixel)
        self.msg.header.frame_id = frame

    def build(self, stamp, data):
        self.msg.header.stamp = stamp
        self.msg.data = data
        return self.msg


def camera_info(frame, intrinsics):
    """sensor_msgs/CameraInfo from :class:`diffbot_sim.sensors.camera.Intrinsics` (set its stamp per image)."""
    msg = CameraInfo(height=intrinsics.height, width=intrinsics.width,
                     distortion_model=intrinsics.distortion_model, D=list(intrinsics.D), K=list(intrinsics.K),
                     R=list(intrinsics.R), P=list(intrinsics.P))
    msg.header.frame_id = frame
    return msg


class PointCloudBuilder:
    """An organised sensor_msgs/PointCloud2 (``fields``: (name, byte offset) of FLOAT32 values)."""

    def __init__(self, frame, width, height, fields, point_step):
        self.msg = PointCloud2(height=height, width=width, is_bigendian=False, point_step=point_step,
                               row_step=point_step * width, is_dense=False,
                               fields=[PointField(name=n, offset=o, datatype=PointField.FLOAT32, count=1)
                                       for n, o in fields])
        self.msg.header.frame_id = frame

    def build(self, stamp, data, dense=False):
        self.msg.header.stamp = stamp
        self.msg.data = data
        self.msg.is_dense = dense
        return self.msg


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
        setattr(msg, field_name, covariance3(value))
    return msg


def covariance3(value):
    """A 3x3 row-major covariance from one number (the whole diagonal), three (the diagonal) or nine."""
    if isinstance(value, (int, float)):
        value = (value,) * 3
    value = [float(v) for v in value]
    if len(value) == 9:
        return value
    return [value[0], 0.0, 0.0, 0.0, value[1], 0.0, 0.0, 0.0, value[2]]


def nav_sat_fix(stamp, frame, latitude, longitude, altitude, covariance=None, status=0, service=1):
    """sensor_msgs/NavSatFix [deg, deg, m]; ``covariance`` (three diagonal values [m^2] or nine) makes the
    type DIAGONAL_KNOWN (or KNOWN), None UNKNOWN."""
    msg = NavSatFix()
    msg.header.stamp, msg.header.frame_id = stamp, frame
    msg.status.status, msg.status.service = status, service
    msg.latitude, msg.longitude, msg.altitude = latitude, longitude, altitude
    if covariance is None:
        msg.position_covariance_type = NavSatFix.COVARIANCE_TYPE_UNKNOWN
    else:
        msg.position_covariance = covariance3(covariance)
        msg.position_covariance_type = (NavSatFix.COVARIANCE_TYPE_KNOWN if len(covariance) == 9
                                        else NavSatFix.COVARIANCE_TYPE_DIAGONAL_KNOWN)
    return msg


def transform_stamped(parent, child, pose, stamp=None):
    """A plain geometry_msgs/TransformStamped ``parent`` -> ``child`` of ``pose`` ((x, y, z), (qx, qy, qz, qw)),
    for a static transform (stamp zero unless given); a new object per call, unlike :class:`TransformBuilder`."""
    msg = TransformStamped()
    msg.header.frame_id, msg.child_frame_id = parent, child
    if stamp is not None:
        msg.header.stamp = stamp
    t, r = msg.transform.translation, msg.transform.rotation
    t.x, t.y, t.z = pose[0]
    r.x, r.y, r.z, r.w = pose[1]
    return msg


def vector3_stamped(stamp, frame, vector):
    msg = Vector3Stamped()
    msg.header.stamp, msg.header.frame_id = stamp, frame
    msg.vector.x, msg.vector.y, msg.vector.z = vector
    return msg


def odometry(stamp, frame, child, position, orientation, linear, angular, pose_covariance, twist_covariance):
    """nav_msgs/Odometry with six-value covariance diagonals (a plain message, for sensors like p3d)."""
    msg = Odometry()
    msg.header.stamp, msg.header.frame_id, msg.child_frame_id = stamp, frame, child
    _fill_motion(msg, position, orientation, linear, angular)
    msg.pose.covariance = diagonal(pose_covariance)
    msg.twist.covariance = diagonal(twist_covariance)
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


# -- ray sensors (diffbot_sim.plugins.laser, .range) --------------------------------------------------------

_SCAN_CONSTANTS = struct.Struct("<7f")  # angle_min, angle_max, angle_increment, time_increment, scan_time,
# range_min, range_max


class PackedLaserScan(LaserScan):
    """sensor_msgs/LaserScan with its frame and the seven constant fields packed once; ``ranges`` and
    ``intensities`` may be numpy arrays (written as float32 in one call each)."""


    def __init__(self, frame, angle_min, angle_max, angle_increment, range_min, range_max):
        super().__init__()
        self.header.frame_id = frame
        self.angle_min, self.angle_max, self.angle_increment = angle_min, angle_max, angle_increment
        self.time_increment = self.scan_time = 0.0  # what gazebo_ros publishes ("instantaneous simulator scan")
        self.range_min, self.range_max = range_min, range_max
        self._constants = _string(frame) + _SCAN_CONSTANTS.pack(
            angle_min, angle_max, angle_increment, 0.0, 0.0, range_min, range_max)

    def serialize(self, buff):
        h = self.header
        buff.write(_HEADER.pack(h.seq, h.stamp.secs, h.stamp.nsecs))
        buff.write(self._constants)
        for values in (self.ranges, self.intensities):
            buff.write(_COUNT.pack(len(values)))
            buff.write(np.asarray(values, dtype="<f4").tobytes())


class LaserScanBuilder:
    """One laser's LaserScan, refilled per build (publish it before the next build)."""

    def __init__(self, frame, angle_min, angle_max, angle_increment, range_min, range_max):
        self.msg = PackedLaserScan(frame, angle_min, angle_max, angle_increment, range_min, range_max)

    def build(self, stamp, ranges, intensities):
        msg = self.msg
        msg.header.stamp = stamp
        msg.ranges, msg.intensities = ranges, intensities
        return msg


class RangeBuilder:
    """sensor_msgs/Range of one sonar or IR sensor; ``ultrasound`` picks ULTRASOUND, else INFRARED."""

    def __init__(self, frame, ultrasound, field_of_view, min_range, max_range):
        msg = self.msg = Range()
        msg.header.frame_id = frame
        msg.radiation_type = Range.ULTRASOUND if ultrasound else Range.INFRARED
        msg.field_of_view, msg.min_range, msg.max_range = field_of_view, min_range, max_range

    def build(self, stamp, value):
        self.msg.header.stamp = stamp
        self.msg.range = value
        return self.msg


class PointCloud2Builder:
    """sensor_msgs/PointCloud2 of x, y, z, intensity float32 points (height 1, dense), as gazebo_ros's
    ROS 2 ray sensor publishes."""

    def __init__(self, frame):
        msg = self.msg = PointCloud2()
        msg.header.frame_id = frame
        msg.height, msg.is_bigendian, msg.is_dense, msg.point_step = 1, False, True, 16
        msg.fields = [PointField(name=n, offset=4 * i, datatype=PointField.FLOAT32, count=1)
                      for i, n in enumerate(("x", "y", "z", "intensity"))]

    def build(self, stamp, points):
        """``points``: (n, 4) float32 array (x, y, z, intensity)."""
        msg = self.msg
        msg.header.stamp = stamp
        msg.width = len(points)
        msg.row_step = msg.point_step * msg.width
        msg.data = points.astype("<f4").tobytes()
        return msg


class RingCloudBuilder:
    """sensor_msgs/PointCloud2 as velodyne_simulator's plugin publishes it: x, y, z, intensity (float32),
    ring (uint16: the laser's row, 0 the lowest), time (float32, 0 here: the scan is instantaneous)."""

    RECORD = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4"), ("ring", "<u2"),
                       ("time", "<f4")])

    def __init__(self, frame):
        msg = self.msg = PointCloud2()
        msg.header.frame_id = frame
        msg.is_bigendian, msg.point_step = False, self.RECORD.itemsize
        msg.fields = [PointField(name=n, offset=self.RECORD.fields[n][1],
                                 datatype=PointField.UINT16 if n == "ring" else PointField.FLOAT32, count=1)
                      for n in self.RECORD.names]

    def build(self, stamp, points, rings, height=1, dense=True):
        """``points``: (n, 4) x, y, z, intensity; ``rings``: (n,) row of each point. ``height`` > 1: an
        organised cloud of that many rows (NaN points where a ray returned nothing)."""
        msg = self.msg
        msg.header.stamp = stamp
        data = np.zeros(len(points), self.RECORD)
        for i, name in enumerate(("x", "y", "z", "intensity")):
            data[name] = points[:, i]
        data["ring"] = rings
        msg.height, msg.width = height, len(points) // max(height, 1)
        msg.is_dense = dense
        msg.row_step = msg.point_step * msg.width
        msg.data = data.tobytes()
        return msg


def point_cloud(stamp, frame, points, channel="intensity"):
    """sensor_msgs/PointCloud of ``points`` ((n, 4): x, y, z, intensity) with one channel of that name
    (gazebo_ros_block_laser's is unnamed)."""
    msg = PointCloud()
    msg.header.stamp, msg.header.frame_id = stamp, frame
    msg.points = [Point32(x, y, z) for x, y, z in points[:, :3].tolist()]
    msg.channels = [ChannelFloat32(name=channel, values=points[:, 3].tolist())]
    return msg
