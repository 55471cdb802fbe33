"""The keyboard teleop: key map, terminal, status line. Pure: no rospy."""
