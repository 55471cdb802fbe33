"""Rays cast into a PyBullet world: in place (``ray_batch``, the answer now) or by the ray process
(:class:`RayProcessLink`, the same answer later in wall time), and the ``laser_retro`` of what they hit."""
from diffbot_sim.physics.client import pybullet

#: Rays per rayTestBatch call. PyBullet's limit is MAX_RAY_INTERSECTION_BATCH_SIZE_STREAMING (16 x 1024 on
#: Linux); at exactly 16384 it returns 16383 results for list input (https://github.com/bulletphysics/bullet3/
#: issues/4215) and none for numpy input (measured here), and above it raises. 16383 works both ways.
RAY_BATCH_LIMIT = 16383


def ray_batch(client, starts, ends, threads=0):
    """Cast rays from ``starts`` to ``ends`` (world, (N, 3)) against everything in ``client``'s world, in calls
    of at most RAY_BATCH_LIMIT rays (PyBullet's per-call limit), numpy in and out; ``threads`` is
    rayTestBatch's numThreads (0: PyBullet picks max(1, rays / 16) threads of its pool).

    Returns:
        (hit fractions along start->end, 1.0 for a miss; hit PyBullet body ids, -1 for a miss; hit link
        indices, -1 for a base or a miss): numpy arrays of N values.
    """
    import numpy as np

    starts = np.ascontiguousarray(starts, dtype=np.float64).reshape(-1, 3)
    ends = np.ascontiguousarray(ends, dtype=np.float64).reshape(-1, 3)
    count = len(starts)
    fractions = np.ones(count)
    bodies = np.full(count, -1, dtype=np.int64)
    links = np.full(count, -1, dtype=np.int64)
    for lo in range(0, count, RAY_BATCH_LIMIT):
        hi = min(lo + RAY_BATCH_LIMIT, count)
        hits = pybullet.rayTestBatch(starts[lo:hi], ends[lo:hi], numThreads=threads, physicsClientId=client)
        if len(hits) != hi - lo:
            raise RuntimeError(f"rayTestBatch returned {len(hits)} results for {hi - lo} rays")
        bodies[lo:hi] = [h[0] for h in hits]
        links[lo:hi] = [h[1] for h in hits]
        fractions[lo:hi] = [h[2] for h in hits]
    fractions[bodies < 0] = 1.0
    return fractions, bodies, links


def retro(table, bodies, links):
    """Gazebo ``laser_retro`` of each hit (body, link) in ``table`` ({(body, link): value}; 0 where none is
    given, and for misses)."""
    import numpy as np

    if not table:
        return np.zeros(len(bodies))
    return np.array([table.get((b, k), 0.0) for b, k in zip(bodies.tolist(), links.tolist())], dtype=float)


def moving_state(client, robots, bodies):
    """{body: (position, orientation, ((joint, position), ...))} of every robot of ``robots`` and every body id
    of ``bodies`` (PyBullet's base frame): what the ray process's mirror must match before it casts."""
    state = {}
    for robot in robots:
        joints = sorted(robot.joint_index.values())
        positions = robot.joint_states(joints)[0] if joints else []
        state[robot.body] = (*pybullet.getBasePositionAndOrientation(robot.body, physicsClientId=client),
                             tuple(zip(joints, positions)))
    for uid in bodies:
        state[uid] = (*pybullet.getBasePositionAndOrientation(uid, physicsClientId=client), ())
    return state


class RayProcessLink:
    """A world's link to the ray process (:mod:`diffbot_sim.physics.ray_process`): each change of the world's
    bodies is sent as it is made once the process runs, kept in a journal until it starts, or dropped when
    it never will; casts are handed over with the world's moving state.

    Args:
        keep: keep a journal of the changes for a ray process started later (False: none will be).
    """

    def __init__(self, keep):
        self.helper = None  # the ray process (physics.ray_process.RayProcess), once started
        # What the ray process must replay to build this world, kept until it starts; None: never
        self.journal = [] if keep else None
        self._state_sent = None  # the world's step count when the mirror was last sent the state

    def record(self, request, *args):
        """A change of the world's bodies (a ``RayProcess`` request: "replay", "remove", "plane"): sent now,
        kept for when the process starts, or dropped. A kept body that is removed again leaves the journal (a
        fast-mode run that spawns and deletes models for hours keeps nothing of them)."""
        if self.helper is not None:
            getattr(self.helper, request)(*args)
        elif self.journal is not None:
            if request == "remove":
                made = [k for k, (kind, entry) in enumerate(self.journal)
                        if kind == "replay" and entry[2] == [args[0]]]
                if made:
                    del self.journal[made[-1]]
                    return
            self.journal.append((request, args))

    def start(self, time_step, gravity):
        """Start the ray process, built from every change recorded so far (nothing when it runs already)."""
        if self.helper is not None:
            return
        from diffbot_sim.physics.ray_process import RayProcess
        helper = RayProcess(time_step, gravity)
        for request, args in self.journal or ():
            getattr(helper, request)(*args)
        self.helper, self.journal = helper, None

    def cast(self, steps, state, key, directions, near, far, position, rotation):
        """Hand a ray sensor's rays to the ray process (as ``World.cast_later``); ``steps`` is the world's step
        count and ``state()`` its :func:`moving_state`, sent with the first cast after each step."""
        sent = None
        if self._state_sent != steps:
            sent, self._state_sent = state(), steps
        return self.helper.cast(sent, key, directions, near, far, position, rotation)

    def close(self):
        if self.helper is not None:
            self.helper.close()
            self.helper = None
