"""gazebo_ros's interfaces as decisions: the /gazebo world API and the gazebo_ros / controller_manager
command lines. Pure: no rospy."""
