"""Plugin filename -> the module that simulates it (one line per plugin), and building a robot's plugins.

The two plugins the model reader parses itself (diff drive, joint-state publisher) are built from their
PluginBlocks; every other one from its element by its module's ``create(ctx, element, path, params)``.
"""
from diffbot_sim.description.plugin_tags import DIFF_DRIVE, JOINT_STATE, plugin_filename
from diffbot_sim.errors import PluginNotLoaded
from diffbot_sim.plugins import (
    body_force,
    bumper,
    diff_drive,
    force_based_move,
    force_torque,
    gps,
    grasp_fix,
    imu,
    joint_state,
    kobuki,
    mimic_joint,
    multicamera,
    p3d,
    planar_move,
    ray_clouds,
    realsense,
    ros_control,
    skid_steer,
    sonar,
)
from diffbot_sim.plugins.camera import create as create_camera
from diffbot_sim.plugins.depth import create as create_depth
from diffbot_sim.plugins.ground_truth import GroundTruth
from diffbot_sim.plugins.joint_motors import JointMotors
from diffbot_sim.plugins.laser import create_laser, create_ray_sensor
from diffbot_sim.plugins.range import create as create_range

#: Model plugins by filename (``libNAME.so``).
MODEL_PLUGINS = {
    "libgazebo_ros_skid_steer_drive.so": skid_steer.create,
    "libgazebo_ros_planar_move.so": planar_move.create,
    "libgazebo_ros_force_based_move.so": force_based_move.create,
    "libridgeback_ros_force_based_move.so": force_based_move.create,
    "libnexus_ros_force_based_move.so": force_based_move.create,
    "libgazebo_ros_kobuki.so": kobuki.create,
    "libgazebo_ros_control.so": ros_control.create,
    "libgazebo_ros_imu.so": imu.create_model,
    "libhector_gazebo_ros_imu.so": imu.create_hector,
    "libgazebo_ros_p3d.so": p3d.create,
    "libhector_gazebo_ros_gps.so": gps.create,
    "libgazebo_grasp_fix.so": grasp_fix.create,
    "libroboticsgroup_gazebo_mimic_joint_plugin.so": mimic_joint.create,
    "libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so": mimic_joint.create,
    "libgazebo_ros_ft_sensor.so": force_torque.create_model,
    "librealsense_gazebo_plugin.so": realsense.create,
    # aliases: the same plugins under their other published names
    "librobotnik_force_based_move.so": force_based_move.create,  # Robotnik's copy of the force-based move
    "libgazebo_mimic_joint_plugin.so": mimic_joint.create,  # the mimic plugin's ROS 2 port (and its first name)
    "libgazebo_ros_force.so": body_force.create,
}
#: Sensor plugins by filename: ``create(ctx, sensor, plugin_element, params)`` with ``sensor`` a
#: :class:`~diffbot_sim.description.plugin_tags.SensorElement` (its type, link, element and path). One line per module.
SENSOR_PLUGINS = {
    "libgazebo_ros_imu_sensor.so": imu.create_sensor,
    "libgazebo_ros_laser.so": create_laser,
    "libgazebo_ros_gpu_laser.so": create_laser,
    "libgazebo_ros_ray_sensor.so": create_ray_sensor,
    "libgazebo_ros_range.so": create_range,
    "libgazebo_ros_block_laser.so": ray_clouds.create_block,
    "libgazebo_ros_velodyne_laser.so": ray_clouds.create_velodyne,
    "libgazebo_ros_velodyne_gpu_laser.so": ray_clouds.create_velodyne,
    "libgazebo_ros_camera.so": create_camera,
    "libgazebo_ros_openni_kinect.so": create_depth,
    "libgazebo_ros_bumper.so": bumper.create,
    "libgazebo_ros_multicamera.so": multicamera.create,
    "libgazebo_ros_ft_sensor.so": force_torque.create_sensor,
    "libgazebo_ros_depth_camera.so": create_depth,  # gazebo_ros_depth_camera: openni_kinect's tags and topics
    "libhector_gazebo_ros_sonar.so": sonar.create,
}
#: Every filename simulated (the rest are named once as not simulated).
KNOWN = (DIFF_DRIVE, JOINT_STATE) + tuple(MODEL_PLUGINS)
KNOWN_SENSORS = tuple(SENSOR_PLUGINS)


def _add(ctx, plugins, factory, *args):
    """Build one plugin into ``plugins``; one Gazebo would not load (PluginNotLoaded) is one warning."""
    try:
        plugins.append(factory(ctx, *args))
    except PluginNotLoaded as err:
        ctx.warnings.append(str(err))


def build(ctx, found, params):
    """Every plugin of one robot, in model order, plus the transmission motors no plugin owns and the
    optional ground truth. ``found`` is the model's :class:`~diffbot_sim.description.plugin_tags.Plugins`.

    Raises:
        DiffbotSimError: a plugin whose tags or parameters cannot be used (naming them).
    """
    plugins = []
    drive = diff_drive.create(ctx, found.diff_drive, params)
    if drive is not None:
        plugins.append(drive)
    for item in found.others:
        factory = MODEL_PLUGINS.get(item.filename)
        if factory is not None:
            _add(ctx, plugins, factory, item.element, item.path, params)
    for sensor in found.sensors:  # a sensor is simulated by its first plugin that a module handles
        for plugin in sensor.element.findall("plugin"):
            factory = SENSOR_PLUGINS.get(plugin_filename(plugin.get("filename")))
            if factory is not None:
                _add(ctx, plugins, factory, sensor, plugin, params)
                break
    js = joint_state.create(ctx, found.joint_state, drive.drive if drive is not None else None)
    if js is not None:
        plugins.append(js)
    owned = set()
    for plugin in plugins:
        owned |= plugin.joints()
    rest = [t for t in ctx.model.transmissions if t.joint not in owned]
    if rest:
        plugins.append(JointMotors(ctx, rest))
    # a <mimic> joint a plugin drives (a mimic plugin, or a controller through its transmission) is not followed
    mimics = mimic_joint.urdf_mimics(ctx, owned | {t.joint for t in rest}
                                     | {p.cfg.mimic_joint for p in plugins if isinstance(p, mimic_joint.MimicJoint)})
    if mimics is not None:
        plugins.append(mimics)
    if ctx.cfg.publish_ground_truth:
        base = next((p.drive.robot_base_frame for p in plugins if isinstance(p, diff_drive.GazeboDiffDrive)),
                    ctx.frame(ctx.model.root))
        plugins.append(GroundTruth(ctx, base))
    return plugins
