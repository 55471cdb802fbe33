"""``librealsense_gazebo_plugin.so`` (pal-robotics/realsense_gazebo_plugin, a model plugin): a RealSense's colour,
two infrared and depth streams from the four camera sensors it names, as its users' launch files get them.

Sensors: ``<prefix>color``, ``<prefix>ired1``, ``<prefix>ired2`` (``<sensor type="camera">``, the infrared ones
L_INT8) and ``<prefix>depth`` (``type="depth"``), each rendered from its own pose on its link. Topics under the
plugin's name (its ``name=`` attribute, relative to the simulator's namespace: ``/camera/color/image_raw``):
``colorTopicName``, ``infrared1TopicName``, ``infrared2TopicName``, ``depthTopicName`` and their
``*CameraInfoTopicName``; frames ``colorOpticalframeName`` ... ; rates ``colorUpdateRate``,
``infraredUpdateRate``, ``depthUpdateRate``; depth 16UC1 mm clipped to ``rangeMinDepth``..``rangeMaxDepth``;
``pointCloud`` and its tags are read, and the cloud is not published (one warning). Encodings rgb8 and 8UC1
(infrared), as the plugin's. A tag it does not know makes the original throw ("Ivalid parameter"): here one
warning. Images render only while subscribed.
"""
import math

from sensor_msgs.msg import CameraInfo, Image

from diffbot_sim.control.schedule import first_due_sensor
from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import PluginNotLoaded
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import Plugin, join, next_due, summary_key
from diffbot_sim.plugins.camera_base import choose_renderer
from diffbot_sim.plugins.sensor_lookup import find_sensor
from diffbot_sim.sensors import camera as cam
from diffbot_sim.sensors.realsense import depth_millimetres, realsense_intrinsics
from diffbot_sim.values import tag_number

STREAMS = (("color", "color", "colorUpdateRate", "colorTopicName", "colorCameraInfoTopicName",
            "colorOpticalframeName"),
           ("ired1", "infrared", "infraredUpdateRate", "infrared1TopicName", "infrared1CameraInfoTopicName",
            "infrared1OpticalframeName"),
           ("ired2", "infrared2", "infraredUpdateRate", "infrared2TopicName", "infrared2CameraInfoTopicName",
            "infrared2OpticalframeName"),
           ("depth", "depth", "depthUpdateRate", "depthTopicName", "depthCameraInfoTopicName",
            "depthOpticalframeName"))
KNOWN = {t for s in STREAMS for t in s[2:]} | {"rangeMinDepth", "rangeMaxDepth", "pointCloud", "pointCloudTopicName",
                                              "pointCloudCutoff", "pointCloudCutoffMax", "prefix", "robotNamespace"}


class Stream:
    """One of the four cameras."""

    def __init__(self, ctx, ns, kind, sensor, tags, path):
        element, link, spath = sensor
        self.ctx, self.kind, self.link = ctx, kind[0], link or ctx.model.root
        self.cfg = cam.parse_sensor(element, spath)
        ctx.warnings.extend(w for w in self.cfg.warnings if "/image/format" not in w)  # the plugin sets encodings
        rate = tag_number(f"<{kind[2]}> of {path}", tags[kind[2]], ctx.warnings, low=0.0) if kind[2] in tags else 0.0
        rate = rate or self.cfg.update_rate
        self.period = 1.0 / rate if rate > 0 else 0.0
        self.next = math.inf  # scheduled when the plugin starts (a camera sensor's timer: first_due_sensor)
        self.frame = ctx.frame(tags.get(kind[5]) or "")
        topic = tags.get(kind[3]) or kind[1]
        info_topic = tags.get(kind[4]) or "camera_info"
        self.image_pub = ctx.publisher(join(ns, topic), Image)
        self.info_pub = ctx.publisher(join(ns, info_topic), CameraInfo)
        self.encoding = "16UC1" if self.kind == "depth" else ("rgb8" if self.kind == "color" else "8UC1")
        channels = {"16UC1": 2, "rgb8": 3, "8UC1": 1}[self.encoding]
        self.image = ros_msgs.ImageBuilder(self.frame, self.cfg.width, self.cfg.height, self.encoding, channels)
        k, p = realsense_intrinsics(self.cfg.width, self.cfg.height, self.cfg.hfov)
        self.info = ros_msgs.camera_info(self.frame, cam.Intrinsics(self.cfg.width, self.cfg.height, K=k,
                                                                     R=[1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0], P=p,
                                                                     D=[0.0] * 5))

    def render(self):
        cfg = self.cfg
        view = cam.sensor_view(self.ctx.robot.link_pose(self.link), cfg.pose)
        return self.ctx.sim.world.render(view, cfg.width, cfg.height, cfg.hfov, cfg.near, cfg.far,
                                         choose_renderer(self.ctx))


class RealSense(Plugin):
    filename = "librealsense_gazebo_plugin.so"
    sensor = True
    sensor_timer = True

    def __init__(self, ctx, streams, range_min, range_max):
        self.ctx, self.streams, self.range = ctx, streams, (range_min, range_max)

    def publishers(self):
        return [p for s in self.streams for p in (s.image_pub, s.info_pub)]

    def next_publish(self):
        return min(s.next for s in self.streams)

    def start(self, now):
        for stream in self.streams:
            stream.next = first_due_sensor(stream.next, stream.period, now)

    def after_step(self, now, stamp, transforms):
        for s in self.streams:
            if now + 1e-9 < s.next:
                continue
            s.next = next_due(s.next, s.period, now)
            if s.image_pub.get_num_connections():
                rgb, depth = s.render()
                if s.kind == "depth":
                    data = depth_millimetres(depth, *self.range).tobytes()
                else:
                    data = cam.to_encoding(rgb, "mono8" if s.kind != "color" else "rgb8").tobytes()
                s.image_pub.publish(s.image.build(stamp, data))
            if s.info_pub.get_num_connections():
                s.info.header.stamp = stamp
                s.info_pub.publish(s.info)

    def summary(self):
        return {summary_key("sensor", f"realsense/{s.kind}"): f"{s.image_pub.resolved_name} in {s.frame}"
                for s in self.streams}


def create(ctx, element, path, params):
    tags = {child.tag: tag_value(child) for child in element}
    unknown = [t for t in tags if t not in KNOWN]
    if unknown:
        ctx.warnings.append(f"{path}: tags the RealSense plugin does not know (the original throws): "
                            f"{', '.join(unknown)}")
    prefix = tags.get("prefix", "")
    ns = join(ctx.plugin_namespace(None, "/"), element.get("name") or "")
    streams = []
    for kind in STREAMS:
        sensor = find_sensor(ctx.model, prefix + kind[0])
        if sensor is None:
            raise PluginNotLoaded(f"{path}: no sensor named '{prefix + kind[0]}' in the model (the RealSense plugin "
                                  "needs its four cameras); not loaded")
        streams.append(Stream(ctx, ns, kind, sensor, tags, path))

    def number(key, default):
        return tag_number(f"<{key}> of {path}", tags[key], ctx.warnings) if key in tags else default

    if tags.get("pointCloud", "false").strip().lower() in ("true", "1"):
        ctx.warnings.append(f"{path}: <pointCloud> is not simulated (the four images and camera_info are)")
    return RealSense(ctx, streams, number("rangeMinDepth", 0.0), number("rangeMaxDepth", math.inf))
