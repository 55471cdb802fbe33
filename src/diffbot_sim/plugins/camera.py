"""``libgazebo_ros_camera.so`` on a ``<sensor type="camera">``: ``image_raw`` (sensor_msgs/Image) and
``camera_info`` at the sensor's ``<update_rate>`` (throttled by the plugin's ``updateRate``), stamped in sim
time, rendered by PyBullet from the sensor's pose looking along its +x (Gazebo's convention; no optical
rotation: ``frameName`` is published as given).

Tags: ROS 1 ``robotNamespace``, ``cameraName``, ``imageTopicName`` (image_raw), ``cameraInfoTopicName``
(camera_info), ``frameName`` (unset: ``world``, as the plugin's ``/world`` without the slash tf2 rejects),
``updateRate``, ``hackBaseline``, ``focalLength``, ``Cx``, ``Cy``, ``CxPrime``, ``distortionK1..K3/T1/T2``
(they only fill D); ROS 2 ``<ros><namespace>``/``<remapping>``, ``camera_name`` (default the sensor's
name), ``frame_name`` (default the sensor's link), ``hack_baseline``. Topics are
``<namespace>/<cameraName>/<topic>``. A ROS 2 plugin on a ``depth`` sensor is the depth camera
(:mod:`diffbot_sim.plugins.depth`).

Cost: the image is rendered only while the image topic has a subscriber (Gazebo activates the sensor on
the first subscriber too); camera_info alone costs no rendering. ``~renderer``: ``tiny`` (default, PyBullet's
CPU TinyRenderer) or ``egl`` (OpenGL off screen; falls back to tiny with one warning when not available).
"""
from sensor_msgs.msg import CameraInfo, Image

from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import summary_key
from diffbot_sim.plugins.camera_base import CameraBase
from diffbot_sim.plugins.depth import DepthCamera
from diffbot_sim.sensors import camera as cam


class Camera(CameraBase):
    filename = "libgazebo_ros_camera.so"

    def __init__(self, ctx, sensor, cfg, tags):
        super().__init__(ctx, sensor, cfg, tags)
        self.image_pub = ctx.publisher(self.topic("image_topic", "image_raw"), Image)
        self.info_pub = ctx.publisher(self.topic("info_topic", "camera_info"), CameraInfo)
        channels = 1 if cfg.encoding == "mono8" else 3
        self.image = ros_msgs.ImageBuilder(self.frame, cfg.width, cfg.height, cfg.encoding, channels)
        self.info = ros_msgs.camera_info(self.frame, self.intrinsics)

    def publishers(self):
        return [self.image_pub, self.info_pub]

    def after_step(self, now, stamp, transforms):
        if not self.due(now):
            return
        if self.image_pub.get_num_connections():
            rgb, _ = self.render()
            self.image_pub.publish(self.image.build(stamp, cam.to_encoding(rgb, self.cfg.encoding).tobytes()))
        if self.info_pub.get_num_connections():
            self.info.header.stamp = stamp
            self.info_pub.publish(self.info)

    def summary(self):
        out = super().summary()
        out[summary_key("camera", self.cfg.name) + "/image_topic"] = self.image_pub.resolved_name
        return out


def create(ctx, sensor, plugin_element, params):
    """The camera of ``sensor`` (a SensorElement), or its depth camera for a ROS 2 plugin on a depth sensor.

    Raises:
        ConfigError: a value that cannot be used. ModelError: the sensor's link is not in the model.
    """
    if sensor.type not in cam.CAMERA_TYPES:
        ctx.warnings.append(f"{sensor.path}: libgazebo_ros_camera.so on a '{sensor.type}' sensor: simulated "
                            "as a plain camera")
    cfg = cam.parse_sensor(sensor.element, sensor.path, sensor.name)
    tags = cam.read_plugin(plugin_element, sensor.path)
    if sensor.type == "depth":
        tags.dialect = "ros2"
        return DepthCamera(ctx, sensor, cfg, tags)
    return Camera(ctx, sensor, cfg, tags)
