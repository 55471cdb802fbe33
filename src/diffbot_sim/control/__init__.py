"""The controllers' mathematics: gazebo_ros_diff_drive's controller, ros_controllers'
DiffDriveController, controller lookup and switching, odometry, kinematics, limits. Pure."""
