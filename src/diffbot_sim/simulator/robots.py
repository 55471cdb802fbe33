"""Building bullet_sim's world and robots from its parameters, at start and when one is spawned at run time
(/gazebo/spawn_urdf_model): each robot's model loaded, its ``<gazebo>`` plugins given to their modules
(:mod:`diffbot_sim.plugins.registry`), and one start-up report of what was loaded and what was not (rospy).

A model is read and placed as the Gymnasium scene reads and places it: :mod:`diffbot_sim.description.prepared_model`
and :mod:`diffbot_sim.physics.robot_loading`."""
from typing import TYPE_CHECKING

import rospy

from diffbot_sim import config as cfgmod
from diffbot_sim.description import meshes
from diffbot_sim.description.prepared_model import prepare_model, read_model_file
from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import ModelError
from diffbot_sim.physics.robot_loading import place_robot
from diffbot_sim.plugins import registry
from diffbot_sim.plugins.base import RobotContext, get_param
from diffbot_sim.simulator.actors import Actors
from diffbot_sim.simulator.loop import RobotRuntime, Simulator
from diffbot_sim.values import check_number
from diffbot_sim.world.loading import load_world

if TYPE_CHECKING:
    from diffbot_sim.plugins.interfaces import PluginSimulator

    def _simulator_conforms(sim: Simulator) -> PluginSimulator:
        """For mypy alone: the Simulator gives its robots' plugins what PluginSimulator promises them."""
        return sim


def _load_model(spec):
    """URDF text and its source name: the spec's file, else ``/<name>/robot_description``, else the
    ``robot_description`` parameter found from the node's namespace (one model shared by every robot)."""
    if spec.model:
        return read_model_file(spec.model, spec.model_args)
    name = f"/{spec.name}/robot_description" if spec.name else None
    if name is None or not rospy.has_param(name):
        name = rospy.search_param("robot_description")
    if not name or not rospy.has_param(name):
        raise ModelError("no ~model given and no robot_description parameter found",
                         f"robot {spec.name}" if spec.name else "robot_description")
    text = rospy.get_param(name)
    if not isinstance(text, str) or not text.strip():
        raise ModelError("parameter is empty or not a string", name)
    return text, name


class LoadedRobot:
    """What build() learned about one robot, kept for the start-up report."""

    def __init__(self, spec, model, plugins, runtime, notes):
        self.spec, self.model, self.plugins, self.runtime, self.notes = spec, model, plugins, runtime, notes


def _build_robot(sim, cfg, spec, params, loaded=None, pose=None, now=None):
    """Load one robot and give each of its plugins to its module. ``loaded``: the URDF text and its source
    name (default: the spec's model); ``pose``: its root link's world pose (default: the spec's x, y, z
    raised onto the world, and yaw); ``now``: the sim time a robot spawned while running starts at."""
    prepared = prepare_model(*(loaded or _load_model(spec)), known=registry.KNOWN,
                             known_sensors=registry.KNOWN_SENSORS)
    model, found = prepared.model, prepared.plugins
    if pose is None:
        robot = place_robot(sim.world, prepared, spec.x, spec.y, spec.z, spec.yaw)
        namespace = "/" + spec.name if spec.name else None
    else:
        robot = sim.world.load_robot(prepared.text, model, pose[0], orientation=pose[1])
        namespace = None  # a spawn request's robot_namespace is already in its plugins' <robotNamespace>
        if spec.tf_prefix is None:
            spec.tf_prefix = _spawned_tf_prefix(model)
    ctx = RobotContext(sim, cfg, spec, model, robot, params, namespace, f"~{spec.name}/" if spec.name else "~")
    try:
        runtime = RobotRuntime(spec.name or model.name, ctx, registry.build(ctx, found, params))
    except BaseException:
        ctx.close()
        sim.world.remove_robot(robot)
        raise
    sim.add_robot(runtime, now)
    return LoadedRobot(spec, model, found, runtime, model.warnings + prepared.notes + ctx.warnings)


def spawn_robot(sim, cfg, params, name, text, source, pose):
    """A robot spawned while running (/gazebo/spawn_urdf_model): every plugin, sensor and controller it
    would get at start. Returns its RobotRuntime; raises DiffbotSimError on bad input."""
    spec = cfgmod.RobotSpec(name=name)
    item = _build_robot(sim, cfg, spec, params, loaded=(text, source), pose=pose, now=sim.sim_time)
    _report_robot(cfg, item)
    return item.runtime


def _spawned_tf_prefix(model):
    """A spawned robot's frames get the ``tf_prefix`` Noetic's gazebo_ros plugins find: ``searchParam
    ("tf_prefix")`` upward from their namespace (the spawn request's, once injected), or none: since
    gazebo_ros_pkgs #1143/#1173 an unset tf_prefix no longer falls back to the namespace. A private
    ``~tf_prefix`` of robot_state_publisher is not found (it lives under that node's name), as in Gazebo."""
    for block in model.gazebo:
        for element in block.element.iter("robotNamespace"):
            namespace = tag_value(element)
            if namespace:
                return search_tf_prefix(namespace)
    return search_tf_prefix("")  # no namespace: the plugins' node handle is the root's, which finds /tf_prefix


def search_tf_prefix(namespace):
    """roscpp's ``NodeHandle(namespace).searchParam("tf_prefix")``, its value stripped of slashes ("" if none)."""
    parts = [p for p in namespace.split("/") if p]
    for depth in range(len(parts), -1, -1):
        name = "/" + "/".join(parts[:depth] + ["tf_prefix"])
        value = get_param(name, None)
        if value is not None:
            return str(value).strip("/")
    return ""


def _read_world(cfg):
    """The world file's description (SDF .world, or a map_server .yaml), or None without ``~world``."""
    return load_world(cfg.world, cfg.map_wall_height) if cfg.world else None


def apply_world_physics(cfg, world, params):
    """A world's ``<physics>`` applies unless the node's parameters set the same: its step (``max_step_size``;
    a Gazebo world that states none runs at SDF's default, 1 ms, as in Gazebo, where published gains were
    tuned; ``~time_step`` chooses another), its gravity and its pace.

    The pace is Gazebo's: ``real_time_update_rate`` 0 runs as fast as the nodes in the loop allow (fast mode,
    ``~wait_for_nodes``); a rate r paces sim time to r x ``max_step_size`` (default 0.001 s) times the wall
    clock; without a rate, ``real_time_factor`` is taken as that factor."""
    if "time_step" not in params:
        step = world.max_step_size or (cfgmod.SDF_MAX_STEP_SIZE if world.sdf else None)
        if step is not None:
            cfg.time_step = check_number(f"{world.source}: <physics><max_step_size>", step,
                                         low=cfgmod.MIN_TIME_STEP, high=cfgmod.MAX_TIME_STEP)
    elif world.max_step_size and abs(world.max_step_size - cfg.time_step) > 1e-12:
        world.not_simulated.append(f"physics max_step_size {world.max_step_size:g} s (~time_step sets the step: "
                                   f"{cfg.time_step:g} s)")
    if "gravity" not in params and world.gravity is not None:
        cfg.gravity = world.gravity[2]
        if abs(world.gravity[0]) > 1e-9 or abs(world.gravity[1]) > 1e-9:
            world.not_simulated.append(f"horizontal gravity {world.gravity[:2]} (only its z is simulated)")
    rate = world.real_time_update_rate
    if rate is not None and "real_time" not in params:
        cfg.real_time = rate > 0
    if "real_time_factor" not in params:
        if rate:
            cfg.real_time_factor = rate * (world.max_step_size or cfgmod.SDF_MAX_STEP_SIZE)
        elif world.real_time_factor:
            cfg.real_time_factor = world.real_time_factor


def build(cfg, params):
    """Build the simulator with every robot of ``~robots`` (or the one robot); raises DiffbotSimError on
    bad input, naming the robot's file, element or parameter."""
    specs = cfgmod.robot_specs(cfg, params)
    world = _read_world(cfg)
    if world is not None:
        apply_world_physics(cfg, world, params)
    sim = Simulator(cfg)
    try:
        if world is not None and world.solver_iterations:
            sim.world.set_solver_iterations(world.solver_iterations)
        if cfg.renderer == "egl":  # before any body exists: the EGL plugin draws only bodies made after it
            reason = sim.world.use_egl()
            if reason is not None:
                rospy.logwarn(f"~renderer egl not available ({reason}); cameras use PyBullet's TinyRenderer")
                cfg.renderer = "tiny"
        if world is not None:
            sim.world_description = world
            sim.world.load_world(world, meshes.default_cache_dir())
            if world.actors:
                sim.actors = Actors(sim.world, world.actors, cfg.seed, lambda: sim.robots)
                world.warnings.extend(sim.actors.notes)
        loaded = [_build_robot(sim, cfg, spec, params) for spec in specs]
    except BaseException:
        sim.close()
        raise
    return sim, loaded


def report(cfg, loaded, world=None):
    """Log the effective configuration once and write it back to the private parameters."""
    for key, value in cfgmod.as_params(cfg).items():
        rospy.set_param("~" + key, value)
    if cfg.physics_engine not in ("", "ode", "bullet"):
        rospy.logwarn(f"bullet_sim: physics={cfg.physics_engine} accepted, not simulated (the engine is Bullet)")
    if world is not None:
        for text in world.warnings:
            rospy.logwarn(f"world {world.source}: {text}")
        if world.not_simulated:
            rospy.logwarn(f"world {world.source}: not simulated (accepted): " + "; ".join(world.not_simulated))
        rospy.set_param("~world_bodies", len(world.bodies))
        rospy.loginfo(f"bullet_sim: world {world.source} ({world.name}): {len(world.bodies)} bodies, "
                      f"{sum(1 for b in world.bodies if not b.static)} dynamic")
    for item in loaded:
        _report_robot(cfg, item)


def _report_robot(cfg, item):
    """Log one robot's warnings and effective settings; write them to its private parameters."""
    found, model, runtime = item.plugins, item.model, item.runtime
    who = f"robot {item.spec.name}: " if item.spec.name else ""
    for text in found.warnings + item.notes:
        rospy.logwarn(who + text)
    if found.unsupported:
        rospy.logwarn(who + "not simulated (ignored): " + "; ".join(found.unsupported))
    for block in (found.diff_drive, found.joint_state):
        if block is not None and block.unknown_tags:
            rospy.logwarn(f"{who}{block.path}: unknown tags ignored: {', '.join(block.unknown_tags)}")
    if not any(p.joints() or getattr(p, "moves_base", False) for p in runtime.plugins):
        rospy.logwarn(who + "the model has no drive plugin or controller that bullet_sim simulates (and no "
                      "~left_joints): nothing moves it")
    params = {}
    for plugin in runtime.plugins:
        params.update(plugin.summary())
    params["plugins"] = ",".join(p.filename for p in runtime.plugins)
    params["loaded_mass"] = runtime.ctx.robot.total_mass()
    params["urdf_mass"] = model.total_mass()
    if item.spec.name:
        params.update({k: v for k, v in cfgmod.as_params(item.spec).items() if k != "name"})
    for key, value in params.items():
        rospy.set_param(runtime.ctx.private + key.strip("/"), value)
    params.update(cfgmod.as_params(cfg))
    summary = ", ".join(f"{k}={v}" for k, v in sorted(params.items()))
    rospy.loginfo(f"bullet_sim: {who}model {model.source} ({model.name}); {summary}")


def world_api(sim, cfg, params):
    """The /gazebo services and topics (None, with a warning, when gazebo_msgs is not built: the overlay
    left out)."""
    try:
        from diffbot_sim.simulator.gazebo_services import GazeboApi
    except ImportError as err:
        rospy.logwarn(f"bullet_sim: no {cfg.gazebo_namespace} services ({err}; the gazebo_msgs overlay "
                      "package is not built)")
        return None
    api = GazeboApi(sim, lambda name, text, source, pose: spawn_robot(sim, cfg, params, name, text, source,
                                                                      pose))
    api.advertise()
    return api
