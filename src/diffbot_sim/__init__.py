"""diffbot_sim: a PyBullet replacement for Gazebo classic + gazebo_ros, for mobile robots and mobile manipulators.

The subpackages follow the data path (docs/architecture.md): ``description`` (URDF/xacro, meshes) ->
``world`` (SDF worlds, maps, actors) -> ``physics`` (the one owner of PyBullet) -> ``plugins`` (one module per
Gazebo plugin or sensor type, ``plugins.ros_control`` for gazebo_ros_control) -> ``control`` and ``sensors``
(pure maths: controllers, PIDs, trajectories, ray processing) -> ``messages`` (the one builder of ROS
messages). ``simulator`` runs the loop and owns sim time; ``nodes/`` hold the thin ROS shells; ``teleop`` owns
the terminal; ``gym`` holds the Gymnasium environments; ``check`` judges bodies against ground truth;
``batch`` runs scenarios locally or on Ray. Pure subpackages import no rospy (tests/unit/test_layers.py).
"""
__all__ = ["errors"]
