"""Laser scanners on ``<sensor type="ray|gpu_ray">``: ROS 1 ``libgazebo_ros_laser.so`` and
``libgazebo_ros_gpu_laser.so`` (sensor_msgs/LaserScan), ROS 2 ``libgazebo_ros_ray_sensor.so`` (LaserScan,
PointCloud2, PointCloud or Range, by ``<output_type>``). What every ray sensor's plugin shares (the sensor on
its link, the schedule, the casting, gazebo_ros's ROS 1 tags) is :mod:`diffbot_sim.plugins.ray_base`.

What the scan contains (angles, +inf misses, noise, intensities) is :mod:`diffbot_sim.sensors.ray`; the
casting is ``World.ray_batch``. As gazebo_ros does:

* ROS 1 tags: ``robotNamespace`` (absent: the node's namespace; present but empty: the model name),
  ``topicName`` (default ``/world``, gazebo_ros_laser's odd default, with a warning) and ``frameName``
  (default here: the sensor's link, with a warning; gazebo_ros_laser says ``/world``). No other tag is read
  by the real plugin (``gaussianNoise``, ``hokuyoMinIntensity``, ``updateRate``...), so they are named as
  ignored; the rate is ``<update_rate>`` of the sensor, noise its ``<ray><noise>``.
* ROS 2 tags: ``<ros><namespace>``, ``<remapping>~/out:=scan`` (unremapped: ``<plugin name>/out``),
  ``<output_type>`` (default sensor_msgs/PointCloud2), ``<frame_name>`` (default the link),
  ``<min_intensity>`` (0), ``<radiation_type>`` (infrared; Range only). LaserScan uses the middle
  vertical row; PointCloud(2) drop non-finite ranges; Range is the minimum of all readings.
* Every sensor publishes at the sensor's ``<update_rate>`` (0: every step), stamped with sim time, and casts
  its rays only while someone subscribes (gazebo_ros_laser deactivates the sensor without subscribers).
* A sensor on a link lumped into its parent by a fixed joint sits at that link's frame and its own
  ``<pose>`` is dropped, as sdformat's URDF reader replaces it (with a warning when it was not zero).
"""
from sensor_msgs.msg import LaserScan, PointCloud, PointCloud2, Range

from diffbot_sim.errors import ConfigError
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins import ray_base
from diffbot_sim.plugins.base import join
from diffbot_sim.sensors import ray as ray_sensor
from diffbot_sim.values import check_string, tag_number

ROS1_LASERS = ("libgazebo_ros_laser.so", "libgazebo_ros_gpu_laser.so")
ROS2_RAY = "libgazebo_ros_ray_sensor.so"
OUTPUT_TYPES = {"sensor_msgs/LaserScan": LaserScan, "sensor_msgs/PointCloud2": PointCloud2,
                "sensor_msgs/PointCloud": PointCloud, "sensor_msgs/Range": Range}


class Laser(ray_base.RaySensorPlugin):
    """A laser scanner: LaserScan (ROS 1 and 2), or the ROS 2 plugin's PointCloud2/PointCloud/Range."""

    def __init__(self, ctx, sensor, plugin_element, path, filename, topic, frame, output="sensor_msgs/LaserScan",
                 min_intensity=0.0, ultrasound=False):
        super().__init__(ctx, sensor, plugin_element, path)
        self.filename = filename
        self.topic, self.frame, self.output = topic, frame, output
        self.min_intensity = min_intensity
        self.pub = ctx.publisher(topic, OUTPUT_TYPES[output])
        cfg = self.cfg
        h = cfg.horizontal
        self.middle_row = filename == ROS2_RAY and cfg.vertical.count > 1
        if output == "sensor_msgs/LaserScan":
            self.scan_builder = ros_msgs.LaserScanBuilder(frame, h.min_angle, h.max_angle, h.increment,
                                                          cfg.range_min, cfg.range_max)
        elif output == "sensor_msgs/PointCloud2":
            self.cloud_builder = ros_msgs.PointCloud2Builder(frame)
        elif output == "sensor_msgs/Range":
            fov = max(h.max_angle - h.min_angle, cfg.vertical.max_angle - cfg.vertical.min_angle)
            self.range_builder = ros_msgs.RangeBuilder(frame, ultrasound, fov, cfg.range_min, cfg.range_max)

    def publish(self, now, stamp):
        fractions, retro = self.cast()
        ranges, intensities = self.processor.process(fractions, retro)
        if self.min_intensity:
            intensities = intensities.clip(min=self.min_intensity)
        if self.output == "sensor_msgs/LaserScan":
            if self.middle_row:  # the ROS 2 plugin publishes only the middle vertical row
                count = self.cfg.horizontal.count
                start = (self.cfg.vertical.count // 2) * count
                ranges, intensities = ranges[start:start + count], intensities[start:start + count]
            msg = self.scan_builder.build(stamp, ranges, intensities)
        elif self.output == "sensor_msgs/Range":
            msg = self.range_builder.build(stamp, float(ranges.min()))
        else:
            points = ray_sensor.scan_points(ranges, intensities, self.cfg, self.min_intensity)
            if self.output == "sensor_msgs/PointCloud2":
                msg = self.cloud_builder.build(stamp, points)
            else:
                msg = ros_msgs.point_cloud(stamp, self.frame, points)
        self.pub.publish(msg)

    def summary(self):
        return self.describe(self.pub.resolved_name, self.frame)


_ROS1_READ = ("robotNamespace", "topicName", "frameName")


def _ros1(ctx, sensor, element, path, filename):
    values = ray_base.plugin_tags(element)
    ignored = [t for t in values if t not in _ROS1_READ]
    if ignored:
        ctx.warnings.append(f"{path}: tags ignored, as {filename} reads only robotNamespace, topicName and "
                            f"frameName (rate and noise come from the <sensor>): {', '.join(ignored)}")
    ns = ray_base.ros1_namespace(ctx, values)
    if "topicName" in values:
        topic = check_string(f"<topicName> of {path}", values["topicName"])
    else:
        topic = "/world"
        ctx.warnings.append(f"{path}: no <topicName>: publishing on /world, {filename}'s default")
    frame = ray_base.ros1_frame(ctx, values, sensor, path)
    return Laser(ctx, sensor, element, path, filename, join(ns, topic), frame)


def ros2_topic(ctx, element, plugin_name, default_ns="/"):
    """Namespace and topic of a ROS 2 gazebo_ros plugin's ``~/out`` publisher: ``<ros><namespace>`` and a
    ``<remapping>`` (or ``<argument>``) of ``~/out`` / ``out``; unremapped, ``<plugin name>/out``."""
    ros = element.find("ros")
    ns, out = None, None
    if ros is not None:
        ns_el = ros.find("namespace")
        if ns_el is not None and (ns_el.text or "").strip():
            ns = ns_el.text.strip()
        for child in ros:
            if child.tag not in ("remapping", "argument"):
                continue
            for rule in (child.text or "").split():
                src, sep, dst = rule.partition(":=")
                if sep and src.strip() in ("~/out", "out", "~out") and dst.strip():
                    out = dst.strip()
    ns = ctx.plugin_namespace(ns, default_ns)
    return join(ns, out if out is not None else f"{plugin_name}/out")


def _ros2(ctx, sensor, element, path):
    values = ray_base.plugin_tags(element)
    output = values.get("output_type", "").strip()
    if not output:
        output = "sensor_msgs/PointCloud2"
        ctx.warnings.append(f"{path}: no <output_type>: publishing sensor_msgs/PointCloud2, the plugin's default")
    output = output.replace("::msg::", "/").replace("/msg/", "/")
    if output not in OUTPUT_TYPES:
        raise ConfigError(f"<output_type> of {path}", output, ", ".join(OUTPUT_TYPES))
    frame = values.get("frame_name", "").strip() or sensor.link or "world"
    frame = ctx.frame(ctx.clean_frame(frame, path))
    min_intensity = (tag_number(f"<min_intensity> of {path}", values["min_intensity"], ctx.warnings)
                     if "min_intensity" in values else 0.0)
    radiation = values.get("radiation_type", "infrared").strip().lower()
    if radiation not in ("infrared", "ultrasound"):
        raise ConfigError(f"<radiation_type> of {path}", radiation, "infrared or ultrasound")
    known = {"ros", "output_type", "frame_name", "min_intensity", "radiation_type"}
    ignored = [t for t in values if t not in known]
    if ignored:
        ctx.warnings.append(f"{path}: unknown tags ignored: {', '.join(ignored)}")
    topic = ros2_topic(ctx, element, element.get("name") or "ray_sensor")
    return Laser(ctx, sensor, element, path, ROS2_RAY, topic, frame, output, min_intensity,
                 radiation == "ultrasound")


def create_laser(ctx, sensor, element, params):
    path = ray_base.plugin_path(sensor, element)
    ray_base.check_type(sensor, path)
    base = (element.get("filename") or "").strip().rsplit("/", 1)[-1]
    filename = "libgazebo_ros_gpu_laser.so" if "gpu" in base else "libgazebo_ros_laser.so"
    return _ros1(ctx, sensor, element, path, filename)


def create_ray_sensor(ctx, sensor, element, params):
    path = ray_base.plugin_path(sensor, element)
    ray_base.check_type(sensor, path)
    return _ros2(ctx, sensor, element, path)
