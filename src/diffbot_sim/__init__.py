"""diffbot_sim: a PyBullet replacement for Gazebo classic + gazebo_ros for differential-drive robots.

Pure modules (no rospy): ``errors``, ``model``, ``config``, ``kinematics``, ``limits``, ``odometry``,
``controller``, ``ddc``, ``lumping``, ``meshes``, ``keymap``, ``streams``, ``plugins.tags``. ``physics`` alone
talks to PyBullet, ``ros_msgs`` alone builds messages, ``terminal`` alone owns the terminal; ``plugins/``
holds one module per Gazebo plugin; ``nodes/`` hold the thin ROS shells.
"""
__all__ = ["errors"]
