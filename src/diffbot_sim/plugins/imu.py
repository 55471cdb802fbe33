"""IMUs: ``<sensor type="imu">`` + ``libgazebo_ros_imu_sensor.so`` (ROS 1 and ROS 2 tags), and the model
plugins ``libgazebo_ros_imu.so`` and ``libhector_gazebo_ros_imu.so``; each publishes sensor_msgs/Imu.

Every reading follows REP 145, whatever the original did: orientation of the mounted frame in the world,
angular velocity and proper acceleration (+g on an upward z at rest) in the mounted frame (the link's, lumped
or not, moved by the sensor's SDF ``<pose>``). The acceleration is the finite difference of the frame
origin's world velocity over the publishing period. Deviations of the originals that are corrected here:
``gazebo_ros_imu`` reads no gravity (≈0 at rest, gazebo_ros_pkgs #468) and rotates rates and accelerations
body→world instead of world→body (gazebo_ros_pkgs #344).

Tags and defaults (gazebo_plugins' ``gazebo_ros_imu.cpp`` and ``gazebo_ros_imu_sensor.cpp``, hector_gazebo_plugins'
``gazebo_ros_imu.cpp``):

* ``gazebo_ros_imu_sensor`` ROS 1: ``robotNamespace``, ``topicName`` (``imu_data``), ``frameName``
  (required), ``updateRateHZ`` (1 Hz, with a warning; the SDF ``<update_rate>`` caps it),
  ``gaussianNoise`` (added to each quaternion component, rate and acceleration axis, over the SDF noise;
  covariance diagonals gaussianNoise²), ``rpyOffset`` (left-multiplies the orientation), ``xyzOffset``
  (read, unused as in the original), ``initialOrientationAsReference`` (false). Lazy.
* ROS 2 (``<ros>``, ``frame_name`` default the link, ``initial_orientation_as_reference``): topic from
  ``<remapping>~/out:=NAME`` (default ``<plugin name>/out``), every SDF ``<update_rate>`` tick; covariances
  are the SDF noise stddev² (orientation 0).
* ``gazebo_ros_imu``: ``bodyName`` (required), ``topicName``/``serviceName`` (``/default_imu``),
  ``frameName`` (bodyName), ``updateRate`` (0: every step), ``gaussianNoise``, ``xyzOffset``,
  ``rpyOffset``; covariances gaussianNoise²; std_srvs/Empty service. Lazy.
* ``hector_gazebo_ros_imu``: ``bodyName`` (the root link), ``frameId`` (the link), ``topicName`` (``imu``),
  ``biasTopicName`` (``<topic>/bias``), ``{accel,rate,yaw}{Offset,Drift,DriftFrequency,GaussianNoise,
  ScaleError}``, ``gaussianNoise`` (accel and rate), ``rpyOffset``, ``updateRate`` (0). The orientation
  carries the yaw error and the accelerometer drift as roll/pitch error (hector's pseudo-AHRS).
  ``headingDrift``/``headingGaussianNoise`` (Husky, Jackal) are not hector tags: ignored with a warning.

SDF noise (``<imu><angular_velocity|linear_acceleration><x|y|z><noise>``, or SDF 1.4's
``<imu><noise><rate|accel>``) is seeded from ``~seed`` and the sensor's name (:mod:`diffbot_sim.sensors.noise`).
"""
import copy
import math
import xml.etree.ElementTree as ET

from sensor_msgs.msg import Imu

from diffbot_sim.description.plugin_tags import read_tags, vector
from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import ModelError, PluginNotLoaded
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import Plugin, join, summary_key
from diffbot_sim.sensors import noise
from diffbot_sim.transforms import qconj, qmul, qnormalize, rpy_quaternion
from diffbot_sim.values import check_bool, tag_number

SENSOR_FILENAME = "libgazebo_ros_imu_sensor.so"
MODEL_FILENAME = "libgazebo_ros_imu.so"
HECTOR_FILENAME = "libhector_gazebo_ros_imu.so"
_ROS2_TAGS = ("ros", "frame_name", "initial_orientation_as_reference")
_COMMON = ("robotNamespace", "alwaysOn", "always_on", "updateRate", "update_rate")


# --------------------------------------------------------------------------------------- pure helpers

def sensor_pose(element, where):
    """The SDF sensor's ``<pose>`` (x y z roll pitch yaw) in its link: ((x, y, z), quaternion) or None."""
    pose = element.find("pose") if element is not None else None
    if pose is None or not (pose.text or "").strip():
        return None
    values = vector(pose.text, where, "pose", 6)
    return values[:3], rpy_quaternion(*values[3:])


def update_rate(element, where, notes=None):
    """The SDF ``<update_rate>`` [Hz] of a sensor (0: every step), read as Gazebo reads it."""
    child = element.find("update_rate") if element is not None else None
    if child is None:
        return 0.0
    return tag_number(f"<update_rate> of {where}", tag_value(child), _notes(notes), low=0.0)


def _notes(notes):
    """Where the notes of a lenient reading go (a throw-away list when the caller keeps none)."""
    return notes if notes is not None else []


def sdf_imu_noise(element, generator, where, notes=None):
    """Per-axis SDF noise of an ``<imu>`` block: ([rate x, y, z], [accel x, y, z]) of Gaussian or None."""
    imu = element.find("imu") if element is not None else None
    rate, accel = [None] * 3, [None] * 3
    if imu is None:
        return rate, accel
    old = imu.find("noise")  # SDF 1.4: one block, <rate> and <accel> for all axes
    if old is not None:
        for key, out in (("rate", rate), ("accel", accel)):
            block = old.find(key)
            if block is not None:
                kind = old.find("type")
                if kind is not None and block.find("type") is None:
                    block = _with_type(block, (kind.text or "").strip())
                for i in range(3):
                    out[i] = noise.sdf_noise(block, generator, f"{where}/imu/noise/{key}", notes)
    for key, out in (("angular_velocity", rate), ("linear_acceleration", accel)):
        block = imu.find(key)
        if block is None:
            continue
        for i, axis in enumerate("xyz"):
            el = block.find(axis)
            if el is not None:
                out[i] = noise.sdf_noise(el.find("noise"), generator, f"{where}/imu/{key}/{axis}/noise", notes)
    return rate, accel


def _with_type(block, kind):
    """A copy of an SDF 1.4 ``<rate>``/``<accel>`` block carrying its parent's ``<type>``."""
    block = copy.copy(block)
    ET.SubElement(block, "type").text = kind
    return block


class ImuSettings:
    """What one IMU does, read from its tags (pure; the plugin below runs it)."""

    def __init__(self, **values):
        self.dialect = "ros1"
        self.link = None
        self.frame = None
        self.topic = "imu"
        self.namespace = None
        self.period = 0.0
        self.lazy = True
        self.gaussian_noise = 0.0
        self.orientation_noise = False  # gaussianNoise on each quaternion component (imu_sensor ROS 1)
        self.rpy_offset = (0.0, 0.0, 0.0)
        self.xyz_offset = (0.0, 0.0, 0.0)
        self.initial_reference = False
        self.sdf_rate = [None] * 3
        self.sdf_accel = [None] * 3
        # orientation, angular velocity, linear acceleration: each one variance, or three (one per axis)
        self.covariance: tuple = (0.0, 0.0, 0.0)
        self.service = None
        self.hector = None  # {"accel": [3 models], "rate": [...], "yaw": [1 model]}
        self.bias_topic = None
        self.mount = None  # SDF sensor <pose> in the link
        self.unknown: list[str] = []  # a warning per tag the plugin does not know
        self.generator = None  # the noise models' random generator
        self.__dict__.update(values)


def sensor_settings(sensor, plugin, seed, where, notes=None):
    """ImuSettings of ``<sensor type="imu">`` + libgazebo_ros_imu_sensor.so (``plugin`` element); what Gazebo
    drops after a number is named in ``notes``."""
    notes = _notes(notes)
    tags = read_tags(plugin)
    if sensor.link is None:
        raise ModelError("an imu sensor must sit in a <gazebo reference=\"LINK\"> block", None, where)
    generator = noise.rng(seed, sensor.name or sensor.link)
    rate_noise, accel_noise = sdf_imu_noise(sensor.element, generator, where, notes)
    sdf_rate = update_rate(sensor.element, where, notes)
    s = ImuSettings(link=sensor.link, sdf_rate=rate_noise, sdf_accel=accel_noise,
                    mount=sensor_pose(sensor.element, where))
    s.unknown = []
    if any(t in tags for t in _ROS2_TAGS):
        s.dialect = "ros2"
        ros = plugin.find("ros")
        s.namespace = None
        s.topic = f"{plugin.get('name') or sensor.name or 'imu'}/out"
        if ros is not None:
            ns = ros.find("namespace")
            if ns is not None and (ns.text or "").strip():
                s.namespace = ns.text.strip()
            for child in ros:
                text = (child.text or "").strip()
                rules = [text] if child.tag == "remapping" else \
                    [t for t in text.split() if ":=" in t] if child.tag == "argument" else []
                for rule in rules:
                    src, _, dst = rule.partition(":=")
                    if src.strip().lstrip("~/") == "out" and dst.strip():
                        s.topic = dst.strip()
        s.frame = tags.get("frame_name") or sensor.link
        s.initial_reference = check_bool(f"<initial_orientation_as_reference> of {where}",
                                    tags.get("initial_orientation_as_reference", "false"))
        s.period = 1.0 / sdf_rate if sdf_rate > 0 else 0.0
        s.lazy = False
        s.covariance = (0.0, [m.variance if m else 0.0 for m in rate_noise],
                        [m.variance if m else 0.0 for m in accel_noise])
        known = set(_ROS2_TAGS)
    else:
        if "frameName" not in tags:
            raise PluginNotLoaded("the IMU sensor plugin needs <frameName> (it refuses to load without it)", None,
                             where)
        s.namespace = tags.get("robotNamespace")
        s.topic = tags.get("topicName", "imu_data")
        s.frame = tags["frameName"]
        if "updateRateHZ" in tags:
            hz = tag_number(f"<updateRateHZ> of {where}", tags["updateRateHZ"], notes, low=0.0)
        else:
            hz = 1.0
            s.unknown.append("no <updateRateHZ>: 1 Hz, as the original (which warns too)")
        if sdf_rate > 0:
            hz = min(hz, sdf_rate) if hz > 0 else sdf_rate
        s.period = 1.0 / hz if hz > 0 else 0.0
        s.gaussian_noise = tag_number(f"<gaussianNoise> of {where}", tags.get("gaussianNoise", 0.0), notes, low=0.0)
        s.orientation_noise = True
        if "rpyOffset" in tags:
            s.rpy_offset = vector(tags["rpyOffset"], where, "rpyOffset")
        if "xyzOffset" in tags:
            s.xyz_offset = vector(tags["xyzOffset"], where, "xyzOffset")
        s.initial_reference = check_bool(f"<initialOrientationAsReference> of {where}",
                                    tags.get("initialOrientationAsReference", "false"))
        s.covariance = (s.gaussian_noise ** 2,) * 3
        known = {"topicName", "frameName", "updateRateHZ", "gaussianNoise", "rpyOffset", "xyzOffset",
                 "initialOrientationAsReference", "bodyName", "serviceName"}
    s.generator = generator
    s.unknown += [f"unknown tag <{t}> ignored" for t in sorted(set(tags) - known - set(_COMMON))]
    return s


def model_settings(element, seed, where, name, notes=None):
    """ImuSettings of the model plugin libgazebo_ros_imu.so."""
    notes = _notes(notes)
    tags = read_tags(element)
    if "bodyName" not in tags:
        raise PluginNotLoaded("libgazebo_ros_imu.so needs <bodyName> (it refuses to load without it)", None, where)
    gn = tag_number(f"<gaussianNoise> of {where}", tags.get("gaussianNoise", 0.0), notes, low=0.0)
    rate = tag_number(f"<updateRate> of {where}", tags.get("updateRate", 0.0), notes, low=0.0)
    s = ImuSettings(link=tags["bodyName"], frame=tags.get("frameName") or tags["bodyName"],
                    topic=tags.get("topicName", "/default_imu"), namespace=tags.get("robotNamespace"),
                    period=1.0 / rate if rate > 0 else 0.0, gaussian_noise=gn, covariance=(gn ** 2,) * 3,
                    service=tags.get("serviceName", "/default_imu"))
    for tag in ("rpyOffset", "rpyOffsets"):
        if tag in tags:
            s.rpy_offset = vector(tags[tag], where, tag)
    for tag in ("xyzOffset", "xyzOffsets"):
        if tag in tags:
            s.xyz_offset = vector(tags[tag], where, tag)
    s.generator = noise.rng(seed, name)
    known = {"bodyName", "frameName", "topicName", "serviceName", "gaussianNoise", "rpyOffset", "rpyOffsets",
             "xyzOffset", "xyzOffsets", "imu"}  # <imu><noise> nested here (TurtleBot3) is never read
    s.unknown = [f"unknown tag <{t}> ignored" for t in sorted(set(tags) - known - set(_COMMON))]
    return s


def hector_settings(element, seed, where, name, root, notes=None):
    """ImuSettings of libhector_gazebo_ros_imu.so (``root``: the model's first link, hector's default)."""
    notes = _notes(notes)
    tags = read_tags(element)
    generator = noise.rng(seed, name)
    link = tags.get("bodyName") or root
    topic = tags.get("topicName", "imu")
    rate = tag_number(f"<updateRate> of {where}", tags.get("updateRate", 0.0), notes, low=0.0)
    period = 1.0 / rate if rate > 0 else 0.0
    if "updatePeriod" in tags:
        period = tag_number(f"<updatePeriod> of {where}", tags["updatePeriod"], notes, low=0.0)
    models = {"accel": noise.hector_models(tags, "accel", generator, where),
              "rate": noise.hector_models(tags, "rate", generator, where),
              "yaw": noise.hector_models(tags, "yaw", generator, where, axes=1)}
    if "gaussianNoise" in tags:
        gn = tag_number(f"<gaussianNoise> of {where}", tags["gaussianNoise"], notes, low=0.0)
        if gn != 0.0:
            for model in models["accel"] + models["rate"]:
                model.gaussian_noise = gn
    s = ImuSettings(link=link, frame=tags.get("frameId") or link, topic=topic,
                    namespace=tags.get("robotNamespace"), period=period, hector=models,
                    bias_topic=tags.get("biasTopicName", f"{topic}/bias" if topic else ""),
                    service=tags.get("serviceName", f"{topic}/calibrate"))
    if "rpyOffset" in tags:
        s.rpy_offset = vector(tags["rpyOffset"], where, "rpyOffset")
    if "xyzOffset" in tags:
        s.xyz_offset = vector(tags["xyzOffset"], where, "xyzOffset")
    s.covariance = hector_covariance(models, 9.81)
    s.generator = generator
    known = {"bodyName", "frameId", "topicName", "biasTopicName", "serviceName", "gaussianNoise", "rpyOffset",
             "xyzOffset", "updatePeriod", "updateOffset"}
    for prefix in ("accel", "rate", "yaw"):
        known |= set(noise.hector_tag_names(prefix))
    s.unknown = []
    misread = sorted(t for t in tags if t.startswith("heading"))
    if misread:
        s.unknown.append(f"<{'>, <'.join(misread)}> are not hector tags (it reads yaw*): ignored, as by hector")
    s.unknown += [f"unknown tag <{t}> ignored" for t in sorted(set(tags) - known - set(_COMMON) - set(misread))]
    return s


def hector_covariance(models, gravity):
    """hector's diagonals: orientation (accel noise²/g² for roll and pitch, yaw noise²), rate, accel."""
    accel = [m.variance for m in models["accel"]]
    g2 = gravity * gravity
    orientation = (accel[0] / g2, accel[1] / g2, models["yaw"][0].variance) if g2 > 0 else (-1.0, -1.0,
                                                                                           models["yaw"][0].variance)
    return orientation, [m.variance for m in models["rate"]], accel


def hector_orientation_error(yaw_bias, accel_drift, gravity):
    """hector's pseudo-AHRS error quaternion: a yaw error, and roll/pitch from the accelerometer drift."""
    yaw = (0.0, 0.0, math.sin(yaw_bias / 2), math.cos(yaw_bias / 2))
    tilt = (0.5 * accel_drift[1] / gravity, -0.5 * accel_drift[0] / gravity, 0.0, 1.0) if gravity else \
        (0.0, 0.0, 0.0, 1.0)
    return qnormalize(qmul(yaw, tilt))


class Reading:
    """One IMU's measurement, noise and all (pure): run by the plugin with the physics' values."""

    def __init__(self, settings, gravity=9.81):
        self.s = settings
        self.gravity = abs(gravity)
        self.offset = rpy_quaternion(*settings.rpy_offset)
        self.reference = None

    def __call__(self, orientation, rate, accel, dt):
        """(orientation, rate, accel) as published, from the true world orientation of the frame and its
        rate and proper acceleration in that frame."""
        s = self.s
        if s.initial_reference:
            if self.reference is None:
                self.reference = orientation
            orientation = qmul(qconj(self.reference), orientation)
        orientation = qnormalize(qmul(self.offset, orientation))
        rate = noise.apply(s.sdf_rate, rate)
        accel = noise.apply(s.sdf_accel, accel)
        if s.hector is not None:
            models = s.hector
            accel = tuple(m(v, dt) for m, v in zip(models["accel"], accel))
            rate = tuple(m(v, dt) for m, v in zip(models["rate"], rate))
            models["yaw"][0].update(dt)
            yaw_bias = models["yaw"][0].offset + models["yaw"][0].current_drift
            drift = [m.offset + m.current_drift for m in models["accel"]]
            self.error = hector_orientation_error(yaw_bias, drift, self.gravity)
            orientation = qnormalize(qmul(self.error, orientation))
        elif s.gaussian_noise > 0:
            g = s.generator
            rate = tuple(v + g.gauss(0.0, s.gaussian_noise) for v in rate)
            accel = tuple(v + g.gauss(0.0, s.gaussian_noise) for v in accel)
            if s.orientation_noise:  # not renormalised, as the original
                orientation = tuple(v + g.gauss(0.0, s.gaussian_noise) for v in orientation)
        return orientation, rate, accel

    def bias(self):
        """hector's bias message values: (orientation error, rate bias, accel bias)."""
        m = self.s.hector
        return (getattr(self, "error", (0.0, 0.0, 0.0, 1.0)),
                tuple(x.offset + x.current_drift for x in m["rate"]),
                tuple(x.offset + x.current_drift for x in m["accel"]))

    def reset(self):
        self.reference = None
        if self.s.hector is not None:
            for models in self.s.hector.values():
                for model in models:
                    model.reset()


# ------------------------------------------------------------------------------------------ the plugin

class ImuPlugin(Plugin):
    def __init__(self, ctx, settings, filename, path):
        self.filename = filename
        # the IMU sensor's timer, and hector's UpdateTimer (multiples of its period), run on sim time from 0;
        # gazebo_ros_imu, a model plugin, counts from its Load
        self.sensor_timer = filename != MODEL_FILENAME
        self.ctx = ctx
        self.s = settings
        try:
            ctx.robot.link_motion(settings.link)
        except KeyError:
            raise PluginNotLoaded(f"IMU link '{settings.link}' is not a link of the model; the plugin is not "
                                  "loaded, as in Gazebo", ctx.model.source, path) from None
        self.reading = Reading(settings, getattr(ctx.robot, "gravity", -9.81))
        ns = ctx.plugin_namespace(settings.namespace)
        self.pub = ctx.publisher(join(ns, settings.topic), Imu)
        self.bias_pub = ctx.publisher(join(ns, settings.bias_topic), Imu) if settings.bias_topic else None
        # Noetic's gazebo_ros_imu and imu_sensor read no tf_prefix: their frame is the tag's, as written
        self.frame_id = ctx.clean_frame(settings.frame, path)
        self.service = None
        if settings.service:
            from std_srvs.srv import Empty, EmptyResponse

            self.service = ctx.service(join(ns, settings.service), Empty, lambda _req: EmptyResponse())
        self.last_time = None
        self.velocity = None
        for note in getattr(settings, "unknown", []):
            ctx.warnings.append(f"{path}: {note}")

    def publishers(self):
        return [self.pub] + ([self.bias_pub] if self.bias_pub is not None else [])

    def start(self, now):
        self.next, self.last_time, self.velocity = self.first_due(now, self.s.period), None, None

    def reset(self, now):
        self.reading.reset()
        self.start(now)

    def after_step(self, now, stamp, transforms):
        if not self.take_due(now, self.s.period):
            return
        if self.s.lazy and not self.pub.get_num_connections():
            self.velocity = None  # the next reading starts a fresh difference
            return
        dt = 0.0 if self.last_time is None else now - self.last_time
        self.last_time = now
        pose, rate, accel, self.velocity = self.ctx.robot.link_imu(self.s.link, self.velocity, dt, self.s.mount)
        orientation, rate, accel = self.reading(pose[1], rate, accel, dt)
        self.pub.publish(ros_msgs.imu(stamp, self.frame_id, orientation, rate, accel, self.s.covariance))
        if self.bias_pub is not None and self.bias_pub.get_num_connections():
            error, rate_bias, accel_bias = self.reading.bias()
            self.bias_pub.publish(ros_msgs.imu(stamp, self.frame_id, error, rate_bias, accel_bias))

    def summary(self):
        s = self.s
        rate = f"{round(1.0 / s.period, 3)} Hz" if s.period > 0 else "every step"
        return {summary_key("imu", self.pub.resolved_name): f"link {s.link}, frame {self.frame_id}, {rate}"}


def _wrap(ctx, fn, *args):
    try:
        return fn(*args)
    except ModelError as err:
        if err.source is None:
            raise type(err)(str(err), ctx.model.source) from None  # PluginNotLoaded stays what it is
        raise


def create_sensor(ctx, sensor, plugin, params):
    """``<sensor type="imu">`` + libgazebo_ros_imu_sensor.so."""
    settings = _wrap(ctx, sensor_settings, sensor, plugin, ctx.cfg.seed, sensor.path, ctx.warnings)
    return ImuPlugin(ctx, settings, SENSOR_FILENAME, sensor.path)


def create_model(ctx, element, path, params):
    """The model plugin libgazebo_ros_imu.so."""
    settings = _wrap(ctx, model_settings, element, ctx.cfg.seed, path, element.get("name") or path, ctx.warnings)
    return ImuPlugin(ctx, settings, MODEL_FILENAME, path)


def create_hector(ctx, element, path, params):
    """The model plugin libhector_gazebo_ros_imu.so."""
    settings = _wrap(ctx, hector_settings, element, ctx.cfg.seed, path, element.get("name") or path,
                     ctx.model.root, ctx.warnings)
    return ImuPlugin(ctx, settings, HECTOR_FILENAME, path)

