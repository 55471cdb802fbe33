"""plot_run: a bag written here (rosbag's API, synthetic messages) gives a PNG whose plotted data is the bag's:
the trajectory, ground truth through world -> odom, the commands and the last scan in the odom frame."""
import math

import numpy as np
import pytest

rosbag = pytest.importorskip("rosbag")
import genpy
from geometry_msgs.msg import TransformStamped, Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage

from diffbot_sim.nodes import plot_run
from diffbot_sim.view import plot_data


def odom(t, x, y, yaw, v, w, frame="odom", child="base_footprint"):
    m = Odometry()
    m.header.stamp = genpy.Time.from_sec(t)
    m.header.frame_id, m.child_frame_id = frame, child
    m.pose.pose.position.x, m.pose.pose.position.y = x, y
    m.pose.pose.orientation.z, m.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    m.twist.twist.linear.x, m.twist.twist.angular.z = v, w
    return m


def transform(t, parent, child, x, y, yaw):
    tr = TransformStamped()
    tr.header.stamp = genpy.Time.from_sec(t)
    tr.header.frame_id, tr.child_frame_id = parent, child
    tr.transform.translation.x, tr.transform.translation.y = x, y
    tr.transform.rotation.z, tr.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return tr


def write_run(path, world_to_odom=None):
    """A robot turning on a circle of radius 1 m (0.5 m/s, 0.5 rad/s) for 4 s; ground truth 1 cm off in y;
    a laser 0.1 m ahead of base_footprint seeing a wall 2 m ahead at the end."""
    poses = []
    with rosbag.Bag(str(path), "w") as bag:
        if world_to_odom is not None:
            bag.write("/tf_static", TFMessage([transform(0, "world", "odom", *world_to_odom)]), genpy.Time(0.001))
        bag.write("/tf_static", TFMessage([transform(0, "base_footprint", "laser", 0.1, 0.0, 0.0)]),
                  genpy.Time(0.001))
        for i in range(201):
            t = 0.02 * i + 1.0
            yaw = 0.5 * (t - 1.0)
            x, y = math.sin(yaw), 1.0 - math.cos(yaw)
            poses.append((x, y, yaw))
            stamp = genpy.Time.from_sec(t)
            if i % 10 == 0:
                cmd = Twist()
                cmd.linear.x, cmd.angular.z = 0.5, 0.5
                bag.write("/cmd_vel", cmd, stamp)
            bag.write("/odom", odom(t, x, y, yaw, 0.5, 0.5), stamp)
            if world_to_odom is None:
                truth = odom(t, x, y + 0.01, yaw, 0.5, 0.5, frame="world")
            else:
                wx, wy, wyaw = world_to_odom
                c, s = math.cos(wyaw), math.sin(wyaw)
                truth = odom(t, wx + c * x - s * y, wy + s * x + c * y, yaw + wyaw, 0.5, 0.5, frame="world")
            bag.write("/bullet_sim/ground_truth", truth, stamp)
            bag.write("/tf", TFMessage([transform(t, "odom", "base_footprint", x, y, yaw)]), stamp)
        scan = LaserScan()
        scan.header.stamp = genpy.Time.from_sec(t)
        scan.header.frame_id = "laser"
        scan.angle_min, scan.angle_increment = -0.1, 0.1
        scan.range_min, scan.range_max = 0.1, 10.0
        scan.ranges = [2.0 / math.cos(a) for a in (-0.1, 0.0, 0.1)] + [float("inf")]
        bag.write("/scan", scan, genpy.Time.from_sec(t))
    return poses


def test_plotted_trajectory_is_the_bags(tmp_path):
    bag = tmp_path / "run.bag"
    poses = write_run(bag)
    data = plot_data.collect(plot_run.read_bag(str(bag)))
    drawn = plot_run.plot(data, str(tmp_path / "run.png"))
    assert (tmp_path / "run.png").stat().st_size > 10000
    np.testing.assert_allclose(drawn["odom"], np.array(poses)[:, :2], atol=1e-9)
    assert drawn["truth_how"] == "as is"
    np.testing.assert_allclose(drawn["truth"][:, 1] - drawn["odom"][:, 1], 0.01, atol=1e-9)
    assert drawn["summary"].final_error == pytest.approx(0.01, abs=1e-9)
    assert drawn["summary"].distance == pytest.approx(2.0, rel=1e-3)  # 4 s at 0.5 m/s
    np.testing.assert_allclose(data.cmd[:, 1:], 0.5)
    # The last scan: three points on a line 2.1 m ahead of base_footprint (laser 0.1 m ahead), in odom.
    x, y, yaw = poses[-1]
    want = [(x + math.cos(yaw) * 2.1 - math.sin(yaw) * 2.0 * math.tan(a), y + math.sin(yaw) * 2.1
             + math.cos(yaw) * 2.0 * math.tan(a)) for a in (-0.1, 0.0, 0.1)]
    np.testing.assert_allclose(drawn["scan"], want, atol=1e-6)


def test_ground_truth_through_world_to_odom(tmp_path):
    bag = tmp_path / "encoder.bag"
    write_run(bag, world_to_odom=(2.0, -1.0, 0.5))
    drawn = plot_run.plot(plot_data.collect(plot_run.read_bag(str(bag))), str(tmp_path / "e.png"))
    assert drawn["truth_how"] == "tf"
    np.testing.assert_allclose(drawn["truth"], drawn["odom"], atol=1e-9)


def test_the_check_fails_on_another_run(tmp_path):
    """The comparison above can fail: another bag's trajectory does not match these poses."""
    bag = tmp_path / "run.bag"
    poses = write_run(bag)
    data = plot_data.collect(plot_run.read_bag(str(bag)))
    shifted = np.array(poses)[:, :2] + [0.05, 0.0]
    assert not np.allclose(data.odom[:, 1:3], shifted, atol=1e-3)


def test_no_odometry_is_one_clear_line(tmp_path, capsys):
    bag = tmp_path / "empty.bag"
    with rosbag.Bag(str(bag), "w") as b:
        b.write("/cmd_vel", Twist(), genpy.Time(1))
    assert plot_run.main([str(bag)]) == 1
    err = capsys.readouterr().err
    assert "empty.bag: no nav_msgs/Odometry" in err and "/cmd_vel" in err
    assert plot_run.main([str(tmp_path / "missing.bag")]) == 1
    assert "missing.bag: no such file" in capsys.readouterr().err
    (tmp_path / "junk.bag").write_text("not a bag")
    assert plot_run.main([str(tmp_path / "junk.bag")]) == 1
    assert "not a readable bag" in capsys.readouterr().err
