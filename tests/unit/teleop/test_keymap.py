"""The teleop key map: bindings with REP 103 signs, speed keys and limits, key timeout, repeat, config."""
import math

import pytest

from diffbot_sim.errors import ConfigError
from diffbot_sim.teleop.keymap import (
    MOVE_BINDINGS,
    QUIT_KEY,
    SPEED_BINDINGS,
    STOP,
    Command,
    Teleop,
    TeleopConfig,
    format_status,
)


def make(**params):
    return Teleop(TeleopConfig.from_mapping(params))


@pytest.mark.parametrize("key, expected", [
    ("i", Command(0.5, 0.0)),    # forward: +x
    ("k", Command(-0.5, 0.0)),   # backward
    ("j", Command(0.0, 2.0)),    # turn left: +z (counter-clockwise)
    ("l", Command(0.0, -2.0)),   # turn right
    ("s", Command(0.0, 0.0)),
])
def test_move_keys_follow_rep103(key, expected):
    assert make(speed=0.5, turn=2.0).press(key, 0.0) == expected


def test_stop_is_all_positive_zeros():
    teleop = make()
    teleop.press("i", 0.0)
    stop = teleop.press("s", 0.1)
    assert stop == STOP and not stop.moving
    assert math.copysign(1.0, stop.linear) == 1.0 and math.copysign(1.0, stop.angular) == 1.0


@pytest.mark.parametrize("key", ["a", "I", "K", " ", "\r", "\x1b", "[", "A", "\x04", "\x13"])
def test_unbound_keys_publish_nothing_and_change_nothing(key):
    teleop = make()
    teleop.press("i", 0.0)
    assert teleop.press(key, 0.1) is None
    assert teleop.command == Command(1.0, 0.0)
    assert not teleop.quit_requested


def test_quit_key_requests_quit_without_publishing():
    teleop = make()
    teleop.press("i", 0.0)
    assert teleop.press(QUIT_KEY, 0.1) is None
    assert teleop.quit_requested


def test_every_binding_is_tested_here():
    assert set(MOVE_BINDINGS) == set("ikjls")
    assert set(SPEED_BINDINGS) == set("qzwxec")


@pytest.mark.parametrize("key, speed, turn", [
    ("q", 1.1, 1.1), ("z", 0.9, 0.9),
    ("w", 1.1, 1.0), ("x", 0.9, 1.0),
    ("e", 1.0, 1.1), ("c", 1.0, 0.9),
])
def test_speed_keys_scale(key, speed, turn):
    teleop = make()
    teleop.press(key, 0.0)
    assert teleop.speed == pytest.approx(speed)
    assert teleop.turn == pytest.approx(turn)


def test_speed_key_republishes_current_motion_at_new_speed():
    teleop = make()
    assert teleop.press("i", 0.0) == Command(1.0, 0.0)
    assert teleop.press("q", 0.1) == pytest.approx(Command(1.1, 0.0))
    assert teleop.press("j", 0.2) == pytest.approx(Command(0.0, 1.1))
    assert teleop.press("c", 0.3) == pytest.approx(Command(0.0, 0.99))


def test_speed_key_while_stopped_publishes_a_stop():
    assert make().press("q", 0.0) == STOP


def test_speed_keys_respect_limits():
    teleop = make(speed=1.0, turn=1.0, speed_limit=1.2, turn_limit=1.05)
    for _ in range(10):
        teleop.press("q", 0.0)
    assert teleop.speed == 1.2
    assert teleop.turn == 1.05
    assert teleop.press("i", 0.0) == Command(1.2, 0.0)


def test_speed_keys_never_go_negative():
    teleop = make()
    for _ in range(500):
        teleop.press("z", 0.0)
    assert 0.0 <= teleop.speed < 1e-9 and 0.0 <= teleop.turn < 1e-9


def test_key_timeout_stops_once_while_moving():
    teleop = make(key_timeout=0.5)
    teleop.press("i", 10.0)
    assert teleop.tick(10.0) is None
    assert teleop.tick(10.49) is None
    assert teleop.tick(10.5) == STOP
    assert teleop.tick(10.6) is None
    assert teleop.tick(100.0) is None
    assert teleop.command == STOP


def test_key_timeout_is_renewed_by_bound_keys_only():
    teleop = make(key_timeout=0.5)
    teleop.press("i", 0.0)
    teleop.press("q", 0.4)   # a speed key counts: it re-sent the motion
    assert teleop.tick(0.8) is None
    teleop.press("a", 0.85)  # an unbound key must not keep the robot going
    assert teleop.tick(0.9) == STOP


def test_key_timeout_sends_nothing_while_stopped():
    teleop = make(key_timeout=0.5)
    assert teleop.tick(0.0) is None
    assert teleop.tick(5.0) is None
    teleop.press("s", 5.0)
    assert teleop.tick(6.0) is None


def test_no_key_timeout_when_zero():
    teleop = make(key_timeout=0.0)
    teleop.press("i", 0.0)
    assert teleop.tick(1e6) is None
    assert teleop.command == Command(1.0, 0.0)


def test_repeat_republishes_last_command_at_rate():
    teleop = make(repeat_rate=4.0)  # period 0.25 s: binary fractions keep the float arithmetic exact
    assert not teleop.due(0.0)            # nothing sent yet: nothing to repeat
    assert teleop.tick(5.0) is None
    teleop.press("j", 1.0)
    assert not teleop.due(1.125)
    assert teleop.due(1.25)
    assert teleop.tick(1.25) == Command(0.0, 1.0)
    assert teleop.tick(1.375) is None
    assert teleop.tick(1.5) == Command(0.0, 1.0)


def test_repeat_off_by_default():
    teleop = make()
    teleop.press("i", 0.0)
    assert not teleop.due(100.0)
    assert teleop.tick(100.0) is None


def test_repeat_continues_the_timeout_stop():
    teleop = make(repeat_rate=8.0, key_timeout=0.375)
    teleop.press("i", 0.0)
    assert teleop.tick(0.125) == Command(1.0, 0.0)
    assert teleop.tick(0.375) == STOP
    assert teleop.tick(0.5) == STOP


def test_next_deadline():
    teleop = make(repeat_rate=4.0, key_timeout=0.1)
    assert teleop.next_deadline(0.0) is None
    teleop.press("i", 1.0)
    assert teleop.next_deadline(1.0) == pytest.approx(0.1)
    assert teleop.next_deadline(2.0) == 0.0
    assert make().next_deadline(0.0) is None


def test_config_defaults():
    config = TeleopConfig.from_mapping({})
    assert config == TeleopConfig()
    assert (config.speed, config.turn, config.repeat_rate, config.key_timeout) == (1.0, 1.0, 0.0, 0.0)
    assert (config.speed_limit, config.turn_limit) == (1000.0, 1000.0)


def test_config_accepts_ints_and_zero():
    config = TeleopConfig.from_mapping({"speed": 2, "turn": 0, "repeat_rate": 0, "key_timeout": 0.25})
    assert config.speed == 2.0 and isinstance(config.speed, float)
    assert config.turn == 0.0
    assert config.key_timeout == 0.25


@pytest.mark.parametrize("name", ["speed", "turn", "repeat_rate", "key_timeout", "speed_limit", "turn_limit"])
@pytest.mark.parametrize("value", [-0.1, float("nan"), float("inf"), float("-inf"), "fast", None, True, [1.0]])
def test_config_refuses_bad_values_naming_the_parameter(name, value):
    with pytest.raises(ConfigError, match=rf"^parameter ~{name}: got") as info:
        TeleopConfig.from_mapping({name: value})
    assert info.value.name == f"~{name}"
    assert "\n" not in str(info.value)


def test_config_refuses_start_speed_above_limit():
    with pytest.raises(ConfigError, match=r"~speed: got 5\.0, expected a number <= ~speed_limit"):
        TeleopConfig.from_mapping({"speed": 5.0, "speed_limit": 2.0})
    with pytest.raises(ConfigError, match=r"~turn: .*~turn_limit"):
        TeleopConfig.from_mapping({"turn": 1001})


def test_config_unknown_keys_are_reported_not_fatal():
    params = {"speed": 1.0, "sped": 2.0, "stamped": True}
    assert TeleopConfig.from_mapping(params).speed == 1.0
    assert TeleopConfig.unknown(params) == ["sped", "stamped"]


def test_format_status():
    text = format_status(Command(0.5, -1.0), 0.5, 1.0)
    assert text == "cmd x:+0.50 m/s z:-1.00 rad/s | speed 0.50 turn 1.00"
    text = format_status(STOP, 1.0, 1.0, pose=(1.234, -2.0, math.pi / 2))
    assert text.endswith("| odom x:+1.23 y:-2.00 yaw:+90deg")
    assert "\n" not in text and "\r" not in text
