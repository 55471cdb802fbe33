"""What the camera and depth-camera plugins share: the sensor's pose, timing, rendering and CameraInfo
(:mod:`diffbot_sim.plugins.camera`, :mod:`diffbot_sim.plugins.depth`)."""
from diffbot_sim.errors import PluginNotLoaded
from diffbot_sim.plugins.base import Plugin, join, summary_key
from diffbot_sim.sensors import camera as cam


def choose_renderer(ctx):
    """The renderer cameras use: ``~renderer`` (SimConfig), which the simulator set back to ``tiny`` (with
    one warning) when the EGL plugin could not be loaded before the world was built."""
    return ctx.cfg.renderer


class CameraBase(Plugin):
    """What the camera and depth plugins share: the sensor's pose, timing, rendering and CameraInfo."""

    sensor = True
    sensor_timer = True

    def __init__(self, ctx, sensor, cfg, tags):
        self.ctx = ctx
        self.sdf_sensor = sensor  # (``sensor`` is Plugin's flag: its publications are sensor data)
        self.cfg = cfg
        self.tags = tags
        self.link = sensor.link or ctx.model.root
        try:
            ctx.robot.link_pose(self.link)
        except KeyError:
            raise PluginNotLoaded(f"camera sensor '{cfg.name}' is on link '{self.link}', which the model does not "
                                  "have; the plugin is not loaded, as in Gazebo", ctx.model.source,
                                  sensor.path) from None
        values = tags.values
        self.intrinsics = cam.intrinsics(
            cfg.width, cfg.height, cfg.hfov, cx=values.get("cx", 0.0), cy=values.get("cy", 0.0),
            cx_prime=values.get("cx_prime", 0.0), focal=values.get("focal_length", 0.0),
            hack_baseline=values.get("hack_baseline", 0.0),
            distortion=tuple(values.get(k, 0.0) for k in ("k1", "k2", "k3", "t1", "t2")))
        for text in cfg.warnings + [f"{sensor.path}: {w}" for w in self.intrinsics.warnings]:
            ctx.warnings.append(text)
        if tags.unknown:
            ctx.warnings.append(f"{sensor.path}: unknown camera plugin tags ignored: {', '.join(tags.unknown)}")
        self.period = cam.effective_period(cfg.update_rate, values.get("update_rate", 0.0))
        if self.period == 0.0:
            ctx.warnings.append(f"{sensor.path}: <update_rate> 0 renders at every physics step (costly); "
                                "give the sensor a rate")
        self.renderer = choose_renderer(ctx)
        self.frame = ctx.frame(self._frame_name())
        self.rng = None
        if cfg.noise_mean or cfg.noise_stddev:
            import zlib

            import numpy as np
            self.rng = np.random.default_rng([ctx.cfg.seed & 0xFFFFFFFF,
                                              zlib.crc32(cfg.name.encode("utf-8"))])
        self.renders = 0  # images rendered (for tests and figures)

    def _frame_name(self):
        frame = self.tags.values.get("frame")
        if frame:
            return self.ctx.clean_frame(frame, f"{self.sdf_sensor.path}/plugin frameName")
        if self.tags.dialect == "ros2":
            return self.link
        self.ctx.warnings.append(f"{self.sdf_sensor.path}: no frameName; images are in 'world' (Gazebo: '/world')")
        return "world"

    def namespace(self):
        """The topics' namespace: ``<robotNamespace>/<cameraName>`` (ROS 1) or ``<ros><namespace>`` (ROS 2)."""
        ns = self.ctx.plugin_namespace(self.tags.values.get("namespace") or None)
        if self.tags.dialect == "ros1":
            name = self.tags.values.get("camera_name") or ""
            return join(ns, name) if name else ns
        return ns

    def topic(self, key, default):
        """A topic from its tag (ROS 1) or ``<camera_name>/<default>`` after remapping (ROS 2)."""
        ns = self.namespace()
        if self.tags.dialect == "ros1":
            return join(ns, self.tags.values.get(key) or default)
        name = f"{self.tags.values.get('camera_name') or self.cfg.name}/{default}"
        out = cam.remapped(self.tags, name)
        out = cam.remapped(self.tags, default) if out == name else out
        return join(ns, out)

    def next_publish(self):
        return self.next

    def view_pose(self):
        return cam.sensor_view(self.ctx.robot.link_pose(self.link), self.cfg.pose)

    def render(self):
        cfg = self.cfg
        rgb, depth = self.ctx.sim.world.render(self.view_pose(), cfg.width, cfg.height, cfg.hfov, cfg.near,
                                               cfg.far, self.renderer)
        self.renders += 1
        if self.rng is not None:
            rgb = cam.image_noise(rgb, cfg.noise_mean, cfg.noise_stddev, self.rng)
        return rgb, depth

    def due(self, now):
        return self.take_due(now, self.period)

    def summary(self):
        return {summary_key("camera", self.cfg.name): cam.describe(self.cfg, self.renderer)}
