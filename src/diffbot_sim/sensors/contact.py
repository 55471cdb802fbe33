"""Contact sensors (``<sensor type="contact">``): what Gazebo's ContactSensor and gazebo_ros_bumper report of a
step's contacts (pure; plain tuples in and out).

Per pair of collisions one state, as Gazebo's contact message has it: ``collision1`` the sensor's collision,
``collision2`` the other; for every contact point its position and normal in the world frame (the normal
pointing from collision2 toward collision1, as ODE's), its depth, and the wrench on collision1's link in
that link's frame (ODEPhysics rotates the force and the torque about the link's centre of mass into the link
frame); the state's total is their sum. gazebo_ros_bumper publishes these values unchanged: its ``frameName``
only labels the message (the transformation into it is commented out upstream).
"""
from typing import NamedTuple

from diffbot_sim.transforms import quaternion_matrix

Vec3 = tuple[float, float, float]


class ContactState(NamedTuple):
    collision1: str
    collision2: str
    positions: list[Vec3]
    normals: list[Vec3]
    depths: list[float]
    wrenches: list[tuple[Vec3, Vec3]]  # (force, torque) on collision1's link, in its frame
    total: tuple[Vec3, Vec3]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _rotate_back(rotation, v):
    """R^T v for a 3x3 rotation (rows) ``rotation``."""
    return tuple(sum(rotation[r][c] * v[r] for r in range(3)) for c in range(3))


def contact_states(points, collision1, name_of, com_position, com_quaternion):
    """One ContactState per other collision touching the sensor's, in the order first met.

    Args:
        points: the step's contact points (``physics.contacts.ContactPoint``-like: other, other_link, position,
            normal, depth, force; world frame, force on the sensor's link).
        collision1: the sensor collision's scoped name (``model::link::collision``).
        name_of: (other body, other link) -> the other collision's scoped name.
        com_position, com_quaternion: the sensor link's centre of mass frame in the world (xyzw).
    """
    rotation = quaternion_matrix(com_quaternion)
    groups = {}
    for p in points:
        groups.setdefault((p.other, p.other_link), []).append(p)
    out = []
    for (other, other_link), group in groups.items():
        wrenches = []
        for p in group:
            arm = tuple(p.position[i] - com_position[i] for i in range(3))
            wrenches.append((_rotate_back(rotation, p.force), _rotate_back(rotation, _cross(arm, p.force))))
        total = (tuple(sum(w[0][i] for w in wrenches) for i in range(3)),
                 tuple(sum(w[1][i] for w in wrenches) for i in range(3)))
        out.append(ContactState(collision1, name_of(other, other_link), [p.position for p in group],
                                [p.normal for p in group], [p.depth for p in group], wrenches, total))
    return out
