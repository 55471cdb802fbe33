"""Gazebo's ray sensor (``<sensor type="ray">`` / ``gpu_ray``) as pure logic: SDF reading, ray geometry and
what Gazebo 7+ turns the hit distances into (pure: numpy only; the casting is ``physics.World.ray_batch``).

What Gazebo does, and so what this does (sources: gazebo_ros_pkgs' gazebo_plugins (noetic) ``gazebo_ros_laser.cpp``,
gazebo-classic's ray sensor, sdformat's ``ray.sdf`` and ``noise.sdf``):

* ``rangeCount = int(samples * resolution)`` per axis; ``angle_increment = (max - min) / (rangeCount - 1)``,
  so the first and last beams sit exactly on ``min_angle`` and ``max_angle``; beams go counter-clockwise
  (REP 103) from ``min_angle``; with vertical samples the scan is ``rows x rangeCount`` long, row by row.
  Only ``samples`` physical rays are cast; when ``resolution`` is not 1 the outputs are a bilinear
  interpolation of the neighbouring rays (Gazebo has no averaging branch, despite the schema's words).
* A ray runs from ``range_min`` to ``range_max`` along its direction (an object closer than ``range_min``
  is not seen, as in Gazebo); its raw range is ``min + fraction * (max - min)``, ``max`` for a miss.
* REP 117 mask: ``raw >= max`` reads +inf, ``raw <= min`` reads -inf. Noise (``out = in + bias + N(mean,
  stddev)``, bias drawn once with a random sign) only on in-range readings, then clamped to [min, max].
  ``<range><resolution>`` is never applied (Gazebo returns it but does not quantise).
* Intensity: the ``laser_retro`` of the hit collision, 0 on a miss.
"""
import math
import zlib
from dataclasses import dataclass, field

import numpy as np

from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import ConfigError
from diffbot_sim.transforms import quaternion_matrix, rays_along, rpy_matrix
from diffbot_sim.values import check_bool, check_number, tag_number


@dataclass
class ScanAxis:
    """``<horizontal>`` or ``<vertical>`` of ``<ray><scan>`` (SDF defaults; horizontal samples default 640)."""

    samples: int = 1
    resolution: float = 1.0
    min_angle: float = 0.0
    max_angle: float = 0.0

    @property
    def count(self):
        """Readings along this axis: Gazebo's ``(int)(samples * resolution)`` (at least 1)."""
        return max(1, int(self.samples * self.resolution))

    @property
    def increment(self):
        """Angle between readings [rad]: ``(max - min) / (count - 1)``; 0 for a single reading."""
        return (self.max_angle - self.min_angle) / (self.count - 1) if self.count > 1 else 0.0

    def ray_angles(self):
        """Angles of the rays actually cast: ``samples`` from min to max; a single ray points along the
        axis (angle 0), as Gazebo's MultiRayShape casts it."""
        if self.samples == 1:
            return np.zeros(1)
        return self.min_angle + np.arange(self.samples) * (self.max_angle - self.min_angle) / (self.samples - 1)

    def reading_angles(self):
        return self.min_angle + np.arange(self.count) * self.increment


@dataclass
class Noise:
    """``<ray><noise>``: Gaussian ``in + bias + N(mean, stddev)`` (bias ~ N(bias_mean, bias_stddev) drawn
    once, sign flipped with probability 1/2); ``precision`` > 0 quantises the output. type ``none``: off."""

    type: str = "none"
    mean: float = 0.0
    stddev: float = 0.0
    bias_mean: float = 0.0
    bias_stddev: float = 0.0
    precision: float = 0.0

    @property
    def active(self):
        return self.type == "gaussian" and (self.mean or self.stddev or self.bias_mean or self.bias_stddev)


Pose6 = tuple[tuple[float, float, float], tuple[float, float, float]]


@dataclass
class RayConfig:
    """One ray sensor as its SDF says it (SDF defaults where it says nothing)."""

    name: str
    type: str  # ray or gpu_ray (also lidar / gpu_lidar, SDF 1.6's later spelling)
    path: str
    update_rate: float = 0.0  # Hz; 0: every step
    always_on: bool = False
    visualize: bool = False
    pose: Pose6 = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))  # xyz, rpy in the link frame
    has_pose: bool = False
    horizontal: ScanAxis = field(default_factory=lambda: ScanAxis(samples=640))
    vertical: ScanAxis = field(default_factory=ScanAxis)
    range_min: float = 0.0
    range_max: float = 0.0
    range_resolution: float = 0.0
    noise: Noise = field(default_factory=Noise)
    warnings: list[str] = field(default_factory=list)

    @property
    def rays(self):
        """Rays cast per scan."""
        return self.horizontal.samples * self.vertical.samples

    @property
    def readings(self):
        """Values per scan (LaserScan ``ranges`` length)."""
        return self.horizontal.count * self.vertical.count


RAY_TYPES = ("ray", "gpu_ray", "lidar", "gpu_lidar")


def _child(element, *names):
    for name in names:
        found = element.find(name)
        if found is not None:
            return found
    return None


def _num(element, tag, where, default, notes, integer=False, **limits):
    """The number in ``element``'s ``<tag>`` (``default`` when absent), read as Gazebo reads it."""
    el = element.find(tag) if element is not None else None
    if el is None:
        return default
    return tag_number(f"<{tag}> of {where}", tag_value(el), notes, integer=integer, **limits)


def _pose(text, where):
    parts = text.split()
    if len(parts) != 6:
        raise ConfigError(f"<pose> of {where}", text, "six numbers: x y z roll pitch yaw")
    values = [check_number(f"<pose> of {where}", p) for p in parts]
    return tuple(values[:3]), tuple(values[3:])


def _axis(element, where, default_samples, notes):
    axis = ScanAxis(samples=default_samples)
    if element is None:
        return axis
    axis.samples = _num(element, "samples", where, default_samples, notes, integer=True, low=1)
    axis.resolution = _num(element, "resolution", where, 1.0, notes, low=0.0, low_open=True)
    axis.min_angle = _num(element, "min_angle", where, 0.0, notes)
    axis.max_angle = _num(element, "max_angle", where, 0.0, notes)
    if axis.max_angle < axis.min_angle:
        raise ConfigError(f"<max_angle> of {where}", axis.max_angle, f"a number >= <min_angle> {axis.min_angle:g}")
    return axis


def parse_sensor(element, path, name=None):
    """A RayConfig from a ``<sensor type="ray|gpu_ray">`` element (``path`` names it in errors).

    Raises:
        ConfigError: a tag whose value cannot be used (naming the tag and ``path``).
    """
    stype = (element.get("type") or "").strip()
    cfg = RayConfig(name=name if name is not None else (element.get("name") or ""), type=stype, path=path)
    notes = cfg.warnings
    cfg.update_rate = _num(element, "update_rate", path, 0.0, notes, low=0.0)
    for tag in ("always_on", "visualize"):
        el = element.find(tag)
        if el is not None:
            setattr(cfg, tag, check_bool(f"<{tag}> of {path}", tag_value(el)))
    pose = element.find("pose")
    if pose is not None and (pose.text or "").strip():
        cfg.pose = _pose(pose.text, path)
        cfg.has_pose = True
    ray = _child(element, "ray", "lidar")
    if ray is None:
        cfg.warnings.append(f"{path}: no <ray> element; SDF defaults apply (640 rays at angle 0, range 0 to 0)")
        ray = element.makeelement("ray", {})
    where = f"{path}/{ray.tag}"
    scan = ray.find("scan")
    cfg.horizontal = _axis(scan.find("horizontal") if scan is not None else None, f"{where}/scan/horizontal", 640,
                           notes)
    cfg.vertical = _axis(scan.find("vertical") if scan is not None else None, f"{where}/scan/vertical", 1, notes)
    rng = ray.find("range")
    cfg.range_min = _num(rng, "min", f"{where}/range", 0.0, notes, low=0.0)
    cfg.range_max = _num(rng, "max", f"{where}/range", 0.0, notes, low=0.0)
    cfg.range_resolution = _num(rng, "resolution", f"{where}/range", 0.0, notes, low=0.0)
    if cfg.range_max <= cfg.range_min:
        raise ConfigError(f"<range><max> of {where}", cfg.range_max, f"a number > <range><min> {cfg.range_min:g}")
    noise = ray.find("noise")
    if noise is not None:
        nwhere = f"{where}/noise"
        type_el = noise.find("type")
        ntype = (tag_value(type_el) if type_el is not None else "none").strip().lower() or "none"
        if ntype not in ("none", "gaussian"):
            raise ConfigError(f"<type> of {nwhere}", ntype, "gaussian or none (a ray sensor's noise types)")
        cfg.noise = Noise(ntype, _num(noise, "mean", nwhere, 0.0, notes),
                          _num(noise, "stddev", nwhere, 0.0, notes, low=0.0),
                          _num(noise, "bias_mean", nwhere, 0.0, notes),
                          _num(noise, "bias_stddev", nwhere, 0.0, notes, low=0.0),
                          _num(noise, "precision", nwhere, 0.0, notes, low=0.0))
    if stype.startswith("gpu"):
        cfg.warnings.append(f"{path}: a {stype} sensor is cast against collision shapes here (Gazebo's GPU "
                            "ray sees visuals)")
    return cfg


def mounted_pose(cfg, model, link):
    """Where ray sensor ``cfg`` sits in the frame of ``link`` (a link of RobotModel ``model``), as Gazebo
    places it: its ``<pose>``, or the link's own frame when the link is lumped into its parent by a fixed
    joint (sdformat's URDF reader then replaces the sensor's pose). Returns (pose (xyz, rpy), a warning or
    None): the warning says a non-zero ``<pose>`` was dropped.

    Raises:
        ConfigError: ``link`` is not a link of the model (a sensor is mounted on a link).
    """
    if not link or link not in model.links:
        raise ConfigError(f"<gazebo reference> of {cfg.path}", link,
                          "the name of a link of the model (a sensor is mounted on a link)")
    parent_joint = next((j for j in model.joints.values() if j.child == link), None)
    if parent_joint is None or parent_joint.type != "fixed":
        return cfg.pose, None
    warning = None
    if cfg.has_pose and any(v != 0.0 for v in cfg.pose[0] + cfg.pose[1]):
        warning = (f"{cfg.path}: <pose> dropped: link '{link}' is lumped into its parent by a fixed joint, and "
                   "Gazebo then puts the sensor at the link's frame")
    return ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)), warning


# -- geometry -----------------------------------------------------------------------------------------------
def ray_directions(cfg):
    """Unit vectors of the cast rays in the sensor frame, (rays, 3): vertical rows of horizontal sweeps.
    Yaw counter-clockwise about z from x; a positive vertical angle points up (Gazebo: pitch about -y)."""
    yaw = cfg.horizontal.ray_angles()
    pitch = cfg.vertical.ray_angles()
    p, y = np.meshgrid(pitch, yaw, indexing="ij")
    dirs = np.stack([np.cos(p) * np.cos(y), np.cos(p) * np.sin(y), np.sin(p)], axis=-1)
    return np.ascontiguousarray(dirs.reshape(-1, 3))


def sensor_pose(link_position, link_quaternion, pose):
    """World (position (3,), rotation (3, 3)) of a sensor at ``pose`` (xyz, rpy) in a link's frame."""
    rot = quaternion_matrix(link_quaternion)
    position = np.asarray(link_position, float) + rot @ np.asarray(pose[0], float)
    return position, rot @ rpy_matrix(pose[1])


def world_rays(position, rotation, directions, range_min, range_max):
    """Start and end points (each (rays, 3), C-contiguous float64) of rays from ``range_min`` to
    ``range_max`` along ``directions`` (sensor frame) of a sensor at ``position``/``rotation``."""
    return rays_along(position, rotation, directions, range_min, range_max)


def raw_ranges(fractions, range_min, range_max):
    """Gazebo's ray lengths from the sensor origin: ``min + f * (max - min)`` (a miss, f = 1, is ``max``)."""
    return range_min + np.asarray(fractions, float) * (range_max - range_min)


def _resample(values, rows, cols, out_rows, out_cols):
    """Bilinear resampling of a (rows, cols) grid of ray values to (out_rows, out_cols) readings, the end
    readings on the end rays (Gazebo's interpolation when ``resolution`` is not 1)."""
    grid = np.asarray(values, float).reshape(rows, cols)
    if cols != out_cols:
        x = np.linspace(0.0, cols - 1, out_cols) if out_cols > 1 else np.zeros(1)
        grid = np.stack([np.interp(x, np.arange(cols), row) for row in grid])
    if rows != out_rows:
        y = np.linspace(0.0, rows - 1, out_rows) if out_rows > 1 else np.zeros(1)
        grid = np.stack([np.interp(y, np.arange(rows), col) for col in grid.T], axis=1)
    return grid.reshape(-1)


def noise_rng(seed, name):
    """The random generator of one sensor: the simulator's ``~seed`` and the sensor's name, so two runs
    give identical noise and two sensors differ."""
    return np.random.default_rng([int(seed) & 0xFFFFFFFF, zlib.crc32(name.encode("utf-8"))])


class ScanProcessor:
    """Hit fractions and retro values of one scan's rays -> Gazebo 7+'s ranges and intensities."""

    def __init__(self, cfg, rng):
        self.cfg = cfg
        self.rng = rng
        noise = cfg.noise
        self.bias = 0.0
        if noise.active and (noise.bias_mean or noise.bias_stddev):
            bias = rng.normal(noise.bias_mean, noise.bias_stddev) if noise.bias_stddev > 0 else noise.bias_mean
            self.bias = -bias if rng.uniform() < 0.5 else bias

    def process(self, fractions, retro=None):
        """(ranges, intensities), float64 arrays of ``cfg.readings`` values, row by row."""
        cfg = self.cfg
        h, v = cfg.horizontal, cfg.vertical
        raw = raw_ranges(fractions, cfg.range_min, cfg.range_max)
        retro = np.zeros(len(raw)) if retro is None else np.where(np.asarray(fractions) < 1.0, retro, 0.0)
        if (h.count, v.count) != (h.samples, v.samples):
            raw = _resample(raw, v.samples, h.samples, v.count, h.count)
            retro = _resample(retro, v.samples, h.samples, v.count, h.count)
        return mask_and_noise(raw, cfg.range_min, cfg.range_max, cfg.noise, self.rng, self.bias), retro

    def noisy(self, values):
        return mask_and_noise(values, self.cfg.range_min, self.cfg.range_max, self.cfg.noise, self.rng, self.bias)


def mask_and_noise(raw, range_min, range_max, noise=None, rng=None, bias=0.0):
    """REP 117 mask (``>= max``: +inf, ``<= min``: -inf), then noise on the in-range readings only, then
    clamped to [min, max] (a noisy hit may read exactly min or max; a miss stays +inf)."""
    ranges = np.array(raw, dtype=float)
    over, under = ranges >= range_max, ranges <= range_min
    ranges[over] = math.inf
    ranges[under] = -math.inf
    inside = ~(over | under)
    if noise is not None and noise.active and rng is not None and inside.any():
        values = ranges[inside] + bias + rng.normal(noise.mean, noise.stddev, int(inside.sum()))
        if noise.precision > 0:
            values = np.round(values / noise.precision) * noise.precision
        ranges[inside] = np.clip(values, range_min, range_max)
    return ranges


def sonar_range(raw, range_max, stddev=0.0, rng=None):
    """gazebo_ros_range's reading: the minimum raw ray length (a miss counts as ``max``); Gaussian noise
    (mean 0) only when that is below ``max``, then at most ``max``. Never inf: no return reads ``max``."""
    value = float(np.min(raw)) if len(raw) else range_max
    if value < range_max and stddev > 0 and rng is not None:
        value = min(value + float(rng.normal(0.0, stddev)), range_max)
    return value


def scan_points(ranges, intensities, cfg, min_intensity=0.0):
    """Points of a scan in the sensor frame, as gazebo_ros (ROS 2) converts it: (n, 4) float32 of x, y, z,
    intensity (clipped up to ``min_intensity``); non-finite ranges dropped."""
    h, v = cfg.horizontal, cfg.vertical
    az = np.tile(h.reading_angles(), v.count)
    incl = np.repeat(v.reading_angles() if v.count > 1 else np.zeros(1), h.count)
    r = np.asarray(ranges, float)
    keep = np.isfinite(r)
    r, az, incl = r[keep], az[keep], incl[keep]
    out = np.empty((len(r), 4), dtype=np.float32)
    out[:, 0] = r * np.cos(incl) * np.cos(az)
    out[:, 1] = r * np.cos(incl) * np.sin(az)
    out[:, 2] = r * np.sin(incl)
    out[:, 3] = np.maximum(np.asarray(intensities, float)[keep], min_intensity)
    return out
