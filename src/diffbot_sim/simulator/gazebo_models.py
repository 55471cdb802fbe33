"""The models /gazebo names (gazebo_ros's entities): robots, world-file models, models without bodies, actors.

Each answers ``links()``, ``motion(link)`` ((pose, linear, angular) in world axes; the model frame for
``link`` None), ``set_motion(pose, linear, angular, link)`` and ``body_of(link)`` (the PyBullet body and link a
wrench pushes).
"""
from diffbot_sim.gazebo.world_api import RequestError
from diffbot_sim.transforms import compose, inverse


class RobotModelEntity:
    """A robot as a Gazebo model: its root link is the model frame."""

    static = False

    def __init__(self, runtime):
        self.runtime = runtime
        self.name = runtime.name
        self.robot = runtime.ctx.robot
        self.model = runtime.ctx.model

    def links(self):
        """The links Gazebo keeps: the root and every child of a moving joint (fixed-joint children are
        lumped into their parent, as Gazebo's URDF reader does); lumped links still answer ``motion``."""
        return [self.model.root] + [j.child for j in self.model.joints.values() if j.type != "fixed"]

    def motion(self, link=None):
        """(pose, linear, angular) of a link frame (the root: the model), world axes."""
        return self.robot.link_motion(link or self.model.root)

    def set_motion(self, pose, linear, angular, link=None):
        if link not in (None, self.model.root):
            raise RequestError(f"link '{self.name}::{link}' is not the model's canonical link "
                               f"'{self.model.root}': only a whole model can be moved here")
        self.robot.set_base_motion(pose, linear, angular)
        self.runtime.ctx.sim.world.lift_out(self.robot)

    def body_of(self, link):
        return self.robot.body, self.robot.link_carrier(link)


class WorldModelEntity:
    """A top-level model of the world file: its links are separate bodies moved together."""

    def __init__(self, name, bodies, world):
        self.name, self.bodies, self.world = name, bodies, world  # bodies: [(uid, world.Body)]
        self.static = all(body.static for _, body in bodies)

    def links(self):
        return [body.name.split("::")[-1] for _, body in self.bodies]

    def _find(self, link):
        if link is None:
            return self.bodies[0]
        for uid, body in self.bodies:
            if body.name.split("::")[-1] == link:
                return uid, body
        raise KeyError(link)

    def motion(self, link=None):
        uid, body = self._find(link)
        pose, linear, angular = self.world.body_motion(uid, body.inertial_pose)
        if link is None:  # the model frame, carried by its first link
            pose = compose(pose, inverse(self._in_model(body)))
        return pose, linear, angular

    @staticmethod
    def _in_model(body):
        return compose(inverse(body.model_pose), body.pose)

    def set_motion(self, pose, linear, angular, link=None):
        if link is not None:
            uid, body = self._find(link)
            self.world.set_body_motion(uid, body.inertial_pose, pose, linear, angular)
            return
        for uid, body in self.bodies:
            self.world.set_body_motion(uid, body.inertial_pose, compose(pose, self._in_model(body)),
                                       linear, angular)

    def body_of(self, link):
        return self._find(link)[0], -1


class GhostModelEntity:
    """A model with nothing for the physics to hold (only visuals, or links without collisions: a goal marker):
    Gazebo keeps it as a model like any other, so it has a pose (set by set_model_state, back to its spawn
    pose on reset_world), is listed in model_states and can be deleted; nothing collides with it."""

    static = True

    def __init__(self, name, pose, links):
        self.name, self.spawn_pose, self.pose = name, pose, pose
        self.link_names = list(links) or ["link"]

    def links(self):
        return list(self.link_names)

    def motion(self, link=None):
        if link is not None and link not in self.link_names:
            raise KeyError(link)
        return self.pose, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)

    def set_motion(self, pose, linear, angular, link=None):
        self.pose = pose

    def reset(self):
        self.pose = self.spawn_pose

    def body_of(self, link):
        raise RequestError(f"model '{self.name}' has no body to push (nothing in it collides)")


class ActorModelEntity:
    """A Gazebo ``<actor>``: a model whose pose its script or plugin sets (simulator.actors)."""

    static = True

    def __init__(self, actor):
        self.actor, self.name = actor, actor.name

    def links(self):
        return ["link"]

    def motion(self, link=None):
        return self.actor.pose, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)

    def set_motion(self, pose, linear, angular, link=None):
        self.actor.set_pose(pose)

    def body_of(self, link):
        raise RequestError(f"actor '{self.name}' is moved by its script, not by forces")
