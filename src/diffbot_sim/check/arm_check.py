"""Judging an arm by its body: where each link is (the physics' ground truth) against where joint_states and
the URDF put it (what robot_state_publisher draws in TF).

Pure: :func:`forward_kinematics` walks the URDF's joint tree from the root (a fixed joint: its origin; a
revolute or continuous one: its origin, then a turn about its axis; a prismatic one: a slide along its axis;
a joint without a position in ``positions``: at 0, or its URDF ``<mimic>`` of one that has one), as
robot_state_publisher does. :func:`pose_errors` compares those poses with measured ones.
"""
import math
from typing import NamedTuple

from diffbot_sim.transforms import compose, inverse, qconj, qmul, rpy_quaternion

IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def _axis_rotation(axis, angle):
    norm = math.sqrt(sum(a * a for a in axis)) or 1.0
    s = math.sin(angle / 2.0) / norm
    return (axis[0] * s, axis[1] * s, axis[2] * s, math.cos(angle / 2.0))


def joint_position(model, name, positions):
    """A joint's position: given, else its URDF mimic of a given one, else 0 (rad or m)."""
    if name in positions:
        return positions[name]
    joint = model.joints[name]
    if joint.mimic is not None and joint.mimic.joint in positions:
        return joint.mimic.multiplier * positions[joint.mimic.joint] + joint.mimic.offset
    return 0.0


def joint_transform(joint, position):
    """Child link frame in the parent link frame for ``joint`` at ``position``."""
    origin = (tuple(joint.xyz), rpy_quaternion(*joint.rpy))
    if joint.type in ("revolute", "continuous"):
        return compose(origin, ((0.0, 0.0, 0.0), _axis_rotation(joint.axis, position)))
    if joint.type == "prismatic":
        norm = math.sqrt(sum(a * a for a in joint.axis)) or 1.0
        return compose(origin, (tuple(a / norm * position for a in joint.axis), (0.0, 0.0, 0.0, 1.0)))
    return origin


def forward_kinematics(model, positions):
    """{link: pose in the root link's frame} for joint ``positions`` ({joint: rad or m})."""
    children = {}
    for joint in model.joints.values():
        children.setdefault(joint.parent, []).append(joint)
    poses = {model.root: IDENTITY}
    stack = [model.root]
    while stack:
        link = stack.pop()
        for joint in children.get(link, ()):
            poses[joint.child] = compose(poses[link], joint_transform(joint, joint_position(model, joint.name,
                                                                                           positions)))
            stack.append(joint.child)
    return poses


class PoseError(NamedTuple):
    distance: float  # m between the two origins
    angle: float  # rad between the two orientations


def pose_error(a, b):
    """How far pose ``b`` is from pose ``a``."""
    d = math.sqrt(sum((a[0][i] - b[0][i]) ** 2 for i in range(3)))
    q = qmul(qconj(a[1]), b[1])
    angle = 2.0 * math.atan2(math.sqrt(q[0] ** 2 + q[1] ** 2 + q[2] ** 2), abs(q[3]))
    return PoseError(d, angle)


def pose_errors(model, positions, measured) -> dict[str, PoseError]:
    """For each link of ``measured`` ({link: world pose}, the physics' ground truth, with the root among
    them): the error of the pose joint_states + the URDF give it, both taken relative to the root."""
    fk = forward_kinematics(model, positions)
    root = inverse(measured[model.root])
    return {link: pose_error(fk[link], compose(root, pose)) for link, pose in measured.items() if link in fk}
