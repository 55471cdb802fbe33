"""Robot descriptions as data: model files (URDF, xacro), the URDF model, Gazebo's reading of it
(lumping, tag values, plugin blocks) and meshes. Pure: no rospy, no PyBullet."""
