"""The names Gazebo gives a URDF's collisions, and which collision a contact sensor's ``<collision>`` means (pure).

A ``<sensor type="contact">`` names a collision as the SDF model has it, after sdformat's URDF reader (sdf9,
Gazebo 11's) lumped every fixed joint's child into its parent (``parser_urdf.cc``):

* a link's collisions are its own first, then each fixed child's (depth first, children in URDF order),
  the child's already holding its own fixed children's; a lumped collision is named after the URDF link it
  came from;
* each becomes ``<name>_collision`` (``_<n>`` added from the second on), and one whose name does not start
  with the link's gets the link's name and ``_fixed_joint_lump__`` in front:
  ``base_footprint_fixed_joint_lump__base_link_collision``;
* a contact sensor on a lumped link moves to the parent; if its ``<collision>`` was ``<link>_collision`` it is
  rewritten to ``<parent>_collision_<link>``, a name no collision has (sdformat's FIXME): such a sensor sees
  nothing in Gazebo, and here;
* ``<gazebo reference="joint"><preserveFixedJoint>true`` (or ``disableFixedJointLumping``) keeps a fixed joint.

URDF ``<collision name="...">`` attributes are not read here (the model keeps none): collisions are named after
their links, as in most published URDFs.
"""
from typing import NamedTuple

LUMP = "_fixed_joint_lump__"
COLLISION = "_collision"
_KEEP_TAGS = ("preserveFixedJoint", "disableFixedJointLumping")


class GazeboCollision(NamedTuple):
    """One SDF collision: its name in the Gazebo link ``link``, the URDF link it came from and its index there
    (``urdf_index``: ``index`` would hide the tuple's own ``index()`` method)."""

    name: str
    link: str
    urdf_link: str
    urdf_index: int


def kept_fixed_joints(model):
    """Fixed joints a ``<gazebo reference>`` keeps (preserveFixedJoint / disableFixedJointLumping true)."""
    kept = set()
    for block in model.gazebo:
        if block.reference in model.joints:
            for child in block.element:
                if child.tag in _KEEP_TAGS and (child.text or child.get("value") or "").strip() in ("true", "1"):
                    kept.add(block.reference)
    return kept


def gazebo_links(model):
    """({URDF link: the Gazebo link it became part of}, {Gazebo link: [GazeboCollision, ...]}) of ``model``."""
    kept = kept_fixed_joints(model)
    children: dict[str, list[tuple[str, object]]] = {}
    for joint in model.joints.values():  # URDF order
        children.setdefault(joint.parent, []).append((joint.child, joint))

    def lumped(joint):
        return joint.type == "fixed" and joint.name not in kept and joint.parent != "world"

    owner: dict[str, str] = {}
    raw: dict[str, list[tuple[str, str, int]]] = {}  # Gazebo link -> [(base name, URDF link, index)]

    def reduce(link, into):
        owner[link] = into
        entries = [(link, link, i) for i in range(len(model.links[link].collisions))] if link in model.links else []
        for child, joint in children.get(link, ()):
            if lumped(joint):
                entries += reduce(child, into)
        for child, joint in children.get(link, ()):
            if not lumped(joint):
                raw.setdefault(child, []).extend(reduce(child, child))
        return entries

    raw.setdefault(model.root, []).extend(reduce(model.root, model.root))
    named: dict[str, list[GazeboCollision]] = {}
    for link, entries in raw.items():
        out = []
        for count, (base, urdf_link, index) in enumerate(entries):
            name = base + COLLISION + (f"_{count}" if count else "")
            if not name.startswith(link):
                name = link + LUMP + name
            out.append(GazeboCollision(name, link, urdf_link, index))
        named[link] = out
    return owner, named


def sensor_collision(model, sensor_link, collision):
    """The collision a contact sensor on ``sensor_link`` names: (GazeboCollision or None, the name as Gazebo
    reads it). None: no such collision in the sensor's (Gazebo) link, and Gazebo's sensor sees nothing."""
    owner, named = gazebo_links(model)
    link = owner.get(sensor_link, sensor_link)
    name = collision.strip()
    if link != sensor_link and name == sensor_link + COLLISION:
        name = f"{link}{COLLISION}_{sensor_link}"  # sdformat's rewrite of a lumped link's contact sensor
    found: GazeboCollision | None = next((c for c in named.get(link, ()) if c.name == name), None)
    return found, name
