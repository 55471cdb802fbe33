"""What the command lines of the Gazebo-era tools have in common (pure, no rospy): gazebo_ros's
``spawn_model`` (:mod:`diffbot_sim.gazebo.spawn_cli`) and controller_manager's ``spawner``, ``unspawner`` and
``controller_manager`` (:mod:`diffbot_sim.gazebo.controller_cli`), ROS 1 noetic semantics.

Why these modules exist: those tools are not Debian packages, so ``overlay/gazebo_ros`` and
``overlay/controller_manager`` ship stand-ins whose nodes talk to the simulator. A launch file written for
Gazebo passes them the same arguments, so what those arguments mean must match noetic's scripts flag for
flag; that is pure logic, kept without rospy so that it is unit-tested without a ROS master.

Shared here: ROS remapping arguments (``__name:=``, ``__log:=``, ``a:=b``, which roslaunch appends) are
dropped first, by ``rospy.myargv``'s rule (any argument containing ``:=``); where upstream fails with a
traceback (``-x abc``, ``--timeout abc``) we give one line naming the flag (:class:`CliError`); help and
usage end the program with a status (:class:`UsageExit`) that the node, not argparse, reports.
"""
import argparse
import math

from diffbot_sim.errors import DiffbotSimError

#: rosgraph.names.REMAP: an argument containing it is a ROS remapping, not the program's.
REMAP = ":="


class CliError(DiffbotSimError):
    """A bad command line; the message is one line naming the flag, file or parameter at fault."""


class UsageExit(Exception):
    """Not an error in the arguments as such: print ``text`` (help or usage) and exit with ``status``.

    ``-h`` exits 0 everywhere; noetic's unspawner exits 1 after its help, and ``controller_manager`` with an
    unknown verb prints its usage and exits 1.
    """

    def __init__(self, text, status=0):
        super().__init__(text)
        self.text = text
        self.status = status


def strip_remappings(argv):
    """``argv`` without ROS remapping arguments (``rospy.myargv``'s rule, done without rospy)."""
    return [arg for arg in argv if REMAP not in arg]


class Parser(argparse.ArgumentParser):
    """argparse, but raising instead of printing and exiting, so a node decides how to report."""

    def error(self, message):
        raise CliError(f"{message} (see {self.prog} -h)")

    def print_help(self, file=None):
        raise UsageExit(self.format_help(), 0)

    def exit(self, status=0, message=None):
        raise UsageExit(message or "", status)


def finite(flag, text, what):
    """``text`` as a finite float, else CliError naming ``flag`` (upstream: a traceback or NaN sent on)."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise CliError(f"{flag}: '{text}' is not a number ({what} expected)") from None
    if not math.isfinite(value):
        raise CliError(f"{flag}: '{text}' is not a finite number ({what} expected)")
    return value
