"""One validated configuration for the simulator, built once at start-up.

Pure. Values come from three places, later ones winning: the defaults below (the only place defaults live),
the model's ``<gazebo><plugin>`` tags (read by :mod:`diffbot_sim.plugins`), and the node's private ROS
parameters. Every bad value raises ``ConfigError`` naming the parameter (``~time_step``) or the tag and the
plugin element it stands in; a model that contradicts itself raises ``ModelError``.
"""
from dataclasses import asdict, dataclass, field, fields

from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.values import check_bool, check_number, check_string, tag_number

#: Wheel speed cap [rad/s] when neither ``~max_wheel_velocity`` nor the URDF ``<limit velocity>`` gives one:
#: keeps a 1e308 command from reaching the physics as an absurd motor target.
FALLBACK_MAX_WHEEL_VELOCITY = 100.0
#: Effort limit [N·m] for a commanded non-drive joint whose URDF gives no <limit effort>.
FALLBACK_JOINT_EFFORT = 100.0
#: ``~ray_process: auto`` starts the ray process in real time once the ray sensors cast this many rays per sim
#: second (about a tenth of a core here: 28 TurtleBot3 lasers of 360 beams at 5 Hz, or one 16-row 3D lidar).
RAY_PROCESS_AUTO_RAYS = 50_000
#: Bounds [s] of the physics step (``~time_step``, a world's ``max_step_size``, set_physics_properties).
MIN_TIME_STEP, MAX_TIME_STEP = 1e-5, 0.05
#: SDF's ``<physics><max_step_size>`` default: the step Gazebo runs a world file at that states none (its own
#: empty.world among them), and the one published gains were tuned at.
SDF_MAX_STEP_SIZE = 0.001


@dataclass
class SimConfig:
    """Simulator-wide settings (private parameters of ``bullet_sim``). Units in the field comments."""

    model: str = ""  # path of a .urdf or .urdf.xacro; empty: the robot_description parameter
    model_args: str = ""  # xacro arguments, "name:=value name2:=value2"
    gui: bool = False
    time_step: float = 1.0 / 240.0  # s; without ~time_step: a world file's max_step_size (SDF's 0.001 if unstated)
    real_time: bool = True  # pace sim time to the wall clock; false: as fast as possible
    real_time_factor: float = 1.0  # sim seconds per wall second when real_time
    fast_batch: float = 0.005  # s (wall); fast mode sends messages in bursts this often; 0: one write each
    wait_for_nodes: bool = True  # fast mode: after each sensor message, hold sim time until its subscribers answered
    wait_for_nodes_timeout: float = 5.0  # s (wall); a node that holds the simulator longer is not waited for
    wait_for_nodes_ignore: list[str] = field(default_factory=lambda: ["/rviz*", "/rqt*"])  # caller-id patterns
    send_timeout: float = 0.5  # s (wall); a subscriber that takes no data for this long is disconnected
    clock_rate: float = 100.0  # Hz of /clock, in sim time
    clock_max_wall_rate: float = 500.0  # Hz (wall): /clock at most this often; a faster run coalesces ticks; 0: no cap
    cmd_vel_timeout: float = 0.0  # s; 0 holds the last command (Gazebo); > 0 brakes on stale commands
    max_wheel_velocity: float = 0.0  # rad/s; 0: the URDF <limit velocity>, else FALLBACK_MAX_WHEEL_VELOCITY
    gravity: float = -9.81  # m/s^2 along z
    x: float = 0.0  # m, spawn pose in the world
    y: float = 0.0
    z: float = 0.0
    yaw: float = 0.0  # rad
    world: str = ""  # an SDF .world file or a map_server .yaml; empty: a ground plane only (also ~world_name)
    map_wall_height: float = 1.0  # m, height of the walls a map image's occupied cells become
    seed: int = 0  # sensor noise: with the sensor's name it seeds each generator, so two runs are identical
    renderer: str = "tiny"  # cameras: tiny (PyBullet's TinyRenderer, CPU) or egl (OpenGL via EGL, if it loads)
    debug_cmd_applied: bool = False  # publish ~debug/cmd_applied (wall time a command reached the motors)
    publish_ground_truth: bool = False  # publish ~ground_truth (physics pose, like Gazebo's p3d plugin)
    paused: bool = False  # start paused (empty_world.launch's paused:=true); unpause_physics starts it
    autostart_controllers: bool = True  # start every ros_control controller found; false: only a spawner does
    enable_ros_network: bool = True  # false: no /gazebo services or topics (gazebo_ros's parameter)
    gazebo_namespace: str = "/gazebo"  # where the gazebo_ros world API lives (spawn_model -gazebo_namespace)
    physics_engine: str = "ode"  # what the world launch asked for; the engine is always Bullet (noted)
    ray_process: object = False  # real time: ray sensors cast in a helper process: true, false or auto (from
    # RAY_PROCESS_AUTO_RAYS rays per sim second on); off by default: docs/fleet.md, "The ray process"


@dataclass
class GazeboDiffDriveConfig:
    """The diff drive, as gazebo_ros_diff_drive defines it (ROS 1 defaults), after tags and parameters."""

    left_joints: list[str] = field(default_factory=lambda: ["left_joint"])
    right_joints: list[str] = field(default_factory=lambda: ["right_joint"])
    wheel_separation: float | None = None  # m; None: from the URDF wheel joint origins
    wheel_diameter: float | None = None  # m; None: from the URDF wheel collision (cylinder/sphere)
    max_wheel_torque: float = 5.0  # N·m per wheel joint
    max_wheel_acceleration: float = 0.0  # m/s^2 at the wheel rim; 0: no limit
    update_rate: float = 100.0  # Hz, in sim time; 0: every physics step
    command_topic: str = "cmd_vel"
    odometry_topic: str = "odom"
    odometry_frame: str = "odom"
    robot_base_frame: str = "base_footprint"
    odometry_source: str = "world"  # world (physics pose) or encoder (wheel joint angles)
    publish_odom: bool = True
    publish_odom_tf: bool = True
    publish_wheel_joint_state: bool = False
    namespace: str | None = None  # None: the node's namespace
    covariance_x: float = 1e-5  # m^2, pose and twist diagonals
    covariance_y: float = 1e-5
    covariance_yaw: float = 1e-3  # rad^2

    @property
    def wheel_radius(self):
        return self.wheel_diameter / 2.0


#: gazebo_ros_skid_steer_drive (ROS 1): its tags as GazeboDiffDriveConfig keys, and the defaults that differ from the
#: diff drive's (it broadcasts no TF unless asked, always reports the world pose, has no acceleration limit).
SKID_STEER_TAGS = {
    "leftFrontJoint": "left_front", "leftRearJoint": "left_rear", "rightFrontJoint": "right_front",
    "rightRearJoint": "right_rear", "wheelSeparation": "wheel_separation", "wheelDiameter": "wheel_diameter",
    "torque": "max_wheel_torque", "commandTopic": "command_topic", "odometryTopic": "odometry_topic",
    "odometryFrame": "odometry_frame", "robotBaseFrame": "robot_base_frame", "updateRate": "update_rate",
    "broadcastTF": "publish_odom_tf", "covariance_x": "covariance_x", "covariance_y": "covariance_y",
    "covariance_yaw": "covariance_yaw", "robotNamespace": "namespace",
}
SKID_STEER_DEFAULTS = {"left_front": "left_front_joint", "left_rear": "left_rear_joint",
                       "right_front": "right_front_joint", "right_rear": "right_rear_joint",
                       "wheel_separation": 0.4, "wheel_diameter": 0.15, "publish_odom_tf": False,
                       "covariance_x": 1e-4, "covariance_y": 1e-4, "covariance_yaw": 0.01}


def skid_steer_config(model, values, path, notes=None):
    """GazeboDiffDriveConfig of a gazebo_ros_skid_steer_drive block: ``values`` maps its tags to their texts.

    Raises:
        ConfigError, ModelError: as :func:`gazebo_diff_drive_config`.
    """
    notes = notes if notes is not None else []
    merged = dict(SKID_STEER_DEFAULTS)
    for tag, text in values.items():
        if tag in SKID_STEER_TAGS:
            merged[SKID_STEER_TAGS[tag]] = text
    cfg = GazeboDiffDriveConfig(odometry_source="world")
    tag_of = {key: tag for tag, key in SKID_STEER_TAGS.items()}
    for key, value in merged.items():
        label = f"<{tag_of.get(key, key)}> of {path}"
        if key in ("left_front", "left_rear", "right_front", "right_rear"):
            continue
        setattr(cfg, key, _drive_value(key, value, label, notes))
    cfg.left_joints = [check_string(f"<leftFrontJoint> of {path}", merged["left_front"]),
                       check_string(f"<leftRearJoint> of {path}", merged["left_rear"])]
    cfg.right_joints = [check_string(f"<rightFrontJoint> of {path}", merged["right_front"]),
                        check_string(f"<rightRearJoint> of {path}", merged["right_rear"])]
    for jname in cfg.left_joints + cfg.right_joints:
        joint = model.joint(jname, path)
        if not joint.movable:
            raise ModelError(f"skid-steer wheel joint '{jname}' is {joint.type}, not a revolute/continuous joint",
                             model.source, f"/robot/joint[@name='{jname}']")
    return cfg


#: The ROS 2 plugin publishes nothing unless asked (its publish_odom / publish_odom_tf default false).
ROS2_DRIVE_DEFAULTS = {"publish_odom": False, "publish_odom_tf": False}


@dataclass
class JointStateConfig:
    joints: list[str] = field(default_factory=list)
    update_rate: float = 100.0  # Hz, in sim time
    topic: str = "joint_states"
    namespace: str | None = None


@dataclass
class RobotSpec:
    """One robot to spawn (an entry of ``~robots``, or the single robot of ``~model``/``~x``...).

    A named robot lives in its own namespace, as ``spawn_model -robot_namespace`` puts a Gazebo robot:
    its plugins' topics move under ``/<name>/`` and its frames get ``<tf_prefix>/`` (robot_state_publisher's
    ``tf_prefix`` rule), so several copies of one model can share the world.
    """

    name: str = ""  # namespace; "" (single robot): the plugins' own namespaces and frames, unprefixed
    model: str = ""  # .urdf/.urdf.xacro path; empty: ~model, then /<name>/robot_description, robot_description
    model_args: str = ""  # xacro arguments, "name:=value ..."
    x: float = 0.0  # m, spawn pose in the world
    y: float = 0.0
    z: float = 0.0
    yaw: float = 0.0  # rad
    tf_prefix: str | None = None  # None: the name; "" : no prefix


# ---------------------------------------------------------------------------------------------- builders

def sim_config(params):
    """Build SimConfig from the node's private parameters (a dict, as ``rospy.get_param('~')``)."""
    cfg = SimConfig()
    known = {f.name for f in fields(SimConfig)}
    for key, value in params.items():
        if key in known:
            setattr(cfg, key, value)

    def name(k):
        return f"~{k}"

    cfg.model = check_string(name("model"), cfg.model, allow_empty=True)
    cfg.model_args = check_string(name("model_args"), cfg.model_args, allow_empty=True)
    if not params.get("world") and params.get("world_name"):
        cfg.world = params["world_name"]  # gazebo_ros's empty_world.launch calls it world_name
    cfg.world = check_string(name("world"), cfg.world, allow_empty=True)
    cfg.map_wall_height = check_number(name("map_wall_height"), cfg.map_wall_height, low=0.0, low_open=True)
    seed = check_number(name("seed"), cfg.seed)
    if seed != int(seed):
        raise ConfigError(name("seed"), params.get("seed"), "an integer")
    cfg.seed = int(seed)
    cfg.renderer = check_string(name("renderer"), cfg.renderer).lower()
    if cfg.renderer not in ("tiny", "egl"):
        raise ConfigError(name("renderer"), cfg.renderer, "tiny or egl")
    cfg.gazebo_namespace = "/" + check_string(name("gazebo_namespace"), cfg.gazebo_namespace).strip("/")
    cfg.physics_engine = check_string(name("physics_engine"), cfg.physics_engine, allow_empty=True)
    for key in ("gui", "real_time", "debug_cmd_applied", "publish_ground_truth", "paused",
                "autostart_controllers", "enable_ros_network", "wait_for_nodes"):
        setattr(cfg, key, check_bool(name(key), getattr(cfg, key)))
    if isinstance(cfg.ray_process, str) and cfg.ray_process.strip().lower() == "auto":
        cfg.ray_process = "auto"
    else:
        try:
            cfg.ray_process = check_bool(name("ray_process"), cfg.ray_process)
        except ConfigError:
            raise ConfigError(name("ray_process"), cfg.ray_process, "true, false or auto") from None
    cfg.time_step = check_number(name("time_step"), cfg.time_step, low=MIN_TIME_STEP, high=MAX_TIME_STEP)
    cfg.real_time_factor = check_number(name("real_time_factor"), cfg.real_time_factor, low=1e-3)
    cfg.clock_rate = check_number(name("clock_rate"), cfg.clock_rate, low=1e-3)
    cfg.clock_max_wall_rate = check_number(name("clock_max_wall_rate"), cfg.clock_max_wall_rate, low=0.0)
    cfg.fast_batch = check_number(name("fast_batch"), cfg.fast_batch, low=0.0, high=0.1)
    cfg.send_timeout = check_number(name("send_timeout"), cfg.send_timeout, low=0.01)
    cfg.wait_for_nodes_timeout = check_number(name("wait_for_nodes_timeout"), cfg.wait_for_nodes_timeout, low=0.0)
    if isinstance(cfg.wait_for_nodes_ignore, str):
        cfg.wait_for_nodes_ignore = cfg.wait_for_nodes_ignore.split()
    if not isinstance(cfg.wait_for_nodes_ignore, list) or not all(isinstance(v, str)
                                                                    for v in cfg.wait_for_nodes_ignore):
        raise ConfigError(name("wait_for_nodes_ignore"), cfg.wait_for_nodes_ignore, "a list of node name patterns")
    cfg.cmd_vel_timeout = check_number(name("cmd_vel_timeout"), cfg.cmd_vel_timeout, low=0.0)
    cfg.max_wheel_velocity = check_number(name("max_wheel_velocity"), cfg.max_wheel_velocity, low=0.0)
    for key in ("gravity", "x", "y", "z", "yaw"):
        setattr(cfg, key, check_number(name(key), getattr(cfg, key)))
    return cfg


def gazebo_diff_drive_config(model, block, params, notes=None):
    """Merge defaults, the diff-drive plugin block (may be None) and private params into a GazeboDiffDriveConfig.

    Wheel separation and diameter missing from both are taken from the URDF. Returns None when neither the
    model nor the parameters describe a drive.

    Raises:
        ConfigError: a value of the wrong type or range. ModelError: a wheel joint the model lacks, a drive
            wheel whose transmission is not a velocity interface, a wheel without a usable radius.

    Values Gazebo tolerates with a warning (``odometrySource ENCODER``) append it to ``notes`` when given.
    """
    notes = notes if notes is not None else []
    given = {k: v for k, v in params.items() if k in {f.name for f in fields(GazeboDiffDriveConfig)}}
    if block is None and "left_joints" not in given:
        return None
    cfg = GazeboDiffDriveConfig()
    if block is not None and block.dialect == "ros2":
        for key, value in ROS2_DRIVE_DEFAULTS.items():
            setattr(cfg, key, value)
    sources = []
    if block is not None:  # tag text, read as Gazebo reads it; then the typed private parameters, strictly
        sources.append((block.values, lambda k: f"<{block.tag(k)}> of {block.path}", True))
    sources.append((given, lambda k: f"~{k}", False))
    for values, label, from_tag in sources:
        for key, value in values.items():
            setattr(cfg, key, _drive_value(key, value, label(key), notes, from_tag))
    if block is not None and block.dialect == "ros1" and "publish_odom_tf" not in given \
            and block.values.get("publish_odom") is not None and not cfg.publish_odom:
        cfg.publish_odom_tf = False  # ROS 1 publishTf=false removes the odom topic and its TF together
    referrer = block.path if block is not None else "~left_joints"
    if not cfg.left_joints or not cfg.right_joints or len(cfg.left_joints) != len(cfg.right_joints):
        raise ConfigError("left_joints/right_joints", (cfg.left_joints, cfg.right_joints),
                          "the same non-zero number of left and right wheel joints")
    for jname in cfg.left_joints + cfg.right_joints:
        joint = model.joint(jname, referrer)
        if not joint.movable:
            raise ModelError(f"drive wheel joint '{jname}' is {joint.type}, not a revolute/continuous joint",
                             model.source, f"/robot/joint[@name='{jname}']")
        for trans in model.transmissions:
            if trans.joint == jname and trans.interface != "VelocityJointInterface":
                raise ModelError(f"drive wheel joint '{jname}' declares {trans.interface}; the diff drive "
                                 "needs VelocityJointInterface", model.source,
                                 f"/robot/transmission[@name='{trans.name}']/joint[@name='{jname}']")
    if cfg.wheel_separation is None:
        cfg.wheel_separation = model.wheel_separation(cfg.left_joints[0], cfg.right_joints[0], referrer)
    if cfg.wheel_diameter is None:
        cfg.wheel_diameter = 2.0 * model.wheel_radius(cfg.left_joints[0], referrer)
    if cfg.wheel_separation <= 0:
        raise ModelError(f"wheel separation must be > 0, got {cfg.wheel_separation}", model.source, referrer)
    return cfg


def joint_state_config(model, block, drive, notes=None):
    """JointStateConfig from the joint-state plugin and, when the drive says so, its wheels.

    Raises:
        ModelError: a listed joint the model lacks (gazebo logs ROS_FATAL; we refuse to start).
    """
    cfg = JointStateConfig()
    if block is not None:
        for key, value in block.values.items():
            label = f"<{key}> of {block.path}"
            if key == "joints":
                cfg.joints = list(value)
            elif key == "update_rate":
                cfg.update_rate = tag_number(label, value, notes if notes is not None else [], low=0.0)
            elif key in ("topic", "namespace"):
                setattr(cfg, key, check_string(label, value, allow_empty=key == "namespace"))
        for jname in cfg.joints:
            model.joint(jname, block.path)
    if drive is not None and drive.publish_wheel_joint_state:
        for jname in drive.left_joints + drive.right_joints:
            if jname not in cfg.joints:
                cfg.joints.append(jname)
        if block is None:
            cfg.update_rate = drive.update_rate
            cfg.namespace = drive.namespace
    return cfg if cfg.joints else None


_ROBOT_KEYS = {f.name for f in fields(RobotSpec)}


def robot_specs(sim, params):
    """The robots to spawn: the ``~robots`` list when given, else one robot from ``~model``, ``~x``...

    ``~robots`` entries are names (``robot1``) or dicts with RobotSpec's keys. Names must be distinct,
    valid ROS names and poses distinct (two bodies spawned in one place explode apart).

    Raises:
        ConfigError: naming the entry and key at fault (``~robots[1].yaw``).
    """
    if "robots" not in params:
        return [RobotSpec(model=sim.model, model_args=sim.model_args, x=sim.x, y=sim.y, z=sim.z, yaw=sim.yaw)]
    entries = params["robots"]
    if not isinstance(entries, (list, tuple)):
        raise ConfigError("~robots", entries, "a list of robot names or {name: ..., x: ...} dicts (empty: "
                          "no robot until one is spawned through the /gazebo services)")
    specs = []
    for i, entry in enumerate(entries):
        label = f"~robots[{i}]"
        if isinstance(entry, str):
            entry = {"name": entry}
        if not isinstance(entry, dict):
            raise ConfigError(label, entry, "a robot name or a dict with a 'name'")
        unknown = sorted(set(entry) - _ROBOT_KEYS)
        if unknown:
            raise ConfigError(f"{label}.{unknown[0]}", entry[unknown[0]],
                              f"one of the keys {', '.join(sorted(_ROBOT_KEYS))}")
        spec = RobotSpec()
        spec.name = _ros_name(f"{label}.name", entry.get("name"))
        for key in ("model", "model_args"):  # an entry without its own model shares ~model
            setattr(spec, key, check_string(f"{label}.{key}", entry.get(key, getattr(sim, key)), allow_empty=True))
        for key in ("x", "y", "z", "yaw"):
            setattr(spec, key, check_number(f"{label}.{key}", entry.get(key, 0.0)))
        if entry.get("tf_prefix") is not None:
            spec.tf_prefix = check_string(f"{label}.tf_prefix", entry["tf_prefix"], allow_empty=True).strip("/")
        for j, other in enumerate(specs):
            if other.name == spec.name:
                raise ConfigError(f"{label}.name", spec.name, f"a name not already used by ~robots[{j}]")
            if (other.x, other.y, other.z) == (spec.x, spec.y, spec.z):
                raise ConfigError(label, entry, f"a spawn position other than that of ~robots[{j}] "
                                  f"({other.x:g}, {other.y:g}, {other.z:g})")
        specs.append(spec)
    return specs


def prefix_frame(prefix, frame):
    """``prefix/frame`` as robot_state_publisher's tf_prefix forms it; the frame unchanged for no prefix."""
    frame = frame.lstrip("/")
    return f"{prefix.strip('/')}/{frame}" if prefix and prefix.strip("/") else frame


def place_in_namespace(spec, drive, joint_cfg):
    """Move a named robot's drive and joint-state endpoints under ``/<name>`` and prefix its frames.

    The robot's namespace replaces the plugins' own, as gazebo_ros's spawner does; absolute topic names
    (``/cmd_vel``) stay absolute, as they would in Gazebo. A no-op for the unnamed single robot.
    """
    if not spec.name:
        return
    namespace = "/" + spec.name
    prefix = spec.name if spec.tf_prefix is None else spec.tf_prefix
    if drive is not None:
        drive.namespace = namespace
        drive.odometry_frame = prefix_frame(prefix, drive.odometry_frame)
        drive.robot_base_frame = prefix_frame(prefix, drive.robot_base_frame)
    if joint_cfg is not None:
        joint_cfg.namespace = namespace


def max_wheel_velocity(sim, model, drive):
    """Cap on each drive wheel's joint velocity [rad/s]: ``~max_wheel_velocity`` if > 0, else the slowest
    URDF ``<limit velocity>`` of the wheels when every wheel has one, else FALLBACK_MAX_WHEEL_VELOCITY."""
    if sim.max_wheel_velocity > 0:
        return sim.max_wheel_velocity
    limits = [model.joints[j].velocity_limit for j in drive.left_joints + drive.right_joints]
    if all(limits):
        return min(limits)
    return FALLBACK_MAX_WHEEL_VELOCITY


def wants_ray_process(setting, real_time, rays_per_second):
    """Whether the ray process should run: ``~ray_process`` true; or auto, in real time (fast mode and lockstep
    wait for every message, so they cast in place), once the ray sensors cast ``RAY_PROCESS_AUTO_RAYS`` rays per
    sim second or more (below that, casting in place costs less than a tenth of a core here, and the process is
    not worth its memory)."""
    if setting is True:
        return True
    return setting == "auto" and real_time and rays_per_second >= RAY_PROCESS_AUTO_RAYS


def wheel_efforts(model, drive):
    """Motor force limit [N·m] per drive wheel (left then right): the plugin's torque, which Gazebo applies
    as the joint's fmax, capped by the URDF ``<limit effort>`` where the model gives one."""
    efforts = []
    for name in drive.left_joints + drive.right_joints:
        limit = model.joints[name].effort_limit
        efforts.append(min(drive.max_wheel_torque, limit) if limit else drive.max_wheel_torque)
    return efforts


def as_params(cfg):
    """The effective configuration as a flat dict of ROS-parameter-friendly values (None dropped)."""
    return {k: v for k, v in asdict(cfg).items() if v is not None}


# -------------------------------------------------------------------------------------------- validators



def _drive_value(key, value, label, notes, from_tag=False):
    """``value`` of GazeboDiffDriveConfig field ``key``, validated; a value Gazebo tolerates with a warning appends
    that warning to ``notes``. A number ``from_tag`` (a plugin tag's text) is read as Gazebo reads it: its
    leading number (:func:`diffbot_sim.values.tag_number`)."""
    def number(**limits):
        return tag_number(label, value, notes, **limits) if from_tag else check_number(label, value, **limits)

    if key in ("left_joints", "right_joints"):
        names = [value] if isinstance(value, str) else value
        if not isinstance(names, (list, tuple)) or not all(isinstance(n, str) and n for n in names):
            raise ConfigError(label, value, "a joint name or a list of joint names")
        out = []
        for item in names:
            out.extend(part for part in item.replace(",", " ").split() if part)
        return out
    if key in ("wheel_separation", "wheel_diameter"):
        return number(low=0.0, low_open=True)
    if key in ("max_wheel_torque", "max_wheel_acceleration", "update_rate"):
        return number(low=0.0)
    if key in ("covariance_x", "covariance_y", "covariance_yaw"):
        return number(low=0.0)
    if key in ("publish_odom", "publish_odom_tf", "publish_wheel_joint_state"):
        return check_bool(label, value)
    if key == "odometry_source":
        text = str(value).strip()
        mapped = {"0": "encoder", "1": "world", "encoder": "encoder", "world": "world"}.get(text)
        if mapped is None:
            # gazebo_ros_diff_drive compares with "encoder" and "world" exactly; anything else (a published
            # model writes ENCODER) gets a warning and the world pose.
            notes.append(f"{label}: '{value}' is neither 'encoder' nor 'world' (Gazebo matches them exactly); "
                         "using world, as Gazebo does")
            return "world"
        return mapped
    if key == "namespace":
        return check_string(label, value, allow_empty=True)
    return check_string(label, value)


def _ros_name(name, value):
    """A relative ROS graph name for a namespace: letters, digits, ``_`` and ``/`` separators."""
    text = value.strip().strip("/") if isinstance(value, str) else None
    if not text or not all(part and part[0].isalpha() and all(c.isalnum() or c == "_" for c in part)
                           for part in text.split("/")):
        raise ConfigError(name, value, "a ROS name such as robot1 (a letter, then letters, digits or _)")
    return text


