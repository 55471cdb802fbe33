"""Sensor noise as Gazebo classic and its plugins add it (pure: no rospy, no pybullet).

Three families:

* SDF ``<noise type="gaussian|gaussian_quantized|none">`` (``mean``, ``stddev``, ``bias_mean``,
  ``bias_stddev``, ``precision``; SDF 1.5+ per axis, or SDF 1.4's ``<noise><type>`` with ``<rate>`` and
  ``<accel>`` blocks): :class:`Gaussian`. As Gazebo's GaussianNoiseModel, the bias is drawn once,
  N(bias_mean, bias_stddev), with a random sign; each reading gets value + N(mean, stddev) + bias, rounded to
  ``precision`` when > 0 (``gaussian_quantized``; a precision on plain ``gaussian`` is honoured too).
* A plugin's ``<gaussianNoise>`` (gazebo_ros_imu, imu_sensor, p3d): N(0, sigma) per value,
  :class:`Gaussian` with only a stddev.
* hector's sensor model (``<PREFIX>Offset``, ``Drift``, ``DriftFrequency``, ``GaussianNoise``,
  ``ScaleError``): :class:`HectorModel`: value * scale + offset + drift(t) + N(0, gaussian), the drift a
  first-order Gauss-Markov process of standard deviation ``drift`` and frequency ``driftFrequency`` (default
  1/3600 Hz), here discretised exactly (hector scales its driving noise by dt rather than sqrt(dt)).

Every generator is seeded from the node's ``~seed`` (default 0) and the sensor's name (:func:`rng`), so two runs
give the same readings and two sensors never share a stream.
"""
import math
import random
import zlib

from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.values import tag_number

SDF_KINDS = ("none", "gaussian", "gaussian_quantized")


def rng(seed, name):
    """A generator for sensor ``name`` under the node's ``seed`` (stable across runs and Python versions)."""
    return random.Random((int(seed) & 0xFFFFFFFF) << 32 | zlib.crc32(str(name).encode("utf-8")))


class Gaussian:
    """value + N(mean, stddev) + bias (drawn once, random sign), rounded to ``precision`` if > 0."""

    def __init__(self, generator, mean=0.0, stddev=0.0, bias_mean=0.0, bias_stddev=0.0, precision=0.0):
        self.rng = generator
        self.mean, self.stddev, self.precision = float(mean), float(stddev), float(precision)
        self.bias_mean, self.bias_stddev = float(bias_mean), float(bias_stddev)
        self.bias = 0.0
        self.reset()

    def reset(self):
        bias = self.bias_mean + (self.rng.gauss(0.0, self.bias_stddev) if self.bias_stddev > 0 else 0.0)
        self.bias = -bias if self.rng.random() < 0.5 else bias

    @property
    def variance(self):
        return self.stddev ** 2

    @property
    def active(self):
        return bool(self.stddev or self.mean or self.bias or self.precision)

    def __call__(self, value):
        out = value + self.mean + self.bias
        if self.stddev > 0:
            out += self.rng.gauss(0.0, self.stddev)
        if self.precision > 0:
            out = round(out / self.precision) * self.precision
        return out


def plain(generator, stddev):
    """A plugin's ``<gaussianNoise>``: N(0, stddev), no bias."""
    return Gaussian(generator, stddev=stddev)


def _float(element, tag, where, notes, default=0.0):
    """The number in ``element``'s ``<tag>``, read as Gazebo reads it (its leading number)."""
    child = element.find(tag)
    if child is None:
        return default
    text = (child.text or "").strip()
    try:
        return tag_number(f"<{tag}> of {where}", text, notes)
    except ConfigError:
        raise ModelError(f"<{tag}> must be a finite number, got '{text}'", where) from None


def sdf_noise(element, generator, where, notes=None):
    """A Gaussian from an SDF ``<noise>`` element (1.5+ with a ``type`` attribute, or a 1.4 block with a
    ``<type>`` child); None for no element or type ``none``. What Gazebo drops after a number is named in
    ``notes``.

    Raises:
        ModelError: an unknown type or a value that is not a number (naming ``where``).
    """
    notes = notes if notes is not None else []
    if element is None:
        return None
    kind = element.get("type")
    if kind is None:
        child = element.find("type")
        kind = (child.text or "").strip() if child is not None else "gaussian"
    if kind not in SDF_KINDS:
        raise ModelError(f"noise type '{kind}' is not one of {', '.join(SDF_KINDS)}", where)
    if kind == "none":
        return None
    stddev = _float(element, "stddev", where, notes)
    bias_stddev = _float(element, "bias_stddev", where, notes)
    if stddev < 0 or bias_stddev < 0:
        raise ModelError("noise <stddev> and <bias_stddev> cannot be negative", where)
    return Gaussian(generator, _float(element, "mean", where, notes), stddev,
                    _float(element, "bias_mean", where, notes), bias_stddev,
                    max(_float(element, "precision", where, notes), 0.0))


def apply(models, values):
    """Each value through its model (None: unchanged)."""
    return tuple(v if m is None else m(v) for m, v in zip(models, values))


class HectorModel:
    """hector_gazebo_plugins' SensorModel for one axis: value * scale_error + offset + drift + N(0, noise)."""

    def __init__(self, generator, offset=0.0, drift=0.0, drift_frequency=1.0 / 3600.0, gaussian_noise=0.0,
                 scale_error=1.0):
        self.rng = generator
        self.offset, self.drift, self.drift_frequency = float(offset), float(drift), float(drift_frequency)
        self.gaussian_noise, self.scale_error = float(gaussian_noise), float(scale_error)
        self.current_drift = 0.0
        self.current_error = 0.0

    def reset(self):
        self.current_drift = self.current_error = 0.0

    def update(self, dt):
        """Advance the drift by ``dt`` s and draw a new error (offset + drift + white noise)."""
        if dt > 0 and self.drift > 0:
            if self.drift_frequency > 0:
                alpha = math.exp(-dt * self.drift_frequency)
                self.current_drift = alpha * self.current_drift + \
                    math.sqrt(1.0 - alpha * alpha) * self.rng.gauss(0.0, self.drift)
            else:  # no decay: a random walk of drift [unit/sqrt(s)]
                self.current_drift += math.sqrt(dt) * self.rng.gauss(0.0, self.drift)
        white = self.rng.gauss(0.0, self.gaussian_noise) if self.gaussian_noise > 0 else 0.0
        self.current_error = self.offset + self.current_drift + white
        return self.current_error

    def __call__(self, value, dt):
        return value * self.scale_error + self.update(dt)

    @property
    def variance(self):
        return self.gaussian_noise ** 2


def _numbers(text, where, tag, count):
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        raise ModelError(f"<{tag}> must be {count} number(s), got '{text}'", where) from None
    if len(values) == 1:
        values *= count
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise ModelError(f"<{tag}> must be {count} finite number(s), got '{text}'", where)
    return values


def hector_models(tags, prefix, generator, where, axes=3):
    """``axes`` HectorModels from a plugin's tags ({tag: text}) with ``prefix`` (``accel``, ``rate``,
    ``yaw``, ``""`` for GPS position -> ``offset``, ``gaussianNoise``..., ``velocity``). A vector tag takes
    three numbers or one for all axes."""
    def name(field):
        return (prefix + field[0].upper() + field[1:]) if prefix else field

    values = {}
    for field, default in (("offset", 0.0), ("drift", 0.0), ("driftFrequency", 1.0 / 3600.0),
                           ("gaussianNoise", 0.0), ("scaleError", 1.0)):
        tag = name(field)
        values[field] = _numbers(tags[tag], where, tag, axes) if tag in tags else [default] * axes
    return [HectorModel(generator, values["offset"][i], values["drift"][i], values["driftFrequency"][i],
                        values["gaussianNoise"][i], values["scaleError"][i]) for i in range(axes)]


def hector_tag_names(prefix):
    """The five tags hector reads for one model."""
    fields = ("offset", "drift", "driftFrequency", "gaussianNoise", "scaleError")
    return tuple((prefix + f[0].upper() + f[1:]) if prefix else f for f in fields)
