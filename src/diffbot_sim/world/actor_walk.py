"""Gazebo-classic's ``libActorPlugin.so`` (the cafe.world walkers) as a pure model, and the box that stands in
for an actor's body (pure).

Reproduced from gazebo-classic ``plugins/ActorPlugin.cc`` (gazebo9+/11 version, with ``Reset()``), read with
ign-math6's ``Vector3::Normalize``, ``Angle::Normalize`` and ``Quaternion::Euler``:

* Tags (each optional): ``<target>`` (default 0 -5 1.2138), ``<target_weight>`` 1.15, ``<obstacle_weight>``
  1.5, ``<animation_factor>`` 4.5, and the ``<model>`` names of the first ``<ignore_obstacles>``; the
  actor's own name is always ignored. The plugin drives the actor through a custom trajectory, so the
  actor's ``<script>`` is not played (when the skin has a ``walking`` animation).
* Every world update (each simulation step, ``dt`` from the previous one): when the target is nearer
  than 0.3 m a new one is drawn, x ~ U(-3, 3.5), y ~ U(-10, 2) (cafe.world's floor, hard-coded), again and
  again until it is 2 m or more from the old target and from the origin of every model of the world (the
  actor and ignored models included; 3-D distances, the target keeping its z). The heading is a vector
  field: the unit vector to the target times ``target_weight``, minus ``obstacle_weight / d`` along the
  unit vector to every other model origin within 4 m. If the heading is more than 10 degrees off, the
  actor only turns by 0.001 of the error (per update, so the turn rate depends on the update rate, as in
  Gazebo); otherwise it steps ``heading * 0.8 m/s * dt`` (so 0.8 x 1.15 = 0.92 m/s in the open) and faces
  the heading. x and y are then clamped to the floor and z is forced to 1.2138 m; roll is 1.5707 because
  the walk mesh is Y-up, and the yaw is the heading + 1.5707. The skeleton's script time advances by
  distance x ``animation_factor`` (kept, not used: there is no skeleton here).

For our bodies, :func:`upright_pose` and :meth:`ActorWalker.body_pose` give the upright frame (feet on the
floor, x along the walking direction) and :func:`person_box` the box to put there.

Deliberately not reproduced: Gazebo's unseeded global random generator (the caller's seeded
``random.Random`` draws instead, so runs repeat); an obstacle exactly at the actor's origin (Gazebo
divides by zero and the pose becomes NaN: it is skipped); a target no draw can satisfy (Gazebo loops
forever: after :data:`MAX_TARGET_DRAWS` the old target is kept).
"""
import math
from dataclasses import dataclass

from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.transforms import qnormalize, quaternion_rpy, rpy_quaternion, wrap_angle
from diffbot_sim.values import check_number, tag_number

Vec3 = tuple[float, float, float]

#: The plugin's file; ``ActorDescription.plugin(PLUGIN_FILENAME)`` finds it.
PLUGIN_FILENAME = "libActorPlugin.so"
#: The skeleton animation the plugin needs (it logs an error and the actor slides without one).
WALKING_ANIMATION = "walking"
#: Walking speed factor, m/s per unit of heading vector (``velocity`` in the plugin).
SPEED = 0.8
#: The roll (rad) that stands the Y-up walk mesh upright; also added to the heading to get the yaw.
WALK_ROLL = 1.5707
#: The z (m) the plugin holds the skin's root bone at. Derived, not stated upstream: walk.dae's root bone
#: sits this high above its feet (scripted actors of actor.world have waypoints at z = 0 and stand on the
#: ground), so the feet are on cafe.world's floor (z = 0).
WALK_ROOT_HEIGHT = 1.2138
#: cafe.world's floor, where targets are drawn and the actor is kept: (min, max) of x and of y, m.
FLOOR_X = (-3.0, 3.5)
FLOOR_Y = (-10.0, 2.0)
#: Nearer than this (m) the target counts as reached.
TARGET_REACHED = 0.3
#: A new target is this far (m) at least from the old one and from every model origin.
TARGET_CLEARANCE = 2.0
#: Models whose origins are nearer than this (m) push the actor away.
OBSTACLE_RANGE = 4.0
#: A heading error above this (rad) makes the actor turn in place.
TURN_IN_PLACE = math.radians(10.0)
#: Fraction of the heading error turned per update while turning in place.
TURN_GAIN = 0.001
#: Draws before giving up on a new target (Gazebo would draw forever).
MAX_TARGET_DRAWS = 10000

#: A standing adult as a box (m): depth along the walking direction, shoulder width, height. Anthropometry
#: (US Army ANSUR II, Gordon et al. 2014, NATICK/TR-15/007; men's means, recalled: stature ~1.76 m,
#: bideltoid breadth ~0.49 m, chest depth ~0.25 m) rounded up for clothes and for a stride's swing.
PERSON_SIZE = (0.35, 0.5, 1.8)


# ------------------------------------------------------------------------------------------ configuration

@dataclass(frozen=True)
class WalkerConfig:
    """The plugin's tags: ``target`` (x, y, z) m; the vector-field weights; ``ignore_models`` besides the
    actor itself (``actor_name``)."""

    actor_name: str
    target: Vec3 = (0.0, -5.0, WALK_ROOT_HEIGHT)
    target_weight: float = 1.15
    obstacle_weight: float = 1.5
    animation_factor: float = 4.5
    ignore_models: tuple[str, ...] = ()


def read_walker_config(description, plugin, path, notes):
    """The :class:`WalkerConfig` of ``plugin`` (a ``PluginRef`` of ``description``, the actor it sits in).

    Numbers are read as the plugin's ``sdf::Element::Get`` reads them (:func:`diffbot_sim.values.tag_number`:
    the leading number, the rest dropped with a note); ``<target>`` must be 3 numbers. A skin without a
    ``walking`` animation is a note: Gazebo logs an error and moves the actor all the same.

    Raises:
        ModelError: a tag without a number, naming ``path``/tag.
    """
    el = plugin.element

    def number(tag, default):
        text = el.findtext(tag)
        if text is None or not text.strip():
            return default
        try:
            return tag_number(f"{path}/{tag}", text, notes)
        except ConfigError:
            raise ModelError(f"'{text.strip()}' is not a number", element=f"{path}/{tag}") from None

    target = WalkerConfig.target
    text = (el.findtext("target") or "").strip()
    if text:
        try:
            target = tuple(float(v) for v in text.split())
        except ValueError:
            target = ()
        if len(target) != 3 or not all(math.isfinite(v) for v in target):
            raise ModelError(f"<target> '{text}' is not 3 finite numbers", element=f"{path}/target")
    ignore_el = el.find("ignore_obstacles")  # Gazebo reads the first block only
    ignored = () if ignore_el is None else tuple(
        (m.text or "").strip() for m in ignore_el.findall("model") if (m.text or "").strip())
    if description.skin is not None and not any(a.name == WALKING_ANIMATION for a in description.animations):
        notes.append(f"{path}: actor '{description.name}' has no '{WALKING_ANIMATION}' animation: Gazebo logs "
                     "an error and the plugin moves it without one")
    return WalkerConfig(description.name, target, number("target_weight", 1.15),
                        number("obstacle_weight", 1.5), number("animation_factor", 4.5), ignored)


# ------------------------------------------------------------------------------------------ the walker

def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _length(v):
    return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


def _normalized(v):
    """Vector3::Normalize: unchanged when its length is (within 1e-6) zero."""
    d = _length(v)
    return v if abs(d) <= 1e-6 else (v[0] / d, v[1] / d, v[2] / d)


class ActorWalker:
    """One ``libActorPlugin.so`` actor: call :meth:`update` every simulation step.

    ``start_pose``: the actor's ``<pose>`` as ((x, y, z), (qx, qy, qz, qw)) (``ActorDescription.world_pose``),
    where it stands until the first update. ``rng``: a ``random.Random`` (seed it so runs repeat); only
    new targets draw from it, x before y as the plugin does.
    """

    def __init__(self, config, start_pose, rng):
        self.config = config
        self.start_pose = (tuple(float(c) for c in start_pose[0]), qnormalize(start_pose[1]))
        self.rng = rng
        self._ignored = set(config.ignore_models) | {config.actor_name}
        self.reset()

    def reset(self):
        """World reset: Actor::Reset puts the actor back at its ``<pose>``, ActorPlugin::Reset restores the
        configured target and the time of the last update (0)."""
        self.position, self.rotation = self.start_pose
        self.target = tuple(float(c) for c in self.config.target)
        self.last_update = 0.0
        #: The skeleton's script time, s: advanced by distance walked x animation_factor.
        self.script_time = 0.0

    @property
    def pose(self):
        """((x, y, z), (qx, qy, qz, qw)): what Gazebo reports for the actor (roll 1.5707 once it walks)."""
        return (self.position, self.rotation)

    def body_pose(self):
        """The upright frame of the actor's body: ((x, y, z of the feet), heading rad); see :func:`upright_pose`."""
        return upright_pose(self.pose, yaw_offset=WALK_ROLL, root_height=WALK_ROOT_HEIGHT)

    def steering(self, obstacles):
        """The plugin's vector field at the current position (before a new target is drawn): unit vector
        to the target x target_weight, minus obstacle_weight / d along each unit vector to a model origin
        (``obstacles``: name -> (x, y, z)) within 4 m that is not ignored."""
        w = self.config.target_weight
        heading = tuple(c * w for c in _normalized(_sub(self.target, self.position)))
        for name, origin in obstacles.items():
            if name in self._ignored:
                continue
            offset = _sub(tuple(float(c) for c in origin), self.position)
            distance = _length(offset)
            if 0.0 < distance < OBSTACLE_RANGE:
                push = self.config.obstacle_weight / distance
                heading = _sub(heading, tuple(c * push for c in _normalized(offset)))
        return heading

    def update(self, sim_time, obstacles=None):
        """ActorPlugin::OnUpdate at ``sim_time`` s; ``obstacles``: name -> (x, y, z) origin of every model of
        the world (robots, furniture, other actors; ignored ones too: new targets keep clear of all of
        them). Returns the new :attr:`pose`."""
        obstacles = dict(obstacles or {})
        dt = sim_time - self.last_update
        _, _, yaw = quaternion_rpy(self.rotation)
        if _length(_sub(self.target, self.position)) < TARGET_REACHED:
            self._choose_new_target(obstacles)
        heading = self.steering(obstacles)
        error = wrap_angle(math.atan2(heading[1], heading[0]) + WALK_ROLL - yaw)
        position = self.position
        if abs(error) > TURN_IN_PLACE:
            self.rotation = rpy_quaternion(WALK_ROLL, 0.0, yaw + error * TURN_GAIN)
        else:
            step = SPEED * dt
            position = tuple(p + h * step for p, h in zip(position, heading))
            self.rotation = rpy_quaternion(WALK_ROLL, 0.0, yaw + error)
        position = (min(max(position[0], FLOOR_X[0]), FLOOR_X[1]),
                    min(max(position[1], FLOOR_Y[0]), FLOOR_Y[1]), WALK_ROOT_HEIGHT)
        self.script_time += _length(_sub(position, self.position)) * self.config.animation_factor
        self.position = position
        self.last_update = sim_time
        return self.pose

    def _choose_new_target(self, obstacles):
        """ActorPlugin::ChooseNewTarget: redraw until 2 m from the old target and from every model origin."""
        origins = [tuple(float(c) for c in p) for name, p in obstacles.items() if name != self.config.actor_name]
        origins.append(self.position)  # the actor is a model of the world too
        old = self.target
        for _ in range(MAX_TARGET_DRAWS):
            x = self.rng.uniform(*FLOOR_X)
            y = self.rng.uniform(*FLOOR_Y)
            candidate = (x, y, old[2])
            if _length(_sub(candidate, old)) < TARGET_CLEARANCE:
                continue
            if all(_length(_sub(o, candidate)) >= TARGET_CLEARANCE for o in origins):
                self.target = candidate
                return


# ------------------------------------------------------------------------------------------ the body

def upright_pose(pose, yaw_offset=0.0, root_height=0.0):
    """((x, y, z - root_height), heading): the upright frame a body box is posed in, x along the heading.

    For a scripted actor use the trajectory pose as it is (its yaw is the heading, its z the feet: the
    defaults). For an ActorPlugin walker use ``yaw_offset=WALK_ROLL, root_height=WALK_ROOT_HEIGHT``
    (:meth:`ActorWalker.body_pose`): its yaw is the heading + 1.5707 and its z the skin's root bone. Roll and
    pitch are dropped: the body stays upright.
    """
    (x, y, z), q = pose
    return ((x, y, z - root_height), wrap_angle(quaternion_rpy(q)[2] - yaw_offset))


def person_box(description, mesh_bounds=None):
    """(size_x, size_y, size_z, (cx, cy, cz)) m: a box for the actor's body in its upright frame
    (:func:`upright_pose`: x along the walking direction, z up, origin at the feet), its centre at (cx, cy, cz).

    ``mesh_bounds``: ((min x, y, z), (max x, y, z)) of the skin's vertices in the skin's own frame, before
    ``<skin><scale>`` (which is applied here). Gazebo's walk meshes are Y-up and walk along +Z (the
    plugin's roll 1.5707 and yaw = heading + 1.5707 turn skin +Y up and skin +Z forward), so the box's
    x (depth) is the skin's Z extent, y (width) its X extent and z (height) its Y extent. Without bounds:
    :data:`PERSON_SIZE` standing on the origin, scaled by the skin's scale.

    Raises:
        ConfigError: bounds that are not finite numbers with min <= max.
    """
    scale = description.skin.scale if description.skin is not None else 1.0
    if mesh_bounds is None:
        sx, sy, sz = (s * scale for s in PERSON_SIZE)
        return (sx, sy, sz, (0.0, 0.0, sz / 2.0))
    try:
        low, high = ([check_number("mesh_bounds", v) for v in corner] for corner in mesh_bounds)
    except (TypeError, ValueError):
        raise ConfigError("mesh_bounds", mesh_bounds, "((min x, y, z), (max x, y, z))") from None
    if len(low) != 3 or len(high) != 3 or any(lo > hi for lo, hi in zip(low, high)):
        raise ConfigError("mesh_bounds", mesh_bounds, "((min x, y, z), (max x, y, z)) with min <= max")
    size = [(hi - lo) * scale for lo, hi in zip(low, high)]
    centre = [(hi + lo) / 2.0 * scale for lo, hi in zip(low, high)]
    # skin (x, y, z) -> body (forward, left, up) = skin (z, x, y)
    return (size[2], size[0], size[1], (centre[2], centre[0], centre[1]))
