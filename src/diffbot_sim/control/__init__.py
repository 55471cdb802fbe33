"""The controllers' mathematics: gazebo_ros_diff_drive's per-step core (``GazeboDiffDriveCore``), ros_controllers'
DiffDriveController (``DiffDriveControllerCore``) and its other controllers, the command inbox, controller lookup
and switching, odometry, kinematics, limits. Pure."""
