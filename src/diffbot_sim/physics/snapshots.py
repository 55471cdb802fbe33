"""Putting a PyBullet world back without memory of what came before: PyBullet's in-memory snapshots, and
dropping the contact caches a reset to the start would otherwise inherit."""
from diffbot_sim.physics.client import pybullet

#: m above the world where :func:`forget_contacts` parks the moving bodies to drop their contacts
FAR_AWAY = 1.0e5


def save_state(client):
    """Snapshot every body's pose, velocity and joint positions and velocities, and the contact caches
    (PyBullet's in-memory ``saveState``); returns its id for :func:`restore_state`.

    A snapshot does not hold motor targets and modes, ``changeDynamics`` values (a robot's landing damping),
    gravity or the time step: after a restore the motors keep what was last set
    (https://github.com/bulletphysics/bullet3/issues/4364), so the caller sets them again. Bodies may not be
    added or removed between save and restore.
    """
    return pybullet.saveState(physicsClientId=client)


def restore_state(client, state):
    """Put every body back as snapshot ``state`` (:func:`save_state`) holds it."""
    pybullet.restoreState(stateId=state, physicsClientId=client)


def discard_state(client, state):
    """Free snapshot ``state``."""
    pybullet.removeState(state, physicsClientId=client)


def forget_contacts(client, moving):
    """Drop the contact points Bullet keeps from step to step for each touching pair (with their impulses, to
    warm-start its solver) of the bodies ``moving``: each is taken far away, apart from the others and from
    everything else, and the contacts recomputed. The caller puts them back where they belong."""
    for k, uid in enumerate(moving):
        pybullet.resetBasePositionAndOrientation(uid, (0.0, 10.0 * k, FAR_AWAY), (0.0, 0.0, 0.0, 1.0),
                                                 physicsClientId=client)
    pybullet.performCollisionDetection(physicsClientId=client)
