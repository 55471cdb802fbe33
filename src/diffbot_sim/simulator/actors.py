"""The world's Gazebo ``<actor>``s in the simulation: each moved every step by its ``<script>``
(:class:`diffbot_sim.world.actor_script.ActorScript`) or by ``libActorPlugin.so``
(:class:`diffbot_sim.world.actor_walk.ActorWalker`), and a person-sized box (:func:`~diffbot_sim.world.actor_walk.
person_box`) that forces never move put where the actor is.

Gazebo's CPU lasers do not see actors (gazebo_ros_pkgs #1508), so a robot drives through the person it should
avoid; here every ray sensor and camera sees the box, and a robot meets it. Actors are models of the world
(/gazebo/model_states, get_model_state). Their script time is sim time: a reset_simulation replays them from
the start; reset_world puts walkers back where they started, as Actor::Reset and ActorPlugin::Reset do.
"""
import math
import random

from diffbot_sim.transforms import quaternion_from_yaw
from diffbot_sim.world.actor_script import ActorScript
from diffbot_sim.world.actor_walk import ActorWalker, person_box, read_walker_config, upright_pose

ACTOR_PLUGIN = "libActorPlugin.so"
#: Where an actor's box waits, out of every ray's and body's way, before its script's first frame.
PARKED = ((0.0, 0.0, -1.0e5), (0.0, 0.0, 0.0, 1.0))


class Actor:
    """One actor: its mover (script or walker) and its box in the physics."""

    def __init__(self, world, description, seed, notes):
        self.world, self.description, self.name = world, description, description.name
        self.size_x, self.size_y, self.size_z, self.centre = person_box(description)
        plugin = description.plugin(ACTOR_PLUGIN)
        self.walker = self.script = None
        if plugin is not None:
            config = read_walker_config(description, plugin, f"actor '{self.name}' plugin {ACTOR_PLUGIN}", notes)
            self.walker = ActorWalker(config, description.world_pose, random.Random(f"{seed}:{self.name}"))
        else:
            self.script = ActorScript(description)
        self.pose = description.world_pose
        self.uid = world.add_kinematic_box((self.size_x, self.size_y, self.size_z), self._body_pose())
        self._placed = self.pose

    def _body_pose(self):
        """Where the box goes: on the actor, except while a script waits for its first frame (the first 1/30 s):
        Gazebo's actor stands at its ``<pose>`` until then with no body, and a box there would be in the rays of
        a laser standing at that pose (a robot spawned at the origin saw it at 1/240 s steps)."""
        if self.script is not None and self.script.about_to_move:
            return PARKED
        return self._box_pose()

    def _box_pose(self):
        if self.walker is not None:
            (x, y, z), heading = self.walker.body_pose()
        else:
            (x, y, z), heading = upright_pose(self.pose)
        c, s = math.cos(heading), math.sin(heading)
        cx, cy, cz = self.centre
        return (x + c * cx - s * cy, y + s * cx + c * cy, z + cz), quaternion_from_yaw(heading)

    def update(self, now, obstacles):
        """Move to where the script or the plugin puts the actor at sim time ``now``."""
        if self.walker is not None:
            self.pose = self.walker.update(now, obstacles)
        else:
            self.pose = self.script.pose_at(now)
        if self.pose != self._placed:
            self.world.move_body(self.uid, self._body_pose())
            self._placed = self.pose

    def reset(self, now):
        if self.walker is not None:
            self.walker.reset()
        else:
            self.script.reset(now)
        self.pose = self.description.world_pose
        self.world.move_body(self.uid, self._body_pose())
        self._placed = self.pose

    def set_pose(self, pose):
        """set_model_state on an actor: it stands there until its mover moves it again."""
        self.pose = pose
        self.world.move_body(self.uid, self._box_pose())


class Actors:
    """Every actor of the world, stepped by the simulator's loop."""

    def __init__(self, world, descriptions, seed, robots):
        self.world = world
        self.robots = robots  # callable: the current RobotRuntimes (their bodies are obstacles to walkers)
        self.notes = []
        self.actors = [Actor(world, d, seed, self.notes) for d in descriptions]
        self._walkers = any(a.walker is not None for a in self.actors)
        self._static = {}  # top model -> origin, of the world models nothing moves (read once)
        for uid, body in world.world_bodies:
            if body.static:
                self._static.setdefault(body.top_model, world.body_pose(uid, body.inertial_pose)[0])

    def __len__(self):
        return len(self.actors)

    def obstacles(self):
        """Every model origin a walker steers around (the plugin's "models"): world models, robots, actors."""
        out = dict(self._static)
        for uid, body in self.world.world_bodies:
            if not body.static:
                out.setdefault(body.top_model, self.world.body_pose(uid, body.inertial_pose)[0])
        for runtime in self.robots():
            out[runtime.name] = runtime.ctx.robot.base_pose()[0]
        for actor in self.actors:
            out[actor.name] = actor.pose[0]
        return out

    def before_step(self, now):
        obstacles = self.obstacles() if self._walkers else None
        for actor in self.actors:
            actor.update(now, obstacles)

    def reset(self, now):
        for actor in self.actors:
            actor.reset(now)
