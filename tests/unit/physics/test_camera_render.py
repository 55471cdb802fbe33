"""physics.World.render on a hand-built world: a red static box where K says, in red, at the right depth;
world bodies take their SDF colour; nothing hit reads NaN."""
import math

import numpy as np
import pytest

from diffbot_sim.physics import World
from diffbot_sim.sensors import camera as cam
from diffbot_sim.world.bodies import Body, Shape, WorldDescription

W, H, HFOV, NEAR, FAR = 320, 240, 1.047, 0.1, 10.0


@pytest.fixture
def world(tmp_path):
    w = World(1.0 / 240.0)
    # A 0.4 m red cube whose near face is at x = 1.8, centred on y = 0.3, z = 0.5; a green one to the right.
    w.load_world(WorldDescription("t", "t", bodies=[
        Body("red::link", "red", ((2.0, 0.3, 0.5), (0, 0, 0, 1)), True, [Shape("box", (0.4, 0.4, 0.4))],
             color=(1.0, 0.0, 0.0, 1.0)),
        Body("green::link", "green", ((3.0, -1.0, 0.5), (0, 0, 0, 1)), True, [Shape("box", (0.4, 0.4, 0.4))],
             color=(0.0, 1.0, 0.0, 1.0))]), str(tmp_path))
    yield w
    w.close()


def test_box_where_k_predicts_in_red_at_its_depth(world):
    rgb, depth = world.render(((0.0, 0.0, 0.5), (0.0, 0.0, 0.0, 1.0)), W, H, HFOV, NEAR, FAR)
    assert rgb.shape == (H, W, 3) and rgb.dtype == np.uint8 and depth.shape == (H, W) and depth.dtype == np.float32
    K = cam.intrinsics(W, H, HFOV).K
    u, v = cam.project(K, cam.body_to_optical((1.8, 0.3, 0.0)))  # the face's centre, Gazebo's K
    # Gazebo's cx = (w+1)/2 counts pixels from 1; the image's 0-based index is one less.
    u0, v0 = u - 1.0, v - 1.0
    face = (rgb[:, :, 0] > 150) & (rgb[:, :, 1] < 60) & (rgb[:, :, 2] < 60) & (np.abs(depth - 1.8) < 0.01)
    rows, cols = np.nonzero(face)
    centre = ((cols.min() + cols.max()) / 2.0, (rows.min() + rows.max()) / 2.0)
    assert centre[0] == pytest.approx(u0, abs=1.0) and centre[1] == pytest.approx(v0, abs=1.0)
    pixel = (int(round(v0)), int(round(u0)))
    assert rgb[pixel][0] > 150 and rgb[pixel][1] < 60 and rgb[pixel][2] < 60
    assert depth[pixel] == pytest.approx(1.8, abs=0.01)
    # The face's width in pixels: 0.4 m at 1.8 m is f * 0.4 / 1.8.
    assert cols.max() - cols.min() + 1 == pytest.approx(K[0] * 0.4 / 1.8, abs=2.0)


def test_colours_and_misses(world):
    rgb, depth = world.render(((0.0, 0.0, 0.5), (0.0, 0.0, 0.0, 1.0)), W, H, HFOV, NEAR, FAR)
    u, v = cam.project(cam.intrinsics(W, H, HFOV).K, cam.body_to_optical((2.8, -1.0, 0.0)))
    g = rgb[int(round(v - 1)), int(round(u - 1))]
    assert g[1] > 150 and g[0] < 60 and g[2] < 60
    assert np.isnan(depth[0, 0])  # sky: nothing hit
    assert np.isfinite(depth[-1, W // 2])  # the ground plane below


def test_camera_follows_yaw(world):
    # Turned 90 degrees left, the camera no longer sees the red box ahead of the original view.
    q = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))
    rgb, depth = world.render(((0.0, 0.0, 0.5), q), W, H, HFOV, NEAR, FAR)
    red = (rgb[:, :, 0] > 150) & (rgb[:, :, 1] < 60)
    assert not red.any()


def test_egl_before_bodies_or_a_reason(tmp_path):
    """The EGL plugin draws the world when loaded first; once bodies exist, use_egl says why not."""
    w = World(1.0 / 240.0)
    try:
        reason = w.use_egl()
        if reason is not None:
            pytest.skip(f"no EGL here: {reason}")
        w.load_world(WorldDescription("t", "t", bodies=[
            Body("red::link", "red", ((2.0, 0.0, 0.5), (0, 0, 0, 1)), True, [Shape("box", (0.4, 0.4, 0.4))],
                 color=(1.0, 0.0, 0.0, 1.0))]), str(tmp_path))
        rgb, depth = w.render(((0.0, 0.0, 0.5), (0.0, 0.0, 0.0, 1.0)), W, H, HFOV, NEAR, FAR, "egl")
        assert rgb[H // 2, W // 2][0] > 150 and rgb[H // 2, W // 2][1] < 60
        assert depth[H // 2, W // 2] == pytest.approx(1.8, abs=0.01)
    finally:
        w.close()
    late = World(1.0 / 240.0)
    try:
        late.load_world(WorldDescription("t", "t", bodies=[
            Body("b::link", "b", ((2.0, 0.0, 0.5), (0, 0, 0, 1)), True, [Shape("box", (0.4, 0.4, 0.4))])]),
            str(tmp_path))
        assert "built already" in late.use_egl()
    finally:
        late.close()


def test_egl_probe_reports_a_plugin_that_ends_its_process(monkeypatch):
    """A machine without EGL: PyBullet's plugin calls exit(); the probe runs it in a child, so we only get
    a reason (this is what happened in a fresh debootstrap chroot, where it used to end pytest itself)."""
    from diffbot_sim import physics

    monkeypatch.setattr(physics.client, "_EGL_PROBE", "import sys; sys.exit(1)\n")
    reason = physics.egl_probe("/any/plugin.so")
    assert "ended its process" in reason and "status 1" in reason
