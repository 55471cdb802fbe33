"""Gazebo's reading of a URDF's fixed joints, as URDF text PyBullet loads faithfully (pure; numpy only).

Gazebo (sdformat's URDF reader) *lumps* the child of every fixed joint into its parent: one body whose mass
is the sum, whose inertia is the combined tensor about the combined centre of mass, and which carries the
child's collisions, each keeping the child's own surface (``mu1``, ``kp``, ...). PyBullet can lump too
(``URDF_MERGE_FIXED_LINKS``), but then the merged body has one friction for all its shapes, and a link
without ``<inertial>`` counts as 1 kg. So we lump ourselves, before PyBullet sees the text:

* a fixed child whose collisions share the surface of the body it joins (or that has no collision) is
  lumped: inertials combined, collisions and visuals moved with their origins composed, its child joints
  re-attached; its frame is remembered (``frames``) so sensors can still be mounted on it;
* a fixed joint ``<gazebo reference>`` keeps (``preserveFixedJoint``, ``disableFixedJointLumping``) stays a
  PyBullet fixed joint, as sdformat keeps it;
* a fixed child whose collisions have a surface of their own stays a separate PyBullet link on a fixed
  joint (rigid in PyBullet's Featherstone multibody), so its shapes keep their friction;
* a link without ``<inertial>`` adds no mass: lumped, it adds nothing; kept for its surface on a fixed joint,
  it gets mass 0 (Gazebo lumps it); kept on a movable joint, it gets PLACEHOLDER_MASS so the joint stays
  well-conditioned; a root left without mass gets ROOT_PLACEHOLDER_MASS (0 would make PyBullet treat the
  whole robot as static);
* an inertia-less root (``base_footprint``, or a ``base_link`` whose mass sits in an ``inertial_link`` or a
  ``chassis_link``) takes its fixed children like any link: Gazebo makes them one body. Kept apart, a 1e-6 kg
  PyBullet base carried the robot's mass through fixed joints, and the wheels hung on that base.

* a robot joined to the world (a URDF ``world`` link, :data:`~diffbot_sim.description.urdf_model.WORLD_LINK`)
  is never lumped into it, as sdformat lumps nothing into the world: with one fixed joint from ``world`` the
  world link and that joint are left out (the root given is its child, which PyBullet then holds fixed);
  otherwise ``world`` is the root, a massless stand-in PyBullet holds fixed, whose children each stay a link
  of their own.

Measured with 10 fixed sensor links: lumping keeps PyBullet's step rate (no extra links), where loading
them unmerged costs ~25 %.
"""
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

import numpy as np

from diffbot_sim.description.urdf_model import WORLD_LINK
from diffbot_sim.transforms import matrix_rpy, rpy_matrix

#: Mass [kg] of a root link left without any: PyBullet treats a base of mass 0 as fixed in the world.
ROOT_PLACEHOLDER_MASS = 1e-6
#: Mass [kg] of an inertia-less link on a movable joint (Gazebo drops such links; we keep the joint).
PLACEHOLDER_MASS = 1e-4
#: Tags whose values decide whether two links' collisions behave alike in PyBullet.
SURFACE_KEYS = ("mu1", "mu2", "kp", "kd")


@dataclass
class LumpedUrdf:
    """The text to load and where every link of the original URDF ended up.

    ``frames[name] = (body_link, xyz, quaternion xyzw)``: the pose of link ``name``'s frame in the frame of
    ``body_link``, the link that carries it in PyBullet (itself, identity, when it was not lumped).
    """

    text: str
    frames: dict[str, tuple[str, tuple[float, float, float], tuple[float, float, float, float]]]
    lumped: list[str] = field(default_factory=list)  # links merged into another
    placeholders: list[str] = field(default_factory=list)  # links given a placeholder mass


def matrix_quaternion(m):
    """(x, y, z, w) of a rotation matrix."""
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0:
        s = math.sqrt(trace + 1.0) * 2
        w, x, y, z = 0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        w, x, y, z = (m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        w, x, y, z = (m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        w, x, y, z = (m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s
    return x, y, z, w


def _numbers(text, count, default):
    if text is None:
        return default
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        return default
    return values if len(values) == count else default


def origin_matrix(element):
    """4x4 transform of an element's ``<origin xyz rpy>`` (identity when absent)."""
    t = np.eye(4)
    origin = element.find("origin") if element is not None else None
    if origin is not None:
        t[:3, :3] = rpy_matrix(_numbers(origin.get("rpy"), 3, (0.0, 0.0, 0.0)))
        t[:3, 3] = _numbers(origin.get("xyz"), 3, (0.0, 0.0, 0.0))
    return t


def _set_origin(element, t):
    origin = element.find("origin")
    if origin is None:
        origin = ET.Element("origin")
        element.insert(0, origin)
    origin.set("xyz", " ".join(repr(float(v)) for v in t[:3, 3]))
    origin.set("rpy", " ".join(repr(float(v)) for v in matrix_rpy(t[:3, :3])))


def read_inertial(link):
    """(mass, com xyz in the link frame, 3x3 inertia about the com in the link's axes), or None."""
    inertial = link.find("inertial")
    if inertial is None:
        return None
    mass_el = inertial.find("mass")
    mass = float(mass_el.get("value")) if mass_el is not None and mass_el.get("value") else 0.0
    t = origin_matrix(inertial)
    el = inertial.find("inertia")
    get = (lambda k: float(el.get(k, 0.0) or 0.0)) if el is not None else (lambda k: 0.0)
    local = np.array([[get("ixx"), get("ixy"), get("ixz")],
                      [get("ixy"), get("iyy"), get("iyz")],
                      [get("ixz"), get("iyz"), get("izz")]])
    r = t[:3, :3]
    return mass, t[:3, 3].copy(), r @ local @ r.T


def combine_inertials(parts):
    """Sum of (mass, com, inertia-about-com) parts given in one frame: the lumped body's, or None for no
    mass. Inertias move to the common centre of mass by the parallel-axis theorem."""
    parts = [p for p in parts if p is not None and p[0] > 0]
    if not parts:
        return None
    mass = sum(p[0] for p in parts)
    com = sum(p[0] * p[1] for p in parts) / mass
    inertia = np.zeros((3, 3))
    for m, c, i in parts:
        d = c - com
        inertia += i + m * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    return mass, com, inertia


def _write_inertial(link, combined):
    old = link.find("inertial")
    if old is not None:
        link.remove(old)
    if combined is None:
        return
    mass, com, inertia = combined
    # Principal axes: PyBullet reads a diagonal tensor in the frame of <origin rpy> (measured: a full tensor's
    # products of inertia change how the robot drives), so write that form.
    moments, axes = np.linalg.eigh((inertia + inertia.T) / 2.0)
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    inertial = ET.Element("inertial")
    ET.SubElement(inertial, "origin", xyz=" ".join(repr(float(v)) for v in com),
                  rpy=" ".join(repr(float(v)) for v in matrix_rpy(axes)))
    ET.SubElement(inertial, "mass", value=repr(float(mass)))
    ET.SubElement(inertial, "inertia", ixx=repr(float(max(moments[0], 0.0))), ixy="0", ixz="0",
                  iyy=repr(float(max(moments[1], 0.0))), iyz="0", izz=repr(float(max(moments[2], 0.0))))
    link.insert(0, inertial)


def _placeholder(link, mass):
    size = 1e-2  # a 1 cm sphere's inertia: small, yet well above PyBullet's numerical floor
    i = repr(0.4 * mass * (size / 2) ** 2)
    _write_inertial(link, (mass, np.zeros(3), np.diag([float(i)] * 3)))


def _transform_inertial(part, t):
    if part is None:
        return None
    mass, com, inertia = part
    r = t[:3, :3]
    return mass, r @ com + t[:3, 3], r @ inertia @ r.T


def preserved_fixed_joints(root):
    """Fixed joints sdformat keeps: ``<gazebo reference="joint"><preserveFixedJoint>true`` (or the older
    ``disableFixedJointLumping``), e.g. the joint of a force-torque sensor, which must exist to be measured."""
    kept = set()
    for block in root.findall("gazebo"):
        for child in block:
            if child.tag in ("preserveFixedJoint", "disableFixedJointLumping") and \
                    (child.text or child.get("value") or "").strip() in ("true", "1"):
                kept.add(block.get("reference"))
    return kept


def lump(urdf_text, root_link, surface):
    """Lump fixed-joint children as described in the module docstring.

    Args:
        urdf_text: the URDF (mesh paths already resolved).
        root_link: the model's root link name (RobotModel.root); links and joints not below it (the ``world``
            link and its joint of a robot held by one fixed joint to the world) are left out.
        surface: ``surface(link) -> dict`` of the link's Gazebo surface tags (RobotModel.surface).

    Returns:
        LumpedUrdf.
    """
    root = ET.fromstring(urdf_text)
    links = {el.get("name"): el for el in root.findall("link")}
    joints = root.findall("joint")
    kept = preserved_fixed_joints(root)
    children = {}
    for joint in joints:
        parent = joint.find("parent").get("link")
        children.setdefault(parent, []).append(joint)

    def key(name):
        values = surface(name)
        return tuple(values.get(k) for k in SURFACE_KEYS)

    body = {root_link: root_link}  # link -> the link that carries it
    offset = {root_link: np.eye(4)}  # link frame in its body's frame
    order = [root_link]
    lumped = []
    index = 0
    while index < len(order):
        name = order[index]
        index += 1
        for joint in children.get(name, []):
            child = joint.find("child").get("link")
            if child not in links or child in body:
                continue
            t = offset[name] @ origin_matrix(joint)
            carrier = body[name]
            has_collision = links[child].find("collision") is not None
            if (joint.get("type") == "fixed" and name != WORLD_LINK and joint.get("name") not in kept
                    and (not has_collision or key(child) == key(carrier))):
                body[child], offset[child] = carrier, t
                lumped.append(child)
            else:
                body[child], offset[child] = child, np.eye(4)
            order.append(child)

    # Inertials: every link's part, expressed in its body's frame, combined per body.
    parts = {}
    for name in order:
        part = _transform_inertial(read_inertial(links[name]), offset[name])
        parts.setdefault(body[name], []).append(part)

    for name, el in links.items():
        if name not in body:  # above the root: the world link of a robot fixed to the world
            root.remove(el)
    for joint in list(joints):
        if joint.find("parent").get("link") not in body:
            root.remove(joint)
            joints.remove(joint)
    for name in lumped:
        el, carrier = links[name], links[body[name]]
        for tag in ("visual", "collision"):
            for item in el.findall(tag):
                _set_origin(item, offset[name] @ origin_matrix(item))
                carrier.append(item)
        root.remove(el)
    for joint in list(joints):
        parent, child = joint.find("parent").get("link"), joint.find("child").get("link")
        if child in lumped:
            root.remove(joint)
        elif parent in lumped:
            _set_origin(joint, offset[parent] @ origin_matrix(joint))
            joint.find("parent").set("link", body[parent])

    placeholders = []
    on_fixed_joint = {j.find("child").get("link") for j in joints if j.get("type") == "fixed"}
    for name, el in links.items():
        if name in lumped or name not in body:
            continue
        own = parts.get(name, [])
        combined = combine_inertials(own)
        if combined is not None and len(own) == 1 and own[0] is not None and own[0][0] > 0:
            pass  # nothing lumped into it: its <inertial> stays as written (PyBullet reads it as Gazebo does)
        elif combined is not None:
            _write_inertial(el, combined)
        else:
            placeholders.append(name)
            if name in on_fixed_joint:
                _placeholder(el, 0.0)  # kept for its surface only: Gazebo lumps it, adding no mass
            else:
                _placeholder(el, ROOT_PLACEHOLDER_MASS if name == root_link else PLACEHOLDER_MASS)

    frames = {}
    for name in order:
        t = offset[name]
        frames[name] = (body[name], tuple(float(v) for v in t[:3, 3]), matrix_quaternion(t[:3, :3]))
    return LumpedUrdf(ET.tostring(root, encoding="unicode"), frames, lumped, placeholders)
