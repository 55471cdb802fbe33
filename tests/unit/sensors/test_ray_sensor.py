"""Ray sensors: SDF reading and defaults, Gazebo 7+'s angles and range semantics (diffbot_sim.sensors.ray),
and the casting (physics.World.ray_batch) against a hand-built room, checked beam by beam by hand."""
import math
import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from diffbot_sim.errors import ConfigError
from diffbot_sim.sensors import ray as rs

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LASER_URDF = os.path.join(os.path.dirname(HERE), "data", "robots", "laser_robot.urdf")


def sensor(body, stype="ray"):
    return ET.fromstring(f'<sensor type="{stype}" name="s">{body}</sensor>')


SCAN = ("<ray><scan><horizontal><samples>{n}</samples><resolution>{res}</resolution><min_angle>{lo}</min_angle>"
        "<max_angle>{hi}</max_angle></horizontal></scan><range><min>{rmin}</min><max>{rmax}</max></range>"
        "{noise}</ray>")


def laser(n=5, res=1, lo=-1.0, hi=1.0, rmin=0.1, rmax=5.0, noise="", extra=""):
    return rs.parse_sensor(sensor(extra + SCAN.format(n=n, res=res, lo=lo, hi=hi, rmin=rmin, rmax=rmax,
                                                      noise=noise)), "/robot/gazebo/sensor")


# -- SDF ----------------------------------------------------------------------------------------------------
def test_sdf_defaults():
    cfg = rs.parse_sensor(sensor("<ray><range><min>0.1</min><max>2</max></range></ray>"), "p")
    assert (cfg.update_rate, cfg.always_on, cfg.visualize) == (0.0, False, False)
    assert (cfg.horizontal.samples, cfg.horizontal.resolution, cfg.horizontal.min_angle) == (640, 1.0, 0.0)
    assert (cfg.vertical.samples, cfg.vertical.count) == (1, 1)
    assert cfg.noise.type == "none" and not cfg.noise.active
    assert cfg.pose == ((0, 0, 0), (0, 0, 0)) and not cfg.has_pose


def test_sdf_full():
    cfg = laser(n=360, lo=0.0, hi=6.28319, rmin=0.12, rmax=3.5,
                noise="<noise><type>gaussian</type><mean>0.01</mean><stddev>0.02</stddev></noise>",
                extra="<pose>0.1 0 0.2 0 0 1.5</pose><always_on>true</always_on><update_rate>5</update_rate>"
                      "<visualize>1</visualize>")
    assert cfg.update_rate == 5 and cfg.always_on and cfg.visualize
    assert cfg.pose == ((0.1, 0.0, 0.2), (0.0, 0.0, 1.5)) and cfg.has_pose
    assert (cfg.range_min, cfg.range_max) == (0.12, 3.5)
    assert (cfg.noise.type, cfg.noise.mean, cfg.noise.stddev) == ("gaussian", 0.01, 0.02)
    assert cfg.rays == cfg.readings == 360


def test_lidar_spelling_and_gpu_warning():
    el = sensor("<lidar><scan><horizontal><samples>3</samples></horizontal></scan>"
                "<range><min>0.1</min><max>1</max></range></lidar>", "gpu_lidar")
    cfg = rs.parse_sensor(el, "p")
    assert cfg.horizontal.samples == 3 and cfg.range_max == 1
    assert any("visuals" in w for w in cfg.warnings)


@pytest.mark.parametrize("body, tag", [
    (SCAN.format(n=0, res=1, lo=0, hi=1, rmin=0.1, rmax=1, noise=""), "<samples>"),
    (SCAN.format(n="many", res=1, lo=0, hi=1, rmin=0.1, rmax=1, noise=""), "<samples>"),
    (SCAN.format(n=5, res=0, lo=0, hi=1, rmin=0.1, rmax=1, noise=""), "<resolution>"),
    (SCAN.format(n=5, res=1, lo=1, hi=0, rmin=0.1, rmax=1, noise=""), "<max_angle>"),
    (SCAN.format(n=5, res=1, lo=0, hi=1, rmin=1, rmax=1, noise=""), "<range><max>"),
    (SCAN.format(n=5, res=1, lo=0, hi=1, rmin=0.1, rmax="x", noise=""), "<max>"),
    (SCAN.format(n=5, res=1, lo=0, hi=1, rmin=0.1, rmax=1, noise="<noise><type>poisson</type></noise>"), "<type>"),
    ("<pose>1 2 3</pose>", "<pose>"),
])
def test_sdf_errors_name_the_tag_and_path(body, tag):
    """A value Gazebo cannot read either (no leading number, out of range) stops the load, naming it."""
    with pytest.raises(ConfigError) as err:
        rs.parse_sensor(sensor(body), "/robot/gazebo[@reference='l']/sensor")
    assert tag in str(err.value) and "/robot/gazebo[@reference='l']/sensor" in str(err.value)


def test_a_computed_sample_count_is_read_as_gazebo_reads_it():
    # A published robot's xacro computes <samples>666.5185185185185</samples>: sdformat's std::stoul takes 666.
    cfg = rs.parse_sensor(sensor(SCAN.format(n="666.5185185185185", res=1, lo=-2.0944, hi=2.0944, rmin=0.05,
                                             rmax=25, noise="")), "/robot/gazebo[@reference='l']/sensor")
    assert cfg.horizontal.samples == 666 and cfg.horizontal.count == 666
    assert [w for w in cfg.warnings if "<samples>" in w] == [
        "<samples> of /robot/gazebo[@reference='l']/sensor/ray/scan/horizontal: took 666 from "
        "'666.5185185185185', as Gazebo's SDF reader (std::stoul) does"]


# -- angles -------------------------------------------------------------------------------------------------
def test_angle_increment_gazebo7():
    cfg = laser(n=360, lo=0.0, hi=6.28319)
    assert cfg.horizontal.increment == pytest.approx(6.28319 / 359)  # 0.017502, TB3's figure
    assert cfg.horizontal.increment == pytest.approx(0.017502, abs=1e-6)
    angles = cfg.horizontal.reading_angles()
    assert angles[0] == 0.0 and angles[-1] == pytest.approx(6.28319)  # first and last beam on min and max


def test_resolution_multiplies_readings_not_rays():
    cfg = laser(n=5, res=2, lo=-1, hi=1)
    assert cfg.rays == 5 and cfg.readings == 10
    assert cfg.horizontal.increment == pytest.approx(2.0 / 9)


def test_directions_counter_clockwise_and_vertical_rows():
    cfg = laser(n=3, lo=-math.pi / 2, hi=math.pi / 2)
    d = rs.ray_directions(cfg)
    np.testing.assert_allclose(d, [[0, -1, 0], [1, 0, 0], [0, 1, 0]], atol=1e-12)  # right, ahead, left
    el = sensor("<ray><scan><horizontal><samples>2</samples><min_angle>0</min_angle><max_angle>1.5707963267948966"
                "</max_angle></horizontal><vertical><samples>2</samples><min_angle>-0.5</min_angle><max_angle>0.5"
                "</max_angle></vertical></scan><range><min>0.1</min><max>1</max></range></ray>")
    d = rs.ray_directions(rs.parse_sensor(el, "p"))
    assert d.shape == (4, 3)
    assert d[0][2] < 0 and d[2][2] > 0  # row 0 is the lowest (min vertical angle), positive angles point up
    assert d[0][0] > 0 and abs(d[0][1]) < 1e-12 and d[1][1] > 0  # each row sweeps counter-clockwise


def test_single_ray_points_along_x():
    d = rs.ray_directions(laser(n=1, lo=-0.3, hi=0.3))
    np.testing.assert_allclose(d, [[1, 0, 0]], atol=1e-12)


def test_sensor_pose_and_world_rays():
    # link at (1, 2, 0) turned 90 deg left, sensor 0.5 ahead of it: the sensor is at (1, 2.5, 0), x looks +y
    q = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))
    origin, rot = rs.sensor_pose((1.0, 2.0, 0.0), q, ((0.5, 0.0, 0.0), (0.0, 0.0, 0.0)))
    np.testing.assert_allclose(origin, [1.0, 2.5, 0.0], atol=1e-12)
    starts, ends = rs.world_rays(origin, rot, np.array([[1.0, 0.0, 0.0]]), 0.1, 2.0)
    np.testing.assert_allclose(starts, [[1.0, 2.6, 0.0]], atol=1e-12)
    np.testing.assert_allclose(ends, [[1.0, 4.5, 0.0]], atol=1e-12)


# -- range semantics ----------------------------------------------------------------------------------------
def test_miss_is_plus_inf_below_min_is_minus_inf():
    cfg = laser(n=4, rmin=0.1, rmax=5.0)
    ranges, intensities = rs.ScanProcessor(cfg, rs.noise_rng(0, "s")).process(
        np.array([1.0, 0.0, 0.5, 0.999999]), np.array([7.0, 7.0, 7.0, 7.0]))
    assert ranges[0] == math.inf and ranges[1] == -math.inf
    assert ranges[2] == pytest.approx(0.1 + 0.5 * 4.9)
    assert ranges[3] == pytest.approx(5.0, abs=1e-5) and math.isfinite(ranges[3])
    assert list(intensities) == [0.0, 7.0, 7.0, 7.0]  # a miss reads intensity 0


def test_noise_only_on_hits_then_clamped():
    noise = "<noise><type>gaussian</type><mean>0</mean><stddev>0.5</stddev></noise>"
    cfg = laser(n=6, rmin=0.1, rmax=5.0, noise=noise)
    fractions = np.array([1.0, 1.0, 0.0, 0.5, 0.001, 0.999])
    ranges, _ = rs.ScanProcessor(cfg, rs.noise_rng(3, "s")).process(fractions)
    assert ranges[0] == ranges[1] == math.inf and ranges[2] == -math.inf
    assert np.all((ranges[3:] >= 0.1) & (ranges[3:] <= 5.0))
    assert ranges[3] != pytest.approx(0.1 + 0.5 * 4.9, abs=1e-9)  # noisy
    many = np.full(2000, 0.001)  # raw 0.1049: half the noisy values would fall below min
    values, _ = rs.ScanProcessor(laser(n=2000, rmin=0.1, rmax=5.0, noise=noise), rs.noise_rng(1, "s")).process(many)
    assert np.all(values >= 0.1) and np.sum(values == 0.1) > 500  # clamped to exactly min, finite


def test_noise_seeded_identical_twice_and_per_sensor():
    noise = "<noise><type>gaussian</type><mean>0</mean><stddev>0.01</stddev></noise>"
    cfg = laser(n=50, noise=noise)
    fractions = np.linspace(0.1, 0.9, 50)
    a, _ = rs.ScanProcessor(cfg, rs.noise_rng(7, "robot/lds")).process(fractions)
    b, _ = rs.ScanProcessor(cfg, rs.noise_rng(7, "robot/lds")).process(fractions)
    c, _ = rs.ScanProcessor(cfg, rs.noise_rng(7, "robot/other")).process(fractions)
    d, _ = rs.ScanProcessor(cfg, rs.noise_rng(8, "robot/lds")).process(fractions)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c) and not np.array_equal(a, d)
    exact = rs.raw_ranges(fractions, cfg.range_min, cfg.range_max)
    assert np.std(a - exact) == pytest.approx(0.01, rel=0.4)


def test_noise_mean_and_bias():
    noise = "<noise><type>gaussian</type><mean>0.2</mean><stddev>0</stddev><bias_mean>0.1</bias_mean></noise>"
    cfg = laser(n=3, noise=noise)
    ranges, _ = rs.ScanProcessor(cfg, rs.noise_rng(0, "s")).process(np.array([0.5, 0.5, 1.0]))
    base = 0.1 + 0.5 * 4.9
    assert ranges[0] in (pytest.approx(base + 0.3), pytest.approx(base + 0.1))  # bias sign drawn once
    assert ranges[0] == ranges[1] and ranges[2] == math.inf


def test_resolution_interpolates_between_rays():
    cfg = laser(n=3, res=2, rmin=0.0, rmax=10.0)  # 3 rays -> 6 readings
    ranges, intensities = rs.ScanProcessor(cfg, rs.noise_rng(0, "s")).process(
        np.array([0.1, 0.2, 0.4]), np.array([10.0, 20.0, 40.0]))
    np.testing.assert_allclose(ranges, np.interp(np.linspace(0, 2, 6), [0, 1, 2], [1.0, 2.0, 4.0]))
    assert intensities[0] == 10 and intensities[-1] == 40


def test_sonar_range_semantics():
    raw = np.array([3.0, 1.2, 4.0])
    assert rs.sonar_range(raw, 4.0) == 1.2  # the minimum ray
    assert rs.sonar_range(np.array([4.0, 4.0]), 4.0) == 4.0  # no return: range_max, not inf
    rng = rs.noise_rng(0, "sonar")
    noisy = [rs.sonar_range(np.array([3.99]), 4.0, 0.1, rng) for _ in range(200)]
    assert max(noisy) == 4.0 and min(noisy) < 3.99  # noise then capped at max
    assert rs.sonar_range(np.array([4.0]), 4.0, 0.1, rng) == 4.0  # no noise on no return


def test_scan_points_drop_non_finite():
    cfg = laser(n=3, lo=-math.pi / 2, hi=math.pi / 2)
    pts = rs.scan_points(np.array([1.0, math.inf, 2.0]), np.array([1.0, 0.0, 3.0]), cfg, min_intensity=2.0)
    np.testing.assert_allclose(pts, [[0, -1, 0, 2], [0, 2, 0, 3]], atol=1e-6)
    assert pts.dtype == np.float32


# -- physics ------------------------------------------------------------------------------------------------
@pytest.fixture
def room():
    """A World with static walls and a pillar (laser_retro on two of them) and the laser robot at the
    origin: yields (world, robot, model)."""
    from diffbot_sim.description.urdf_model import parse_urdf
    from diffbot_sim.physics import World
    from diffbot_sim.world.bodies import Body, Shape, WorldDescription

    def box(name, x, y, sx, sy, retro=None):
        surface = {"laser_retro": retro} if retro else {}
        return Body(name, name, ((x, y, 0.5), (0, 0, 0, 1)), True, [Shape("box", (sx, sy, 1.0), surface=surface)])

    bodies = [box("east", 3.0, 0.0, 0.2, 6.0, 100), box("north", 0.0, 2.5, 6.2, 0.2), box("south", 0.0, -2.0, 6.2, 0.2),
              Body("pillar", "pillar", ((0.5, 1.2, 0.5), (0, 0, 0, 1)), True,
                   [Shape("cylinder", (0.2, 1.0), surface={"laser_retro": 200})])]
    world = World(1.0 / 240.0)
    world.load_world(WorldDescription("room", "test", bodies), "/nonexistent")
    text = open(LASER_URDF).read()
    model = parse_urdf(text, LASER_URDF)
    robot = world.load_robot(text, model)
    for _ in range(20):
        world.step()
    yield world, robot, model
    world.close()


def lds_config(model):
    from diffbot_sim.description.plugin_tags import read_plugins

    found = read_plugins(model)
    el = next(s for s in found.sensors if s.name == "lds")
    cfg = rs.parse_sensor(el.element, el.path)
    cfg.noise = rs.Noise()  # exact geometry
    return cfg


def expected_range(ox, oy, angle, rmax):
    """By hand: distance from (ox, oy) along ``angle`` to the room's wall faces and the pillar."""
    dx, dy = math.cos(angle), math.sin(angle)
    best = math.inf
    for face, axis, lo, hi in ((2.9, "x", -3.0, 3.0), (2.4, "y", -3.1, 3.1), (-1.9, "y", -3.1, 3.1)):
        d = dx if axis == "x" else dy
        o = ox if axis == "x" else oy
        if abs(d) < 1e-12:
            continue
        t = (face - o) / d
        other = (oy + t * dy) if axis == "x" else (ox + t * dx)
        if t > 0 and lo <= other <= hi:
            best = min(best, t)
    cx, cy, r = 0.5 - ox, 1.2 - oy, 0.2
    b = cx * dx + cy * dy
    disc = b * b - (cx * cx + cy * cy - r * r)
    if disc >= 0 and b - math.sqrt(disc) > 0:
        best = min(best, b - math.sqrt(disc))
    return best if best < rmax else math.inf


def scan(world, robot, cfg, pose=((0, 0, 0), (0, 0, 0))):
    position, quaternion = robot.link_pose("laser_link")
    origin, rotation = rs.sensor_pose(position, quaternion, pose)
    starts, ends = rs.world_rays(origin, rotation, rs.ray_directions(cfg), cfg.range_min, cfg.range_max)
    fractions, bodies, links = world.ray_batch(starts, ends)
    ranges, intensities = rs.ScanProcessor(cfg, rs.noise_rng(0, "lds")).process(fractions, world.retro(bodies, links))
    return origin, ranges, intensities


def test_scan_matches_hand_geometry(room):
    world, robot, model = room
    cfg = lds_config(model)
    origin, ranges, intensities = scan(world, robot, cfg)
    # laser_link is lumped into base_link: its frame is still 0.05 ahead and 0.113 m up
    assert origin[0] == pytest.approx(0.05, abs=2e-3) and origin[2] == pytest.approx(0.113, abs=2e-3)
    angles = cfg.horizontal.min_angle + np.arange(cfg.readings) * cfg.horizontal.increment
    want = np.array([expected_range(origin[0], origin[1], a, cfg.range_max) for a in angles])
    assert np.array_equal(np.isinf(ranges), np.isinf(want))  # the open west reads +inf on the same beams
    assert np.isinf(ranges).sum() > 20 and np.all(ranges[np.isinf(ranges)] > 0)
    finite = np.isfinite(want)
    assert np.max(np.abs(ranges[finite] - want[finite])) < 2e-3
    # intensities: the pillar (200) at positive angles (left), the east wall (100) ahead, others 0
    pillar = int(np.argmin(np.where(finite, np.abs(angles - math.atan2(1.2, 0.45)), 9)))
    assert intensities[pillar] == 200 and intensities[0] == 100
    assert intensities[90] == 0 and ranges[90] == pytest.approx(2.4 - origin[1], abs=2e-3)  # north wall, no retro
    assert np.all(intensities[np.isinf(ranges)] == 0)


def test_scan_sees_own_robot_with_its_retro(room):
    world, robot, model = room
    position, _ = robot.link_pose("base_link")
    # a ray from above straight down onto the robot's body: hits base_link (laserRetro 50)
    start = np.array([[position[0], position[1], 1.0]])
    end = np.array([[position[0], position[1], -1.0]])
    fractions, bodies, links = world.ray_batch(start, end)
    assert bodies[0] == robot.body and world.retro(bodies, links)[0] == 50.0


def test_ray_batch_chunks_beyond_pybullet_limit(room):
    from diffbot_sim.physics import RAY_BATCH_LIMIT

    world, _, _ = room
    n = 2 * RAY_BATCH_LIMIT + 5
    angles = np.linspace(-0.3, 0.3, n)  # all at the east wall face x = 2.9, from z 0.5
    starts = np.tile([0.0, 0.0, 0.5], (n, 1))
    ends = np.stack([10 * np.cos(angles), 10 * np.sin(angles), np.full(n, 0.5)], axis=1)
    fractions, bodies, _ = world.ray_batch(starts, ends)
    assert len(fractions) == n and np.all(bodies >= 0)
    np.testing.assert_allclose(fractions * 10, 2.9 / np.cos(angles), atol=1e-6)


def test_scan_rotates_with_robot(room):
    import pybullet

    world, robot, model = room
    cfg = lds_config(model)
    yaw = 0.5
    pos, _ = pybullet.getBasePositionAndOrientation(robot.body, physicsClientId=world.client)
    pybullet.resetBasePositionAndOrientation(robot.body, pos, pybullet.getQuaternionFromEuler((0, 0, yaw)),
                                             physicsClientId=world.client)
    world.step()
    origin, ranges, _ = scan(world, robot, cfg)
    angles = cfg.horizontal.reading_angles() + yaw  # beam angle in the world
    want = np.array([expected_range(origin[0], origin[1], a, cfg.range_max) for a in angles])
    finite = np.isfinite(want) & np.isfinite(ranges)
    assert finite.sum() > 250
    assert np.max(np.abs(ranges[finite] - want[finite])) < 5e-3


# -- messages -----------------------------------------------------------------------------------------------
def test_laserscan_bytes_match_genpy():
    import io

    import genpy
    from sensor_msgs.msg import LaserScan

    from diffbot_sim.messages import common as ros_msgs

    builder = ros_msgs.LaserScanBuilder("robot1/laser", 0.0, 6.28319, 6.28319 / 359, 0.12, 10.0)
    ranges = np.array([1.5, math.inf, -math.inf, 0.25])
    msg = builder.build(genpy.Time(3, 500), ranges, np.array([0.0, 0.0, 100.0, 200.0]))
    msg.header.seq = 4
    packed, plain = io.BytesIO(), io.BytesIO()
    msg.serialize(packed)
    ref = LaserScan()
    ref.header.seq, ref.header.stamp, ref.header.frame_id = 4, genpy.Time(3, 500), "robot1/laser"
    ref.angle_min, ref.angle_max, ref.angle_increment = 0.0, 6.28319, 6.28319 / 359
    ref.range_min, ref.range_max = 0.12, 10.0
    ref.ranges, ref.intensities = ranges.tolist(), [0.0, 0.0, 100.0, 200.0]
    ref.serialize(plain)
    assert packed.getvalue() == plain.getvalue()
    back = LaserScan()
    back.deserialize(packed.getvalue())
    assert back.ranges[1] == math.inf and back.ranges[2] == -math.inf and back.time_increment == 0.0
    assert builder.build(genpy.Time(4, 0), ranges, ranges) is msg  # one object, refilled


def test_range_and_pointcloud2_builders():
    import genpy
    from sensor_msgs.msg import PointCloud2, Range

    from diffbot_sim.messages import common as ros_msgs

    r = ros_msgs.RangeBuilder("sonar", True, 0.1, 0.02, 4.0).build(genpy.Time(1, 0), 2.5)
    assert (r.radiation_type, r.field_of_view, r.min_range, r.max_range, r.range) == (Range.ULTRASOUND, 0.1, 0.02,
                                                                                        4.0, 2.5)
    points = np.array([[1, 2, 3, 4], [5, 6, 7, 8]], dtype=np.float32)
    cloud = ros_msgs.PointCloud2Builder("laser").build(genpy.Time(1, 0), points)
    assert (cloud.width, cloud.height, cloud.row_step, cloud.is_dense) == (2, 1, 32, True)
    assert [f.name for f in cloud.fields] == ["x", "y", "z", "intensity"]
    import io

    buff = io.BytesIO()
    cloud.serialize(buff)
    back = PointCloud2()
    back.deserialize(buff.getvalue())
    assert np.array_equal(np.frombuffer(back.data, dtype="<f4").reshape(-1, 4), points)


# -- plugins (no master: the publisher is a stand-in) -------------------------------------------------------
class _Pub:
    def __init__(self, name, cls):
        self.resolved_name, self.cls = name, cls

    def get_num_connections(self):
        return 0


class _Ctx:
    """Enough of plugins.base.RobotContext for building sensor plugins."""

    def __init__(self, model, namespace=None, params=None):
        from diffbot_sim.config import sim_config
        from diffbot_sim.plugins.base import RobotContext

        self.model, self.namespace, self.params = model, namespace, params or {}
        self.cfg = sim_config(self.params)
        self.warnings = []
        self.spec = type("Spec", (), {"name": "", "tf_prefix": None})()
        self.frame = lambda name: name
        self.clean_frame = lambda name, where: RobotContext.clean_frame(self, name, where)
        self.plugin_namespace = lambda tag, default=None: RobotContext.plugin_namespace(self, tag, default)
        from diffbot_sim.plugins import base

        self.publisher = lambda name, msg_class: base.publisher(name, msg_class)  # stubbed by the tests


def _plugin_robot(sensor_xml):
    from diffbot_sim.description.plugin_tags import read_plugins
    from diffbot_sim.description.urdf_model import parse_urdf

    text = ('<robot name="bot"><link name="base_link"/><link name="laser_link"/>'
            '<joint name="j" type="fixed"><parent link="base_link"/><child link="laser_link"/></joint>'
            f'<gazebo reference="laser_link">{sensor_xml}</gazebo></robot>')
    model = parse_urdf(text, "bot.urdf")
    return model, read_plugins(model).sensors[0]


RAY = ('<ray><scan><horizontal><samples>4</samples><min_angle>-1</min_angle><max_angle>1</max_angle></horizontal>'
       '</scan><range><min>0.1</min><max>5</max></range></ray>')


@pytest.fixture
def stub_publisher(monkeypatch):
    from diffbot_sim.plugins import base

    monkeypatch.setattr(base, "publisher", _Pub)


def test_ros1_laser_tags(stub_publisher):
    from diffbot_sim.plugins import registry

    model, sensor = _plugin_robot(f'<sensor type="ray" name="lds"><update_rate>5</update_rate>{RAY}'
                                  '<plugin name="p" filename="libgazebo_ros_laser.so"><topicName>scan</topicName>'
                                  '<frameName>/laser_link</frameName><robotNamespace>bot1</robotNamespace>'
                                  '<gaussianNoise>0.01</gaussianNoise></plugin></sensor>')
    ctx = _Ctx(model)
    plugin = registry.SENSOR_PLUGINS["libgazebo_ros_laser.so"](ctx, sensor, sensor.element.find("plugin"), {})
    assert (plugin.pub.resolved_name, plugin.frame, plugin.period) == ("bot1/scan", "laser_link", 0.2)
    assert any("leading slash" in w for w in ctx.warnings)
    assert any("gaussianNoise" in w for w in ctx.warnings)  # the real plugin does not read it
    assert "bot1/scan" in plugin.summary()["sensor/lds"]


def test_ros1_laser_defaults_and_empty_namespace(stub_publisher):
    from diffbot_sim.plugins import laser

    model, sensor = _plugin_robot(f'<sensor type="gpu_ray" name="lds">{RAY}<plugin name="p" '
                                  'filename="libgazebo_ros_gpu_laser.so"><robotNamespace></robotNamespace></plugin>'
                                  '</sensor>')
    ctx = _Ctx(model)
    plugin = laser.create_laser(ctx, sensor, sensor.element.find("plugin"), {})
    assert plugin.pub.resolved_name == "/world"  # gazebo_ros_laser's default topic, absolute
    assert plugin.frame == "laser_link" and plugin.filename == "libgazebo_ros_gpu_laser.so"
    assert any("<topicName>" in w for w in ctx.warnings) and any("<frameName>" in w for w in ctx.warnings)
    element = sensor.element.find("plugin")
    element.append(element.makeelement("topicName", {}))
    element[-1].text = "scan"
    plugin = laser.create_laser(ctx, sensor, element, {})
    assert plugin.pub.resolved_name == "bot/scan"  # robotNamespace present but empty: the model name


@pytest.mark.parametrize("ros, output, topic, cls", [
    ("<ros><namespace>/bot</namespace><remapping>~/out:=scan</remapping></ros>", "sensor_msgs/LaserScan",
     "/bot/scan", "LaserScan"),
    ("", "sensor_msgs/PointCloud2", "/p/out", "PointCloud2"),
    ("<ros><argument>~/out:=cloud</argument></ros>", "sensor_msgs/PointCloud", "/cloud", "PointCloud"),
    ("<ros><remapping>~/out:=range</remapping></ros>", "sensor_msgs/Range", "/range", "Range"),
])
def test_ros2_ray_sensor_outputs(stub_publisher, ros, output, topic, cls):
    from diffbot_sim.plugins import laser

    model, sensor = _plugin_robot(f'<sensor type="ray" name="lds">{RAY}<plugin name="p" '
                                  f'filename="libgazebo_ros_ray_sensor.so">{ros}<output_type>{output}</output_type>'
                                  '</plugin></sensor>')
    plugin = laser.create_ray_sensor(_Ctx(model), sensor, sensor.element.find("plugin"), {})
    assert plugin.pub.resolved_name == topic and plugin.pub.cls.__name__ == cls and plugin.frame == "laser_link"


def test_bad_tags_raise(stub_publisher):
    from diffbot_sim.plugins import laser, range as range_plugin

    model, sensor = _plugin_robot(f'<sensor type="ray" name="lds">{RAY}<plugin name="p" '
                                  'filename="libgazebo_ros_ray_sensor.so"><output_type>sensor_msgs/Image'
                                  '</output_type></plugin></sensor>')
    with pytest.raises(ConfigError, match="output_type"):
        laser.create_ray_sensor(_Ctx(model), sensor, sensor.element.find("plugin"), {})
    model, sensor = _plugin_robot('<sensor type="camera" name="c"><plugin name="p" filename="libgazebo_ros_range.so">'
                                  '</plugin></sensor>')
    with pytest.raises(ConfigError, match="ray or gpu_ray"):
        range_plugin.create(_Ctx(model), sensor, sensor.element.find("plugin"), {})
    model, sensor = _plugin_robot(f'<sensor type="ray" name="s">{RAY}<plugin name="p" '
                                  'filename="libgazebo_ros_range.so"><fov>wide</fov></plugin></sensor>')
    with pytest.raises(ConfigError, match="<fov>"):
        range_plugin.create(_Ctx(model), sensor, sensor.element.find("plugin"), {})
    model, sensor = _plugin_robot(f'<sensor type="ray" name="s">{RAY}<plugin name="p" '
                                  'filename="libgazebo_ros_range.so"></plugin></sensor>')
    with pytest.raises(ConfigError, match="~seed"):
        range_plugin.create(_Ctx(model, params={"seed": "x"}), sensor, sensor.element.find("plugin"), {})


def test_range_plugin_defaults(stub_publisher):
    from diffbot_sim.plugins import range as range_plugin

    model, sensor = _plugin_robot(f'<sensor type="ray" name="s">{RAY}<plugin name="p" '
                                  'filename="libgazebo_ros_range.so"><radiation>infrared</radiation></plugin></sensor>')
    plugin = range_plugin.create(_Ctx(model), sensor, sensor.element.find("plugin"), {})
    assert plugin.pub.resolved_name == "/range" and plugin.throttle == 0.0 and plugin.stddev == 0.0
    msg = plugin.builder.msg
    assert (msg.radiation_type, msg.field_of_view, msg.min_range, msg.max_range) == (1, 0.05, 0.1, 5.0)


class _Listened(_Pub):
    def __init__(self, name, cls):
        super().__init__(name, cls)
        self.sent = []

    def get_num_connections(self):
        return 1

    def publish(self, msg):
        self.sent.append(msg)


@pytest.mark.parametrize("output", ["sensor_msgs/LaserScan", "sensor_msgs/PointCloud2", "sensor_msgs/PointCloud",
                                    "sensor_msgs/Range"])
def test_ros2_outputs_publish_from_the_room(room, monkeypatch, output):
    """The ROS 2 plugin on the fixture's laser link in the hand-built room: each output type is filled."""
    import genpy

    from diffbot_sim.description.plugin_tags import read_plugins
    from diffbot_sim.plugins import base, laser

    world, robot, model = room
    monkeypatch.setattr(base, "publisher", _Listened)
    lds = next(s for s in read_plugins(model).sensors if s.name == "lds")
    element = ET.fromstring(f'<plugin name="p" filename="libgazebo_ros_ray_sensor.so"><output_type>{output}'
                            '</output_type><min_intensity>1</min_intensity></plugin>')
    ctx = _Ctx(model)
    ctx.robot, ctx.sim = robot, type("Sim", (), {"world": world})()
    plugin = laser.create_ray_sensor(ctx, lds, element, {})
    plugin.start(0.0)
    plugin.after_step(0.1, genpy.Time.from_sec(0.1), [])  # not due: a 5 Hz sensor first scans at 0.2 s
    assert plugin.pub.sent == []
    plugin.after_step(0.2, genpy.Time.from_sec(0.2), [])
    assert len(plugin.pub.sent) == 1 and plugin.next == pytest.approx(0.4)
    msg = plugin.pub.sent[0]
    if output == "sensor_msgs/LaserScan":
        assert len(msg.ranges) == 360 and min(msg.intensities) == 1.0  # clipped up to min_intensity
    elif output == "sensor_msgs/PointCloud2":
        pts = np.frombuffer(msg.data, dtype="<f4").reshape(-1, 4)
        assert 280 < len(pts) < 300 and np.all(pts[:, 3] >= 1.0)  # the +inf beams dropped
        assert np.all(np.abs(pts[:, 2]) < 1e-3)
    elif output == "sensor_msgs/PointCloud":
        assert 280 < len(msg.points) < 300 and msg.channels[0].name == "intensity"
    else:
        # the minimum of all (noisy, stddev 5 mm) readings: the pillar, hypot(0.45, 1.2) - 0.2 from the laser
        assert msg.range == pytest.approx(math.hypot(0.45, 1.2) - 0.2, abs=0.03)
