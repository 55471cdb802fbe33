"""What ``robot_check`` says about a model before driving it: mass, drive, plugins, warnings (pure).

A user migrating from Gazebo wants to know, in one screen, whether the simulator reads their robot as Gazebo
did: which plugin or controller drives it, where each number of its geometry came from (a tag, a YAML
parameter, or measured from the URDF as diff_drive_controller measures it), what is not simulated, and what
``bullet_sim`` will warn about. This module answers from the same pure units the simulator uses (description,
model, plugins.tags, config, ddc, meshes, physics), without a ROS master; :func:`build_report` returns plain
data and :func:`diffbot_sim.check.report_text.format_report` turns it into lines. Controller YAML files are passed
in already loaded (``rosparam.load_file`` in the node), so nothing here needs ROS.
"""
import math
import os
from dataclasses import dataclass, field

from diffbot_sim import config as cfgmod
from diffbot_sim.check import arc_check, arm_report
from diffbot_sim.check.drive_check import HOLONOMIC_PLUGINS
from diffbot_sim.control import (
    ackermann_steering_controller as asc,
    diff_drive_config as ddc,
    steer_bot_hardware as sbh,
)
from diffbot_sim.control.controller_lookup import find_controllers
from diffbot_sim.control.four_wheel_steering_controller import joint_offset
from diffbot_sim.description.gazebo_collisions import sensor_collision
from diffbot_sim.description.plugin_tags import DIFF_DRIVE, JOINT_STATE
from diffbot_sim.description.prepared_model import prepare_model, read_model_file
from diffbot_sim.description.urdf_model import tag_value

SKID_STEER = "libgazebo_ros_skid_steer_drive.so"
PLANAR_MOVE = "libgazebo_ros_planar_move.so"
KOBUKI = "libgazebo_ros_kobuki.so"
ROS_CONTROL = "libgazebo_ros_control.so"
DEFAULT_SIM_TYPE = "gazebo_ros_control/DefaultRobotHWSim"
#: The sentence bullet_sim logs when nothing can move the robot (sim_node's start-up report).
NO_DRIVE = ("the model has no drive plugin or controller that bullet_sim simulates (and no ~left_joints): "
            "nothing moves it")
#: Loaded and URDF mass may differ by this much [kg] (an inertia-less root weighs 1 mg in PyBullet).
MASS_TOLERANCE = 1e-3
#: Controller types known simulated when the caller passes none (the node passes the controller manager's).
DEFAULT_CONTROLLER_TYPES = frozenset((ddc.CONTROLLER_TYPE, "joint_state_controller/JointStateController",
                                      "velocity_controllers/JointVelocityController",
                                      "position_controllers/JointPositionController",
                                      "effort_controllers/JointEffortController"))


@dataclass
class Drive:
    """The plugin or controller that moves the robot, and where its geometry came from."""

    kind: str  # plugin filename or controller type
    where: str  # element path, or ``/controller from file.yaml``
    left: list[str] = field(default_factory=list)
    right: list[str] = field(default_factory=list)
    separation: float | None = None  # m, as used (multiplier applied)
    separation_from: str = ""
    radius: float | None = None  # m, as used (multiplier applied)
    radius_from: str = ""
    note: str = ""  # e.g. "holonomic: no wheels"
    #: car-like (ackermann_steering_controller): the bicycle model's wheelbase [m], the rear axle's middle in the
    #: root link's frame (x, y) and the turning radii its arc may have (None: L / tan δ exactly)
    wheelbase: float | None = None
    steering: list[str] = field(default_factory=list)  # steering joints (a car's): neither wheels nor arm joints
    rear_axle: tuple[float, float] = (0.0, 0.0)
    radius_range: tuple[float, float] | None = None


@dataclass
class Item:
    """One plugin, sensor or controller of the model, and whether bullet_sim simulates it."""

    kind: str  # "plugin", "sensor" or "controller"
    name: str
    what: str  # filename, sensor type or controller type
    where: str
    simulated: bool


@dataclass
class Report:
    source: str
    name: str
    urdf_mass: float  # kg
    loaded_mass: float  # kg
    drives: list[Drive] = field(default_factory=list)
    items: list[Item] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    rest_height: float | None = None  # m: the root link's height when the robot stands on flat ground
    #: m: the middle of the first drive's wheel centres in the root link's frame (x, y), which turns in place
    wheel_centre: tuple[float, float] = (0.0, 0.0)
    footprint: tuple[float, float] | None = None  # m: those wheels' farthest |x|, |y| from that middle
    #: every transmission joint: interface, limits, controller, role (check.arm_report.JointInfo)
    joints: list[arm_report.JointInfo] = field(default_factory=list)
    model: object = None  # the parsed URDF (description.urdf_model.RobotModel)
    control_ns: str = "/"  # gazebo_ros_control's robotNamespace
    controllers: dict = field(default_factory=dict)  # {controller namespace: parameters} found under it
    contacts: list[str] = field(default_factory=list)  # one line per contact sensor: its collision, its topics

    @property
    def arm_joints(self):
        """Transmission joints that are neither drive wheels nor mimic joints."""
        return [j for j in self.joints if j.arm]

    @property
    def holonomic(self):
        """True when the drive moves the body sideways too (planar or force-based move): it is driven sideways
        as well (drive_check.HOLONOMIC_RUNS)."""
        return self.drive is not None and self.drive.kind in HOLONOMIC_PLUGINS

    @property
    def skid(self):
        """True when the first drive has more than one wheel a side (its wheels slide as it turns)."""
        drive = self.drive
        return drive is not None and (len(drive.left) > 1 or len(drive.right) > 1)

    @property
    def drive(self):
        """The drive the simulator runs first (None: nothing moves the robot)."""
        return self.drives[0] if self.drives else None

    @property
    def car(self):
        """True when the first drive steers (a car cannot turn in place: it is driven in an arc)."""
        return self.drive is not None and self.drive.wheelbase is not None


# ----------------------------------------------------------------------------------------- parameters

def merge_params(tree, namespace, values):
    """Put ``values`` under ``namespace`` in the nested dict ``tree``, dicts merged key by key as
    ``rosparam load`` updates the parameter server (a later file wins per key, not per subtree)."""
    node = tree
    for part in [p for p in namespace.split("/") if p]:
        if not isinstance(node.get(part), dict):
            node[part] = {}
        node = node[part]
    _update(node, values)
    return tree


def _update(node, values):
    for key, value in values.items():
        if isinstance(value, dict):
            if not isinstance(node.get(key), dict):
                node[key] = {}
            _update(node[key], value)
        else:
            node[key] = value


# --------------------------------------------------------------------------------------------- report

def build_report(path, model_args="", controller_files=(), known=(), known_sensors=(), resolve_package=None,
                 cache_dir=None, known_controllers=None):
    """Load ``path`` as bullet_sim would and describe it.

    Args:
        path: .urdf or .urdf.xacro.
        model_args: xacro arguments, ``"a:=1 b:=2"``.
        controller_files: ``[(file, tree)]``: each controller YAML and its parameters as loaded at ``/``
            (``rosparam.load_file``), in the order they are loaded.
        known, known_sensors: model and sensor plugin filenames bullet_sim simulates (``plugins.registry``'s
            KNOWN and KNOWN_SENSORS: the caller passes them, this layer does not import the plugins).
        resolve_package: ``pkg -> path`` for ``package://`` meshes (LookupError when unknown); None: every
            package is unknown.
        cache_dir: converted-mesh cache; None: the user's (``meshes.default_cache_dir()``).
        known_controllers: controller types the simulator runs (the controller manager's); None: the
            diff-drive, joint-state and single-joint forward controllers.

    Returns:
        Report.

    Raises:
        ModelError, ConfigError: what would stop bullet_sim, naming the file, element or parameter.
    """
    text, source = read_model_file(path, model_args)
    prepared = prepare_model(text, source, known=known, known_sensors=known_sensors, cache_dir=cache_dir,
                             resolve_package=resolve_package or _no_package)
    text, model, found, mesh_notes = prepared.text, prepared.model, prepared.plugins, prepared.notes
    tree = {}
    origin = {}  # controller namespace -> the file that last set it
    for name, values in controller_files:
        merge_params(tree, "/", values)
        for ns in find_controllers(values, "/"):
            origin[ns] = os.path.basename(name)

    warnings = list(found.warnings)
    known_controllers = DEFAULT_CONTROLLER_TYPES if known_controllers is None else frozenset(known_controllers)
    drives, items = [], []
    control_ns, control_controllers, mimics = "/", {}, []
    block = found.diff_drive
    if block is not None:
        drives.append(_diff_drive(model, block, warnings))
        items.append(Item("plugin", _name_of(block.path, DIFF_DRIVE), DIFF_DRIVE, block.path, True))
    if found.joint_state is not None:
        js = found.joint_state
        items.append(Item("plugin", _name_of(js.path, JOINT_STATE), JOINT_STATE, js.path, True))
    for other in found.others:
        items.append(Item("plugin", other.name, other.filename, other.path, other.filename in known))
        if other.filename not in known:
            continue
        values = {child.tag: tag_value(child) for child in other.element}
        mimics += arm_report.mimic_pairs([(other.filename, values)])
        if other.filename == SKID_STEER:
            drives.append(_skid_steer(model, values, other.path, warnings))
        elif other.filename == KOBUKI:
            drives.append(_kobuki(values, other.path))
        elif other.filename == PLANAR_MOVE:
            drives.append(Drive(PLANAR_MOVE, other.path, note="holonomic: sets the body's velocity, no wheels"))
        elif other.filename in HOLONOMIC_PLUGINS:
            drives.append(Drive(other.filename, other.path,
                                note="holonomic: pushes the body towards the commanded velocity, no wheels"))
        elif other.filename == ROS_CONTROL:
            ns = values.get("robotNamespace") or "/"
            sim_type = values.get("robotSimType") or DEFAULT_SIM_TYPE
            steer_bot = None
            if sim_type == sbh.SIM_TYPE:
                found_ns = ns if _param(tree, f"{ns}/{sbh.PARAM_NS}") is not None else "/"  # as the plugin looks
                steer_bot = (_param(tree, f"{found_ns}/{sbh.PARAM_NS}"), _param(tree, f"{found_ns}/gains"), found_ns)
            elif sim_type != DEFAULT_SIM_TYPE:
                warnings.append(f"{other.path}: robotSimType '{sim_type}' is not simulated; using {DEFAULT_SIM_TYPE}")
            warnings.extend(f"gazebo_ros_control: {skipped.warning}" for skipped in model.other_transmissions)
            controllers = find_controllers(tree, ns)
            control_ns, control_controllers = ns, controllers
            if not controllers:
                warnings.append(f"{other.path}: no controller found on the parameter server under {ns} (load "
                                "your controller YAML with <rosparam command=\"load\"> before bullet_sim starts)")
            for name, params in sorted(controllers.items()):
                kind = params.get("type")
                simulated = kind in known_controllers
                file = origin.get(name, "?")
                items.append(Item("controller", name, kind, f"from {file}", simulated))
                if not simulated:
                    warnings.append(f"{name}: controller type {kind} is not simulated")
                if kind == ddc.CONTROLLER_TYPE:
                    drive, notes = _ddc(model, name, params, file)
                    drives.append(drive)
                    warnings.extend(notes)
                elif kind == asc.CONTROLLER_TYPE:
                    drive, notes = _ackermann(model, name, params, file, steer_bot)
                    drives.append(drive)
                    warnings.extend(notes)
    for sensor in found.sensors:  # simulated when one of its plugins is (a bare <sensor> publishes nothing)
        items.append(Item("sensor", sensor.name or "?", sensor.type or "?", sensor.path,
                          any(p in known_sensors for p in sensor.plugins)))
    contacts = _contact_lines(model, found)
    for blk in (found.diff_drive, found.joint_state):
        if blk is not None and blk.unknown_tags:
            warnings.append(f"{blk.path}: unknown tags ignored: {', '.join(blk.unknown_tags)}")

    from diffbot_sim.physics import World  # PyBullet, only once the model is known to be good

    world = World(1.0 / 240.0)
    try:
        loaded = world.load_robot(text, model)  # at the origin, lifted onto the ground it was placed into
        loaded_mass, rest_height = loaded.total_mass(), loaded.base_pose()[0][2]
        wheel_centre, footprint = _footprint(loaded, model, drives[0]) if drives else ((0.0, 0.0), None)
    finally:
        world.close()
    # model.warnings grows while loading (surface tags are read then), so it is taken last.
    warnings = model.warnings + mesh_notes + warnings
    if found.unsupported:
        warnings.append("not simulated (ignored): " + "; ".join(found.unsupported))
    if not drives:
        warnings.append(NO_DRIVE)
    wheels = {joint for drive in drives for joint in drive.left + drive.right + drive.steering}
    joints = arm_report.joint_infos(model, tree, control_ns, control_controllers, wheels, mimics)
    return Report(source, model.name, model.total_mass(), loaded_mass, drives, items, unique(warnings),
                  rest_height, wheel_centre, footprint, joints, model, control_ns, control_controllers, contacts)


def _param(tree, name):
    """The value at parameter ``name`` of a merged parameter tree (nested dicts), or None."""
    node = tree
    for part in [p for p in name.split("/") if p]:
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def _ackermann(model, name, params, file, steer_bot):
    """An AckermannSteeringController: a car-like drive (its bicycle model), and the warnings bullet_sim logs."""
    cfg = asc.ackermann_config(params, name)
    notes = list(cfg.warnings)
    if cfg.unknown_keys:
        notes.append(f"{name}: parameters AckermannSteeringController does not read, ignored: "
                     f"{', '.join(cfg.unknown_keys)}")
    joints = {j.name: (j.parent, j.child, j.xyz) for j in model.joints.values()}
    if cfg.wheel_separation_h is None:
        rear, steer = model.joint(cfg.rear_wheel, name).xyz, model.joint(cfg.front_steer, name).xyz
        wheelbase, base_from = abs(rear[0] - steer[0]), f"measured: x of {cfg.rear_wheel} and {cfg.front_steer}"
    else:
        wheelbase, base_from = cfg.wheel_separation_h, f"{name}/wheel_separation_h in {file}"
    wheelbase *= cfg.wheel_separation_h_multiplier
    try:
        offset = joint_offset(joints, cfg.rear_wheel, model.root)[:2]
    except KeyError:
        offset = (0.0, 0.0)
    radius_range, hw = None, ""
    if steer_bot is not None:
        hw_cfg = sbh.steer_bot_config(*steer_bot)
        right, left = (joints[j][2] for j in hw_cfg.virtual_front_steers)
        track = math.dist(right[:2], left[:2])
        radius_range = arc_check.front_wheel_radii(wheelbase, track, *sbh.linkage_angles(arc_check.ARC_STEER, hw_cfg))
        hw = (f"; {sbh.SIM_TYPE} maps it onto {', '.join(hw_cfg.virtual_wheels)} and the linkage of "
              f"{', '.join(hw_cfg.virtual_front_steers)}")
    note = (f"car-like (bicycle model): rear wheel {cfg.rear_wheel}, steering {cfg.front_steer} (cmd_vel angular.z is "
            f"the steering angle), wheelbase {wheelbase:.3f} m ({base_from}){hw}; driven in an arc, not turned in "
            "place")
    steering = [cfg.front_steer] + (list(hw_cfg.virtual_front_steers) if steer_bot is not None else [])
    return Drive(asc.CONTROLLER_TYPE, f"{name} from {file}", [cfg.rear_wheel], [], note=note, wheelbase=wheelbase,
                 steering=steering, rear_axle=offset, radius_range=radius_range), notes


def _contact_lines(model, found):
    """One line per contact sensor: the collision it watches (as Gazebo names it) and what publishes it."""
    kobuki_names = {}
    for other in found.others:
        if other.filename == KOBUKI:
            values = {child.tag: tag_value(child) for child in other.element}
            for key, topic in (("bumper_name", "events/bumper"), ("wheel_drop_left_sensor_name", "events/wheel_drop"),
                               ("wheel_drop_right_sensor_name", "events/wheel_drop")):
                if values.get(key):
                    kobuki_names[values[key].strip()] = topic
    lines = []
    for sensor in found.sensors:
        if sensor.type != "contact":
            continue
        contact = sensor.element.find("contact")
        named = tag_value(contact.find("collision")) if contact is not None and contact.find("collision") is not None \
            else ""
        collision, name = sensor_collision(model, sensor.link or model.root, named)
        watched = f"collision {name}" + ("" if collision else " (no such collision: it reports nothing, as in Gazebo)")
        topics = []
        for plugin in sensor.element.findall("plugin"):
            if (plugin.get("filename") or "").endswith("gazebo_ros_bumper.so"):
                tags = {child.tag: tag_value(child) for child in plugin}
                ns = (tags.get("robotNamespace") or "").strip().rstrip("/")
                topics.append(f"{ns}/{tags.get('bumperTopicName') or 'bumper_states'} (gazebo_msgs/ContactsState)")
        if sensor.name in kobuki_names:
            topics.append(f"<base_prefix>/{kobuki_names[sensor.name]} (the Kobuki plugin's kobuki_msgs events)")
        lines.append(f"  contact sensor {sensor.name}: {watched}; publishes " + (", ".join(topics) or "nothing "
                                                                                  "(no plugin reads it)"))
    return lines


def _footprint(loaded, model, drive):
    """``((x, y), (half length, half width))`` [m] of ``drive``'s wheel centres as loaded, in the root link's
    frame: their middle and how far the farthest lies from it along x and y."""
    points = [loaded.position_in_base(model.joints[joint].child) for joint in drive.left + drive.right
              if joint in model.joints]
    if not points:
        return (0.0, 0.0), None
    cx, cy = (sum(p[0] for p in points) / len(points), sum(p[1] for p in points) / len(points))
    return (cx, cy), (max(abs(p[0] - cx) for p in points), max(abs(p[1] - cy) for p in points))


def _no_package(package):
    raise LookupError(package)


def unique(lines):
    seen, out = set(), []
    for line in lines:
        if line not in seen:
            seen.add(line)
            out.append(line)
    return out


def _name_of(path, default):
    return path.split("@name='", 1)[1].split("'", 1)[0] if "@name='" in path else default


def _measured_radius(model, joint):
    link = model.links[model.joints[joint].child]
    kind = next((g.kind for g in link.collisions if g.kind in ("cylinder", "sphere")), "?")
    return f"measured: {kind} collision of {link.name}"


def _measured_separation(left, right):
    return f"measured: origins of {left} and {right}"


def _diff_drive(model, block, notes):
    cfg = cfgmod.gazebo_diff_drive_config(model, block, {}, notes)
    left, right = cfg.left_joints[0], cfg.right_joints[0]
    sep_from = (f"<{block.tag('wheel_separation')}> tag" if "wheel_separation" in block.values
                else _measured_separation(left, right))
    rad_from = (f"<{block.tag('wheel_diameter')}> tag / 2" if "wheel_diameter" in block.values
                else _measured_radius(model, left))
    return Drive(DIFF_DRIVE, block.path, cfg.left_joints, cfg.right_joints, cfg.wheel_separation, sep_from,
                 cfg.wheel_radius, rad_from)


def _skid_steer(model, values, path, notes):
    cfg = cfgmod.skid_steer_config(model, values, path, notes)
    sep_from = "<wheelSeparation> tag" if "wheelSeparation" in values else "plugin default"
    rad_from = "<wheelDiameter> tag / 2" if "wheelDiameter" in values else "plugin default"
    return Drive(SKID_STEER, path, cfg.left_joints, cfg.right_joints, cfg.wheel_separation, sep_from,
                 cfg.wheel_radius, rad_from)


def _kobuki(values, path):
    """The Kobuki plugin requires its geometry tags (the simulator refuses it without them)."""
    def number(tag):
        try:
            return float(values[tag])
        except (KeyError, ValueError):
            return None

    diameter = number("wheel_diameter")
    return Drive(KOBUKI, path, [values.get("left_wheel_joint_name", "?")],
                 [values.get("right_wheel_joint_name", "?")], number("wheel_separation"), "<wheel_separation> tag",
                 diameter / 2.0 if diameter is not None else None, "<wheel_diameter> tag / 2")


def _ddc(model, name, params, file):
    """A DiffDriveController: its drive and the warnings bullet_sim logs for it."""
    cfg = ddc.diff_drive_controller_config(params, name)
    notes = list(cfg.warnings)
    if cfg.unknown_keys:
        notes.append(f"{name}: parameters DiffDriveController does not read, ignored: {', '.join(cfg.unknown_keys)}")
    for joint in cfg.joints:
        model.joint(joint, name)
    left, right = cfg.left_wheels[0], cfg.right_wheels[0]
    if cfg.wheel_separation is None:
        separation = model.wheel_separation(left, right, name)
        sep_from = _measured_separation(left, right)
    else:
        separation, sep_from = cfg.wheel_separation, f"{name}/wheel_separation in {file}"
    if cfg.wheel_radius is None:
        radius = model.wheel_radius(left, name)
        rad_from = _measured_radius(model, left)
    else:
        radius, rad_from = cfg.wheel_radius, f"{name}/wheel_radius in {file}"
    if cfg.wheel_separation_multiplier != 1.0:
        sep_from += f", x wheel_separation_multiplier {cfg.wheel_separation_multiplier:g}"
        separation *= cfg.wheel_separation_multiplier
    if cfg.left_wheel_radius_multiplier != 1.0:
        rad_from += f", x left_wheel_radius_multiplier {cfg.left_wheel_radius_multiplier:g}"
        radius *= cfg.left_wheel_radius_multiplier
    return Drive(ddc.CONTROLLER_TYPE, f"{name} from {file}", list(cfg.left_wheels), list(cfg.right_wheels),
                 separation, sep_from, radius, rad_from), notes
