"""bullet_sim at run time: the loop that owns sim time, the robots it runs, the /gazebo services
(rospy)."""
