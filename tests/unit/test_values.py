"""values: numbers in Gazebo tags read as Gazebo reads them (std::stod / std::stoul: the leading number,
the rest dropped) with one warning naming the tag; a text with no leading number is still an error."""
import math

import pytest

from diffbot_sim.errors import ConfigError
from diffbot_sim.values import check_mapping, leading_number, tag_number


@pytest.mark.parametrize("text, value, rest", [
    ("0.5", 0.5, ""), ("  0.5  ", 0.5, ""), ("-1e-3", -0.001, ""), (".25", 0.25, ""), ("5.", 5.0, ""),
    ("666.5185185185185", 666.5185185185185, ""), ("50.0Hz", 50.0, "Hz"), ("0.5abc", 0.5, "abc"),
    ("1 2", 1.0, "2"), ("inf", math.inf, ""), ("-Infinity", -math.inf, ""),
])
def test_stod_takes_the_leading_number(text, value, rest):
    assert leading_number(text) == (value, rest)


def test_stod_reads_nan():
    value, rest = leading_number("nan")
    assert math.isnan(value) and rest == ""


@pytest.mark.parametrize("text, value, rest", [
    ("666.5185185185185", 666, ".5185185185185"), ("360", 360, ""), (" 12px", 12, "px"), ("-3", -3, ""),
])
def test_stoul_takes_the_leading_digits(text, value, rest):
    assert leading_number(text, integer=True) == (value, rest)


@pytest.mark.parametrize("text, integer", [("", False), ("wide", False), ("x1", False), (".5", True),
                                            ("e5", False)])
def test_no_leading_number_is_an_error(text, integer):
    with pytest.raises(ValueError):
        leading_number(text, integer)


def test_tag_number_drops_the_rest_with_one_note():
    notes = []
    assert tag_number("<samples> of /robot/gazebo/sensor", "666.5185185185185", notes, integer=True, low=1) == 666
    assert notes == ["<samples> of /robot/gazebo/sensor: took 666 from '666.5185185185185', as Gazebo's SDF "
                     "reader (std::stoul) does"]
    assert tag_number("<mu1>", " 0.5 ", notes) == 0.5 and len(notes) == 1  # white space is no junk


def test_tag_number_errors_name_the_tag_and_the_text_as_written():
    with pytest.raises(ConfigError, match=r"parameter <updateRate> of p: got 'fast', expected a number"):
        tag_number("<updateRate> of p", "fast", [])
    with pytest.raises(ConfigError, match=r"got '-5Hz', expected a number >= 0"):
        tag_number("<updateRate> of p", "-5Hz", [], low=0.0)
    with pytest.raises(ConfigError, match="a finite number"):
        tag_number("<kp>", "inf", [])
    with pytest.raises(ConfigError, match=r"got .0\.9., expected a number >= 1"):
        tag_number("<samples>", "0.9", [], integer=True, low=1)


def test_values_that_are_not_text_are_only_checked():
    notes = []
    assert tag_number("<width>", 320, notes, integer=True, low=1) == 320 and notes == []


def test_check_mapping_reads_a_namespace_of_parameters():
    """The one check of a parameter sub-namespace: absent is empty, a dict is itself, else one line naming it."""
    assert check_mapping("/arm/constraints", None) == {}
    gains = {"p": 1.0}
    assert check_mapping("/arm/gains", gains) is gains
    with pytest.raises(ConfigError, match=r"^parameter /arm/gains: got \[1, 2\], expected a dictionary$"):
        check_mapping("/arm/gains", [1, 2])
    with pytest.raises(ConfigError, match=r"expected a mapping of joint name -> PID gains$"):
        check_mapping("/gripper/gains", 3.0, "a mapping of joint name -> PID gains")
