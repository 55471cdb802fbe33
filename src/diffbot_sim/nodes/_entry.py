"""The one wrapper every node's ``main`` goes through (no ROS of its own).

A node's output may have no reader by the time it exits: roslaunch's terminal closed, ``robot_check ... |
head -3``, a hung-up ``teleop_key``. The interpreter's final flush would then turn the node's exit status
into 120 (see :mod:`diffbot_sim.streams`). :func:`entry_point` makes ``main`` empty standard output and error
itself, through :func:`diffbot_sim.streams.finish`, however it ends, so its status stands.
"""
import functools

from diffbot_sim import streams


def entry_point(main):
    """``main`` (a node's entry point, returning its exit status) ending through ``streams.finish``, on a
    return and on an exception alike; the status is returned unchanged."""

    @functools.wraps(main)
    def finishing(*args, **kwargs):
        try:
            return main(*args, **kwargs)
        finally:
            streams.finish()

    return finishing
