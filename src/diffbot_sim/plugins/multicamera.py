"""``libgazebo_ros_multicamera.so`` on a ``<sensor type="multicamera">``: one ``image_raw`` and ``camera_info``
per camera, as gazebo_ros_multicamera (noetic) publishes a stereo pair.

Each ``<camera name=...>`` of the sensor is a camera of its own, rendered from the sensor's pose composed with
the camera's ``<pose>``. As upstream: a camera whose name contains ``left`` publishes under
``<robotNamespace>/<cameraName>/left`` with no baseline in P; one whose name contains ``right`` under
``.../right`` with ``P[3] = -f · hackBaseline`` (the plugin's tag); a camera named neither gets no topics (one
warning). Every other tag is the camera plugin's (:mod:`diffbot_sim.plugins.camera`); ``frameName`` is shared.
"""
import copy
import xml.etree.ElementTree as ET

from diffbot_sim.plugins.base import Plugin
from diffbot_sim.plugins.camera import Camera
from diffbot_sim.sensors import camera as cam
from diffbot_sim.transforms import compose, quaternion_rpy, rpy_quaternion

SIDES = ("left", "right")


class MultiCameraPart(Camera):
    filename = "libgazebo_ros_multicamera.so"


class MultiCamera(Plugin):
    """The sensor's cameras as one plugin (each keeps its own schedule and topics)."""

    filename = "libgazebo_ros_multicamera.so"
    sensor = True

    def __init__(self, cameras):
        self.cameras = cameras

    def publishers(self):
        return [p for c in self.cameras for p in c.publishers()]

    def next_publish(self):
        return min((c.next_publish() for c in self.cameras), default=float("inf"))

    def after_step(self, now, stamp, transforms):
        for camera in self.cameras:
            camera.after_step(now, stamp, transforms)

    def start(self, now):
        for camera in self.cameras:
            camera.start(now)

    def reset(self, now):
        for camera in self.cameras:
            camera.reset(now)

    def summary(self):
        out = {}
        for camera in self.cameras:
            out.update(camera.summary())
        return out


def _pose(element):
    """(xyz, quaternion) of an element's ``<pose>`` (identity when none)."""
    text = (element.findtext("pose") or "").split() if element is not None else []
    values = [float(v) for v in text] if len(text) == 6 else [0.0] * 6
    return tuple(values[:3]), rpy_quaternion(*values[3:])


def camera_sensor(sensor_element, camera_element):
    """A ``<sensor type="camera">`` element equal to one camera of a multicamera sensor: its update rate,
    the composed pose, that ``<camera>``."""
    out = ET.Element("sensor", {"type": "camera", "name": camera_element.get("name") or ""})
    rate = sensor_element.find("update_rate")
    if rate is not None:
        out.append(copy.deepcopy(rate))
    position, quaternion = compose(_pose(sensor_element), _pose(camera_element))
    ET.SubElement(out, "pose").text = " ".join(f"{v:.12g}" for v in (*position, *quaternion_rpy(quaternion)))
    inner = copy.deepcopy(camera_element)
    for pose in inner.findall("pose"):
        inner.remove(pose)
    out.append(inner)
    return out


def create(ctx, sensor, plugin_element, params):
    """One camera per ``left``/``right`` camera of ``sensor``, together one plugin."""
    if sensor.type != "multicamera":
        ctx.warnings.append(f"{sensor.path}: libgazebo_ros_multicamera.so on a '{sensor.type}' sensor")
    tags = cam.read_plugin(plugin_element, sensor.path)
    cameras = []
    for index, element in enumerate(sensor.element.findall("camera")):
        name = element.get("name") or f"camera{index}"
        side = next((s for s in SIDES if s in name), None)
        if side is None:
            ctx.warnings.append(f"{sensor.path}/camera[@name='{name}']: gazebo_ros_multicamera publishes only cameras "
                                "named left or right; this one has no topics")
            continue
        path = f"{sensor.path}/camera[@name='{name}']"
        cfg = cam.parse_sensor(camera_sensor(sensor.element, element), path, name)
        own = copy.deepcopy(tags)
        own.values["camera_name"] = f"{tags.values.get('camera_name') or ''}/{side}".lstrip("/")
        own.values["hack_baseline"] = tags.values.get("hack_baseline", 0.0) if side == "right" else 0.0
        cameras.append(MultiCameraPart(ctx, sensor, cfg, own))
    return MultiCamera(cameras)
