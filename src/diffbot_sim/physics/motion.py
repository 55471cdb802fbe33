"""Moving a world's bodies from outside the physics (the /gazebo services): a world body's motion read and
set through its link frame, and wrenches applied for the coming step."""
from diffbot_sim.physics.building import link_pose, place
from diffbot_sim.physics.client import pybullet
from diffbot_sim.physics.robot import point_velocity


def body_motion(client, uid, inertial_pose):
    """Body ``uid``'s link frame (its inertial frame at ``inertial_pose``): (pose, linear velocity of its
    origin, angular velocity), world axes (as Robot.link_motion)."""
    com, _ = pybullet.getBasePositionAndOrientation(uid, physicsClientId=client)
    linear, angular = pybullet.getBaseVelocity(uid, physicsClientId=client)
    pose = link_pose(client, uid, inertial_pose)
    v = point_velocity(linear, angular, [pose[0][i] - com[i] for i in range(3)])
    return (tuple(pose[0]), tuple(pose[1])), v, tuple(angular)


def set_body_motion(client, uid, inertial_pose, pose, linear, angular):
    """Teleport body ``uid``'s link frame to ``pose`` with the given velocity of its origin (world axes); a
    static body only moves."""
    place(client, uid, pose, inertial_pose)
    com, _ = pybullet.getBasePositionAndOrientation(uid, physicsClientId=client)
    v = point_velocity(linear, angular, [com[i] - pose[0][i] for i in range(3)])
    pybullet.resetBaseVelocity(uid, v, angular, physicsClientId=client)


def apply_wrench(client, uid, link, force, torque, point=None):
    """Push body ``uid`` (PyBullet link index ``link``) for the coming step: ``force`` [N] at the world ``point``
    (None: the link's centre of mass, as Gazebo's Link::SetForce) and ``torque`` [N·m], world axes (PyBullet
    clears external forces after each step)."""
    if point is None:
        point = (pybullet.getBasePositionAndOrientation(uid, physicsClientId=client)[0] if link == -1
                 else pybullet.getLinkState(uid, link, physicsClientId=client)[0])
    if any(force):
        pybullet.applyExternalForce(uid, link, force, point, pybullet.WORLD_FRAME, physicsClientId=client)
    if any(torque):
        pybullet.applyExternalTorque(uid, link, torque, pybullet.WORLD_FRAME, physicsClientId=client)
