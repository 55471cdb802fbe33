"""Worlds as data: Gazebo SDF worlds and map_server maps read into bodies and shapes, and their
markers. Pure: no rospy, no PyBullet."""
