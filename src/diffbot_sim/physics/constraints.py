"""Joining two bodies where they are: the link attacher's fixed joint.

gazebo_ros_link_attacher creates a joint between two links at their current relative pose, limits 0..0 (rigid),
and detaching releases it. Here: a PyBullet fixed constraint between the two links' centre-of-mass frames (the
frames constraints use), at their relative pose now, removed on release.
"""
from diffbot_sim.physics.client import pybullet

#: N: the constraint's force limit, far above any load a gripper carries (a fixed joint in Gazebo has none).
MAX_FORCE = 1e5


def _com_frame(client, body, link):
    if link == -1:
        return pybullet.getBasePositionAndOrientation(body, physicsClientId=client)
    state = pybullet.getLinkState(body, link, physicsClientId=client)
    return state[0], state[1]


def fix_together(client, body1, link1, body2, link2):
    """A fixed constraint holding ``body2``'s ``link2`` to ``body1``'s ``link1`` as they are now; its id."""
    frame1, frame2 = _com_frame(client, body1, link1), _com_frame(client, body2, link2)
    inverse = pybullet.invertTransform(*frame1)
    rel = pybullet.multiplyTransforms(inverse[0], inverse[1], frame2[0], frame2[1])
    cid = pybullet.createConstraint(body1, link1, body2, link2, pybullet.JOINT_FIXED, (0, 0, 0), rel[0], (0, 0, 0),
                                    rel[1], (0, 0, 0, 1), physicsClientId=client)
    pybullet.changeConstraint(cid, maxForce=MAX_FORCE, physicsClientId=client)
    return cid


def release(client, cid):
    pybullet.removeConstraint(cid, physicsClientId=client)
