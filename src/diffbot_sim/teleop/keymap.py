"""The keyboard teleop's logic: which key means which command, speed scaling, key timeout and repeat.

Pure: no rospy, no termios, no clock. Every method that depends on time takes ``now`` (seconds, any
monotonic origin), so the whole state machine is tested with made-up times and the node passes
``time.monotonic()``. Commands are plain ``(linear, angular)`` pairs; the node turns them into Twists.

Signs follow REP 103 (x forward, positive yaw counter-clockwise): ``i`` drives forward (+linear.x) and
``j`` turns left (+angular.z). The seed tutorial had both the other way round.
"""
import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import NamedTuple

from diffbot_sim.errors import ConfigError

#: Ctrl-C as a byte: the terminal is put in a mode where it arrives as input, not as SIGINT.
QUIT_KEY = "\x03"

#: key -> (linear direction, angular direction); multiplied by the current speed and turn.
MOVE_BINDINGS = {
    "i": (1, 0),   # forward
    "k": (-1, 0),  # backward
    "j": (0, 1),   # turn left (counter-clockwise)
    "l": (0, -1),  # turn right
    "s": (0, 0),   # stop
}

#: key -> (speed factor, turn factor), as in teleop_twist_keyboard.
SPEED_BINDINGS = {
    "q": (1.1, 1.1),
    "z": (0.9, 0.9),
    "w": (1.1, 1.0),
    "x": (0.9, 1.0),
    "e": (1.0, 1.1),
    "c": (1.0, 0.9),
}

BANNER = """\
we are ready, please press
   i
j  k  l      i/k: forward/backward, j/l: turn left/right
             s: stop
q/z : increase/decrease max speeds by 10%
w/x : increase/decrease only linear speed by 10%
e/c : increase/decrease only angular speed by 10%
Ctrl-C to quit (the robot is stopped first)"""


class Command(NamedTuple):
    """A velocity command: ``linear`` along +x (m/s) and ``angular`` about +z (rad/s)."""

    linear: float
    angular: float

    @property
    def moving(self):
        """True unless both components are zero."""
        return self.linear != 0.0 or self.angular != 0.0


STOP = Command(0.0, 0.0)


@dataclass(frozen=True)
class TeleopConfig:
    """The teleop node's private parameters. Defaults live here and nowhere else.

    Attributes:
        speed: linear speed of ``i`` / ``k`` at start (m/s).
        turn: angular speed of ``j`` / ``l`` at start (rad/s).
        repeat_rate: re-publish the last command at this rate (Hz); 0 publishes on key presses only.
        key_timeout: stop the robot when no key arrived for this long while moving (s); 0 never does.
        speed_limit: the speed keys never raise ``speed`` above this (m/s).
        turn_limit: the speed keys never raise ``turn`` above this (rad/s).
    """

    speed: float = 1.0
    turn: float = 1.0
    repeat_rate: float = 0.0
    key_timeout: float = 0.0
    speed_limit: float = 1000.0
    turn_limit: float = 1000.0

    @classmethod
    def from_mapping(cls, params: Mapping[str, object]) -> "TeleopConfig":
        """Build a config from the node's private parameters (``rospy.get_param('~')``).

        Keys this config does not know are ignored here; see :meth:`unknown`.

        Raises:
            ConfigError: a value is not a finite number >= 0, or ``speed`` / ``turn`` exceeds its limit.
                The error names the parameter as ``~name``.
        """
        values = {}
        for f in fields(cls):
            if f.name in params:
                values[f.name] = _non_negative(f"~{f.name}", params[f.name])
        config = cls(**values)
        for name, limit in (("speed", "speed_limit"), ("turn", "turn_limit")):
            value, bound = getattr(config, name), getattr(config, limit)
            if value > bound:
                raise ConfigError(f"~{name}", value, f"a number <= ~{limit} ({bound})")
        return config

    @classmethod
    def unknown(cls, params: Mapping[str, object]):
        """Return the sorted keys of ``params`` that are not parameters of this config (likely typos)."""
        known = {f.name for f in fields(cls)}
        return sorted(key for key in params if key not in known)


def _non_negative(name, value):
    # bool is an int subclass: `_speed:=true` is a typo, not 1.0.
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(name, value, "a finite number >= 0")
    value = float(value)
    if not math.isfinite(value) or value < 0.0:
        raise ConfigError(name, value, "a finite number >= 0")
    return value


class Teleop:
    """Key -> command state machine.

    Call :meth:`press` for every key read and :meth:`tick` on every loop turn (also after a key); each
    returns the command to publish now, or None. A returned command is assumed published at ``now``.

    Args:
        config: the validated parameters.
    """

    def __init__(self, config: TeleopConfig):
        self.config = config
        self.speed = config.speed
        self.turn = config.turn
        self.quit_requested = False
        self._direction = (0, 0)
        self._last_key: float | None = None     # when the last bound key arrived
        self._last_sent: float | None = None    # when the last command was handed out
        self._last_command: Command | None = None

    @property
    def command(self) -> Command:
        """The command the current direction, speed and turn give."""
        lin, ang = self._direction
        # `+ 0.0` turns -0.0 (direction 0 times a speed) into 0.0, so a stop is all zeros.
        return Command(lin * self.speed + 0.0, ang * self.turn + 0.0)

    def press(self, key: str, now: float) -> Command | None:
        """Handle one key.

        Args:
            key: a one-character string.
            now: the time the key was read (s).

        Returns:
            The command to publish, or None for keys without a binding and for the quit key (the node
            publishes the final stop itself, on every way out).
        """
        if key == QUIT_KEY:
            self.quit_requested = True
            return None
        if key in MOVE_BINDINGS:
            self._direction = MOVE_BINDINGS[key]
        elif key in SPEED_BINDINGS:
            speed_factor, turn_factor = SPEED_BINDINGS[key]
            self.speed = _clamp(self.speed * speed_factor, self.config.speed_limit)
            self.turn = _clamp(self.turn * turn_factor, self.config.turn_limit)
        else:
            # An unbound key must not keep a moving robot alive past key_timeout.
            return None
        self._last_key = now
        return self._send(self.command, now)

    def tick(self, now: float) -> Command | None:
        """Apply the key timeout and the repeat rate.

        Returns:
            A stop, once, when the robot is moving and no key arrived within ``key_timeout``; else the last
            command when a repeat is :meth:`due`; else None.
        """
        timeout = self.config.key_timeout
        if (timeout > 0.0 and self._direction != (0, 0) and self._last_key is not None
                and now - self._last_key >= timeout):
            self._direction = (0, 0)
            return self._send(self.command, now)
        if self.due(now):
            return self._send(self._last_command, now)
        return None

    def due(self, now: float) -> bool:
        """True when repeating is on, a command was sent, and ``1 / repeat_rate`` has passed since."""
        rate = self.config.repeat_rate
        return rate > 0.0 and self._last_sent is not None and now - self._last_sent >= 1.0 / rate

    def next_deadline(self, now: float) -> float | None:
        """Seconds from ``now`` until :meth:`tick` may have something to send (None: only a key can).

        Lets the node sleep in ``select`` no longer than needed.
        """
        waits: list[float] = []
        if self.config.key_timeout > 0.0 and self._direction != (0, 0) and self._last_key is not None:
            waits.append(self._last_key + self.config.key_timeout - now)
        if self.config.repeat_rate > 0.0 and self._last_sent is not None:
            waits.append(self._last_sent + 1.0 / self.config.repeat_rate - now)
        return max(0.0, min(waits)) if waits else None

    def _send(self, command, now):
        self._last_command = command
        self._last_sent = now
        return command


def _clamp(value, limit):
    return min(max(value, 0.0), limit)


def format_status(command: Command, speed: float, turn: float, pose=None) -> str:
    """The one status line: current command, the scale, and the pose when odometry is known.

    Args:
        command: the last command sent (or STOP).
        speed: current linear scale (m/s).
        turn: current angular scale (rad/s).
        pose: ``(x, y, yaw)`` in the odometry frame (m, m, rad), or None when no odometry arrives.
    """
    text = (f"cmd x:{command.linear:+.2f} m/s z:{command.angular:+.2f} rad/s"
            f" | speed {speed:.2f} turn {turn:.2f}")
    if pose is not None:
        x, y, yaw = pose
        text += f" | odom x:{x:+.2f} y:{y:+.2f} yaw:{math.degrees(yaw):+.0f}deg"
    return text
