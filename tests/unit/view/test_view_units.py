"""The pure parts of the view: world shapes -> marker specs (their message: tests/unit/messages/test_markers.py),
the rviz config for a run, window trees and picture analysis (xscreen), with made-up inputs."""
import math

import numpy as np
import pytest

from diffbot_sim.view import rviz_config, xscreen
from diffbot_sim.world import markers as world_markers
from diffbot_sim.world.bodies import Body, Shape, WorldDescription

Q90 = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))


def world():
    return WorldDescription("w", "w.world", bodies=[
        Body("ground::link", "ground", ((0, 0, 0), (0, 0, 0, 1)), True, [Shape("plane", (0, 0, 1))]),
        Body("wall::link", "wall", ((3.0, 0.0, 0.5), Q90), True,
             [Shape("box", (6.0, 0.2, 1.0), pose=((0.0, 0.0, 0.0), (0, 0, 0, 1)))], color=(1, 0, 0, 1)),
        Body("pillar::link", "pillar", ((0.5, 1.2, 0.5), (0, 0, 0, 1)), True, [Shape("cylinder", (0.2, 1.0))]),
        Body("ring::link", "ring", ((-1, 0, 0), (0, 0, 0, 1)), True, [Shape("mesh", mesh="/m/ring.dae",
                                                                            scale=(2, 2, 1))]),
        Body("box::link", "box", ((1, 1, 0.1), (0, 0, 0, 1)), False, [Shape("box", (0.2, 0.2, 0.2))]),
    ])


def test_static_shapes_become_markers_in_the_world_frame():
    specs = world_markers.marker_specs(world())
    assert [(s.ns, s.kind) for s in specs] == [("wall::link", "CUBE"), ("pillar::link", "CYLINDER"),
                                                ("ring::link", "MESH_RESOURCE")]  # no plane, no dynamic box
    wall, pillar, ring = specs
    assert wall.scale == (6.0, 0.2, 1.0) and wall.color == (1, 0, 0, 1)
    assert wall.pose[0] == pytest.approx((3.0, 0.0, 0.5)) and wall.pose[1] == pytest.approx(Q90)
    assert pillar.scale == (0.4, 0.4, 1.0) and pillar.color == world_markers.DEFAULT_COLOR
    assert ring.mesh == "file:///m/ring.dae" and ring.scale == (2, 2, 1)


def test_bounds_follow_the_turned_wall():
    # The wall is 6 m long along y once turned 90 degrees: y -3..3, x 2.9..3.1.
    xmin, ymin, xmax, ymax = world_markers.bounds_xy(world_markers.marker_specs(world()))
    assert (ymin, ymax) == pytest.approx((-3.0, 3.0))
    assert xmax == pytest.approx(3.1) and xmin == pytest.approx(-1.0)  # the ring's origin
    assert world_markers.bounds_xy([]) is None


def test_map_walls_are_triangle_lists_with_a_limit():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 1]], dtype=float)
    indices = np.array([[0, 1, 2], [1, 3, 2], [0, 3, 1]])
    w = WorldDescription("m", "m.yaml", bodies=[Body("map::walls", "map", ((0, 0, 0), (0, 0, 0, 1)), True,
                                                     [Shape("trimesh", vertices=vertices, indices=indices)])])
    warnings = []
    specs = world_markers.marker_specs(w, warnings, max_triangles=2)
    assert len(specs) == 1 and specs[0].kind == "TRIANGLE_LIST"
    np.testing.assert_array_equal(specs[0].points, vertices[[0, 1, 2, 1, 3, 2]])
    assert warnings and "3 wall triangles, 2 drawn" in warnings[0]


def test_odom_offset_is_the_spawn_pose_for_encoder_odometry_only():
    from diffbot_sim.nodes.world_markers import odom_offset

    assert odom_offset("world", 1, 2, 0.5) == ((0, 0, 0), (0, 0, 0, 1))
    p, q = odom_offset("encoder", 1, 2, 0.5)
    assert p == (1.0, 2.0, 0.0) and q[2] == pytest.approx(math.sin(0.25))


def template():
    return rviz_config.load_template(rviz_config_path())


def rviz_config_path():
    import os
    return os.path.join(os.path.dirname(__file__), "..", "..", "..", "rviz", "diffbot.rviz")


def test_config_for_one_robot_with_sensors():
    robot = rviz_config.RobotView("", "", "robot_description", "/odom", "odom", ["/scan"], ["/cam/image_raw"])
    config = rviz_config.build(template(), [robot], (-1.0, -2.0, 3.0, 2.0))
    manager = config["Visualization Manager"]
    names = [d["Name"] for d in manager["Displays"]]
    assert names == ["Grid", "World", "TF", "RobotModel", "Odometry", "LaserScan /scan", "Image /cam/image_raw"]
    assert manager["Global Options"]["Fixed Frame"] == "odom"
    view = manager["Views"]["Current"]
    assert view["Class"] == "rviz/TopDownOrtho" and (view["X"], view["Y"]) == (1.0, 0.0)
    # 4.8 x 4.8 m with the margins into 900 x 700 pixels: the height decides.
    assert view["Scale"] == pytest.approx(700 / 4.8, abs=1e-3)
    assert rviz_config.dump(config).startswith("Panels:")


def test_config_for_named_robots():
    robots = [rviz_config.RobotView(n, n, "robot_description", f"/{n}/odom", f"{n}/odom", spawn=(0, i))
              for i, n in enumerate(("robot1", "robot2"))]
    config = rviz_config.build(template(), robots, None, view="3d")
    displays = config["Visualization Manager"]["Displays"]
    models = [d for d in displays if d["Class"] == "rviz/RobotModel"]
    assert [(m["Name"], m["TF Prefix"]) for m in models] == [("robot1 RobotModel", "robot1"),
                                                             ("robot2 RobotModel", "robot2")]
    assert config["Visualization Manager"]["Global Options"]["Fixed Frame"] == "robot1/odom"
    assert config["Visualization Manager"]["Views"]["Current"]["Class"] == "rviz/Orbit"
    with pytest.raises(ValueError, match="view 'side'"):
        rviz_config.build(template(), robots, None, view="side")
    with pytest.raises(ValueError, match="no robot"):
        rviz_config.build(template(), [], None)


def test_sensor_topics_by_namespace_and_type():
    published = [("/scan", "sensor_msgs/LaserScan"), ("/r1/scan", "sensor_msgs/LaserScan"),
                 ("/r1/cam/image_raw", "sensor_msgs/Image"), ("/r1/cam/depth/image_raw", "sensor_msgs/Image"),
                 ("/odom", "nav_msgs/Odometry")]
    assert rviz_config.sensor_topics(published, "/r1") == (["/r1/scan"], ["/r1/cam/image_raw"])
    assert rviz_config.sensor_topics(published)[0] == ["/r1/scan", "/scan"]
    assert rviz_config.prefix_of("robot1/odom") == "robot1" and rviz_config.prefix_of("odom") == ""


TREE = """
xwininfo: Window id: 0x50d (the root window) (has no name)
     2 children:
     0x200006 "view.rviz - RViz": ("rviz" "rviz")  1280x800+0+0  +0+0
        2 children:
        0x20000b "rviz": ("rviz" "rviz")  932x709+348+62  +348+62
           1 child:
           0x600004 (has no name): ()  900x709+0+0  +364+62
        0x200009 "rviz": ("rviz" "rviz")  1280x29+0+771  +0+771
     0x200004 "Qt Selection Owner for rviz": ()  3x3+0+0  +0+0
"""


def test_window_tree():
    windows = xscreen.parse_tree(TREE)
    assert [w.wid for w in windows] == ["0x200006", "0x20000b", "0x600004", "0x200009", "0x200004"]
    top = windows[0]
    assert (top.name, top.width, top.height, top.children) == ("view.rviz - RViz", 1280, 800, 3)
    panel = [w for w in xscreen.subtree(windows, top) if not w.name]
    assert [(w.x, w.y, w.width) for w in panel] == [(364, 62, 900)]


def test_picture_analysis():
    image = np.full((100, 200, 3), 48, dtype=np.uint8)
    image[10:14, 5:40] = xscreen.STATUS_OK
    assert xscreen.status_colors(image) == {"ok": 140, "warn": 0, "error": 0}
    image[20:22, 5:10] = xscreen.STATUS_ERROR
    assert xscreen.status_colors(image)["error"] == 10
    assert xscreen.rows_of_color(image, xscreen.STATUS_ERROR) == [20, 21]
    a, b = image.copy(), image.copy()
    a[40:50, 100:120] = (255, 216, 0)  # the robot
    a[90, 5] = (255, 216, 0)  # a stray pixel far away
    count, centre, stray = xscreen.patch(xscreen.changed(a, b), radius=20)
    assert (count, stray) == (200, 1) and centre == pytest.approx((109.5, 44.5))
    assert xscreen.patch(xscreen.changed(b, b), 20) == (0, None, 0)
    g = np.zeros((1, 2, 3), dtype=np.uint8)
    g[0, 0] = (90, 215, 92)
    assert xscreen.greenish(g).tolist() == [[True, False]]


def test_top_view_and_camera_projection():
    assert xscreen.top_view_pixel(1.0, 1.0, (100, 50, 1000, 750), (0.0, 0.0), 100.0) == (650.0, 300.0)
    import pybullet
    view = pybullet.computeViewMatrix((0, 0, 5), (0, 0, 0), (0, 1, 0))
    proj = pybullet.computeProjectionMatrixFOV(90, 1.0, 0.1, 100)
    u, v = xscreen.project((0, 0, 0), view, proj, (200, 200))
    assert (u, v) == pytest.approx((100, 100))
    u, v = xscreen.project((2.5, 0, 0), view, proj, (200, 200))
    assert (u, v) == pytest.approx((150, 100))  # +x to the right from above with y up
