"""messages/common.py: the packed messages write exactly what genpy writes, and builders refill one object."""
import io

import genpy
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage

from diffbot_sim.messages import common as ros_msgs


def _bytes(serialize, msg):
    buff = io.BytesIO()
    serialize(msg, buff)
    return buff.getvalue()


def _roundtrip(msg_class, data):
    out = msg_class()
    out.deserialize(data)
    return out


def test_odometry_bytes_match_genpy():
    builder = ros_msgs.OdometryBuilder("robot1/odom", "robot1/base_footprint", 1e-5, 2e-5, 1e-3)
    msg = builder.build(genpy.Time(12, 345), (1.5, -2.25, 0.01), (0.0, 0.0, 0.38268343, 0.92387953),
                        (0.3, 0.0, 0.0), (0.0, 0.0, -0.5))
    msg.header.seq = 7
    packed = _bytes(type(msg).serialize, msg)
    assert packed == _bytes(Odometry.serialize, msg)
    back = _roundtrip(Odometry, packed)
    assert back.header.frame_id == "robot1/odom" and back.child_frame_id == "robot1/base_footprint"
    assert back.pose.pose.position.y == -2.25 and back.twist.twist.angular.z == -0.5
    assert back.pose.covariance[7] == 2e-5 and back.twist.covariance[35] == 1e-3
    assert (back.header.seq, back.header.stamp) == (7, genpy.Time(12, 345))


def test_builders_refill_one_object():
    builder = ros_msgs.OdometryBuilder("odom", "base_footprint", 0.0, 0.0, 0.0)
    first = builder.build(genpy.Time(1, 0), (1, 2, 3), (0, 0, 0, 1), (0, 0, 0), (0, 0, 0))
    second = builder.build(genpy.Time(2, 0), (4, 5, 6), (0, 0, 0, 1), (0, 0, 0), (0, 0, 0))
    assert first is second and second.pose.pose.position.x == 4


def test_joint_state_bytes_match_genpy_and_odd_lengths_fall_back():
    names = ["left_wheel_joint", "right_wheel_joint", "front_caster_joint"]
    msg = ros_msgs.JointStateBuilder(names).build(genpy.Time(3, 4), [0.1, 0.2, 0.3], [1.0, 2.0, 3.0],
                                                  [-1.0, 0.0, 1.0])
    assert _bytes(type(msg).serialize, msg) == _bytes(JointState.serialize, msg)
    assert _roundtrip(JointState, _bytes(type(msg).serialize, msg)).name == names
    msg.effort = []  # not the fixed layout: genpy's own code writes it
    assert _bytes(type(msg).serialize, msg) == _bytes(JointState.serialize, msg)


def test_tf_message_bytes_match_genpy_with_packed_and_plain_transforms():
    a = ros_msgs.TransformBuilder("robot1/odom", "robot1/base_footprint").build(
        genpy.Time(5, 6), (1.0, 2.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    b = TransformStamped()
    b.header.frame_id, b.child_frame_id = "map", "odom"
    b.transform.rotation.w = 1.0
    msg = ros_msgs.tf_message([a, b])
    packed = _bytes(type(msg).serialize, msg)
    assert packed == _bytes(TFMessage.serialize, msg)
    back = _roundtrip(TFMessage, packed)
    assert [t.child_frame_id for t in back.transforms] == ["robot1/base_footprint", "odom"]


def test_packed_types_keep_the_wire_identity():
    for packed, plain in ((ros_msgs.PackedOdometry, Odometry), (ros_msgs.PackedJointState, JointState),
                          (ros_msgs.PackedTFMessage, TFMessage), (ros_msgs.PackedTransformStamped, TransformStamped)):
        assert (packed._type, packed._md5sum) == (plain._type, plain._md5sum)
        assert issubclass(packed, plain)


def test_plain_odometry_has_its_motion_and_six_value_diagonals():
    msg = ros_msgs.odometry(genpy.Time(3, 0), "world", "robot/base_link", (1.0, 2.0, 0.1),
                            (0.0, 0.0, 0.6, 0.8), (0.5, -0.1, 0.0), (0.0, 0.0, 0.25), [1, 2, 3, 4, 5, 6],
                            [0.1] * 6)
    assert (msg.header.frame_id, msg.child_frame_id, msg.header.stamp.secs) == ("world", "robot/base_link", 3)
    p, q = msg.pose.pose.position, msg.pose.pose.orientation
    assert (p.x, p.y, p.z, q.z, q.w) == (1.0, 2.0, 0.1, 0.6, 0.8)
    assert (msg.twist.twist.linear.x, msg.twist.twist.linear.y, msg.twist.twist.angular.z) == (0.5, -0.1, 0.25)
    assert msg.pose.covariance[0] == 1.0 and msg.pose.covariance[35] == 6.0 and msg.pose.covariance[1] == 0.0
    assert msg.twist.covariance[7] == 0.1
    again = ros_msgs.odometry(genpy.Time(4, 0), "world", "b", (0, 0, 0), (0, 0, 0, 1), (0, 0, 0), (0, 0, 0),
                              [0] * 6, [0] * 6)
    assert again is not msg and msg.pose.pose.position.x == 1.0  # a new message each call


def test_a_static_transform_is_a_new_plain_message_with_a_zero_stamp():
    pose = ((1.0, -2.0, 0.0), (0.0, 0.0, 0.6, 0.8))
    msg = ros_msgs.transform_stamped("world", "robot1/odom", pose)
    assert type(msg) is TransformStamped
    assert (msg.header.frame_id, msg.child_frame_id, msg.header.stamp) == ("world", "robot1/odom", genpy.Time())
    t, r = msg.transform.translation, msg.transform.rotation
    assert (t.x, t.y, t.z, r.x, r.y, r.z, r.w) == (1.0, -2.0, 0.0, 0.0, 0.0, 0.6, 0.8)
    stamped = ros_msgs.transform_stamped("world", "b", pose, stamp=genpy.Time(7, 5))
    assert stamped.header.stamp == genpy.Time(7, 5) and stamped is not msg
