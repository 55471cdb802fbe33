"""What the plugins of ray sensors (``<sensor type="ray|gpu_ray">``) share: the sensor mounted on its link,
its schedule and the casting of its rays (:class:`RaySensorPlugin`), and reading gazebo_ros's ROS 1 plugin
tags (namespace, frame). Used by :mod:`diffbot_sim.plugins.laser`, :mod:`diffbot_sim.plugins.range` and
:mod:`diffbot_sim.plugins.ray_clouds`, as :mod:`diffbot_sim.plugins.camera_base` serves the cameras.

What the rays measure (angles, misses, noise, intensities) is :mod:`diffbot_sim.sensors.ray`; the casting is
``World.ray_batch``. A sensor on a link lumped into its parent by a fixed joint sits at that link's frame and
its own ``<pose>`` is dropped, as sdformat's URDF reader replaces it (with a warning when it was not zero).
"""
from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import ConfigError
from diffbot_sim.plugins.base import Plugin, summary_key
from diffbot_sim.sensors import ray as ray_sensor
from diffbot_sim.values import check_string


def plugin_tags(element):
    """{tag: text} of a plugin element's direct children (text or ``value=`` form)."""
    return {child.tag: tag_value(child) for child in element}


def sensor_seed(ctx, where):
    """The noise seed: the simulator's ``~seed`` (validated in SimConfig), so two runs are identical."""
    return ctx.cfg.seed


def ros1_frame(ctx, values, sensor, path, warn=True):
    """The frame a ROS 1 ray plugin publishes in: ``frameName``, else the sensor's link (gazebo_ros says
    ``/world``: with a warning when ``warn``), without a leading slash, with the robot's tf_prefix."""
    if "frameName" in values:
        frame = check_string(f"<frameName> of {path}", values["frameName"])
    else:
        frame = sensor.link or "world"
        if warn:
            ctx.warnings.append(f"{path}: no <frameName>: using the sensor's link '{frame}' (gazebo_ros would "
                                "say /world)")
    return ctx.frame(ctx.clean_frame(frame, path))


def ros1_namespace(ctx, values):
    """gazebo_ros's GetRobotNamespace: tag absent -> the node's ("/"), present but empty -> the model name."""
    if "robotNamespace" in values:
        return ctx.plugin_namespace(values["robotNamespace"].strip() or ctx.model.name, "/")
    return ctx.plugin_namespace(None, "/")


class RaySensorPlugin(Plugin):
    """A ray sensor mounted on a robot link: schedule, pose and casting; subclasses publish."""

    sensor = True

    def __init__(self, ctx, sensor, plugin_element, path):
        self.ctx = ctx
        self.path = path
        self.cfg = cfg = ray_sensor.parse_sensor(sensor.element, sensor.path)
        ctx.warnings.extend(cfg.warnings)
        self.name = sensor.name or sensor.path
        self.link = sensor.link
        self.pose, warning = ray_sensor.mounted_pose(cfg, ctx.model, self.link)
        if warning is not None:
            ctx.warnings.append(warning)
        self.directions = ray_sensor.ray_directions(cfg)
        rng = ray_sensor.noise_rng(sensor_seed(ctx, sensor.path), f"{ctx.spec.name or ''}/{self.name}")
        self.rng = rng
        self.processor = ray_sensor.ScanProcessor(cfg, rng)
        self.period = 1.0 / cfg.update_rate if cfg.update_rate > 0 else 0.0
        self.pub = None

    def publishers(self):
        return [self.pub] if self.pub is not None else []

    def cast(self):
        """(hit fractions, retro values) of this sensor's rays from its current pose."""
        cfg = self.cfg
        position, quaternion = self.ctx.robot.link_pose(self.link)
        origin, rotation = ray_sensor.sensor_pose(position, quaternion, self.pose)
        starts, ends = ray_sensor.world_rays(origin, rotation, self.directions, cfg.range_min, cfg.range_max)
        world = self.ctx.sim.world
        fractions, bodies, links = world.ray_batch(starts, ends)
        return fractions, world.retro(bodies, links)

    def after_step(self, now, stamp, transforms):
        if not self.take_due(now, self.period):
            return
        if self.pub is not None and self.pub.get_num_connections():  # lazy, as gazebo_ros
            self.publish(now, stamp)

    def publish(self, now, stamp):
        raise NotImplementedError

    def describe(self, topic, frame):
        rate = f"{self.cfg.update_rate:g} Hz" if self.cfg.update_rate > 0 else "every step"
        return {summary_key("sensor", self.name): f"{self.filename} topic {topic} frame {frame} rays {self.cfg.rays} "
                                       f"readings {self.cfg.readings} {rate}"}


def plugin_path(sensor, element):
    """Where a ray sensor's ``<plugin>`` is, for messages: ``<sensor path>/plugin[@name='...']``."""
    name = element.get("name")
    return f"{sensor.path}/plugin[@name='{name}']" if name else f"{sensor.path}/plugin"


def check_type(sensor, path):
    """ConfigError unless the plugin sits on a ray sensor (``ray`` or ``gpu_ray``)."""
    if sensor.type not in ray_sensor.RAY_TYPES:
        raise ConfigError(f"<sensor type> of {path}", sensor.type, "ray or gpu_ray (a ray sensor's plugin)")
