"""steer_bot_hardware_gazebo/SteerBotHardwareGazebo (CIR-KIT/steer_drive_ros, melodic-devel), pure: its YAML
and its mapping of a bicycle model onto a four-wheel car.

A car-like robot's ``robotSimType`` names this hardware when its controller (ackermann_steering_controller,
steer_drive_controller) drives a bicycle model: one ``rear_wheel`` velocity joint and one ``front_steer``
position joint. The hardware maps them onto the real wheels and the steering linkage (upstream's
``writeSim``):

* every virtual wheel, rear and front, right and left, turns at the ``rear_wheel`` command (Gazebo's
  ``SetVelocity``: no differential; the wheels of a turning car scrub);
* the two virtual front steers are set to the linkage's angles: with ``enable_ackermann_link`` (default true)
  ``atan2(2h·tan δ, 2h ± (w/2)·tan δ)`` (+ right, - left; ``h``/``w`` are ``wheel_separation_h``/``_w``),
  otherwise δ on the right and **2·δ on the left** (upstream's parallel link, as written);
* what the controller reads: ``rear_wheel`` is the mean of the virtual rear wheels (position, velocity),
  ``front_steer``'s position is its own last command (not the measured angle).

The YAML lives under ``<robotNamespace>/steer_bot_hardware_gazebo/``; PID gains (``p`` required) under
``<robotNamespace>/gains/<virtual rear wheel>``: upstream's initSim fails without them, though its wheels are
driven by SetVelocity and the gains are never used.
"""
import math
from dataclasses import dataclass

from diffbot_sim.errors import ConfigError

SIM_TYPE = "steer_bot_hardware_gazebo/SteerBotHardwareGazebo"
PARAM_NS = "steer_bot_hardware_gazebo"
RIGHT, LEFT = 0, 1  # upstream's INDEX_RIGHT, INDEX_LEFT: every virtual list is [right, left]


@dataclass(frozen=True)
class SteerBotConfig:
    """SteerBotHardwareGazebo's parameters; each virtual pair is (right, left)."""

    rear_wheel: str
    front_steer: str
    virtual_rear_wheels: tuple[str, str]
    virtual_front_wheels: tuple[str, str]
    virtual_front_steers: tuple[str, str]
    enable_ackermann_link: bool = True
    wheel_separation_w: float = 0.0
    wheel_separation_h: float = 0.0

    @property
    def virtual_wheels(self):
        return self.virtual_rear_wheels + self.virtual_front_wheels


def steer_bot_config(params, gains, ns):
    """Check ``<ns>/steer_bot_hardware_gazebo`` (``params``) and ``<ns>/gains`` (``gains``).

    Raises:
        ConfigError: naming the parameter at fault, where upstream's initSim would fail or crash (a missing
            joint list indexes an empty vector; missing gains fail ``Pid::init``).
    """
    base = f"{ns.rstrip('/')}/{PARAM_NS}"
    if not isinstance(params, dict):
        raise ConfigError(base, params, "the hardware's parameters (load its YAML under the robot's namespace)")

    def name(key):
        value = params.get(key)
        if not isinstance(value, str) or not value:
            raise ConfigError(f"{base}/{key}", value, "a joint name")
        return value

    def pair(key):
        value = params.get(key)
        if (not isinstance(value, (list, tuple)) or len(value) != 2
                or not all(isinstance(v, str) and v for v in value)):
            raise ConfigError(f"{base}/{key}", value, "two joint names [right, left]")
        return tuple(value)

    ackermann = params.get("enable_ackermann_link", True)
    if not isinstance(ackermann, bool):
        raise ConfigError(f"{base}/enable_ackermann_link", ackermann, "true or false")
    separations = {}
    for key in ("wheel_separation_w", "wheel_separation_h"):
        value = params.get(key)
        if value is None and not ackermann:
            value = 0.0
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or \
                (ackermann and value <= 0):
            raise ConfigError(f"{base}/{key}", value, "a number > 0 [m] (the Ackermann link needs it)")
        separations[key] = float(value)
    config = SteerBotConfig(name("rear_wheel"), name("front_steer"), pair("virtual_rear_wheels"),
                            pair("virtual_front_wheels"), pair("virtual_front_steers"), ackermann, **separations)
    for joint in config.virtual_rear_wheels:
        entry = gains.get(joint) if isinstance(gains, dict) else None
        if not isinstance(entry, dict) or isinstance(entry.get("p"), bool) or \
                not isinstance(entry.get("p"), (int, float)):
            raise ConfigError(f"{ns.rstrip('/')}/gains/{joint}/p", None if not isinstance(entry, dict) else
                              entry.get("p"), "a number (SteerBotHardwareGazebo's initSim fails without it)")
    return config


def linkage_angles(steer, config):
    """The (right, left) virtual steer angles [rad] for the bicycle model's steering angle ``steer`` [rad]."""
    if not config.enable_ackermann_link:
        return steer, 2.0 * steer
    h, w, t = config.wheel_separation_h, config.wheel_separation_w, math.tan(steer)
    return math.atan2(2 * h * t, 2 * h + w / 2.0 * t), math.atan2(2 * h * t, 2 * h - w / 2.0 * t)
