"""Ray sensors that publish point clouds: ``libgazebo_ros_block_laser.so`` (ROS 1, sensor_msgs/PointCloud)
and ``libgazebo_ros_velodyne_laser.so`` / ``libgazebo_ros_velodyne_gpu_laser.so`` (velodyne_simulator,
sensor_msgs/PointCloud2 with x, y, z, intensity, ring, time). Casting and range semantics are the laser's
(:class:`diffbot_sim.plugins.ray_base.RaySensorPlugin`, :mod:`diffbot_sim.sensors.ray`).

* Block laser (gazebo_plugins' ``gazebo_ros_block_laser.cpp``): tags ``robotNamespace``, ``topicName`` (``/world``),
  ``frameName``, ``gaussianNoise`` (0, on x, y, z of every finite point); ``hokuyoMinIntensity`` and
  ``updateRate`` are read by the original but never applied. One point per reading (Gazebo interpolates
  between the four nearest rays; at resolution 1, the usual case, that is the ray itself), a miss at +inf,
  below the minimum at -inf; one unnamed channel: the hit surface's retro value.
* Velodyne (velodyne_simulator's plugin): tags ``topicName`` (``/velodyne_points``), ``frameName`` (the
  link), ``min_range`` (0.9 m) and ``max_range`` (130 m) clip the points, ``gaussianNoise`` (m, on the range),
  ``organize_cloud`` (false: only returns; true: rows x columns with NaN where a ray returned nothing),
  ``min_intensity`` (0). ``ring`` is the vertical row, 0 the lowest.
"""
import numpy as np
from sensor_msgs.msg import PointCloud, PointCloud2

from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins import ray_base
from diffbot_sim.plugins.base import join
from diffbot_sim.values import check_bool, tag_number

BLOCK = "libgazebo_ros_block_laser.so"
VELODYNE = ("libgazebo_ros_velodyne_laser.so", "libgazebo_ros_velodyne_gpu_laser.so")


def _angles(cfg):
    """(azimuth, inclination) of every reading, in the order the processor returns them (rows of h)."""
    h, v = cfg.horizontal, cfg.vertical
    azimuth = np.tile(h.reading_angles(), v.count)
    inclination = np.repeat(v.reading_angles() if v.count > 1 else np.zeros(1), h.count)
    return azimuth, inclination


def _points(ranges, azimuth, inclination):
    r = np.asarray(ranges, float)
    with np.errstate(invalid="ignore"):
        return np.stack([r * np.cos(inclination) * np.cos(azimuth), r * np.cos(inclination) * np.sin(azimuth),
                         r * np.sin(inclination)], axis=1)


class BlockLaser(ray_base.RaySensorPlugin):
    filename = BLOCK

    def __init__(self, ctx, sensor, element, path, values):
        super().__init__(ctx, sensor, element, path)
        ns = ray_base.ros1_namespace(ctx, values)
        self.frame = ray_base.ros1_frame(ctx, values, sensor, path, warn=False)
        self.noise = tag_number(f"<gaussianNoise> of {path}", values.get("gaussianNoise", 0.0), ctx.warnings,
                                low=0.0)
        self.pub = ctx.publisher(join(ns, values.get("topicName") or "/world"), PointCloud)
        self.azimuth, self.inclination = _angles(self.cfg)

    def publish(self, now, stamp):
        fractions, retro = self.cast()
        ranges, intensities = self.processor.process(fractions, retro)
        xyz = _points(ranges, self.azimuth, self.inclination)
        finite = np.isfinite(ranges)
        if self.noise > 0:
            xyz[finite] += self.rng.normal(0.0, self.noise, (int(finite.sum()), 3))
        self.pub.publish(ros_msgs.point_cloud(stamp, self.frame, np.column_stack([xyz, intensities]),
                                              channel=""))

    def summary(self):
        return self.describe(self.pub.resolved_name, self.frame)


class VelodyneLaser(ray_base.RaySensorPlugin):
    filename = VELODYNE[0]

    def __init__(self, ctx, sensor, element, path, values):
        super().__init__(ctx, sensor, element, path)
        ns = ray_base.ros1_namespace(ctx, values)

        def label(tag):
            return f"<{tag}> of {path}"

        self.frame = ray_base.ros1_frame(ctx, values, sensor, path, warn=False)
        notes = ctx.warnings
        self.min_range = tag_number(label("min_range"), values.get("min_range", 0.9), notes, low=0.0)
        self.max_range = tag_number(label("max_range"), values.get("max_range", 130.0), notes, low=0.0,
                                    low_open=True)
        self.noise = tag_number(label("gaussianNoise"), values.get("gaussianNoise", 0.0), notes, low=0.0)
        self.organize = check_bool(label("organize_cloud"), values.get("organize_cloud", "false"))
        self.min_intensity = tag_number(label("min_intensity"), values.get("min_intensity", 0.0), notes)
        self.pub = ctx.publisher(join(ns, values.get("topicName") or "/velodyne_points"), PointCloud2)
        self.builder = ros_msgs.RingCloudBuilder(self.frame)
        self.azimuth, self.inclination = _angles(self.cfg)
        rows = self.cfg.vertical.count if self.cfg.vertical.count > 1 else 1
        self.rings = np.repeat(np.arange(rows, dtype=np.uint16), self.cfg.horizontal.count)

    def publish(self, now, stamp):
        fractions, retro = self.cast()
        ranges, intensities = self.processor.process(fractions, retro)
        ranges = np.asarray(ranges, float).copy()
        finite = np.isfinite(ranges)
        if self.noise > 0:
            ranges[finite] += self.rng.normal(0.0, self.noise, int(finite.sum()))
        valid = finite & (ranges >= self.min_range) & (ranges <= self.max_range)
        xyz = _points(np.where(valid, ranges, np.nan), self.azimuth, self.inclination)
        points = np.column_stack([xyz, np.maximum(np.asarray(intensities, float), self.min_intensity)])
        if self.organize:
            rows = max(self.cfg.vertical.count, 1)
            msg = self.builder.build(stamp, points, self.rings, height=rows, dense=bool(valid.all()))
        else:
            msg = self.builder.build(stamp, points[valid], self.rings[valid])
        self.pub.publish(msg)

    def summary(self):
        return self.describe(self.pub.resolved_name, self.frame)


def create_block(ctx, sensor, element, params):
    path = ray_base.plugin_path(sensor, element)
    ray_base.check_type(sensor, path)
    return BlockLaser(ctx, sensor, element, path, ray_base.plugin_tags(element))


def create_velodyne(ctx, sensor, element, params):
    path = ray_base.plugin_path(sensor, element)
    ray_base.check_type(sensor, path)
    return VelodyneLaser(ctx, sensor, element, path, ray_base.plugin_tags(element))


