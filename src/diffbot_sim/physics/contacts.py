"""Contact queries for contact sensors: what touches one link of a robot in the last physics step.

PyBullet's getContactPoints gives, per point of a pair (A = the robot's link, B = the other body): the point on
A, the normal on B pointing toward A, the signed distance (negative: penetration), the normal force and two
friction forces along their directions. A sensor reads them as plain tuples: :class:`ContactPoint`.
"""
from typing import NamedTuple

from diffbot_sim.physics.client import pybullet

Vec3 = tuple[float, float, float]


class ContactPoint(NamedTuple):
    """One contact point of a robot link with another body, world frame.

    Attributes:
        other: the other body's PyBullet id; other_link: its link index (-1: its base).
        position: the point on the robot's link [m]. normal: unit normal pointing from the other body toward the
        robot's link. depth: penetration [m] (>= 0 when touching). force: the force on the robot's link [N]
        (normal and friction).
    """

    other: int
    other_link: int
    position: Vec3
    normal: Vec3
    depth: float
    force: Vec3


def link_contact_points(robot, link):
    """The contact points of URDF ``link`` (its PyBullet carrier) with every other body in the last step."""
    index = robot.link_carrier(link)
    out = []
    for point in pybullet.getContactPoints(bodyA=robot.body, linkIndexA=index, physicsClientId=robot.client):
        other = point[2]
        if other == robot.body:
            continue
        normal, fn, f1, d1, f2, d2 = point[7], point[9], point[10], point[11], point[12], point[13]
        force = tuple(fn * normal[i] + f1 * d1[i] + f2 * d2[i] for i in range(3))
        out.append(ContactPoint(other, point[4], tuple(point[5]), tuple(normal), max(0.0, -point[8]), force))
    return out


def link_com_pose(robot, link):
    """World (position, quaternion xyzw) of the centre of mass frame of URDF ``link``'s carrier (the frame
    a contact's torque is taken about, as ODE takes it about the body's centre of mass)."""
    index = robot.link_carrier(link)
    if index == -1:
        return pybullet.getBasePositionAndOrientation(robot.body, physicsClientId=robot.client)
    state = pybullet.getLinkState(robot.body, index, physicsClientId=robot.client)
    return state[0], state[1]
