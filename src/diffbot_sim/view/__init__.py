"""Seeing a run: the rviz config, plot data and headless X screens. Pure: no rospy."""
