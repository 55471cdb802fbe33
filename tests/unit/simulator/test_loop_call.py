"""Simulator.call: a service request the loop has not begun within its timeout is withdrawn (the caller was told
it failed, so it must never run later); one the loop has begun is waited for (no master, no loop: requests are
run by hand)."""
import threading

import pytest
import rospy

from diffbot_sim.simulator.loop import Simulator


class Posted:
    """Just the loop's request queue."""

    def __init__(self):
        self.requests = []

    def post(self, action):
        self.requests.append(action)


def test_a_request_not_begun_in_time_is_withdrawn_and_never_runs():
    loop, ran = Posted(), []
    with pytest.raises(rospy.ServiceException, match="withdrawn"):
        Simulator.call(loop, lambda: ran.append(1), timeout=0.05)
    loop.requests[0]()  # the loop gets to it late
    assert ran == []


def test_a_request_begun_before_the_timeout_is_waited_for():
    loop, started, release = Posted(), threading.Event(), threading.Event()

    def slow():
        started.set()
        release.wait(5)
        return "done"
    out = {}
    caller = threading.Thread(target=lambda: out.setdefault("result", Simulator.call(loop, slow, timeout=0.1)))
    caller.start()
    while not loop.requests:
        pass
    worker = threading.Thread(target=loop.requests[0])
    worker.start()
    assert started.wait(5)
    caller.join(0.3)
    assert caller.is_alive(), "the caller gave up on a request the loop had begun"
    release.set()
    caller.join(5)
    worker.join(5)
    assert out["result"] == "done"


def test_errors_come_back_to_the_caller():
    loop = Posted()
    caller_error = {}

    def call():
        try:
            Simulator.call(loop, lambda: 1 / 0, timeout=5)
        except ZeroDivisionError as err:
            caller_error["err"] = err
    caller = threading.Thread(target=call)
    caller.start()
    while not loop.requests:
        pass
    loop.requests[0]()
    caller.join(5)
    assert isinstance(caller_error.get("err"), ZeroDivisionError)
