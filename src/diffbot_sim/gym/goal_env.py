"""``GoalEnv``: drive a robot to a goal in a world without touching anything (Gymnasium 1.x API, in-process).

The task is the one of TurtleBot3's machine-learning chapter (ROBOTIS-GIT/turtlebot3_machine_learning,
noetic ``src/turtlebot3_dqn/environment_stage_1.py``),
simulated here without Gazebo or ROS, for speed and repeatability:

Observation (``Box``, float32), in this order:
    ``beams`` laser ranges [m] (default 24), counter-clockwise from the sensor's min_angle, within the sensor's
    [range_min, range_max] (no return reads range_max, as TurtleBot3's inf -> 3.5); then the odometry twist,
    linear.x [m/s] and angular.z [rad/s]; then the goal in polar form, its distance [m] and its bearing
    relative to the heading [rad] in [-pi, pi] (TurtleBot3's ``heading``).
Actions:
    discrete (``Discrete(5)``, TurtleBot3's mapping): action ``a`` commands linear.x 0.15 m/s and angular.z
    ((5 - 1) / 2 - a) * 1.5 * 0.5 rad/s: 0 -> +1.5, 1 -> +0.75, 2 -> 0, 3 -> -0.75, 4 -> -1.5 (the code's
    signs; the e-Manual's table has them reversed). Continuous (``Box``): (linear.x, angular.z) within
    +-max_linear, +-max_angular, which must lie within the robot's wheel limits.
    Each action is one cmd_vel held for exactly ``control_period`` s of sim time (default 0.2 s: one scan of
    TurtleBot3's 5 Hz LDS), the observation taken at its end.
Reward (defaults; every term a GoalConfig field):
    ``progress_reward`` (10) per metre the goal got closer during the step (potential-based shaping: it sums
    to 10 x (start distance - final distance), so it cannot change which policy is best), plus
    ``step_reward`` (-0.01) per step; on reaching the goal (ground-truth distance <= ``goal_radius``, 0.2 m as
    TurtleBot3's) ``goal_reward`` (+10); on a collision ``collision_reward`` (-10).
Termination:
    goal reached, or a collision: a physics contact of the robot with any body but the ground (ground truth;
    optionally also TurtleBot3's rule, the nearest laser range below ``collision_range``), or the robot
    leaving the arena by more than OUT_OF_BOUNDS m (``collision_reward`` too). ``info["outcome"]`` says which.
    Truncation: the registration's ``max_episode_steps`` (TimeLimit).
Reset:
    restores the physics snapshot taken when the robot had landed (no respawn, no drift), then stands the
    robot at rest at a start drawn from ``np_random`` with a uniform heading, and draws a goal at least
    ``min_goal_distance`` away; both from the free, reachable cells of the world (``free_space``).
    ``options={"start": (x, y, yaw), "goal": (x, y)}`` overrides either. The laser noise is seeded from
    ``np_random`` too, so ``reset(seed=s)`` fixes the whole episode: same actions, same trajectory.
"""
import math
from dataclasses import dataclass, field, fields

import gymnasium
import numpy as np
from gymnasium import spaces

from diffbot_sim.errors import ConfigError
from diffbot_sim.gym.free_space import draw_start_goal
from diffbot_sim.gym.scene import DEFAULT_MODEL, DEFAULT_WORLD, SCAN_MODES, Scene
from diffbot_sim.transforms import wrap_angle
from diffbot_sim.values import check_bool, check_number, check_string

#: TurtleBot3's DQN actions (environment_stage_1.py): five turn rates at one forward speed.
TURTLEBOT3_ACTIONS = 5
TURTLEBOT3_LINEAR = 0.15  # m/s
TURTLEBOT3_MAX_ANGULAR = 1.5  # rad/s
#: How far [m] outside its arena (the world's bounded bodies) a robot may go before the episode ends.
OUT_OF_BOUNDS = 0.5
OUTCOMES = ("running", "goal", "collision", "out_of_bounds")


def turtlebot3_command(action, action_size=TURTLEBOT3_ACTIONS):
    """(linear.x [m/s], angular.z [rad/s]) of discrete ``action``: ((size - 1) / 2 - action) * 1.5 * 0.5."""
    return TURTLEBOT3_LINEAR, ((action_size - 1) / 2.0 - action) * TURTLEBOT3_MAX_ANGULAR * 0.5


@dataclass
class GoalConfig:
    """What a GoalEnv is made of; every field is a keyword of ``gymnasium.make``. Units in the comments."""

    model: str = DEFAULT_MODEL  # .urdf or .urdf.xacro; a path, or relative to this package
    model_args: str = ""  # xacro arguments, "name:=value ..."
    world: str = DEFAULT_WORLD  # .world or map .yaml (world.loading); "" for a ground plane only
    map_wall_height: float = 1.0  # m, a map's walls
    spawn: tuple = (0.0, 0.0, 0.0)  # x, y [m], yaw [rad] where the robot is loaded (its free area's seed)
    drive: dict = field(default_factory=dict)  # diff-drive parameters, as bullet_sim's (~left_joints ...)
    sensor: str = ""  # the ray sensor's name; "": the model's first
    beams: int = 24  # laser ranges in the observation
    scan_mode: str = "samples"  # samples (the e-Manual's <samples> edit) or min_pool (nearest per sector)
    laser_noise: bool = True  # the sensor's own <noise>
    actions: str = "discrete"  # discrete (TurtleBot3's 5) or continuous
    control_period: float = 0.2  # s of sim time per step: a multiple of time_step
    time_step: float = 1.0 / 240.0  # s, bullet_sim's default
    cmd_vel_timeout: float = 0.0  # s, bullet_sim's ~cmd_vel_timeout: > 0 brakes a command older than it; 0: held
    max_linear: float = 0.3  # m/s, continuous actions
    max_angular: float = 1.5  # rad/s, continuous actions
    goal_radius: float = 0.2  # m
    min_goal_distance: float = 1.0  # m between start and goal
    clearance: float = 0.1  # m around the robot's footprint that starts and goals keep from bodies
    grid: float = 0.1  # m between candidate start/goal cells
    arena: tuple | None = None  # ((x_lo, y_lo), (x_hi, y_hi)) [m]; None: the world's bounded bodies
    collision_range: float = 0.0  # m; > 0 also ends on a laser range below it (TurtleBot3: 0.13)
    progress_reward: float = 10.0  # per metre closer
    goal_reward: float = 10.0
    collision_reward: float = -10.0
    step_reward: float = -0.01


def goal_config(**kwargs):
    """A validated GoalConfig from keyword arguments.

    Raises:
        ConfigError: an unknown keyword or a bad value, named ``GoalEnv <keyword>``.
    """
    known = {f.name for f in fields(GoalConfig)}
    for key in kwargs:
        if key not in known:
            raise ConfigError(f"GoalEnv {key}", kwargs[key], f"one of the keywords {', '.join(sorted(known))}")
    cfg = GoalConfig(**kwargs)

    def name(key):
        return f"GoalEnv {key}"

    for key in ("model", "actions", "scan_mode"):
        setattr(cfg, key, check_string(name(key), getattr(cfg, key)))
    for key in ("model_args", "world", "sensor"):
        setattr(cfg, key, check_string(name(key), getattr(cfg, key), allow_empty=True))
    if cfg.actions not in ("discrete", "continuous"):
        raise ConfigError(name("actions"), cfg.actions, "discrete or continuous")
    if cfg.scan_mode not in SCAN_MODES:
        raise ConfigError(name("scan_mode"), cfg.scan_mode, " or ".join(SCAN_MODES))
    cfg.laser_noise = check_bool(name("laser_noise"), cfg.laser_noise)
    beams = check_number(name("beams"), cfg.beams, low=1, high=100000)
    if beams != int(beams):
        raise ConfigError(name("beams"), cfg.beams, "an integer >= 1")
    cfg.beams = int(beams)
    cfg.time_step = check_number(name("time_step"), cfg.time_step, low=1e-5, high=0.05)
    cfg.control_period = check_number(name("control_period"), cfg.control_period, low=cfg.time_step)
    if abs(cfg.control_period / cfg.time_step - round(cfg.control_period / cfg.time_step)) > 1e-6:
        raise ConfigError(name("control_period"), cfg.control_period, f"a multiple of time_step {cfg.time_step:g}")
    for key in ("map_wall_height", "max_linear", "max_angular", "goal_radius", "grid"):
        setattr(cfg, key, check_number(name(key), getattr(cfg, key), low=0.0, low_open=True))
    for key in ("min_goal_distance", "clearance", "collision_range", "cmd_vel_timeout"):
        setattr(cfg, key, check_number(name(key), getattr(cfg, key), low=0.0))
    for key in ("progress_reward", "goal_reward", "collision_reward", "step_reward"):
        setattr(cfg, key, check_number(name(key), getattr(cfg, key)))
    if not isinstance(cfg.spawn, (tuple, list)) or len(cfg.spawn) != 3:
        raise ConfigError(name("spawn"), cfg.spawn, "(x, y, yaw)")
    cfg.spawn = tuple(check_number(name("spawn"), v) for v in cfg.spawn)
    if not isinstance(cfg.drive, dict):
        raise ConfigError(name("drive"), cfg.drive, "a dict of diff-drive parameters")
    if cfg.arena is not None:
        try:
            (x_lo, y_lo), (x_hi, y_hi) = cfg.arena
        except (TypeError, ValueError):
            raise ConfigError(name("arena"), cfg.arena, "((x_lo, y_lo), (x_hi, y_hi))") from None
        values = [check_number(name("arena"), v) for v in (x_lo, y_lo, x_hi, y_hi)]
        if values[2] <= values[0] or values[3] <= values[1]:
            raise ConfigError(name("arena"), cfg.arena, "hi corner above and right of lo corner")
        cfg.arena = ((values[0], values[1]), (values[2], values[3]))
    return cfg


def _numbers(name, values, expected):
    """A tuple of finite numbers of the length ``expected`` shows, or ConfigError."""
    count = expected.count(",") + 1
    if not isinstance(values, (tuple, list, np.ndarray)) or len(values) != count:
        raise ConfigError(name, values, expected)
    return tuple(check_number(name, v) for v in values)


class GoalEnv(gymnasium.Env):
    """Reach a goal without collision (spaces, termination and reset: the module docstring).

    Reward per step, with the GoalConfig defaults: ``10 * (distance before - distance after) - 0.01``, plus
    ``+10`` on reaching the goal (true distance <= 0.2 m) or ``-10`` on a collision (a contact with any body
    but the ground) or on leaving the arena; either ends the episode (``terminated``).
    """

    metadata: dict[str, list[str]] = {"render_modes": []}

    def __init__(self, render_mode=None, **kwargs):
        if render_mode is not None:
            raise ConfigError("GoalEnv render_mode", render_mode, "None (no rendering)")
        self.config = cfg = goal_config(**kwargs)
        self.scene = scene = Scene(cfg)
        drive = scene.drive
        if cfg.actions == "discrete":
            self.action_space = spaces.Discrete(TURTLEBOT3_ACTIONS)
        else:
            for key, limit in (("max_linear", drive.max_linear), ("max_angular", drive.max_angular)):
                if getattr(cfg, key) > limit + 1e-9:
                    scene.close()
                    raise ConfigError(f"GoalEnv {key}", getattr(cfg, key), f"at most the robot's {limit:g}")
            high = np.array([cfg.max_linear, cfg.max_angular], dtype=np.float32)
            self.action_space = spaces.Box(-high, high, dtype=np.float32)
        (x_lo, y_lo), (x_hi, y_hi) = scene.arena
        self.bounds = (x_lo - OUT_OF_BOUNDS, y_lo - OUT_OF_BOUNDS, x_hi + OUT_OF_BOUNDS, y_hi + OUT_OF_BOUNDS)
        self.max_distance = math.hypot(self.bounds[2] - self.bounds[0], self.bounds[3] - self.bounds[1])
        laser = scene.laser.cfg
        low = [laser.range_min] * cfg.beams + [-drive.max_linear, -drive.max_angular, 0.0, -math.pi]
        high = [laser.range_max] * cfg.beams + [drive.max_linear, drive.max_angular, self.max_distance, math.pi]
        self.observation_space = spaces.Box(np.array(low, np.float32), np.array(high, np.float32),
                                            dtype=np.float32)
        self._low, self._high = self.observation_space.low, self.observation_space.high
        self.period_steps = int(round(cfg.control_period / cfg.time_step))
        self.goal = (0.0, 0.0)
        self.distance = 0.0

    # -- the Gymnasium API ------------------------------------------------------------------------------
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        rng = self.np_random
        start, goal = draw_start_goal(rng, self.scene.cells, self.config.min_goal_distance)
        yaw = float(rng.uniform(-math.pi, math.pi))
        self.scene.laser.reseed(np.random.default_rng(int(rng.integers(2 ** 63))))
        options = options or {}
        if "start" in options:
            x, y, yaw = _numbers("reset options start", options["start"], "(x, y, yaw)")
            start = (x, y)
        if "goal" in options:
            goal = _numbers("reset options goal", options["goal"], "(x, y)")
        self.goal = goal
        self.scene.reset(start[0], start[1], yaw)
        obs, x, y, heading = self._observe()
        return obs, self._info("running", x, y, heading)

    def step(self, action):
        linear, angular = self.command_for(action)
        touched = self.scene.advance(linear, angular, self.period_steps)
        previous = self.distance
        obs, x, y, heading = self._observe()
        cfg = self.config
        reward = cfg.progress_reward * (previous - self.distance) + cfg.step_reward
        outcome = "running"
        if touched or (cfg.collision_range > 0 and float(obs[:cfg.beams].min()) < cfg.collision_range):
            outcome = "collision"
        elif self.distance <= cfg.goal_radius:
            outcome = "goal"
        elif not (self.bounds[0] <= x <= self.bounds[2] and self.bounds[1] <= y <= self.bounds[3]):
            outcome = "out_of_bounds"
        if outcome == "goal":
            reward += cfg.goal_reward
        elif outcome != "running":
            reward += cfg.collision_reward
        return obs, float(reward), outcome != "running", False, self._info(outcome, x, y, heading)

    def close(self):
        self.scene.close()

    # -- parts ------------------------------------------------------------------------------------------
    def command_for(self, action):
        """The cmd_vel (linear.x [m/s], angular.z [rad/s]) an action stands for."""
        if self.config.actions == "discrete":
            if not self.action_space.contains(action):
                raise ValueError(f"action {action!r} is not in {self.action_space}")
            return turtlebot3_command(int(action))
        values = np.clip(np.asarray(action, dtype=np.float64).reshape(2), self.action_space.low,
                         self.action_space.high)
        return float(values[0]), float(values[1])

    def _observe(self):
        """The observation now, and the ground-truth pose it was computed from (x, y, yaw)."""
        scene = self.scene
        ranges = scene.laser.scan(scene.world)
        linear, angular = scene.velocity()
        x, y, yaw = scene.pose2d()
        dx, dy = self.goal[0] - x, self.goal[1] - y
        self.distance = math.hypot(dx, dy)
        bearing = wrap_angle(math.atan2(dy, dx) - yaw)
        obs = np.concatenate([ranges, (linear, angular, self.distance, bearing)]).astype(np.float32)
        return np.clip(obs, self._low, self._high), x, y, yaw

    def _info(self, outcome, x, y, yaw):
        return {"outcome": outcome, "is_success": outcome == "goal", "distance": self.distance,
                "sim_time": self.scene.time, "x": x, "y": y, "yaw": yaw,
                "goal_x": self.goal[0], "goal_y": self.goal[1]}
