"""ROS messages built from plain numbers and back: the one place that fills message classes (message modules
only, no rospy). ``common``: the common_msgs the plugins and the loop publish (odometry, TF, clock, joint
states, sensor data); ``controllers``: control_msgs and trajectory_msgs of the simulated ros_controllers;
``gazebo``: gazebo_msgs states of the /gazebo API; ``markers``: visualization_msgs for rviz's world."""
