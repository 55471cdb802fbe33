"""``libgazebo_ros_range.so`` (ROS 1, on a ``<sensor type="ray">``): sonar and IR rangers -> sensor_msgs/Range.

As gazebo_plugins' ``gazebo_ros_range.cpp`` does: ``range`` is the minimum over all the sensor's raw rays (its h x v
samples make the cone; ``fov`` is only published), a ray without a hit counting as ``range_max``; Gaussian
noise (``gaussianNoise``, mean 0) only when that minimum is below ``range_max``, then at most ``range_max``.
So no return reads ``range_max``, never inf. The SDF ``<ray><noise>`` does not apply (the plugin reads the
raw rays).

Tags (defaults): ``robotNamespace``; ``topicName`` (``/range``); ``frameName`` (here the sensor's link, with a
warning; gazebo_ros says ``/world``); ``radiation`` (``ultrasound``, anything else INFRARED); ``fov``
(0.05 rad); ``gaussianNoise`` (0 m); ``updateRate`` (0: each sensor update; else at most one reading per
``1/updateRate`` s of the sensor's updates, the sensor's own rate being ``<update_rate>``).
"""
from sensor_msgs.msg import Range as RangeMsg

from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins import ray_base
from diffbot_sim.plugins.base import join
from diffbot_sim.sensors import ray as ray_sensor
from diffbot_sim.values import check_string, tag_number

_READ = ("robotNamespace", "topicName", "frameName", "radiation", "fov", "gaussianNoise", "updateRate")


class RangeSensor(ray_base.RaySensorPlugin):
    filename = "libgazebo_ros_range.so"

    def __init__(self, ctx, sensor, element, path, topic, frame, ultrasound, fov, stddev, update_rate):
        super().__init__(ctx, sensor, element, path)
        self.frame = frame
        self.stddev = stddev
        self.throttle = 1.0 / update_rate if update_rate > 0 else 0.0
        self.last = None
        self.pub = ctx.publisher(topic, RangeMsg)
        self.builder = ros_msgs.RangeBuilder(frame, ultrasound, fov, self.cfg.range_min, self.cfg.range_max)

    def publish(self, now, stamp):
        if self.last is not None and now - self.last < self.throttle - 1e-9:
            return
        self.last = now
        fractions, _ = self.cast()
        raw = ray_sensor.raw_ranges(fractions, self.cfg.range_min, self.cfg.range_max)
        value = ray_sensor.sonar_range(raw, self.cfg.range_max, self.stddev, self.rng)
        self.pub.publish(self.builder.build(stamp, value))

    def reset(self, now):
        self.last = None

    def summary(self):
        return self.describe(self.pub.resolved_name, self.frame)


def create(ctx, sensor, element, params):
    path = ray_base.plugin_path(sensor, element)
    ray_base.check_type(sensor, path)
    values = ray_base.plugin_tags(element)
    ignored = [t for t in values if t not in _READ]
    if ignored:
        ctx.warnings.append(f"{path}: tags ignored (gazebo_ros_range does not read them): {', '.join(ignored)}")
    ns = ray_base.ros1_namespace(ctx, values)
    topic = check_string(f"<topicName> of {path}", values["topicName"]) if "topicName" in values else "/range"
    frame = ray_base.ros1_frame(ctx, values, sensor, path)
    ultrasound = values.get("radiation", "ultrasound").strip() == "ultrasound"
    fov = tag_number(f"<fov> of {path}", values["fov"], ctx.warnings, low=0.0) if "fov" in values else 0.05
    stddev = tag_number(f"<gaussianNoise> of {path}", values["gaussianNoise"], ctx.warnings, low=0.0) \
        if "gaussianNoise" in values else 0.0
    rate = tag_number(f"<updateRate> of {path}", values["updateRate"], ctx.warnings, low=0.0) \
        if "updateRate" in values else 0.0
    return RangeSensor(ctx, sensor, element, path, join(ns, topic), frame, ultrasound, fov, stddev, rate)
