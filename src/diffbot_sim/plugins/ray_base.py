"""What the plugins of ray sensors (``<sensor type="ray|gpu_ray">``) share: the sensor mounted on its link,
its schedule and the casting of its rays (:class:`RaySensorPlugin`), and reading gazebo_ros's ROS 1 plugin
tags (namespace, frame). Used by :mod:`diffbot_sim.plugins.laser`, :mod:`diffbot_sim.plugins.range` and
:mod:`diffbot_sim.plugins.ray_clouds`, as :mod:`diffbot_sim.plugins.camera_base` serves the cameras.

What the rays measure (angles, misses, noise, intensities) is :mod:`diffbot_sim.sensors.ray`; the casting is
``World.ray_batch``. A sensor on a link lumped into its parent by a fixed joint sits at that link's frame and
its own ``<pose>`` is dropped, as sdformat's URDF reader replaces it (with a warning when it was not zero).
"""
import itertools
from typing import Any

from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import ConfigError
from diffbot_sim.plugins.base import Plugin, summary_key
from diffbot_sim.sensors import ray as ray_sensor
from diffbot_sim.values import check_string

#: Keys of the ray sensors' rays in the ray process (``World.cast_later``), one per sensor ever made.
_RAY_KEYS = itertools.count()


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
    sensor_timer = True

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
        self.pub: Any = None  # the sensor's rospy publisher, which each subclass makes (None: it publishes nothing)
        self._ray_key = next(_RAY_KEYS)  # names this sensor's rays to the ray process
        self._waiting = None  # (ticket, sim time, stamp) of a cast the ray process has not answered yet
        self._answer = None  # its answer, for the publish() it is handed to

    def publishers(self):
        return [self.pub] if self.pub is not None else []

    def rays_per_second(self):
        rate = self.cfg.update_rate if self.cfg.update_rate > 0 else 1.0 / self.ctx.cfg.time_step
        return self.cfg.rays * rate

    def _pose(self):
        """World (position, rotation) of the sensor now."""
        return ray_sensor.sensor_pose(*self.ctx.robot.link_pose(self.link), self.pose)

    def cast(self):
        """(hit fractions, retro values) of this sensor's rays from its current pose: the answer the ray
        process gave for this step when there is one (``~ray_process``), else cast now."""
        world = self.ctx.sim.world
        if self._answer is not None:
            fractions, bodies, links = self._answer
            self._answer = None
        else:
            cfg = self.cfg
            position, rotation = self._pose()
            starts, ends = ray_sensor.world_rays(position, rotation, self.directions, cfg.range_min, cfg.range_max)
            fractions, bodies, links = world.ray_batch(starts, ends)
        return fractions, world.retro(bodies, links)

    def _casts_later(self):
        """Real time with ``~ray_process``: the rays go to the helper process and the message is published
        when their answer is back (a step or two later in wall time, stamped with the step it was due)."""
        return self.ctx.sim.world.ray_helper is not None and self.ctx.cfg.real_time

    def next_publish(self):
        return self._waiting[1] if self._waiting is not None else self.next

    def after_step(self, now, stamp, transforms):
        if self._waiting is not None:
            ticket, due, due_stamp = self._waiting
            answer = self.ctx.sim.world.cast_answer(ticket, wait=not self._casts_later())
            if answer is None:
                return  # not back yet: the loop asks again next step (next_publish says it is due)
            self._waiting, self._answer = None, answer
            self.publish(due, due_stamp)
            self._answer = None  # unused when publish() chose not to publish (a range sensor's throttle)
        if not self.take_due(now, self.period):
            return
        if self.pub is not None and self.pub.get_num_connections():  # lazy, as gazebo_ros
            if self._casts_later():
                ticket = self.ctx.sim.world.cast_later(self._ray_key, self.directions, self.cfg.range_min,
                                                       self.cfg.range_max, *self._pose())
                self._waiting = (ticket, now, stamp)
            else:
                self.publish(now, stamp)

    def start(self, now):
        super().start(now)
        self.drop_waiting()

    def close(self):
        self.drop_waiting()

    def drop_waiting(self):
        """A cast still out belongs to the time before a reset or a deletion: its answer is thrown away."""
        if self._waiting is not None:
            self.ctx.sim.world.cast_drop(self._waiting[0])
        self._waiting = self._answer = None

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
