"""``libgazebo_ros_p3d.so``: nav_msgs/Odometry of a body (a URDF link, lumped or not) in the world or in
another link's frame, as gazebo_plugins' GazeboRosP3D publishes it (``gazebo_ros_p3d.cpp``).

Tags: ``bodyName`` and ``topicName`` (both required), ``frameName`` (``world``; a link name makes pose and
twist relative to that link), ``xyzOffset``/``rpyOffset`` (the position is shifted and the orientation
left-multiplied, in the reference frame), ``gaussianNoise`` (N(0, sigma) on each twist component, and sigma²
on both covariance diagonals), ``updateRate`` (0: every step), ``robotNamespace``. Lazy.
``child_frame_id`` is ``bodyName``. As the original, the twist is in the reference frame's axes (world by
default), not in the child frame nav_msgs asks for. Gazebo cannot find a link that URDF→SDF lumped away;
here a lumped link works too.
"""
from nav_msgs.msg import Odometry

from diffbot_sim.description.plugin_tags import read_tags, vector
from diffbot_sim.errors import ModelError, PluginNotLoaded
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import Plugin, join, summary_key
from diffbot_sim.sensors import noise
from diffbot_sim.transforms import qconj, qmul, qnormalize, rotate, rpy_quaternion
from diffbot_sim.values import tag_number

FILENAME = "libgazebo_ros_p3d.so"
WORLD_FRAMES = ("world", "/world", "map", "/map", "")
KNOWN = {"bodyName", "topicName", "frameName", "xyzOffset", "xyzOffsets", "rpyOffset", "rpyOffsets",
         "gaussianNoise", "updateRate", "robotNamespace", "alwaysOn"}


def settings(tags, where, notes=None):
    """{body, topic, frame, xyz, rpy, gaussian_noise, period} from the plugin's tags (pure)."""
    for tag in ("bodyName", "topicName"):
        if not tags.get(tag):
            raise PluginNotLoaded(f"the p3d plugin needs <{tag}> (it refuses to load without it)", None, where)
    notes = notes if notes is not None else []
    rate = tag_number(f"<updateRate> of {where}", tags.get("updateRate", 0.0), notes, low=0.0)
    xyz = next((vector(tags[t], where, t) for t in ("xyzOffset", "xyzOffsets") if t in tags), (0.0, 0.0, 0.0))
    rpy = next((vector(tags[t], where, t) for t in ("rpyOffset", "rpyOffsets") if t in tags), (0.0, 0.0, 0.0))
    return {"body": tags["bodyName"], "topic": tags["topicName"], "frame": tags.get("frameName", "world"),
            "xyz": xyz, "rpy": rpy, "namespace": tags.get("robotNamespace"),
            "gaussian_noise": tag_number(f"<gaussianNoise> of {where}", tags.get("gaussianNoise", 0.0), notes,
                                         low=0.0),
            "period": 1.0 / rate if rate > 0 else 0.0}


def relative(body, reference):
    """Pose and twist of ``body`` relative to ``reference`` (each ((p, q), v, w), world values), in the
    reference's axes; None for the world (pure)."""
    (p, q), v, w = body
    if reference is None:
        return (p, q), v, w
    (rp, rq), rv, rw = reference
    inv = qconj(rq)
    return ((rotate(inv, [p[i] - rp[i] for i in range(3)]), qnormalize(qmul(inv, q))),
            rotate(inv, [v[i] - rv[i] for i in range(3)]), rotate(inv, [w[i] - rw[i] for i in range(3)]))


class P3D(Plugin):
    filename = FILENAME

    def __init__(self, ctx, values, path, generator):
        self.ctx, self.v, self.rng = ctx, values, generator
        self.reference = None if values["frame"] in WORLD_FRAMES else values["frame"]
        for link in (values["body"], self.reference):
            if link is None:
                continue
            try:
                ctx.robot.link_motion(link)
            except KeyError:
                raise PluginNotLoaded(f"p3d: '{link}' is not a link of the model; the plugin is not loaded, as in "
                                      "Gazebo", ctx.model.source, path) from None
        self.offset_rot = rpy_quaternion(*values["rpy"])
        ns = ctx.plugin_namespace(values["namespace"])
        self.pub = ctx.publisher(join(ns, values["topic"]), Odometry)
        frame = ctx.clean_frame(values["frame"], path) or "world"
        self.frame_id = frame if self.reference is None else ctx.frame(frame)
        self.child = ctx.frame(ctx.clean_frame(values["body"], path))
        gn2 = values["gaussian_noise"] ** 2
        self.covariance = (gn2,) * 6

    def publishers(self):
        return [self.pub]

    def start(self, now):
        self.next = self.first_due(now, self.v["period"])

    def after_step(self, now, stamp, transforms):
        if not self.take_due(now, self.v["period"]):
            return
        if not self.pub.get_num_connections():
            return
        robot = self.ctx.robot
        body = robot.link_motion(self.v["body"])
        reference = robot.link_motion(self.reference) if self.reference is not None else None
        (p, q), v, w = relative(body, reference)
        p = tuple(p[i] + self.v["xyz"][i] for i in range(3))
        q = qnormalize(qmul(self.offset_rot, q))
        sigma = self.v["gaussian_noise"]
        if sigma > 0:
            v = tuple(x + self.rng.gauss(0.0, sigma) for x in v)
            w = tuple(x + self.rng.gauss(0.0, sigma) for x in w)
        self.pub.publish(ros_msgs.odometry(stamp, self.frame_id, self.child, p, q, v, w, self.covariance,
                                           self.covariance))

    def summary(self):
        rate = f"{round(1.0 / self.v['period'], 3)} Hz" if self.v["period"] > 0 else "every step"
        return {summary_key("p3d", self.pub.resolved_name): f"body {self.v['body']}, frame {self.frame_id}, {rate}"}


def create(ctx, element, path, params):
    tags = read_tags(element)
    try:
        values = settings(tags, path, ctx.warnings)
    except ModelError as err:
        raise type(err)(str(err), ctx.model.source) from None  # PluginNotLoaded stays what it is
    unknown = sorted(set(tags) - KNOWN)
    if unknown:
        ctx.warnings.append(f"{path}: unknown tags ignored: {', '.join(unknown)}")
    return P3D(ctx, values, path, noise.rng(ctx.cfg.seed, element.get("name") or path))
