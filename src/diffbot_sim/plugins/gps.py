"""``libhector_gazebo_ros_gps.so``: sensor_msgs/NavSatFix and geometry_msgs/Vector3Stamped (velocity) of a
link, as hector_gazebo_plugins' GazeboRosGps gives them (``gazebo_ros_gps.cpp``).

Tags and defaults: ``bodyName`` (the model's first link; a lumped link works too), ``frameId`` (``world``;
hector's default ``/world`` loses its slash, which tf2 rejects), ``topicName`` (``fix``),
``velocityTopicName`` (``fix_velocity``), ``referenceLatitude``/``referenceLongitude`` [deg] (49.9, 8.9),
``referenceHeading`` [deg] (0), ``referenceAltitude`` [m] (0), ``status`` (0: STATUS_FIX), ``service``
(1: GPS), ``updateRate`` (0: every step) or ``updatePeriod``, ``robotNamespace``; position error
``offset``, ``drift``, ``driftFrequency``, ``gaussianNoise``, ``scaleError`` (3 values or one) and the same
with the ``velocity`` prefix (:class:`diffbot_sim.sensors.noise.HectorModel`; the velocity drift is integrated into
the position drift, as hector does). ``useWorldSphericalCoordinates`` is ignored (warned): worlds here carry
no ``<spherical_coordinates>``.

Conversion (:func:`to_geodetic`): a local tangent plane on the WGS84 ellipsoid at the reference point. With
heading h (clockwise from north, hector's convention), the world's +x points along heading h and +y 90°
to its left: north = cos h·x + sin h·y, west = −sin h·x + cos h·y. So with hector's default h = 0 the world is
north-west-up (+x north, +y west), and h = 90 gives REP 103's east-north-up (+x east, +y north). The
velocity vector is published in the same (north, west, up) axes, as hector does.
"""
import math

from geometry_msgs.msg import Vector3Stamped
from sensor_msgs.msg import NavSatFix

from diffbot_sim.description.plugin_tags import read_tags
from diffbot_sim.errors import ModelError, PluginNotLoaded
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import Plugin, join, summary_key
from diffbot_sim.sensors import noise
from diffbot_sim.values import check_bool, tag_number

FILENAME = "libhector_gazebo_ros_gps.so"
#: WGS84 ellipsoid.
EQUATORIAL_RADIUS = 6378137.0
FLATTENING = 1.0 / 298.257223563
ECCENTRICITY2 = 2 * FLATTENING - FLATTENING ** 2
DEFAULTS = {"referenceLatitude": 49.9, "referenceLongitude": 8.9, "referenceHeading": 0.0,
            "referenceAltitude": 0.0}
KNOWN = {"bodyName", "frameId", "topicName", "velocityTopicName", "status", "service", "updateRate",
         "updatePeriod", "updateOffset", "robotNamespace", "alwaysOn", "useWorldSphericalCoordinates"} \
    | set(DEFAULTS) | set(noise.hector_tag_names("")) | set(noise.hector_tag_names("velocity"))


def radii(latitude_deg):
    """(north, east) radii [m] of the WGS84 ellipsoid at a latitude: metres per radian of latitude (the
    meridian radius M) and of longitude (the prime vertical radius N times cos(latitude))."""
    phi = math.radians(latitude_deg)
    s2 = math.sin(phi) ** 2
    n = EQUATORIAL_RADIUS / math.sqrt(1.0 - ECCENTRICITY2 * s2)
    m = EQUATORIAL_RADIUS * (1.0 - ECCENTRICITY2) / (1.0 - ECCENTRICITY2 * s2) ** 1.5
    return m, n * math.cos(phi)


def north_west(x, y, heading_deg):
    """World (x, y) -> (north, west) [m] for a reference heading (deg, clockwise from north)."""
    h = math.radians(heading_deg)
    return math.cos(h) * x + math.sin(h) * y, -math.sin(h) * x + math.cos(h) * y


def to_geodetic(position, reference):
    """World position (x, y, z) [m] -> (latitude, longitude [deg], altitude [m]); ``reference`` =
    (latitude, longitude, heading, altitude) (pure)."""
    lat0, lon0, heading, alt0 = reference
    r_north, r_east = radii(lat0)
    north, west = north_west(position[0], position[1], heading)
    return (lat0 + math.degrees(north / r_north), lon0 - math.degrees(west / r_east), alt0 + position[2])


def settings(tags, where, root, generator, notes=None):
    """Everything the plugin does, from its tags (pure); numbers read as Gazebo reads them, what it drops
    after a number named in ``notes``."""
    notes = notes if notes is not None else []
    values = {key: tag_number(f"<{key}> of {where}", tags.get(key, default), notes)
              for key, default in DEFAULTS.items()}
    rate = tag_number(f"<updateRate> of {where}", tags.get("updateRate", 0.0), notes, low=0.0)
    period = 1.0 / rate if rate > 0 else 0.0
    if "updatePeriod" in tags:
        period = tag_number(f"<updatePeriod> of {where}", tags["updatePeriod"], notes, low=0.0)
    out = {
        "body": tags.get("bodyName") or root,
        "frame": tags.get("frameId", "world"),
        "topic": tags.get("topicName", "fix"),
        "velocity_topic": tags.get("velocityTopicName", "fix_velocity"),
        "namespace": tags.get("robotNamespace"),
        "reference": (values["referenceLatitude"], values["referenceLongitude"], values["referenceHeading"],
                      values["referenceAltitude"]),
        "status": tag_number(f"<status> of {where}", tags.get("status", 0), notes, integer=True, low=-1, high=2),
        "service": tag_number(f"<service> of {where}", tags.get("service", 1), notes, integer=True, low=0, high=15),
        "period": period,
        "position": noise.hector_models(tags, "", generator, where),
        "velocity": noise.hector_models(tags, "velocity", generator, where),
        "world_coordinates": check_bool(f"<useWorldSphericalCoordinates> of {where}",
                                   tags.get("useWorldSphericalCoordinates", "false")),
    }
    return out


def covariance(models):
    """hector's position covariance diagonal: drift² + gaussianNoise² per axis."""
    return tuple(m.drift ** 2 + m.gaussian_noise ** 2 for m in models)


class Gps(Plugin):
    filename = FILENAME
    sensor_timer = True  # hector's UpdateTimer updates at multiples of its period on sim time

    def __init__(self, ctx, values, path):
        self.ctx, self.v = ctx, values
        try:
            ctx.robot.link_motion(values["body"])
        except KeyError:
            raise PluginNotLoaded(f"GPS: bodyName '{values['body']}' is not a link of the model; the plugin is "
                                  "not loaded, as in Gazebo", ctx.model.source, path) from None
        ns = ctx.plugin_namespace(values["namespace"])
        self.fix_pub = ctx.publisher(join(ns, values["topic"]), NavSatFix)
        self.vel_pub = ctx.publisher(join(ns, values["velocity_topic"]), Vector3Stamped)
        frame = ctx.clean_frame(values["frame"], path) or "world"
        self.frame_id = frame if frame in ("world", "map") else ctx.frame(frame)
        self.covariance = covariance(values["position"])
        self.last_time = None

    def publishers(self):
        return [self.fix_pub, self.vel_pub]

    def start(self, now):
        self.next, self.last_time = self.first_due(now, self.v["period"]), None

    def reset(self, now):
        for model in self.v["position"] + self.v["velocity"]:
            model.reset()
        self.start(now)

    def after_step(self, now, stamp, transforms):
        if not self.take_due(now, self.v["period"]):
            return
        dt = 0.0 if self.last_time is None else now - self.last_time
        self.last_time = now
        (position, _), body_velocity, _ = self.ctx.robot.link_motion(self.v["body"])
        velocity = [m(x, dt) for m, x in zip(self.v["velocity"], body_velocity)]
        for p, vm in zip(self.v["position"], self.v["velocity"]):
            p.current_drift += dt * vm.current_drift  # a velocity bias walks the position, as hector
        measured = [m(x, dt) for m, x in zip(self.v["position"], position)]
        lat, lon, alt = to_geodetic(measured, self.v["reference"])
        if self.fix_pub.get_num_connections():
            self.fix_pub.publish(ros_msgs.nav_sat_fix(stamp, self.frame_id, lat, lon, alt, self.covariance,
                                                      self.v["status"], self.v["service"]))
        if self.vel_pub.get_num_connections():
            north, west = north_west(velocity[0], velocity[1], self.v["reference"][2])
            self.vel_pub.publish(ros_msgs.vector3_stamped(stamp, self.frame_id, (north, west, velocity[2])))

    def summary(self):
        lat, lon, heading, alt = self.v["reference"]
        rate = f"{round(1.0 / self.v['period'], 3)} Hz" if self.v["period"] > 0 else "every step"
        return {summary_key("gps", self.fix_pub.resolved_name): f"velocity {self.vel_pub.resolved_name}, body "
                f"{self.v['body']}, reference {lat} deg, {lon} deg, heading {heading} deg, {alt} m, {rate}"}


def create(ctx, element, path, params):
    tags = read_tags(element)
    generator = noise.rng(ctx.cfg.seed, element.get("name") or path)
    try:
        values = settings(tags, path, ctx.model.root, generator, ctx.warnings)
    except ModelError as err:
        raise type(err)(str(err), ctx.model.source) from None
    if values["world_coordinates"]:
        ctx.warnings.append(f"{path}: <useWorldSphericalCoordinates> ignored (no world spherical coordinates "
                            "here); using the reference tags")
    unknown = sorted(set(tags) - KNOWN)
    if unknown:
        ctx.warnings.append(f"{path}: unknown tags ignored: {', '.join(unknown)}")
    return Gps(ctx, values, path)
