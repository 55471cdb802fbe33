"""Block laser (PointCloud) and velodyne (PointCloud2 with rings) on the laser fixture (0.113 m up; rows within
+-0.02 rad, which meet the ground beyond 5.6 m), in front of a wall
whose face is 2.85 m ahead of the sensor: every point lies on that face, rings number the rows from the
lowest, min_range/max_range clip, an organised cloud keeps NaN where nothing returned."""
import os
import time
import xml.etree.ElementTree as ET

import genpy
import numpy as np
import pytest

from diffbot_sim.config import sim_config
from diffbot_sim.description.plugin_tags import SensorElement
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.physics import World
from diffbot_sim.plugins import base, ray_clouds
from diffbot_sim.plugins.base import RobotContext
from diffbot_sim.world.bodies import Body, Shape, WorldDescription

LASER_URDF = os.path.join(os.path.dirname(__file__), "..", "..", "data", "robots", "laser_robot.urdf")
FACE = 2.9 - 0.05  # the wall's face at x = 2.9, the laser link 0.05 m ahead of base_link
SENSOR = ('<sensor type="ray" name="lidar"><update_rate>10</update_rate><ray><scan>'
          '<horizontal><samples>8</samples><min_angle>-0.2</min_angle><max_angle>0.2</max_angle></horizontal>'
          '<vertical><samples>3</samples><min_angle>-0.02</min_angle><max_angle>0.02</max_angle></vertical>'
          '</scan><range><min>0.1</min><max>50</max></range></ray>{plugin}</sensor>')


class _Pub:
    def __init__(self, name, cls):
        self.resolved_name, self.sent = name, []

    def get_num_connections(self):
        return 1

    def publish(self, msg):
        self.sent.append(msg)


@pytest.fixture
def scene(monkeypatch):
    monkeypatch.setattr(base, "publisher", _Pub)
    world = World(1.0 / 240.0)
    wall = Body("east", "east", ((3.0, 0.0, 0.5), (0, 0, 0, 1)), True,
                [Shape("box", (0.2, 6.0, 1.0), surface={"laser_retro": 100.0})])
    world.load_world(WorldDescription("w", "test", [wall]), "/nonexistent")
    text = open(LASER_URDF).read()
    model = parse_urdf(text, LASER_URDF)
    robot = world.load_robot(text, model)
    yield world, robot, model
    world.close()


def make(scene, plugin_xml, create):
    world, robot, model = scene
    element = ET.fromstring(SENSOR.format(plugin=plugin_xml))
    sensor = SensorElement("ray", "lidar", "laser_link", element, "/robot/gazebo[@reference='laser_link']/sensor",
                           [])
    spec = type("Spec", (), {"name": "", "tf_prefix": None})()
    ctx = RobotContext(type("Sim", (), {"world": world})(), sim_config({}), spec, model, robot, {}, None, "~")
    plugin = create(ctx, sensor, element.find("plugin"), {})
    plugin.start(0.0)  # as the loop starts it: the first scan one sensor period (0.1 s) on
    plugin.after_step(0.1, genpy.Time.from_sec(0.1), [])
    return plugin, plugin.pub.sent[-1] if plugin.pub.sent else None


def cloud(msg):
    record = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4"), ("ring", "<u2"),
                       ("time", "<f4")])
    assert msg.point_step == record.itemsize
    assert [(f.name, f.offset) for f in msg.fields] == [(n, record.fields[n][1]) for n in record.names]
    return np.frombuffer(msg.data, dtype=record)


def test_velodyne_points_on_the_wall_with_rings(scene):
    plugin, msg = make(scene, '<plugin name="v" filename="libgazebo_ros_velodyne_laser.so"><topicName>points'
                              '</topicName><frameName>laser_link</frameName></plugin>', ray_clouds.create_velodyne)
    pts = cloud(msg)
    assert len(pts) == 24 and msg.height == 1 and msg.header.frame_id == "laser_link"
    np.testing.assert_allclose(pts["x"], FACE, atol=0.01)
    assert sorted(set(pts["ring"].tolist())) == [0, 1, 2]
    lowest, highest = pts[pts["ring"] == 0], pts[pts["ring"] == 2]
    assert np.all(lowest["z"] < 0) and np.all(highest["z"] > 0)  # ring 0 is the lowest row
    assert np.all(pts["intensity"] == 100.0)


def test_velodyne_max_range_clips_and_organised_cloud_keeps_nan(scene):
    _, msg = make(scene, '<plugin name="v" filename="libgazebo_ros_velodyne_laser.so"><max_range>2.0</max_range>'
                         '</plugin>', ray_clouds.create_velodyne)
    assert len(cloud(msg)) == 0
    _, msg = make(scene, '<plugin name="v" filename="libgazebo_ros_velodyne_laser.so"><max_range>2.0</max_range>'
                         '<organize_cloud>true</organize_cloud></plugin>', ray_clouds.create_velodyne)
    pts = cloud(msg)
    assert (msg.height, msg.width, msg.is_dense) == (3, 8, False) and np.all(np.isnan(pts["x"]))


def test_block_laser_point_cloud(scene):
    plugin, msg = make(scene, '<plugin name="b" filename="libgazebo_ros_block_laser.so"><topicName>cloud'
                              '</topicName><frameName>laser_link</frameName></plugin>', ray_clouds.create_block)
    assert plugin.pub.resolved_name == "/cloud" and len(msg.points) == 24
    np.testing.assert_allclose([p.x for p in msg.points], FACE, atol=0.01)
    assert msg.channels[0].name == "" and set(msg.channels[0].values) == {100.0}


def test_in_the_ray_process_a_scan_is_published_when_its_answer_is_back(monkeypatch):
    """~ray_process in real time: the due step only hands the rays over; a later step publishes the cloud,
    stamped with the due step and equal to the one cast in place; a deleted robot's cast is dropped."""
    monkeypatch.setattr(base, "publisher", _Pub)
    world = World(1.0 / 240.0, ray_process=True)
    try:
        wall = Body("east", "east", ((3.0, 0.0, 0.5), (0, 0, 0, 1)), True,
                    [Shape("box", (0.2, 6.0, 1.0), surface={"laser_retro": 100.0})])
        world.load_world(WorldDescription("w", "test", [wall]), "/nonexistent")
        plugin, _ = make((world, *_robot(world)), VELODYNE, ray_clouds.create_velodyne)
        assert plugin.pub.sent == [] and plugin.next_publish() == 0.1  # handed over; due again next step
        step, deadline = 0, time.monotonic() + 20.0  # the helper's start (PyBullet's import) is most of it
        while not plugin.pub.sent and time.monotonic() < deadline:
            step += 1
            world.step()
            plugin.after_step(step / 240.0, genpy.Time.from_sec(step / 240.0), [])
            time.sleep(0.004)  # a real-time step
        msg = plugin.pub.sent[0]
        assert msg.header.stamp == genpy.Time.from_sec(0.1)  # as of the step it was due, published later
        pts = cloud(msg)
        assert len(pts) == 24
        np.testing.assert_allclose(pts["x"], FACE, atol=0.01)
        assert np.all(pts["intensity"] == 100.0)  # the wall's laser_retro: hits named by the simulator's ids
        if plugin._waiting is None:  # the next scan was due already when the first came back: handed over then
            plugin.after_step(1.0, genpy.Time.from_sec(1.0), [])
        ticket = plugin._waiting[0]
        plugin.close()
        assert plugin._waiting is None and ticket not in world.ray_helper._waiting
    finally:
        world.close()


VELODYNE = '<plugin name="v" filename="libgazebo_ros_velodyne_laser.so"><frameName>laser_link</frameName></plugin>'


def _robot(world):
    text = open(LASER_URDF).read()
    model = parse_urdf(text, LASER_URDF)
    return world.load_robot(text, model), model
