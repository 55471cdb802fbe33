"""Waiting on a condition with a deadline: the one poll loop of the tools, the tests and the nodes.

A wait that sleeps a fixed time and hopes is wrong on a slower or busier machine; a wait that polls forever
hangs a test run. ``wait_for`` polls a predicate until it gives a true value (returned, so a wait can also
fetch: ``msg = wait_for(lambda: latest.get(), 10, "a scan")``) and fails after ``timeout`` wall seconds with one
line naming what was waited for. Callers choose the exception (a test's ``AssertionError``, a node's
``DiffbotSimError``), what ends the wait early (ROS shutting down, the process under test gone), and may make
the predicate itself raise to fail at once with a message of their own.

Pure: no ROS, no clock but the one passed in (``time.monotonic`` by default), so it is unit-tested without
sleeping.
"""
import time
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")

#: how often ``wait_for`` polls by default [s]: short against what tests and tools wait for (tenths of a second
#: and more), long enough that a Python poll costs a waiting process nothing to speak of
POLL = 0.01


def wait_for(predicate: Callable[[], T], timeout: float, what: str, poll: float = POLL, *,
             error: Callable[[str], BaseException] = TimeoutError,
             give_up: Callable[[], object] | None = None,
             clock: Callable[[], float] = time.monotonic,
             sleep: Callable[[float], object] = time.sleep) -> T:
    """Poll ``predicate`` every ``poll`` s until it returns a true value, and return that value.

    The predicate is asked at least once, however short ``timeout``. After ``timeout`` s of ``clock`` it
    raises ``error("timed out after {timeout} s waiting for {what}")``. ``give_up``, when given, is asked after
    each unsuccessful poll: a true value ends the wait at once with ``error("{reason} while waiting for
    {what}")``, the reason being that value when it is a string (``lambda: rospy.is_shutdown() and "ROS shut
    down"``). ``error`` is an exception class or any callable that makes an exception from the message (to add
    a log's tail, say).
    """
    deadline = clock() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if give_up is not None:
            reason = give_up()
            if reason:
                reason = reason if isinstance(reason, str) else "gave up"
                raise error(f"{reason} while waiting for {what}")
        if clock() > deadline:
            raise error(f"timed out after {timeout:g} s waiting for {what}")
        sleep(poll)
