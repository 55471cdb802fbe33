"""The robot description as plain data: links, joints, transmissions and ``<gazebo>`` blocks.

Pure (no rospy, no PyBullet). We parse the URDF with ElementTree rather than urdf_parser_py because we need
what that library drops: ``mechanicalReduction`` (its ``Actuator`` discards it), every ``<gazebo>`` element
(plugins and per-link surface tags), and an element path for every error. Errors are ``ModelError`` naming
the source and the element, e.g. ``/robot/transmission[@name='left_trans']/joint[@name='nope']``.
"""
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.values import tag_number

#: Per-link ``<gazebo reference>`` tags that carry a number (ODE surface and contact parameters).
SURFACE_NUMBERS = ("mu1", "mu2", "kp", "kd", "minDepth", "maxVel", "laserRetro")


def tag_value(element):
    """The value of a Gazebo tag in either form: ``<mu1>0.5</mu1>`` or ``<mu1 value="0.5"/>``."""
    text = (element.text or "").strip()
    if not text and element.get("value") is not None:
        text = element.get("value").strip()
    return text


#: The link name by which a URDF joins a robot to the world: sdformat's URDF reader models no link of that name
#: but turns each joint from it into a joint between the model and the world (the model is held where it is
#: spawned), and never lumps a link into it (the first real link keeps its name).
WORLD_LINK = "world"

#: Joint interfaces a transmission may declare (ros_control's, without the ``hardware_interface/`` prefix).
JOINT_INTERFACES = ("VelocityJointInterface", "EffortJointInterface", "PositionJointInterface")

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class Geometry:
    """A collision shape: ``kind`` is cylinder, sphere, box or mesh; sizes in m."""

    kind: str
    radius: float | None = None
    length: float | None = None


@dataclass
class Link:
    name: str
    mass: float | None  # None: the link has no <inertial> (e.g. base_footprint)
    collisions: list[Geometry] = field(default_factory=list)


@dataclass(frozen=True)
class Mimic:
    """A URDF ``<mimic joint multiplier offset>``: position = multiplier * position(joint) + offset."""

    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class SafetyController:
    """A URDF ``<safety_controller>``: the soft limits ros_control's joint_limits_interface reads from it."""

    k_velocity: float
    k_position: float = 0.0
    soft_lower_limit: float = 0.0
    soft_upper_limit: float = 0.0


@dataclass
class Joint:
    name: str
    type: str
    parent: str
    child: str
    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)
    axis: Vec3 = (1.0, 0.0, 0.0)
    effort_limit: float | None = None  # N·m (or N); None when the URDF gives no <limit effort>
    velocity_limit: float | None = None  # rad/s (or m/s)
    has_limit: bool = False  # the joint has a <limit> element (joint_limits_interface reads limits only then)
    lower: float = 0.0  # rad (or m), <limit lower>; URDF's default 0
    upper: float = 0.0  # rad (or m), <limit upper>
    mimic: Mimic | None = None
    safety: SafetyController | None = None

    @property
    def movable(self):
        return self.type not in ("fixed", "floating", "planar")

    @property
    def has_position_limits(self):
        """Revolute and prismatic joints with a <limit> are bounded (continuous ones wrap around)."""
        return self.has_limit and self.type in ("revolute", "prismatic")


@dataclass
class Transmission:
    """One ros_control SimpleTransmission: actuator <-> joint with reduction n.

    joint velocity = actuator velocity / n; joint effort = n * actuator effort;
    joint position = actuator position / n + offset (ros_control's simple_transmission.h).
    """

    name: str
    type: str
    joint: str
    interface: str  # one of JOINT_INTERFACES
    actuator: str | None = None
    reduction: float = 1.0
    offset: float = 0.0

    def actuator_to_joint_velocity(self, velocity):
        return velocity / self.reduction

    def joint_to_actuator_velocity(self, velocity):
        return velocity * self.reduction

    def actuator_to_joint_effort(self, effort):
        return effort * self.reduction

    def joint_to_actuator_effort(self, effort):
        return effort / self.reduction

    def actuator_to_joint_position(self, position):
        return position / self.reduction + self.offset

    def joint_to_actuator_position(self, position):
        return (position - self.offset) * self.reduction


@dataclass
class OtherTransmission:
    """A ``<transmission>`` gazebo_ros_control's DefaultRobotHWSim does not simulate: one over several joints
    (franka_hw's ``FrankaStateInterface`` and ``FrankaModelInterface`` name every joint of the arm) or one whose
    hardware interface is none of JOINT_INTERFACES. Kept as read, for a ``robotSimType`` that uses it; the
    default hardware skips it with :attr:`warning`, as DefaultRobotHWSim's ``initSim`` warns and skips it."""

    name: str
    type: str
    joints: list[str]
    interfaces: list[str]  # each joint's first <hardwareInterface>, as written ("" when it has none)
    why: str  # why DefaultRobotHWSim skips it
    roles: list[str] = field(default_factory=list)  # each joint's <role> (franka_hw's root and tip), "" if none

    @property
    def warning(self):
        return f"transmission '{self.name}' ({self.type}) skipped by DefaultRobotHWSim: {self.why}"


@dataclass
class GazeboBlock:
    """A ``<gazebo>`` element; ``reference`` is the link (or joint) it applies to, None for the robot."""

    reference: str | None
    element: ET.Element
    path: str


@dataclass
class RobotModel:
    name: str
    source: str
    links: dict[str, Link]
    joints: dict[str, Joint]
    transmissions: list[Transmission]
    gazebo: list[GazeboBlock]
    #: The model's canonical link, the one /gazebo names first and PyBullet's base: the URDF's root link; for a
    #: robot joined to the world by one fixed joint from ``world``, that joint's child; ``world`` itself (a
    #: massless stand-in for the world, fixed) when it is joined by a movable joint or by several.
    root: str
    #: The joints from ``world`` (WORLD_LINK): each holds the robot to the world as Gazebo's joint to the world
    #: does (the model's base is fixed where it is spawned). Empty for a free robot.
    world_joints: list[Joint] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)  # published mistakes survived, one line each
    #: The transmissions DefaultRobotHWSim does not simulate (``transmissions`` holds those it does).
    other_transmissions: list[OtherTransmission] = field(default_factory=list)
    _surfaces: dict[str, dict] = field(default_factory=dict, repr=False)

    @property
    def fixed_to_world(self):
        """The robot is joined to the world (a URDF ``world`` link), so its base never moves."""
        return bool(self.world_joints)

    @property
    def anchor(self):
        """The one fixed joint from ``world`` whose child is the root (the world link then is not loaded), or
        None: a free robot, or one whose root is the ``world`` stand-in itself."""
        if len(self.world_joints) == 1 and self.world_joints[0].type == "fixed" and self.root != WORLD_LINK:
            return self.world_joints[0]
        return None

    def gazebo_links(self):
        """The links Gazebo keeps, canonical first: the root (never the ``world`` stand-in), every child of a
        joint from the world, and every child of a moving joint (fixed-joint children are lumped into their
        parent). Lumped links still have poses (``Robot.link_motion``)."""
        out = [] if self.root == WORLD_LINK else [self.root]
        for joint in self.joints.values():
            if (joint.type != "fixed" or joint.parent == WORLD_LINK) and joint.child not in out:
                out.append(joint.child)
        return out

    def joint(self, name, referrer):
        """Return joint ``name`` or raise ModelError naming ``referrer`` (the element that asked for it)."""
        if name not in self.joints:
            known = ", ".join(sorted(j for j, v in self.joints.items() if v.movable)) or "none"
            raise ModelError(f"names joint '{name}', which the model does not have (movable joints: {known})",
                             self.source, referrer)
        return self.joints[name]

    def total_mass(self):
        """Sum of the URDF's <inertial> masses [kg]."""
        return sum(link.mass or 0.0 for link in self.links.values())

    def surface(self, link):
        """Gazebo surface tags given in ``<gazebo reference=link>``: {tag: float} for the numeric ones
        (SURFACE_NUMBERS), ``fdir1`` as a 3-tuple. Text form ``<mu1>0.5</mu1>`` and attribute form
        ``<mu1 value="0.5"/>`` are both read, as Gazebo's URDF reader does. A value that is not a number is
        skipped (recorded in ``warnings``), as Gazebo goes on with its default."""
        if link in self._surfaces:
            return dict(self._surfaces[link])
        values = {}
        for block in self.gazebo:
            if block.reference != link:
                continue
            for child in block.element:
                if child.tag not in SURFACE_NUMBERS and child.tag != "fdir1":
                    continue
                text = tag_value(child)
                try:
                    if child.tag == "fdir1":
                        values["fdir1"] = _vec(text, self.source, f"{block.path}/fdir1")
                    else:  # read as Gazebo's URDF reader does (std::stod: the leading number)
                        values[child.tag] = tag_number(f"{self.source}: {block.path}/{child.tag}", text, self.warnings)
                except (ModelError, ConfigError) as err:
                    self.warnings.append(f"{err}; ignored (Gazebo's default applies)")
        self._surfaces[link] = values
        return dict(values)

    def wheel_radius(self, joint_name, referrer):
        """Radius [m] of the wheel driven by ``joint_name``: its child link's cylinder or sphere collision.

        As diff_drive_controller does; any other shape cannot give a radius.
        """
        joint = self.joint(joint_name, referrer)
        link = self.links[joint.child]
        for geom in link.collisions:
            if geom.kind in ("cylinder", "sphere"):
                if not geom.radius or geom.radius <= 0 or not math.isfinite(geom.radius):
                    raise ModelError(f"wheel radius must be > 0, got {geom.radius}", self.source,
                                     f"/robot/link[@name='{link.name}']/collision/geometry/{geom.kind}")
                return geom.radius
        raise ModelError("has no cylinder or sphere collision to take a wheel radius from "
                         "(add one, or give the plugin's wheel diameter)",
                         self.source, f"/robot/link[@name='{link.name}']")

    def wheel_separation(self, left, right, referrer):
        """Distance [m] between the two wheel joints' origins, as diff_drive_controller computes it."""
        a, b = self.joint(left, referrer).xyz, self.joint(right, referrer).xyz
        return math.dist(a, b)


def parse_urdf(text, source="robot_description"):
    """Parse URDF XML text into a RobotModel.

    Raises:
        ModelError: malformed XML, a missing name, a joint whose links do not exist, a transmission naming a
            missing joint or an unknown interface, a non-positive mechanicalReduction.
    """
    try:
        root = ET.fromstring(text)
    except ET.ParseError as err:
        raise ModelError(f"malformed XML ({err})", source) from None
    if root.tag != "robot":
        raise ModelError(f"root element is <{root.tag}>, expected <robot>", source, f"/{root.tag}")
    name = root.get("name", "")

    links = {}
    for el in root.findall("link"):
        lname = _required(el, "name", source, "/robot/link")
        path = f"/robot/link[@name='{lname}']"
        if lname in links:  # urdfdom refuses the model; PyBullet would crash on it
            raise ModelError(f"link '{lname}' is not unique (a second <link> of that name)", source, path)
        mass = None
        inertial = el.find("inertial")
        if inertial is not None:
            mass_el = inertial.find("mass")
            if mass_el is None:
                raise ModelError("<inertial> has no <mass>", source, f"{path}/inertial")
            mass = _float(mass_el.get("value"), source, f"{path}/inertial/mass[@value]")
            if mass < 0:
                raise ModelError(f"mass must be >= 0, got {mass}", source, f"{path}/inertial/mass[@value]")
        collisions = [_geometry(c.find("geometry"), source, f"{path}/collision") for c in el.findall("collision")]
        links[lname] = Link(lname, mass, [g for g in collisions if g is not None])
    if not links:
        raise ModelError("has no <link>", source, "/robot")

    joints = {}
    for el in root.findall("joint"):
        jname = _required(el, "name", source, "/robot/joint")
        path = f"/robot/joint[@name='{jname}']"
        if jname in joints:
            raise ModelError(f"joint '{jname}' is not unique (a second <joint> of that name)", source, path)
        jtype = _required(el, "type", source, path)
        parent = _link_ref(el, "parent", links, source, path)
        child = _link_ref(el, "child", links, source, path)
        origin = el.find("origin")
        xyz = _vec(origin.get("xyz") if origin is not None else None, source, f"{path}/origin[@xyz]")
        rpy = _vec(origin.get("rpy") if origin is not None else None, source, f"{path}/origin[@rpy]")
        axis_el = el.find("axis")
        axis = _vec(axis_el.get("xyz") if axis_el is not None else None, source, f"{path}/axis[@xyz]",
                    default=(1.0, 0.0, 0.0))
        limit = el.find("limit")
        effort = velocity = None
        lower = upper = 0.0
        if limit is not None:
            if limit.get("effort") is not None:
                effort = _float(limit.get("effort"), source, f"{path}/limit[@effort]")
            if limit.get("velocity") is not None:
                velocity = _float(limit.get("velocity"), source, f"{path}/limit[@velocity]")
            lower = _float(limit.get("lower", "0"), source, f"{path}/limit[@lower]")
            upper = _float(limit.get("upper", "0"), source, f"{path}/limit[@upper]")
        joints[jname] = Joint(jname, jtype, parent, child, xyz, rpy, axis, effort, velocity, limit is not None,
                              lower, upper, _mimic(el.find("mimic"), source, path),
                              _safety(el.find("safety_controller"), source, path))

    children = {j.child for j in joints.values()}
    roots = [name for name in links if name not in children]
    if len(roots) != 1:
        raise ModelError(f"must have exactly one root link, found {len(roots)}: {', '.join(roots)}", source, "/robot")

    world_joints = [j for j in joints.values() if j.parent == WORLD_LINK] if roots[0] == WORLD_LINK else []
    canonical = roots[0]
    if len(world_joints) == 1 and world_joints[0].type == "fixed":
        canonical = world_joints[0].child  # the world link itself is not loaded (WORLD_LINK)
    model = RobotModel(name, source, links, joints, [], [], canonical, world_joints)
    for index, el in enumerate(root.findall("transmission"), start=1):
        trans = _transmission(el, index, model)
        (model.other_transmissions if isinstance(trans, OtherTransmission) else model.transmissions).append(trans)
    for index, el in enumerate(root.findall("gazebo"), start=1):
        ref = el.get("reference")
        path = f"/robot/gazebo[@reference='{ref}']" if ref else f"/robot/gazebo[{index}]"
        if ref and ref not in links and ref not in joints:
            # Gazebo drops such a block (a sensor in it too) and loads the rest of the robot.
            model.warnings.append(f"{source}: {path} names no link or joint of the model; the block (its tags, "
                                  "sensors and plugins) is ignored, as in Gazebo")
            continue
        model.gazebo.append(GazeboBlock(ref, el, path))
    return model


def _transmission(el, index, model):
    source = model.source
    tname = el.get("name")
    path = f"/robot/transmission[@name='{tname}']" if tname else f"/robot/transmission[{index}]"
    type_el = el.find("type")
    ttype = (type_el.text or "").strip() if type_el is not None else el.get("type", "")
    if not ttype:
        raise ModelError("has no <type> (e.g. transmission_interface/SimpleTransmission)", source, path)
    joint_els = el.findall("joint")
    if not joint_els:
        raise ModelError("names no <joint>", source, path)
    if len(joint_els) > 1:
        names = [_required(j, "name", source, f"{path}/joint") for j in joint_els]
        return OtherTransmission(tname or f"transmission_{index}", ttype, names,
                                 [(j.findtext("hardwareInterface") or "").strip() for j in joint_els],
                                 f"it names {len(names)} joints; DefaultRobotHWSim simulates one per transmission",
                                 [(j.findtext("role") or "").strip() for j in joint_els])
    jname = _required(joint_els[0], "name", source, f"{path}/joint")
    jpath = f"{path}/joint[@name='{jname}']"
    actuator = el.find("actuator")
    interfaces = [i.text for i in joint_els[0].findall("hardwareInterface")]
    if not interfaces and actuator is not None:  # deprecated: interface only on the actuator
        interfaces = [i.text for i in actuator.findall("hardwareInterface")]
    if not interfaces:
        raise ModelError("has no <hardwareInterface>", source, jpath)
    if len(interfaces) > 1:  # gazebo_ros_control's DefaultRobotHWSim warns and uses the first
        model.warnings.append(f"{source}: {jpath} declares {len(interfaces)} hardware interfaces; using the "
                              f"first, {(interfaces[0] or '').strip()}, as gazebo_ros_control does")
    interface = (interfaces[0] or "").strip().split("/")[-1]
    if interface not in JOINT_INTERFACES:
        given = (interfaces[0] or "").strip()
        return OtherTransmission(tname or f"transmission_{index}", ttype, [jname], [given],
                                 f"its hardware interface '{given}' is not one it simulates "
                                 f"({', '.join(JOINT_INTERFACES)})")
    model.joint(jname, jpath)  # only now: a transmission DefaultRobotHWSim skips never looks its joint up
    reduction, offset = 1.0, 0.0
    red_el = actuator.find("mechanicalReduction") if actuator is not None else el.find("mechanicalReduction")
    if red_el is not None:
        reduction = _float(red_el.text, source, f"{path}/actuator/mechanicalReduction")
        if reduction == 0:
            raise ModelError("mechanicalReduction must not be 0", source, f"{path}/actuator/mechanicalReduction")
    off_el = joint_els[0].find("offset")
    if off_el is not None:
        offset = _float(off_el.text, source, f"{jpath}/offset")
    return Transmission(tname or f"transmission_{index}", ttype, jname, interface,
                        actuator.get("name") if actuator is not None else None, reduction, offset)


def _mimic(el, source, path):
    if el is None:
        return None
    return Mimic(_required(el, "joint", source, f"{path}/mimic"),
                 _float(el.get("multiplier", "1"), source, f"{path}/mimic[@multiplier]"),
                 _float(el.get("offset", "0"), source, f"{path}/mimic[@offset]"))


def _safety(el, source, path):
    if el is None:
        return None
    where = f"{path}/safety_controller"
    return SafetyController(_float(_required(el, "k_velocity", source, where), source, f"{where}[@k_velocity]"),
                            *(_float(el.get(key, "0"), source, f"{where}[@{key}]")
                              for key in ("k_position", "soft_lower_limit", "soft_upper_limit")))


def _required(el, attr, source, path):
    value = el.get(attr)
    if not value:
        raise ModelError(f"missing attribute '{attr}'", source, path)
    return value


def _link_ref(el, tag, links, source, path):
    ref = el.find(tag)
    if ref is None or not ref.get("link"):
        raise ModelError(f"missing <{tag} link=...>", source, path)
    if ref.get("link") not in links:
        raise ModelError(f"names link '{ref.get('link')}', which the model does not have", source, f"{path}/{tag}")
    return ref.get("link")


def _float(text, source, path):
    try:
        value = float(str(text).strip())
    except (TypeError, ValueError):
        raise ModelError(f"'{text}' is not a number", source, path) from None
    if not math.isfinite(value):
        raise ModelError(f"'{text}' is not a finite number", source, path)
    return value


def _vec(text, source, path, default=(0.0, 0.0, 0.0)):
    if text is None:
        return default
    parts = text.split()
    if len(parts) != 3:
        raise ModelError(f"'{text}' is not three numbers", source, path)
    return tuple(_float(p, source, path) for p in parts)


def _geometry(geom, source, path):
    if geom is None or len(geom) == 0:
        return None
    shape = geom[0]
    gpath = f"{path}/geometry/{shape.tag}"
    if shape.tag == "cylinder":
        return Geometry("cylinder", _float(shape.get("radius"), source, f"{gpath}[@radius]"),
                        _float(shape.get("length"), source, f"{gpath}[@length]"))
    if shape.tag == "sphere":
        return Geometry("sphere", _float(shape.get("radius"), source, f"{gpath}[@radius]"))
    return Geometry(shape.tag)
