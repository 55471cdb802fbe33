"""Gazebo's camera and depth sensors (``<sensor type="camera|depth">``) as pure logic: SDF and plugin-tag
reading, CameraInfo as gazebo_ros computes it, the projection PyBullet needs, depth linearisation and the
depth -> point-cloud conversion of ``gazebo_ros_openni_kinect`` (pure: numpy only; the rendering is
``physics.World.render``). Sources: gazebo_ros_pkgs' gazebo_plugins (noetic) ``gazebo_ros_camera_utils.cpp`` and
``gazebo_ros_openni_kinect.cpp``, and PyBullet's ``getCameraImage``.

* Gazebo renders along the sensor's **+x** (y left, z up); the plugins publish in ``frameName`` as given and
  rotate nothing: a robot names a child ``*_optical_frame`` (rpy -pi/2 0 -pi/2) there itself.
* CameraInfo (GazeboRosCameraUtils): ``f = width / (2 tan(hfov/2))`` for fx and fy; ``cx = (width+1)/2``,
  ``cy = (height+1)/2`` unless the ``Cx``/``Cy`` tags say otherwise; ``K = [f 0 cx; 0 f cy; 0 0 1]``,
  ``R = I``, ``P = [f 0 cx' -f*hackBaseline; 0 f cy 0; 0 0 1 0]``, ``plumb_bob`` with ``D = [k1 k2 t1 t2 k3]``.
  Note that Gazebo's ``(width+1)/2`` is the image centre counted from 1: the rendered optical axis meets
  the image at ``(width-1)/2`` in the 0-based pixel indices of ROS images, one pixel left and up of what K
  says, in Gazebo as here (the same symmetric frustum).
* The point cloud (ROS 1 kinect plugin): organised ``h x w``, in the optical convention, ``x = d (i -
  (w-1)/2)/f``, ``y = d (j - (h-1)/2)/f``, ``z = d``; points with ``d`` outside ``(cutoff, cutoffMax)`` are
  NaN; colour bytes R, G, B in the ``rgb`` field's first three bytes (as the plugin writes them).
"""
import math
from dataclasses import dataclass, field

import numpy as np

from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import ConfigError
from diffbot_sim.transforms import qmul, quaternion_matrix, rpy_quaternion
from diffbot_sim.values import check_number, tag_number

CAMERA_TYPES = ("camera", "depth")
#: ``<image><format>`` -> ROS encoding (GazeboRosCameraUtils). Rendered here: these three.
ENCODINGS = {"R8G8B8": "rgb8", "B8G8R8": "bgr8", "L8": "mono8"}
#: Formats Gazebo knows and we render as rgb8 instead (with a warning).
OTHER_FORMATS = ("L16", "R16G16B16", "BAYER_RGGB8", "BAYER_BGGR8", "BAYER_GBRG8", "BAYER_GRBG8")


@dataclass
class CameraConfig:
    """One ``<sensor type="camera|depth">`` as its SDF says it (SDF defaults where it says nothing)."""

    name: str
    type: str
    path: str
    update_rate: float = 0.0  # Hz; 0: every physics step (Gazebo: as fast as it renders)
    pose: tuple[tuple[float, float, float], tuple[float, float, float]] = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    hfov: float = 1.047
    width: int = 320
    height: int = 240
    format: str = "R8G8B8"
    near: float = 0.1
    far: float = 100.0
    noise_mean: float = 0.0
    noise_stddev: float = 0.0
    warnings: list[str] = field(default_factory=list)

    @property
    def encoding(self):
        return ENCODINGS.get(self.format, "rgb8")


def _num(element, tag, where, default, notes, integer=False, **limits):
    """The number in ``element``'s ``<tag>`` (``default`` when absent or empty), read as Gazebo reads it."""
    el = element.find(tag) if element is not None else None
    if el is None or not tag_value(el):
        return default
    return tag_number(f"<{tag}> of {where}", tag_value(el), notes, integer=integer, **limits)


def parse_sensor(element, path, name=None):
    """A CameraConfig from a ``<sensor type="camera|depth">`` element (``path`` names it in errors).

    Raises:
        ConfigError: a value that cannot be used (naming the tag and ``path``).
    """
    cfg = CameraConfig(name=name if name is not None else (element.get("name") or ""),
                       type=(element.get("type") or "").strip(), path=path)
    notes = cfg.warnings
    cfg.update_rate = _num(element, "update_rate", path, 0.0, notes, low=0.0)
    pose = element.find("pose")
    if pose is not None and (pose.text or "").strip():
        parts = pose.text.split()
        if len(parts) != 6:
            raise ConfigError(f"<pose> of {path}", pose.text, "six numbers: x y z roll pitch yaw")
        values = [check_number(f"<pose> of {path}", p) for p in parts]
        cfg.pose = (tuple(values[:3]), tuple(values[3:]))
    camera = element.find("camera")
    if camera is None:
        cfg.warnings.append(f"{path}: no <camera> element; SDF defaults apply (320x240, hfov 1.047)")
        return cfg
    where = f"{path}/camera"
    cfg.hfov = _num(camera, "horizontal_fov", where, 1.047, notes, low=0.1, high=6.283)
    if cfg.hfov >= math.pi:
        raise ConfigError(f"<horizontal_fov> of {where}", cfg.hfov, "less than pi for a pinhole camera "
                          "(wider lenses are not simulated)")
    image = camera.find("image")
    cfg.width = _num(image, "width", f"{where}/image", 320, notes, integer=True, low=1)
    cfg.height = _num(image, "height", f"{where}/image", 240, notes, integer=True, low=1)
    fmt = image.find("format") if image is not None else None
    if fmt is not None and tag_value(fmt):
        cfg.format = tag_value(fmt)
        if cfg.format not in ENCODINGS:
            cfg.warnings.append(f"{where}/image/format: {cfg.format} is rendered as R8G8B8 (rgb8) here")
    clip = camera.find("clip")
    cfg.near = _num(clip, "near", f"{where}/clip", 0.1, notes, low=0.0, low_open=True)
    cfg.far = _num(clip, "far", f"{where}/clip", 100.0, notes, low=0.0, low_open=True)
    if cfg.far <= cfg.near:
        raise ConfigError(f"<clip><far> of {where}", cfg.far, f"a number > <clip><near> {cfg.near:g}")
    noise = camera.find("noise")
    if noise is not None:
        ntype = (noise.findtext("type") or "gaussian").strip().lower()
        if ntype not in ("gaussian", "none"):
            raise ConfigError(f"<type> of {where}/noise", ntype, "gaussian or none")
        if ntype == "gaussian":
            cfg.noise_mean = _num(noise, "mean", f"{where}/noise", 0.0, notes)
            cfg.noise_stddev = _num(noise, "stddev", f"{where}/noise", 0.0, notes, low=0.0)
    for tag in ("distortion", "lens", "intrinsics"):
        if camera.find(tag) is not None:
            cfg.warnings.append(f"{where}/{tag}: not simulated (an ideal pinhole image is rendered)")
    return cfg


# -- CameraInfo --------------------------------------------------------------------------------------------
def focal_length(width, hfov):
    """Gazebo's focal length [px] for both axes: ``width / (2 tan(hfov/2))``."""
    return width / (2.0 * math.tan(hfov / 2.0))


def vertical_fov_degrees(hfov, width, height):
    """PyBullet's projection angle: the vertical FOV in degrees, ``2 atan(tan(hfov/2) h/w)``."""
    return math.degrees(2.0 * math.atan(math.tan(hfov / 2.0) * height / width))


@dataclass
class Intrinsics:
    """CameraInfo's matrices, as gazebo_ros fills them (row-major lists)."""

    width: int
    height: int
    K: list[float]
    R: list[float]
    P: list[float]
    D: list[float]
    distortion_model: str = "plumb_bob"
    warnings: list[str] = field(default_factory=list)


def intrinsics(width, height, hfov, cx=0.0, cy=0.0, cx_prime=0.0, focal=0.0, hack_baseline=0.0,
               distortion=(0.0, 0.0, 0.0, 0.0, 0.0)):
    """K, R, P, D as GazeboRosCameraUtils computes them. ``cx``, ``cy``, ``cx_prime``, ``focal`` 0: computed
    (``(width+1)/2``, ``(height+1)/2``, ``cx``, from hfov); a ``focal`` that differs from the computed one is
    used with a warning, as Gazebo does. ``distortion`` is (k1, k2, k3, t1, t2); D is ``[k1 k2 t1 t2 k3]``."""
    warnings = []
    computed = focal_length(width, hfov)
    if focal == 0:
        focal = computed
    elif abs(focal - computed) > 1e-6 * computed:
        warnings.append(f"focalLength {focal:g} differs from the {computed:g} the horizontal_fov gives; "
                        "the image is rendered with the latter, CameraInfo says the former (as Gazebo)")
    cx = (width + 1) / 2.0 if cx == 0 else cx
    cy = (height + 1) / 2.0 if cy == 0 else cy
    cx_prime = cx if cx_prime == 0 else cx_prime
    k1, k2, k3, t1, t2 = distortion
    return Intrinsics(width, height,
                      K=[focal, 0.0, cx, 0.0, focal, cy, 0.0, 0.0, 1.0],
                      R=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
                      P=[focal, 0.0, cx_prime, -focal * hack_baseline, 0.0, focal, cy, 0.0, 0.0, 0.0, 1.0, 0.0],
                      D=[k1, k2, t1, t2, k3], warnings=warnings)


def project(K, point):
    """Pixel (u, v) that ``K`` assigns to a point (x, y, z) in the optical frame (z forward)."""
    x, y, z = point
    return K[0] * x / z + K[2], K[4] * y / z + K[5]


def body_to_optical(point):
    """A point in a Gazebo camera's body frame (x forward, y left, z up) in its optical frame."""
    x, y, z = point
    return -y, -z, x


# -- rendering ---------------------------------------------------------------------------------------------
def sensor_view(link_pose, pose):
    """World pose (position, quaternion) of a sensor at ``pose`` (xyz, rpy) in a link at ``link_pose``."""
    position, quat = link_pose
    rot = quaternion_matrix(quat)
    offset = rot @ np.asarray(pose[0], float)
    q = qmul(quat, rpy_quaternion(*pose[1]))
    return tuple(float(v) for v in np.asarray(position, float) + offset), q


def look_at(view_pose):
    """(eye, target, up) for an OpenGL view matrix of a camera looking along its frame's +x, up its +z."""
    position, quat = view_pose
    rot = quaternion_matrix(quat)
    eye = np.asarray(position, float)
    return tuple(eye), tuple(eye + rot[:, 0]), tuple(rot[:, 2])


def linear_depth(buffer, near, far):
    """OpenGL depth-buffer values (0..1) -> z-depth along the optical axis [m] (float32), NaN where nothing
    was drawn (the cleared value 1) or at/beyond ``far``: ``far near / (far - (far - near) buffer)``."""
    b = np.asarray(buffer, np.float64)
    depth = (far * near / (far - (far - near) * b)).astype(np.float32)
    depth[(b >= 1.0) | (depth >= far)] = np.nan
    return depth


def cutoff(depth, low, high):
    """Depth [m] with values outside (low, high) made NaN (openni_kinect's depth image and cloud)."""
    out = np.array(depth, np.float32, copy=True)
    with np.errstate(invalid="ignore"):
        out[~((out > low) & (out < high))] = np.nan
    return out


def to_encoding(rgb, encoding):
    """An (h, w, 3) uint8 RGB image in ``encoding`` (rgb8, bgr8 or mono8), C-contiguous."""
    if encoding == "bgr8":
        return np.ascontiguousarray(rgb[:, :, ::-1])
    if encoding == "mono8":
        grey = rgb.astype(np.float32) @ np.array([0.299, 0.587, 0.114], np.float32)
        return np.ascontiguousarray(np.clip(np.rint(grey), 0, 255).astype(np.uint8))
    return np.ascontiguousarray(rgb)


def image_noise(rgb, mean, stddev, rng):
    """Gazebo's per-pixel Gaussian image noise: each channel value in [0, 1] + N(mean, stddev), clamped."""
    if not (mean or stddev):
        return rgb
    noisy = rgb.astype(np.float32) / 255.0 + rng.normal(mean, stddev, rgb.shape).astype(np.float32)
    return np.clip(np.rint(noisy * 255.0), 0, 255).astype(np.uint8)


# -- point cloud -------------------------------------------------------------------------------------------
def cloud_points(depth, focal):
    """(h, w, 3) float32 points in the optical frame from a z-depth image, as gazebo_ros_openni_kinect:
    ``x = d (i - (w-1)/2) / f``, ``y = d (j - (h-1)/2) / f``, ``z = d``; a NaN depth gives a NaN point."""
    d = np.asarray(depth, np.float32)
    h, w = d.shape
    i = (np.arange(w, dtype=np.float32) - 0.5 * (w - 1)) / focal if w > 1 else np.zeros(1, np.float32)
    j = (np.arange(h, dtype=np.float32) - 0.5 * (h - 1)) / focal if h > 1 else np.zeros(1, np.float32)
    out = np.empty((h, w, 3), np.float32)
    out[:, :, 0] = d * i[None, :]
    out[:, :, 1] = d * j[:, None]
    out[:, :, 2] = d
    return out


#: PointCloud2 layout of ``setPointCloud2FieldsByString(2, "xyz", "rgb")``: (name, offset); FLOAT32, count 1.
CLOUD_FIELDS = (("x", 0), ("y", 4), ("z", 8), ("rgb", 16))
CLOUD_POINT_STEP = 32
_CLOUD_DTYPE = np.dtype({"names": ["xyz", "rgb"], "formats": [("<f4", 3), ("u1", 3)], "offsets": [0, 16],
                         "itemsize": CLOUD_POINT_STEP})


def cloud_bytes(points, rgb):
    """The data of an organised PointCloud2 (32-byte points: x y z float32, pad, r g b bytes, pad)."""
    h, w, _ = points.shape
    buf = np.zeros(h * w, _CLOUD_DTYPE)
    buf["xyz"] = points.reshape(-1, 3)
    buf["rgb"] = np.asarray(rgb, np.uint8).reshape(-1, 3)
    return buf.tobytes()


# -- plugin tags -------------------------------------------------------------------------------------------
#: ROS 1 camelCase and ROS 2 snake_case tags of the camera plugins -> canonical key.
PLUGIN_TAGS = {
    "robotNamespace": "namespace", "cameraName": "camera_name", "camera_name": "camera_name",
    "imageTopicName": "image_topic", "cameraInfoTopicName": "info_topic", "frameName": "frame",
    "frame_name": "frame", "updateRate": "update_rate", "update_rate": "update_rate",
    "hackBaseline": "hack_baseline", "hack_baseline": "hack_baseline", "focalLength": "focal_length",
    "focal_length": "focal_length", "Cx": "cx", "cx": "cx", "Cy": "cy", "cy": "cy", "CxPrime": "cx_prime",
    "distortionK1": "k1", "distortionK2": "k2", "distortionK3": "k3", "distortionT1": "t1",
    "distortionT2": "t2", "depthImageTopicName": "depth_topic",
    "depthImageCameraInfoTopicName": "depth_info_topic", "pointCloudTopicName": "points_topic",
    "pointCloudCutoff": "cutoff", "pointCloudCutoffMax": "cutoff_max", "min_depth": "cutoff",
    "max_depth": "cutoff_max", "useDepth16UC1Format": "depth16",
}
#: Tags accepted and without effect here.
IGNORED_TAGS = ("alwaysOn", "always_on", "triggerTopicName", "borderCrop", "border_crop", "autoDistortion",
                "imageTopicName_", "ros", "pointCloudTopicName_", "triggered")
NUMERIC = ("update_rate", "hack_baseline", "focal_length", "cx", "cy", "cx_prime", "k1", "k2", "k3", "t1",
           "t2", "cutoff", "cutoff_max")


@dataclass
class PluginTags:
    values: dict[str, object] = field(default_factory=dict)
    remap: dict[str, str] = field(default_factory=dict)  # ROS 2 <remapping> from -> to
    dialect: str = "ros1"
    unknown: list[str] = field(default_factory=list)


def read_plugin(element, path):
    """The camera/depth plugin's tags in canonical keys (numbers converted), ROS 2 ``<ros>`` included.

    Raises:
        ConfigError: a numeric tag that is not a number.
    """
    tags = PluginTags()
    if element is None:
        return tags
    for child in element:
        key = PLUGIN_TAGS.get(child.tag)
        if child.tag in ("camera_name", "frame_name", "ros", "hack_baseline", "min_depth", "max_depth"):
            tags.dialect = "ros2"
        if key is None:
            if child.tag not in IGNORED_TAGS:
                tags.unknown.append(child.tag)
            continue
        text = tag_value(child)
        if key in NUMERIC:
            tags.values[key] = check_number(f"<{child.tag}> of {path}", text) if text else 0.0
        elif key == "depth16":
            tags.values[key] = text.lower() in ("true", "1")
        else:
            tags.values[key] = text
    ros = element.find("ros")
    if ros is not None:
        ns = ros.findtext("namespace")
        if ns and ns.strip():
            tags.values["namespace"] = ns.strip()
        for child in ros:
            rules = [child.text or ""] if child.tag == "remapping" else (
                (child.text or "").split() if child.tag == "argument" else [])
            for rule in rules:
                src, sep, dst = rule.strip().partition(":=")
                if sep and dst.strip():
                    tags.remap[src.strip().lstrip("~").lstrip("/")] = dst.strip()
    return tags


def remapped(tags, name):
    """A ROS 2 topic name after the plugin's ``<remapping>`` rules (the rule's left side as written,
    ``~/`` stripped); unchanged when no rule names it."""
    return tags.remap.get(name, name)


def optional(value):
    return None if value in (None, "") else value


def effective_period(sensor_rate, plugin_rate):
    """Seconds between images: the sensor's update_rate, throttled by the plugin's updateRate (0: none);
    0 means every physics step."""
    rates = [r for r in (sensor_rate, plugin_rate or 0.0) if r and r > 0]
    return 1.0 / min(rates) if rates else 0.0


def describe(cfg: CameraConfig, renderer: str | None = None):
    text = f"{cfg.width}x{cfg.height} hfov {cfg.hfov:g} clip {cfg.near:g}-{cfg.far:g} m"
    return text + (f" ({renderer})" if renderer else "")
