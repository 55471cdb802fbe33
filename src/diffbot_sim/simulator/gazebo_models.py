"""The models /gazebo names (gazebo_ros's entities): robots, world-file models, models without bodies, actors.

Each answers ``links()``, ``motion(link)`` ((pose, linear, angular) in world axes; the model frame for
``link`` None), ``set_motion(pose, linear, angular, link)`` and ``body_of(link)`` (the PyBullet body and link a
wrench pushes).
"""
import rospy

from diffbot_sim.gazebo.world_api import RequestError
from diffbot_sim.transforms import compose, inverse, rpy_quaternion


class RobotModelEntity:
    """A robot as a Gazebo model: its root link is the model frame (for a robot joined to the world by a fixed
    joint, the model frame is where the spawn put it and the root sits at that joint's origin in it)."""

    static = False

    def __init__(self, runtime):
        self.runtime = runtime
        self.name = runtime.name
        self.robot = runtime.ctx.robot
        self.model = runtime.ctx.model
        self._warned_fixed = False

    def links(self):
        """The links Gazebo keeps (``RobotModel.gazebo_links``: the root, the children of joints to the world
        and of moving joints; fixed-joint children are lumped into their parent, as Gazebo's URDF reader does);
        lumped links still answer ``motion``."""
        return self.model.gazebo_links()

    def motion(self, link=None):
        """(pose, linear, angular) of a link frame (none: the model frame), world axes."""
        pose, linear, angular = self.robot.link_motion(link or self.model.root)
        anchor = self.model.anchor
        if link is None and anchor is not None:  # the model frame: the root's pose less its joint to the world
            pose = compose(pose, inverse((anchor.xyz, rpy_quaternion(*anchor.rpy))))
        return pose, linear, angular

    def set_motion(self, pose, linear, angular, link=None):
        if link not in (None, self.model.root):
            raise RequestError(f"link '{self.name}::{link}' is not the model's canonical link "
                               f"'{self.model.root}': only a whole model can be moved here")
        if self.model.fixed_to_world:
            # Gazebo's fixed joint to the world keeps the relative pose it was attached with (ODE's
            # dJointSetFixed at load) and pulls a teleported model straight back: it stays where spawned.
            if not self._warned_fixed:
                self._warned_fixed = True
                joints = ", ".join(j.name for j in self.model.world_joints)
                rospy.logwarn(f"model '{self.name}' is joined to the world ({joints}): a new pose for it does not "
                              "move it; its joint to the world holds it where it was spawned, as in Gazebo")
            return
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
