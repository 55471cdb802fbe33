"""``<sensor type="contact">`` and ``libgazebo_ros_bumper.so`` on it: gazebo_msgs/ContactsState of the sensor's
collision, as gazebo_ros_bumper (noetic) publishes it.

The sensor's ``<contact><collision>`` names an SDF collision as Gazebo names it after lumping
(:mod:`diffbot_sim.description.gazebo_collisions`: ``base_footprint_fixed_joint_lump__base_link_collision``);
one that names none is one warning, and the sensor reports no contact (Gazebo's sees none either). Contacts
are those of the PyBullet link carrying that collision in the last physics step, at the sensor's
``<update_rate>`` (0: every step); values as :mod:`diffbot_sim.sensors.contact` says (world positions and
normals, wrenches on the sensor's link in its frame, depths).

Plugin tags: ``robotNamespace`` (topics under it; none: the node's namespace), ``bumperTopicName``
(``bumper_states``), ``frameName`` (``world``; only the header's frame_id, with the robot's tf_prefix, as
upstream). Published only while subscribed, also with no contact (empty ``states``), stamped in sim time.
"""
from gazebo_msgs.msg import ContactsState

from diffbot_sim.description.gazebo_collisions import sensor_collision
from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import ConfigError
from diffbot_sim.messages.contacts import contacts_state
from diffbot_sim.physics.contacts import link_com_pose, link_contact_points
from diffbot_sim.plugins.base import Plugin, join, summary_key
from diffbot_sim.sensors.contact import contact_states
from diffbot_sim.values import tag_number

_READ = ("robotNamespace", "bumperTopicName", "frameName", "alwaysOn", "updateRate")


class ContactSensor:
    """A ``<sensor type="contact">`` on a robot: its collision and the step's contacts of it (also read by the
    Kobuki plugin's bumper and wheel drops)."""

    def __init__(self, ctx, sensor_element, link, path):
        self.ctx, self.link, self.path = ctx, link, path
        contact = sensor_element.find("contact")
        names = [tag_value(c) for c in contact.findall("collision")] if contact is not None else []
        if not names:
            raise ConfigError(f"{path}/contact/collision", None, "the name of the collision the sensor watches")
        self.collision, self.collision_name = sensor_collision(ctx.model, link, names[0])
        if self.collision is None:
            ctx.warnings.append(f"{path}: <contact><collision> '{self.collision_name}' is no collision of link "
                                f"'{link}' as Gazebo names them; the sensor reports no contact (as Gazebo's)")
        self.scoped = f"{ctx.spec.name or ctx.model.name}::{self.collision.link if self.collision else link}::" \
                      f"{self.collision_name}"
        rate = sensor_element.find("update_rate")
        rate = tag_number(f"{path}/update_rate", tag_value(rate), ctx.warnings, low=0.0) if rate is not None else 0.0
        self.period = 1.0 / rate if rate > 0 else 0.0

    def points(self):
        """The last step's contact points of the watched collision (none when it names no collision)."""
        if self.collision is None:
            return []
        return link_contact_points(self.ctx.robot, self.collision.urdf_link)

    def states(self):
        """The last step's :class:`~diffbot_sim.sensors.contact.ContactState` list."""
        points = self.points()
        if not points:
            return []
        com = link_com_pose(self.ctx.robot, self.collision.urdf_link)
        return contact_states(points, self.scoped, self._name_of, *com)

    def _name_of(self, body, link):
        for uid, world_body in self.ctx.sim.world.world_bodies:
            if uid == body:
                shape = world_body.shapes[0].name if world_body.shapes and world_body.shapes[0].name else "collision"
                scoped = world_body.name if "::" in world_body.name else f"{world_body.model}::{world_body.name}"
                return f"{scoped}::{shape}"
        return f"body{body}::link{link}::collision"


class Bumper(Plugin):
    filename = "libgazebo_ros_bumper.so"
    sensor = True
    sensor_timer = True

    def __init__(self, ctx, contact, topic, frame):
        self.ctx, self.contact, self.frame = ctx, contact, frame
        self.pub = ctx.publisher(topic, ContactsState)

    def publishers(self):
        return [self.pub]

    def start(self, now):
        self.next = self.first_due(now, self.contact.period)

    def after_step(self, now, stamp, transforms):
        if not self.take_due(now, self.contact.period) or not self.pub.get_num_connections():
            return
        self.pub.publish(contacts_state(stamp, self.frame, self.contact.states()))

    def summary(self):
        return {summary_key("sensor", self.contact.path): f"{self.filename} topic {self.pub.resolved_name} "
                                                          f"collision {self.contact.scoped}"}


def create(ctx, sensor, element, params):
    path = f"{sensor.path}/plugin[@name='{element.get('name')}']"
    if sensor.type != "contact":
        raise ConfigError(f"<sensor type> of {path}", sensor.type, "contact (libgazebo_ros_bumper.so's sensor)")
    tags = {child.tag: tag_value(child) for child in element}
    ignored = [t for t in tags if t not in _READ]
    if ignored:
        ctx.warnings.append(f"{path}: tags ignored (gazebo_ros_bumper does not read them): {', '.join(ignored)}")
    ns = ctx.plugin_namespace(tags["robotNamespace"].strip() if "robotNamespace" in tags else None, "/")
    topic = join(ns, tags.get("bumperTopicName") or "bumper_states")
    frame = ctx.frame(ctx.clean_frame(tags.get("frameName") or "world", path))
    return Bumper(ctx, ContactSensor(ctx, sensor.element, sensor.link, sensor.path), topic, frame)
