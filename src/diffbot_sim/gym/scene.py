"""One robot in one world, in-process and without ROS, for learning environments: loaded as bullet_sim loads
them, driven by gazebo_ros_diff_drive's controller, seen through its own laser, reset by restoring a snapshot.

What bullet_sim does, this does through the same code (so a policy sees what it would see through ROS):

* The world through ``world.loading.load_world`` (SDF ``.world`` or map_server ``.yaml``), its gravity, and
  ``physics.World.load_world``; the robot's model read by ``description.prepared_model`` (xacro in-process,
  parsed, meshes prepared) and placed by ``physics.robot_loading.place_robot`` (raised onto the world at its
  spawn point, set down calmly by ``World.load_robot``), as ``simulator/robots.py`` does.
* The drive: the model's ``libgazebo_ros_diff_drive.so`` tags (or ``left_joints``... given as parameters, as
  bullet_sim's ``~left_joints``) read by ``config.gazebo_diff_drive_config``; before each physics step the plugin's own
  step runs (``control.gazebo_diff_drive``, which ``plugins/diff_drive.py`` wraps with ROS): a new command
  reaches the wheel motors at once, otherwise the wheels are updated at the plugin's ``<update_rate>`` from
  their measured speeds, with its acceleration and wheel-speed limits, and braked when a command outlives
  bullet_sim's ``cmd_vel_timeout`` (0 by default: held, as in Gazebo).
* The laser: the model's ``<sensor type="ray">`` read by ``sensors.ray.parse_sensor``, mounted as
  ``sensors.ray.mounted_pose`` says, its rays cast by ``World.ray_batch`` and turned into ranges (REP 117
  mask, Gazebo's noise) by ``sensors.ray.ScanProcessor``, as ``plugins/laser.py`` does.

What it does not: no ROS topics, no TF, no other plugins (joint_state, cameras, IMUs are not simulated).
A reset restores the snapshot taken once the robot had landed (``World.save_state``) and sets the wheel motors
again, which a snapshot does not hold (bullet3 #4364); then the robot is moved, at rest, to its start.
"""
import dataclasses
import math
import os

import numpy as np

from diffbot_sim import config as cfgmod
from diffbot_sim.control.gazebo_diff_drive import DriveWheels, GazeboDiffDriveCore
from diffbot_sim.description import meshes
from diffbot_sim.description.model_files import package_path
from diffbot_sim.description.prepared_model import prepare_model, read_model_file
from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.gym.free_space import arena_bounds, grid, reachable_cells
from diffbot_sim.physics import World
from diffbot_sim.physics.robot_loading import place_robot, settle
from diffbot_sim.sensors import ray as ray_sensor
from diffbot_sim.transforms import qmul, quaternion_from_yaw, yaw_from_quaternion
from diffbot_sim.world.loading import load_world

#: The seed robot with its 2D laser, and the example room (package-relative paths).
DEFAULT_MODEL = "urdf/diffbot_laser.urdf.xacro"
DEFAULT_WORLD = "worlds/room.world"
#: Half size [m] of the square arena of a world with no bounded body (an empty world).
EMPTY_ARENA_HALF_SIZE = 2.0
#: How a scan becomes the observation's beams: "samples" edits the sensor's horizontal <samples> to the
#: number of beams (the TurtleBot3 e-Manual's edit: only those rays are cast); "min_pool" casts the sensor's
#: own rays and keeps the nearest reading of each of the beams' equal sectors.
SCAN_MODES = ("samples", "min_pool")
#: Physics steps between two readings of the robot's contacts: 2 steps of 1/240 s is 120 Hz, faster than the
#: diff drive's 100 Hz updates (a robot at 0.3 m/s moves 2.5 mm in between); every step would cost ~7 % more.
CONTACT_EVERY = 2


def _package_root():
    """This package's directory (rospkg's, else the source tree's)."""
    try:
        return package_path("diffbot_sim")
    except (LookupError, ImportError):
        return os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


def resolve_model(name):
    """The model file ``name`` names: a path as given, else relative to this package (its ``urdf/``).

    Raises:
        ModelError: no such file.
    """
    path = os.path.abspath(os.path.expanduser(name))
    if os.path.isfile(path):
        return path
    candidate = os.path.join(_package_root(), name)
    if os.path.isfile(candidate):
        return candidate
    raise ModelError("no such model file (searched the working directory and the diffbot_sim package)", name)


class SceneDrive:
    """The robot's gazebo_ros_diff_drive: the plugin's own step (``control.gazebo_diff_drive``, as
    ``plugins/diff_drive.py`` runs it under ROS) on the robot's wheels, commanded by the environment's actions
    instead of ``cmd_vel``.

    Args:
        sim: bullet_sim's settings this drive follows as the plugin does (``config.SimConfig``: its
            ``max_wheel_velocity``, ``cmd_vel_timeout`` and ``time_step``).
    """

    def __init__(self, robot, model, drive, sim):
        max_wheel_velocity = cfgmod.max_wheel_velocity(sim, model, drive)
        self.core = GazeboDiffDriveCore(drive.wheel_separation, drive.wheel_radius, max_wheel_velocity,
                                        drive.max_wheel_acceleration, sim.cmd_vel_timeout, drive.update_rate,
                                        sim.time_step)
        self.wheels = DriveWheels(robot, robot.indices(drive.left_joints), robot.indices(drive.right_joints),
                                  cfgmod.wheel_efforts(model, drive))
        self.max_linear, self.max_angular = self.core.max_linear, self.core.max_angular

    def command(self, linear, angular):
        """A cmd_vel (linear.x [m/s], angular.z [rad/s]): it reaches the wheels at the next step. A non-finite
        one is dropped (the plugin's subscriber drops it), so the last valid command holds."""
        linear, angular = float(linear), float(angular)
        if math.isfinite(linear) and math.isfinite(angular):
            self.core.inbox.put((linear, angular))

    def before_step(self, now):
        """The plugin's work before the physics step at sim time ``now``."""
        self.core.before_step(now, self.wheels)

    def reset(self):
        """The plugin's Reset, then its start at sim time 0: command zero, wheel motors braking."""
        self.core.reset()
        self.wheels.brake()
        self.core.start(0.0)


class SceneLaser:
    """The robot's ray sensor as ``beams`` ranges [m] (misses read ``range_max``, too close ``range_min``)."""

    def __init__(self, robot, model, sensor, beams, mode, noise):
        cfg = ray_sensor.parse_sensor(sensor.element, sensor.path)
        self.warnings = list(cfg.warnings)
        self.pose, warning = ray_sensor.mounted_pose(cfg, model, sensor.link)
        if warning:
            self.warnings.append(warning)
        h = cfg.horizontal
        if mode == "samples":
            cfg = dataclasses.replace(cfg, horizontal=ray_sensor.ScanAxis(beams, 1.0, h.min_angle, h.max_angle))
        elif h.count < beams:
            raise ConfigError("GoalEnv beams", beams, f"at most the sensor's {h.count} readings (scan_mode min_pool)")
        if not noise:
            cfg = dataclasses.replace(cfg, noise=ray_sensor.Noise())
        self.robot, self.link, self.cfg, self.beams, self.mode = robot, sensor.link, cfg, beams, mode
        self.name = sensor.name or sensor.path
        self.directions = ray_sensor.ray_directions(cfg)
        cols = cfg.horizontal.count
        self.edges = (np.arange(beams) * cols) // beams
        angles = cfg.horizontal.reading_angles()
        self.angles = angles if mode == "samples" else np.minimum.reduceat(angles, self.edges)
        self.processor = ray_sensor.ScanProcessor(cfg, np.random.default_rng(0))

    def reseed(self, rng):
        """Noise from ``rng`` (numpy Generator) from now on; a bias, if any, drawn anew (Gazebo draws it once
        per sensor load)."""
        self.processor = ray_sensor.ScanProcessor(self.cfg, rng)

    def scan(self, world):
        """The ranges now: (beams,) float64."""
        cfg = self.cfg
        position, quaternion = self.robot.link_pose(self.link)
        origin, rotation = ray_sensor.sensor_pose(position, quaternion, self.pose)
        starts, ends = ray_sensor.world_rays(origin, rotation, self.directions, cfg.range_min, cfg.range_max)
        fractions, _, _ = world.ray_batch(starts, ends)
        ranges, _ = self.processor.process(fractions)
        ranges = np.clip(ranges, cfg.range_min, cfg.range_max)  # +inf (no return) -> max, -inf -> min
        ranges = ranges.reshape(cfg.vertical.count, cfg.horizontal.count).min(axis=0)
        return ranges if self.mode == "samples" else np.minimum.reduceat(ranges, self.edges)


def _ray_sensor(found, name):
    """The model's ray sensor called ``name`` (its first one when ``name`` is empty)."""
    for sensor in found.sensors:
        if sensor.type in ray_sensor.RAY_TYPES and (not name or sensor.name == name):
            return sensor
    raise ConfigError("GoalEnv sensor", name or "(first)", "a <sensor type=\"ray\"> of the model (the observation's "
                      "laser)")


class Scene:
    """A world, one robot, its drive and its laser; stepped only by :meth:`advance`. Arguments: see
    :class:`diffbot_sim.gym.goal_env.GoalConfig` (``model``, ``world``, ``drive``, ``sensor``, ...)."""

    def __init__(self, cfg):
        self.cfg = cfg
        description = load_world(cfg.world, cfg.map_wall_height) if cfg.world else None
        gravity = description.gravity[2] if description is not None and description.gravity is not None else -9.81
        self.world = World(cfg.time_step, gravity)
        self.state = None
        self.steps = 0
        try:
            if description is not None:
                self.world.load_world(description, meshes.default_cache_dir())
            self._build()
        except BaseException:
            self.world.close()
            raise

    def _build(self):
        cfg, world = self.cfg, self.world
        self.prepared = prepare_model(*read_model_file(resolve_model(cfg.model), cfg.model_args))
        model, found, notes = self.prepared.model, self.prepared.plugins, list(self.prepared.notes)
        drive = cfgmod.gazebo_diff_drive_config(model, found.diff_drive, dict(cfg.drive), notes)
        if drive is None:
            raise ConfigError("GoalEnv drive", cfg.drive, "a model with a libgazebo_ros_diff_drive.so plugin, or "
                              "left_joints/right_joints naming its wheels")
        sensor = _ray_sensor(found, cfg.sensor)
        self.model = model
        self.warnings = model.warnings + notes + found.warnings
        self.ground = {world.plane} if world.plane is not None else set()
        self.ground |= {uid for uid, body in world.world_bodies if all(s.kind == "plane" for s in body.shapes)}
        x, y, yaw = cfg.spawn
        robot = self._load_robot(x, y, yaw)
        self.cells = self._free_cells(robot, (x, y))
        if len(self.cells) == 0:
            raise ConfigError("GoalEnv clearance", cfg.clearance, f"a clearance that leaves free floor in {cfg.world}")
        if not world.free_of_bodies([(x, y)], self.radius + cfg.clearance, self.bottom, self.top,
                                    self.ground | {robot.body})[0]:
            near = self.cells[int(np.argmin(np.hypot(self.cells[:, 0] - x, self.cells[:, 1] - y)))]
            world.remove_robot(robot)
            robot = self._load_robot(float(near[0]), float(near[1]), yaw)
        self.robot = robot
        sim = cfgmod.SimConfig(time_step=cfg.time_step, cmd_vel_timeout=cfg.cmd_vel_timeout)  # bullet_sim's defaults
        self.drive = SceneDrive(robot, model, drive, sim)
        self.laser = SceneLaser(robot, model, sensor, cfg.beams, cfg.scan_mode, cfg.laser_noise)
        self.warnings += self.laser.warnings
        self.drive.reset()
        settle(world, robot)
        self.rest_pose = robot.base_pose()
        self.state = world.save_state()

    def _load_robot(self, x, y, yaw):
        """The robot placed as bullet_sim places it: raised onto the world at (x, y), turned by ``yaw``."""
        return place_robot(self.world, self.prepared, x, y, 0.0, yaw)

    def _free_cells(self, robot, near):
        """The reachable free cells (free_space) for this robot, and its footprint (radius, bottom, top)."""
        cfg, world = self.cfg, self.world
        (px, py, pz), _ = robot.base_pose()
        lo, hi = world.bounds(robot.body)
        self.radius = max(math.hypot(cx - px, cy - py) for cx in (lo[0], hi[0]) for cy in (lo[1], hi[1]))
        # the floor is z = 0 (a ground plane, a map's floor): the robot standing on it, wherever it was loaded
        self.bottom, self.top = 0.02, max(hi[2] - lo[2], 0.04)
        boxes = [world.bounds(uid) for uid, _ in world.world_bodies if uid not in self.ground]
        self.arena = tuple(map(tuple, cfg.arena)) if cfg.arena else arena_bounds(
            boxes, EMPTY_ARENA_HALF_SIZE)
        rows, cols, points = grid(self.arena, cfg.grid)
        free = world.free_of_bodies(points, self.radius + cfg.clearance, self.bottom, self.top,
                                    self.ground | {robot.body})
        return reachable_cells(points, free, rows, cols, near)

    # -- run time ---------------------------------------------------------------------------------------
    @property
    def time(self):
        """Sim time [s] since the last reset."""
        return self.steps * self.cfg.time_step

    def reset(self, x, y, yaw):
        """Restore the landed snapshot and stand the robot at (x, y) [m] facing ``yaw`` [rad], at rest, its
        drive reset; sim time 0."""
        self.world.restore_state(self.state)
        (_, _, z), rest = self.rest_pose
        turn = quaternion_from_yaw(yaw - yaw_from_quaternion(*rest))
        self.robot.set_base_motion(((x, y, z), qmul(turn, rest)), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        self.drive.reset()
        self.steps = 0

    def advance(self, linear, angular, steps):
        """Command (``linear`` [m/s], ``angular`` [rad/s]) and run ``steps`` physics steps. The robot's
        contacts are read every CONTACT_EVERY steps and after the last one; the first reading in which it
        touches a body other than the ground ends the run early. Returns the PyBullet ids it touches (empty:
        none)."""
        world, body, ground, drive = self.world, self.robot.body, self.ground, self.drive
        drive.command(linear, angular)
        step_time = self.cfg.time_step
        touched = frozenset()
        for index in range(1, steps + 1):
            drive.before_step(self.steps * step_time)
            world.step()
            self.steps += 1
            if index % CONTACT_EVERY == 0 or index == steps:
                touched = world.touching(body, ground)
                if touched:
                    break
        return touched

    def pose2d(self):
        """Ground truth (x [m], y [m], yaw [rad]) of the robot's root link."""
        (x, y, _), q = self.robot.base_pose()
        return x, y, yaw_from_quaternion(*q)

    def velocity(self):
        """(linear.x [m/s], angular.z [rad/s]) of the root link in its own frame: gazebo_ros_diff_drive's
        /odom twist with its default odometrySource world."""
        linear, angular = self.robot.base_twist()
        return linear[0], angular[2]

    def close(self):
        self.world.close()
