"""Ray casting in a second process (``~ray_process``), the simulator's side: a mirror of the world
(:mod:`diffbot_sim.physics.ray_mirror`, the helper's side) casts the ray sensors' rays while the simulator's
own process goes on stepping.

Why: PyBullet keeps Python's interpreter lock through ``stepSimulation`` and ``rayTestBatch``, so in one
process the rays of a fleet's lasers and its physics take turns on one core (docs/fleet.md: with 66 laser
robots at real time the rays cost about a quarter of the loop). Here the rays are cast on the machine's other
core against a copy of the world's collision geometry, kept the same by:

* replaying every call that adds or removes a body (``World`` sends each one as it makes it: the same URDF
  text and parsed model, the same world description), so the mirror's bodies are built by the same code;
* a snapshot of every moving thing (each robot's base pose and joint positions, each world body's and actor's
  pose) sent with the first cast after each physics step, so a scan is cast against the world as it was on
  the step that was due, as if it had been cast in place.

The answers are the same numbers ``World.ray_batch`` gives in place (bodies reported by the simulator's own
ids); they arrive a little later in wall time, which is why only real-time mode uses this (fast mode and
lockstep wait for every message, so they cast in place). The helper ends when its pipe closes (the simulator
exited or crashed); if it dies first, the next call raises ``RuntimeError`` naming it.
"""
import os
import socket
import subprocess
import sys
from multiprocessing.connection import Connection

import numpy as np

#: Wall seconds ``close`` waits for the helper to end before it is killed.
CLOSE_TIMEOUT = 5.0


class RayProcess:
    """The simulator's side: starts the helper, forwards the world's changes, hands casts over and collects
    their answers (one thread: the loop's).

    A cast names its sensor's rays (local start and end directions, sent once) and the sensor's pose, so a
    request is a few hundred bytes and the simulator never waits to write one; the helper writes its answers
    from a thread of their own, so it never waits for the simulator to read them either."""

    def __init__(self, time_step, gravity):
        parent, child = socket.socketpair()
        package_root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (package_root, env.get("PYTHONPATH", "")) if p)
        try:
            self.process = subprocess.Popen(
                [sys.executable, "-m", "diffbot_sim.physics.ray_mirror", str(child.fileno())],
                pass_fds=(child.fileno(),), stdin=subprocess.DEVNULL, env=env)
        finally:
            child.close()
        self.conn = Connection(parent.detach())
        self._next_ticket = 0
        self._answers = {}
        self._waiting = set()
        self._fans = {}  # sensor key -> the directions array the helper has for it
        self._send(("world", time_step, gravity))

    # -- sending ---------------------------------------------------------------------------------------------
    def _send(self, message):
        try:
            self.conn.send(message)
        except OSError as err:
            raise RuntimeError(self._ended(f"could not be written to ({err})")) from None

    def _ended(self, how):
        code = self.process.poll()
        status = f"exit status {code}" if code is not None else "still running"
        return f"diffbot_sim: the ray process (~ray_process) {how}; {status}"

    def replay(self, method, args, ids):
        """Have the mirror call ``World.<method>(*args)``; ``ids`` are the simulator's PyBullet ids the call
        made (in the order the mirror's call returns its own), so answers name the simulator's bodies."""
        self._send(("call", method, args, ids))

    def remove(self, uid):
        """The simulator removed body ``uid`` (a robot or a world body): the mirror removes its own."""
        self._send(("remove", uid))

    def plane(self, uid):
        """The simulator's ground plane is now body ``uid`` (None: removed by a world's own ground)."""
        self._send(("plane", uid))

    def cast(self, state, key, directions, near, far, position, rotation):
        """Cast the rays of sensor ``key`` (``directions`` (N, 3) in its frame, from ``near`` to ``far`` m) from
        ``position``/``rotation`` against the world as ``state`` has it (None: as the last state sent).
        Returns a ticket for :meth:`answer`."""
        fan = None
        if self._fans.get(key) is not directions:
            self._fans[key] = directions
            fan = np.ascontiguousarray(directions, dtype=np.float64)
        ticket = self._next_ticket
        self._next_ticket += 1
        self._waiting.add(ticket)
        self._send(("cast", ticket, state, key, fan, float(near), float(far),
                    np.asarray(position, dtype=np.float64), np.asarray(rotation, dtype=np.float64)))
        return ticket

    # -- receiving -------------------------------------------------------------------------------------------
    def _receive(self):
        try:
            message = self.conn.recv()
        except (EOFError, OSError):
            raise RuntimeError(self._ended("ended")) from None
        if message[0] == "error":
            raise RuntimeError(self._ended(f"failed: {message[1]}"))
        _, ticket, fractions, bodies, links = message
        if ticket in self._waiting:
            self._answers[ticket] = (fractions, bodies.astype(np.int64), links.astype(np.int64))

    def answer(self, ticket, wait=False):
        """``(fractions, bodies, links)`` of a cast (as ``World.ray_batch``), or None while it is not back
        (``wait``: block until it is)."""
        while ticket not in self._answers:
            if ticket not in self._waiting:
                raise KeyError(f"no ray cast {ticket} is waiting")
            if not wait and not self.conn.poll(0):
                return None
            self._receive()
        self._waiting.discard(ticket)
        return self._answers.pop(ticket)

    def drop(self, ticket):
        """Nobody wants this cast any more (a reset, a deleted robot): its answer is thrown away."""
        self._waiting.discard(ticket)
        self._answers.pop(ticket, None)

    def close(self):
        if self.process.poll() is None:
            try:
                self.conn.send(None)
            except OSError:
                pass
            try:
                self.process.wait(timeout=CLOSE_TIMEOUT)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self.conn.close()
