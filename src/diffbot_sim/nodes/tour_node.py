"""``tour``: drive the robot through ``~waypoints`` (the scripted drive of ``slam.launch drive:=tour``).

The pose is TF's ``~frame`` -> ``~base_frame`` (default ``base_footprint``) when ``~frame`` is set
(slam.launch sets ``map``: gmapping's corrected pose, so a skidding four-wheel robot whose encoders drift still
follows the tour), else ``~odom_topic`` (nav_msgs/Odometry, default ``odom``). Publishes ``~cmd_topic``
(geometry_msgs/Twist, default ``cmd_vel``) at ``~rate`` Hz of sim time with the command of
:class:`diffbot_sim.control.waypoint_tour.Tour`; ``~speed`` [m/s] and ``~tolerance`` [m] as there. When the
last waypoint is reached it stops the robot, sets ``~done`` to true (a script or test waits on it) and idles.
Parameters are read once; a bad one is one line and exit 1.
"""
import sys
import threading

import rospy
import tf2_ros
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from diffbot_sim.control.waypoint_tour import Tour, TourConfig
from diffbot_sim.errors import ConfigError
from diffbot_sim.nodes._entry import entry_point
from diffbot_sim.transforms import yaw_from_quaternion
from diffbot_sim.values import check_number


def read_waypoints(value):
    """``[[x, y], ...]`` from the parameter, checked (ConfigError naming ``~waypoints``)."""
    if not isinstance(value, list) or not value:
        raise ConfigError("~waypoints", value, "a non-empty list of [x, y] pairs")
    points = []
    for index, item in enumerate(value):
        if not isinstance(item, (list, tuple)) or len(item) != 2:
            raise ConfigError(f"~waypoints[{index}]", item, "a pair [x, y]")
        points.append((check_number(f"~waypoints[{index}]", item[0]), check_number(f"~waypoints[{index}]", item[1])))
    return points


@entry_point
def main(argv=None):
    """Entry point of ``rosrun diffbot_sim tour``; returns the exit status."""
    rospy.init_node("tour")
    try:
        waypoints = read_waypoints(rospy.get_param("~waypoints", None))
        config = TourConfig(speed=check_number("~speed", rospy.get_param("~speed", 0.3), low=0.0, low_open=True),
                            tolerance=check_number("~tolerance", rospy.get_param("~tolerance", 0.15), low=0.0,
                                                   low_open=True))
        rate_hz = check_number("~rate", rospy.get_param("~rate", 20.0), low=0.0, low_open=True)
    except ConfigError as err:
        rospy.logfatal(f"tour: {err}")
        return 1
    tour = Tour(waypoints, config)
    lock = threading.Lock()
    pose = [None]

    def on_odom(msg):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        with lock:
            pose[0] = (p.x, p.y, yaw_from_quaternion(q.x, q.y, q.z, q.w))

    frame, base_frame = str(rospy.get_param("~frame", "")), str(rospy.get_param("~base_frame", "base_footprint"))
    if frame:
        buffer = tf2_ros.Buffer()
        tf2_ros.TransformListener(buffer)
    else:
        rospy.Subscriber(rospy.get_param("~odom_topic", "odom"), Odometry, on_odom, queue_size=1)

    def current_pose():
        if not frame:
            with lock:
                return pose[0]
        try:
            t = buffer.lookup_transform(frame, base_frame, rospy.Time(0)).transform
        except (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException):
            return None  # not yet (gmapping publishes map -> odom after its first scan)
        q = t.rotation
        return t.translation.x, t.translation.y, yaw_from_quaternion(q.x, q.y, q.z, q.w)

    pub = rospy.Publisher(rospy.get_param("~cmd_topic", "cmd_vel"), Twist, queue_size=1)
    rospy.set_param("~done", False)
    rate = rospy.Rate(rate_hz)
    rospy.loginfo(f"tour: {len(waypoints)} waypoints at {config.speed} m/s, pose from "
                  f"{'TF ' + frame + ' -> ' + base_frame if frame else 'odometry'}")
    try:
        while not rospy.is_shutdown() and not tour.done:
            current = current_pose()
            if current is not None:
                msg = Twist()
                msg.linear.x, msg.angular.z = tour.command(*current)
                pub.publish(msg)
            rate.sleep()
        pub.publish(Twist())
        rospy.set_param("~done", True)
        rospy.loginfo("tour: done")
        rospy.spin()
    except rospy.ROSInterruptException:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
