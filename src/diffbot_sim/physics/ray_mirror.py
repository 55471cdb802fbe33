"""Ray casting in a second process (``~ray_process``), the helper's side: a mirror of the simulator's world,
built by the same ``World`` calls and moved to each state it is sent, answering casts
(:mod:`diffbot_sim.physics.ray_process` starts it and talks to it; run as
``python -m diffbot_sim.physics.ray_mirror FD``, FD a socket to the simulator)."""
import queue
import signal
import sys
import threading
import traceback
from multiprocessing.connection import Connection

import numpy as np

from diffbot_sim.physics.client import pybullet
from diffbot_sim.physics.world import World
from diffbot_sim.transforms import rays_along


class Mirror:
    """The helper's side: its own ``World`` built by the same calls, moved to each state it is sent."""

    def __init__(self, time_step, gravity):
        self.world = World(time_step, gravity)
        self.world.ray_threads = 1  # the simulator's process has the other core
        self.to_ours = {}  # the simulator's id -> ours
        self.to_theirs = {}  # ours -> the simulator's id
        self.last = {}  # our id -> the pose (and joint positions) last set
        self.their_plane = None
        self.fans = {}  # sensor key -> its rays' directions (sensor frame)

    def _map(self, theirs, ours):
        self.to_ours[theirs] = ours
        self.to_theirs[ours] = theirs

    def call(self, method, args, ids):
        result = getattr(self.world, method)(*args)
        made = []
        if method == "load_robot":
            made = [result.body]
        elif method == "load_world":
            made = [uid for uid, _ in self.world.world_bodies[len(self.world.world_bodies) - result:]]
        elif method == "add_kinematic_box":
            made = [result]
        if len(made) != len(ids):
            raise RuntimeError(f"World.{method} made {len(made)} bodies here and {len(ids)} in the simulator")
        for theirs, ours in zip(ids, made):
            self._map(theirs, ours)

    def forget(self, theirs):
        """Drop the mapping of the simulator's body ``theirs``; returns our id (None: none)."""
        ours = self.to_ours.pop(theirs, None)
        if ours is not None:
            self.to_theirs.pop(ours, None)
            self.last.pop(ours, None)
        return ours

    def remove(self, theirs):
        """The simulator removed body ``theirs``: remove ours (a robot or a world body)."""
        ours = self.forget(theirs)
        if ours is None:
            return
        robot = next((r for r in self.world.robots if r.body == ours), None)
        if robot is not None:
            self.world.remove_robot(robot)
        else:
            self.world.remove_body(ours)

    def plane(self, theirs):
        """The simulator's ground plane is body ``theirs`` (None: it has none); ours answers for it."""
        if self.their_plane is not None:
            self.forget(self.their_plane)
        self.their_plane = theirs
        if theirs is not None and self.world.plane is not None:
            self._map(theirs, self.world.plane)

    def apply(self, state):
        """Move every body to ``state``: {the simulator's id: (position, orientation, joint positions)}."""
        c = self.world.client
        for theirs, (position, orientation, joints) in state.items():
            ours = self.to_ours.get(theirs)
            if ours is None:
                continue
            key = (tuple(position), tuple(orientation), tuple(joints))
            if self.last.get(ours) == key:
                continue
            self.last[ours] = key
            pybullet.resetBasePositionAndOrientation(ours, position, orientation, physicsClientId=c)
            for index, value in joints:
                pybullet.resetJointState(ours, index, value, 0.0, physicsClientId=c)

    def cast(self, key, fan, near, far, position, rotation):
        """(fractions, the simulator's body ids, links) of sensor ``key``'s rays from ``position``/``rotation``
        (``fan``: its directions, when they are new), as ``World.ray_batch`` answers in the simulator."""
        if fan is not None:
            self.fans[key] = fan
        fractions, bodies, links = self.world.ray_batch(*rays_along(position, rotation, self.fans[key], near, far))
        theirs = np.array([self.to_theirs.get(b, -1) if b >= 0 else -1 for b in bodies.tolist()], dtype=np.int32)
        return fractions, theirs, links.astype(np.int32)


def serve(conn):
    """Answer the simulator until it closes the pipe. Answers are written by a thread of their own, so a
    simulator busy stepping never holds up the casting (nor the casting its requests)."""
    answers = queue.Queue()

    def write():
        while (message := answers.get()) is not None:
            try:
                conn.send(message)
            except OSError:
                return
    writer = threading.Thread(target=write, name="ray answers", daemon=True)
    writer.start()
    mirror = None
    try:
        while True:
            try:
                message = conn.recv()
            except EOFError:
                return
            if message is None:
                return
            kind = message[0]
            if kind == "world":
                mirror = Mirror(message[1], message[2])
            elif kind == "call":
                mirror.call(*message[1:])
            elif kind == "remove":
                mirror.remove(message[1])
            elif kind == "plane":
                mirror.plane(message[1])
            elif kind == "cast":
                ticket, state = message[1], message[2]
                if state is not None:
                    mirror.apply(state)
                answers.put(("answer", ticket, *mirror.cast(*message[3:])))
            else:
                raise ValueError(f"unknown request {kind!r}")
    except Exception:
        answers.put(("error", traceback.format_exc(limit=4).strip().splitlines()[-1]))
        raise
    finally:
        answers.put(None)
        writer.join(timeout=5.0)
        if mirror is not None:
            mirror.world.close()


if __name__ == "__main__":
    # roslaunch stops a node by signalling its process group, this helper included: it ends when the
    # simulator's end closes its pipe instead (a crash of the simulator too), never half-way through a request.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    serve(Connection(int(sys.argv[1])))
