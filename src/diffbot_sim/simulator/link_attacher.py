"""``libgazebo_ros_link_attacher.so`` (pal-robotics, world plugin): ``/link_attacher_node/attach`` and
``/link_attacher_node/detach`` (gazebo_ros_link_attacher/Attach from the overlay), as upstream serves them.

attach(model_name_1, link_name_1, model_name_2, link_name_2) joins the two links rigidly where they are now;
``ok`` false (with upstream's error line) when a model or a link is not found (links as Gazebo has them: a
link lumped by a fixed joint is not one). The same pair attached again reuses its joint; detach releases it
(the links move freely again) and answers false for a pair never attached. Each request runs on the loop.
"""
import rospy

from diffbot_sim.physics.constraints import fix_together, release

FILENAME = "libgazebo_ros_link_attacher.so"
NODE = "/link_attacher_node"


class LinkAttacher:
    def __init__(self, sim):
        from gazebo_ros_link_attacher.srv import Attach, AttachResponse

        self.sim, self.response = sim, AttachResponse
        self.joints = {}  # (model1, link1, model2, link2) -> constraint id, or None while detached
        self.services = [rospy.Service(f"{NODE}/attach", Attach, self._attach),
                         rospy.Service(f"{NODE}/detach", Attach, self._detach)]

    def _body(self, model, link):
        entity = self.sim.api.models().get(model) if self.sim.api is not None else None
        if entity is None:
            raise LookupError(f"{model} model was not found")
        if link not in entity.links():
            raise LookupError(f"{link} link was not found")
        return entity.body_of(link)

    def attach(self, key):
        if self.joints.get(key) is not None:
            return True  # "Joint already existed, reusing it."
        try:
            (b1, l1), (b2, l2) = self._body(key[0], key[1]), self._body(key[2], key[3])
        except LookupError as err:
            rospy.logerr(f"link_attacher: {err}")
            return False
        self.joints[key] = fix_together(self.sim.world.client, b1, l1, b2, l2)
        return True

    def detach(self, key):
        if key not in self.joints:
            return False
        if self.joints[key] is not None:
            release(self.sim.world.client, self.joints[key])
            self.joints[key] = None
        return True

    def _attach(self, req):
        key = (req.model_name_1, req.link_name_1, req.model_name_2, req.link_name_2)
        return self.response(self.sim.call(lambda: self.attach(key)))

    def _detach(self, req):
        key = (req.model_name_1, req.link_name_1, req.model_name_2, req.link_name_2)
        return self.response(self.sim.call(lambda: self.detach(key)))


def start_if_named(sim, world_file):
    """The attacher when the world file names its plugin (None otherwise, or when the overlay is left out)."""
    from diffbot_sim.world.world_plugins import world_plugins

    if not any(filename.endswith(FILENAME) or filename == FILENAME.removesuffix(".so").removeprefix("lib")
               for filename, _ in world_plugins(world_file)):
        return None
    try:
        return LinkAttacher(sim)
    except ImportError:
        rospy.logwarn(f"bullet_sim: {FILENAME} in the world, but gazebo_ros_link_attacher is not built (overlay left "
                      "out): no /link_attacher_node services")
        return None
