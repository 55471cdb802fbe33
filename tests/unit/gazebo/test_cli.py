"""gazebo.cli: what the stand-in command lines share (ROS remapping arguments dropped, one-line errors that
name the flag, help as an exit status), and that none of the command-line modules imports rospy.
"""
import subprocess
import sys

import pytest

from diffbot_sim.gazebo import cli as gazebo_cli
from diffbot_sim.gazebo.cli import CliError, UsageExit


@pytest.mark.parametrize("module", ["cli", "spawn_cli", "controller_cli"])
def test_no_rospy_at_import(module):
    code = f"import sys; import diffbot_sim.gazebo.{module}; sys.exit('rospy' in sys.modules)"
    subprocess.run([sys.executable, "-c", code], check=True, cwd=gazebo_cli.__file__.rsplit("/", 2)[0])


def test_strip_remappings():
    assert gazebo_cli.strip_remappings(["a", "b:=c", "__ns:=/x", "d"]) == ["a", "d"]


@pytest.mark.parametrize("text, words", [("abc", "'abc' is not a number (seconds expected)"),
                                         ("nan", "'nan' is not a finite number"), ("-inf", "not a finite number"),
                                         (None, "is not a number")])
def test_finite_names_the_flag(text, words):
    with pytest.raises(CliError) as err:
        gazebo_cli.finite("--timeout", text, "seconds")
    assert str(err.value).startswith("--timeout: ") and words in str(err.value)
    assert gazebo_cli.finite("-x", "-1.5", "a position") == -1.5


def test_parser_raises_instead_of_exiting():
    parser = gazebo_cli.Parser(prog="tool")
    parser.add_argument("--n", required=True)
    with pytest.raises(CliError) as err:
        parser.parse_args([])
    assert str(err.value) == "the following arguments are required: --n (see tool -h)"
    with pytest.raises(UsageExit) as usage:
        parser.parse_args(["-h"])
    assert usage.value.status == 0 and "--n" in usage.value.text
