"""diffbot_sim: a PyBullet replacement for Gazebo classic + gazebo_ros for differential-drive robots.

Pure modules (no rospy): ``errors``, ``model``, ``plugins``, ``config``, ``kinematics``, ``limits``,
``odometry``, ``controller``, ``keymap``. ``physics`` alone talks to PyBullet, ``ros_msgs`` alone builds
messages, ``terminal`` alone owns the terminal; ``nodes/`` hold the thin ROS shells.
"""
__all__ = ["errors"]
