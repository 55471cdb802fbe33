"""Requests from rospy's threads (service and subscriber callbacks) onto the simulator loop's thread, the only one
that touches physics and plugins: ``call`` waits for the result, ``post`` does not. The loop takes them between
steps (``_handle_requests``) and sleeps on ``wake`` when it has nothing due."""
import threading

import rospy

#: Wall seconds a service request may wait for the loop (gazebo_ros's deleteModel waits 60 s for the world).
CALL_TIMEOUT = 60.0


class LoopRequests:
    """The request queue of :class:`diffbot_sim.simulator.loop.Simulator` (a base class of it)."""

    def __init__(self):
        self.wake = threading.Event()
        self._requests = []
        self._requests_lock = threading.Lock()

    def call(self, action, timeout=CALL_TIMEOUT):
        """Run ``action()`` on the loop's thread (the only one that touches physics and plugins) and return
        its result; an exception it raises is raised here. Works while paused.

        A request the loop has not begun within ``timeout`` wall seconds is withdrawn (it never runs later:
        the caller's failure answer stays true); one it has begun is waited for to its end.

        Raises:
            rospy.ServiceException: the loop did not get to it within ``timeout`` wall seconds.
        """
        done = threading.Event()
        box = {}
        state_lock = threading.Lock()

        def run():
            with state_lock:
                if box.get("withdrawn"):
                    return
                box["begun"] = True
            try:
                box["result"] = action()
            except Exception as err:  # handed back to the caller's thread, raised there
                box["error"] = err
            done.set()
        self.post(run)
        if not done.wait(timeout):
            with state_lock:
                box["withdrawn"] = not box.get("begun")
            if box["withdrawn"]:
                raise rospy.ServiceException(f"the simulator loop did not get to the request within {timeout:g} s "
                                             "(withdrawn: it will not run)")
            done.wait()
        if "error" in box:
            raise box["error"]
        return box.get("result")

    def post(self, action):
        """Queue ``action()`` for the loop without waiting (a subscriber callback)."""
        with self._requests_lock:
            self._requests.append(action)
        self.wake.set()

    def _handle_requests(self):
        with self._requests_lock:
            requests, self._requests = self._requests, []
        for action in requests:
            action()
