"""``make bench``'s items, one module per theme (tools/bench.py lists them in the order they run):

- ``drive``: the seed robot driving: fast mode and real time against bare PyBullet, command latency, the
  four-wheel ros_control robot;
- ``startup``: ``roslaunch`` to the first ``/odom``: the seed robot, a robot of meshes, worlds of meshes and maps;
- ``sensors``: a laser and an IMU subscribed, fast mode and real time;
- ``world_api``: the ``/gazebo`` services (spawn to first odometry, ``set_model_state`` round trips);
- ``batch``: what ``rosrun diffbot_sim batch`` costs and gains;
- ``arm``: a mobile base with a 6-joint arm on a trajectory against bare PyBullet, command to motion;
- ``learning``: a Gazebo-style step-and-wait learning environment, and the Gymnasium environment;
- ``fleet``: how many robots one simulator keeps at real time (the seed robot; TurtleBot3-class robots with
  lasers, against bare PyBullet in back-to-back pairs).

Each module has ``ITEMS`` (``benchkit.report.Item``) and ``PROBES`` (the ROS-side probes only it uses).
"""
