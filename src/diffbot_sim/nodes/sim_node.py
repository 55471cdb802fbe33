"""``bullet_sim``: the PyBullet simulator node (the thin ROS shell around the pure modules).

Loads URDF/xacro robots into PyBullet (fixed links lumped as Gazebo lumps them, meshes converted), gives
each of their ``<gazebo>`` plugins to the module that simulates it (:mod:`diffbot_sim.plugins.registry`:
diff drive, skid steer, planar move, Kobuki, gazebo_ros_control with the controllers found on the parameter
server, joint-state publisher) and publishes what gazebo_ros would. One thread owns PyBullet: subscriber and
service callbacks only hand data to the loop, which asks every plugin what is due and knows none by name.

Topics: each plugin's (its module docstring; resolved names are written to ``~cmd_vel_topic``,
``~odom_topic`` and the other start-up summary parameters), plus:
    /clock (rosgraph_msgs/Clock): sim time, at ~clock_rate.
    /tf (tf2_msgs/TFMessage): every plugin's transforms of a step, in one message.
    ~ground_truth (nav_msgs/Odometry): when ~publish_ground_truth.
    ~debug/cmd_applied (geometry_msgs/TwistStamped): when ~debug_cmd_applied, the wall time a diff-drive
        command reached the motors (for latency measurement).
Services: ~pause_physics, ~unpause_physics, ~reset_simulation (std_srvs/Empty); the /gazebo world API under
``~gazebo_namespace`` (default /gazebo; a node named ``gazebo``, as empty_world.launch names it, serves it
under its own name, as gazebo_ros does: ``/<group ns>/gazebo/...``).
Parameters: see diffbot_sim.config.SimConfig and GazeboDiffDriveConfig (README table).
"""
import os

import rospy

from diffbot_sim import config as cfgmod, streams
from diffbot_sim.errors import DiffbotSimError
from diffbot_sim.simulator import link_attacher, robots


def _own_the_clock():
    """Stop rospy listening to /clock in this node: with use_sim_time, init_node subscribes every node to
    /clock, so the simulator would receive (a loopback wake-up and a deserialization) each tick it
    publishes. rospy's time is set directly in _publish_clock instead, through the hook rospy's own /clock
    callback uses (rospy.rostime._set_rostime)."""
    from rospy.impl import simtime
    sub = getattr(simtime, "_clock_sub", None)
    if sub is not None:
        sub.unregister()
        simtime._clock_sub = None
    return sub is not None


def main(argv=None):
    """Entry point of ``rosrun diffbot_sim bullet_sim``. Exits 1 with one line on bad input.

    Output that cannot be written (roslaunch's terminal closed, a pipe whose reader left) never changes the
    exit status: :func:`diffbot_sim.streams.finish` empties the buffers first.
    """
    try:
        return _main()
    finally:
        streams.finish()


def _main():
    rospy.init_node("bullet_sim")
    owns_clock = _own_the_clock()
    try:
        params = rospy.get_param("~", {})
        if "gazebo_namespace" not in params and rospy.get_name().rsplit("/", 1)[-1] == "gazebo":
            # gazebo_ros advertises its world API under its node's name ("~"): empty_world.launch inside
            # <group ns="my_robot"> serves /my_robot/gazebo/spawn_urdf_model; /clock stays global
            params["gazebo_namespace"] = rospy.get_name()
        cfg = cfgmod.sim_config(params)
        if cfg.gui and not os.environ.get("DISPLAY"):
            rospy.logwarn("~gui is true but there is no display (DISPLAY unset): running headless (DIRECT)")
            cfg.gui = False
        sim, loaded = robots.build(cfg, params)
        sim.owns_clock = owns_clock
    except DiffbotSimError as err:
        rospy.logfatal(f"bullet_sim: {err}")
        rospy.signal_shutdown("bad input")
        return 1
    try:
        robots.report(cfg, loaded, sim.world_description)
        if not rospy.has_param("/use_sim_time"):
            rospy.set_param("/use_sim_time", True)  # as gazebo_ros: later nodes follow /clock
        if cfg.enable_ros_network:
            sim.api = robots.world_api(sim, cfg, params)
            if sim.api is not None and sim.world_description is not None:  # the world plugin it simulates
                sim.link_attacher = link_attacher.start_if_named(sim, sim.world_description.source)
        sim.advertise_services()
        sim.run()
    finally:
        sim.close()
    return 0
