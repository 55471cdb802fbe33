"""Questions asked of a PyBullet world's geometry, moving nothing: the top surface under a point, a body's
bounds, whether a spot is free of bodies, what a body touches."""
from diffbot_sim.physics.client import pybullet, quiet


def top_at(client, x, y, ignore=()):
    """Height [m] of the highest surface at (x, y) (a ray from 100 m down), bodies in ``ignore`` not counted;
    0 when none."""
    hits = pybullet.rayTestBatch([(x, y, 100.0)], [(x, y, -100.0)], physicsClientId=client)
    top = 0.0
    for hit in hits:
        if hit[0] >= 0 and hit[0] not in ignore:
            top = max(top, hit[3][2])
    return top


def bounds(client, uid):
    """Axis-aligned box (lo (x, y, z), hi (x, y, z)) [m], world axes, around every link of body ``uid``
    (PyBullet's collision bounds; an infinite plane reads about +-1e30)."""
    boxes = [pybullet.getAABB(uid, link, physicsClientId=client)
             for link in range(-1, pybullet.getNumJoints(uid, physicsClientId=client))]
    lo = tuple(min(box[0][i] for box in boxes) for i in range(3))
    hi = tuple(max(box[1][i] for box in boxes) for i in range(3))
    return lo, hi


def free_of_bodies(client, points, radius, bottom, top, ignore=()):
    """For each (x, y) of ``points``: True when an upright cylinder of ``radius`` [m] from height ``bottom`` to
    ``top`` [m] there touches no body other than those in ``ignore`` (PyBullet ids), judged on collision shapes
    (the broadphase names the candidates, then their closest points)."""
    c = client
    height = top - bottom
    shape = pybullet.createCollisionShape(pybullet.GEOM_CYLINDER, radius=radius, height=height, physicsClientId=c)
    ignore = set(ignore)
    free = []
    try:
        for x, y in points:
            z = bottom + height / 2.0
            lo, hi = (x - radius, y - radius, bottom), (x + radius, y + radius, top)
            candidates = {(uid, link) for uid, link in
                          (pybullet.getOverlappingObjects(lo, hi, physicsClientId=c) or ())
                          if uid not in ignore}
            free.append(not any(pybullet.getClosestPoints(
                bodyA=-1, bodyB=uid, distance=0.0, linkIndexB=link, collisionShapeA=shape,
                collisionShapePositionA=(x, y, z), physicsClientId=c) for uid, link in candidates))
    finally:
        with quiet(1), quiet(2):  # PyBullet prints a "TODO: dealloc" warning for every removed shape
            pybullet.removeCollisionShape(shape, physicsClientId=c)
    return free


def touching(client, body, ignore=()):
    """PyBullet ids of the bodies that body ``body`` touches or penetrates after the last step (a contact point
    at distance <= 0), other than itself and those in ``ignore``: a frozenset."""
    return frozenset(point[2] for point in pybullet.getContactPoints(bodyA=body, physicsClientId=client)
                     if point[8] <= 0.0 and point[2] != body and point[2] not in ignore)
