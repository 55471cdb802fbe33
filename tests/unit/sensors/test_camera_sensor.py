"""sensors.camera (pure): SDF parsing with SDF defaults, CameraInfo as gazebo_ros computes it, PyBullet's
vertical FOV, depth-buffer linearisation, the kinect plugin's point cloud and its byte layout."""
import math
import struct
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from diffbot_sim.errors import ConfigError
from diffbot_sim.sensors import camera as cam

PATH = "/robot/gazebo[@reference='camera_link']/sensor[@name='c']"


def sensor(text):
    return cam.parse_sensor(ET.fromstring(text), PATH)


def test_defaults_without_camera_element():
    cfg = sensor('<sensor type="camera" name="c"/>')
    assert (cfg.width, cfg.height, cfg.hfov, cfg.near, cfg.far, cfg.format) == (320, 240, 1.047, 0.1, 100.0, "R8G8B8")
    assert cfg.update_rate == 0.0 and cfg.encoding == "rgb8"
    assert cfg.warnings


def test_parse_full_sensor():
    cfg = sensor("""<sensor type="depth" name="c"><update_rate>30</update_rate><pose>0.1 0 0.2 0 0.5 0</pose>
      <camera><horizontal_fov>1.3962634</horizontal_fov><image><width>640</width><height>480</height>
      <format>B8G8R8</format></image><clip><near>0.02</near><far>300</far></clip>
      <noise><type>gaussian</type><mean>0.0</mean><stddev>0.007</stddev></noise></camera></sensor>""")
    assert (cfg.type, cfg.update_rate, cfg.width, cfg.height) == ("depth", 30.0, 640, 480)
    assert cfg.hfov == pytest.approx(1.3962634) and (cfg.near, cfg.far) == (0.02, 300.0)
    assert cfg.encoding == "bgr8" and cfg.noise_stddev == 0.007
    assert cfg.pose == ((0.1, 0.0, 0.2), (0.0, 0.5, 0.0))


@pytest.mark.parametrize("body, tag", [
    ("<camera><image><width>0</width></image></camera>", "<width>"),
    ("<camera><image><width>wide</width></image></camera>", "<width>"),
    ("<camera><clip><near>1</near><far>0.5</far></clip></camera>", "<clip><far>"),
    ("<camera><horizontal_fov>3.5</horizontal_fov></camera>", "<horizontal_fov>"),
    ("<camera><horizontal_fov>wide</horizontal_fov></camera>", "<horizontal_fov>"),
])
def test_bad_values_name_the_tag(body, tag):
    with pytest.raises(ConfigError) as err:
        sensor(f'<sensor type="camera" name="c">{body}</sensor>')
    assert tag in str(err.value)


def test_a_computed_width_is_read_as_gazebo_reads_it():
    cfg = sensor('<sensor type="camera" name="c"><camera><image><width>640.7</width></image></camera></sensor>')
    assert cfg.width == 640
    assert [w for w in cfg.warnings if "<width>" in w] == [
        f"<width> of {PATH}/camera/image: took 640 from '640.7', as Gazebo's SDF reader (std::stoul) "
        "does"]


def test_intrinsics_as_gazebo():
    # 640x480, hfov 1.047: f = 640 / (2 tan(0.5235)) = 554.383 (554.256 at exactly pi/3); centre (w+1)/2, (h+1)/2.
    info = cam.intrinsics(640, 480, 1.047, hack_baseline=0.07, distortion=(0.1, 0.2, 0.3, 0.4, 0.5))
    f = 640 / (2 * math.tan(1.047 / 2))
    assert f == pytest.approx(554.3827, abs=1e-3)
    assert pytest.approx([f, 0, 320.5, 0, f, 240.5, 0, 0, 1]) == info.K
    assert pytest.approx([f, 0, 320.5, -f * 0.07, 0, f, 240.5, 0, 0, 0, 1, 0]) == info.P
    assert info.R == [1, 0, 0, 0, 1, 0, 0, 0, 1]
    assert info.D == [0.1, 0.2, 0.4, 0.5, 0.3] and info.distortion_model == "plumb_bob"


def test_intrinsics_user_values():
    info = cam.intrinsics(320, 240, 1.047, cx=100.0, cy=50.0, cx_prime=110.0, focal=300.0)
    assert info.K[0] == 300.0 and info.K[2] == 100.0 and info.K[5] == 50.0 and info.P[2] == 110.0
    assert "focalLength" in info.warnings[0]


def test_vertical_fov():
    # A square image has equal FOVs; 4:3 at 90 degrees horizontal: 2 atan(0.75) = 73.74 degrees.
    assert cam.vertical_fov_degrees(1.0, 100, 100) == pytest.approx(math.degrees(1.0))
    assert cam.vertical_fov_degrees(math.pi / 2, 640, 480) == pytest.approx(73.7398, abs=1e-3)


def test_linear_depth():
    near, far = 0.1, 10.0
    z = np.array([0.1, 1.0, 5.0])
    buffer = far * (z - near) / (z * (far - near))  # the inverse of the linearisation
    assert cam.linear_depth(buffer, near, far) == pytest.approx(z, rel=1e-5)
    out = cam.linear_depth(np.array([1.0, 0.0]), near, far)
    assert math.isnan(out[0]) and out[1] == pytest.approx(near)
    assert out.dtype == np.float32


def test_cutoff():
    out = cam.cutoff(np.array([0.2, 0.4, 1.0, 5.0, np.nan], np.float32), 0.4, 5.0)
    assert np.isnan(out[[0, 1, 3, 4]]).all() and out[2] == 1.0


def test_look_at_is_plus_x_up_z():
    eye, target, up = cam.look_at(((1.0, 2.0, 3.0), (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))))
    assert eye == pytest.approx((1, 2, 3))
    assert np.subtract(target, eye) == pytest.approx((0, 1, 0), abs=1e-12)  # yaw 90 degrees: looks along +y
    assert up == pytest.approx((0, 0, 1), abs=1e-12)


def test_sensor_view_composes_pose():
    position, quat = cam.sensor_view(((1.0, 0.0, 0.0), (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))),
                                     ((0.5, 0.0, 0.1), (0.0, 0.0, math.pi / 2)))
    assert position == pytest.approx((1.0, 0.5, 0.1))
    assert quat == pytest.approx((0, 0, 1, 0), abs=1e-9) or quat == pytest.approx((0, 0, -1, 0), abs=1e-9)


def test_projection_of_body_point():
    info = cam.intrinsics(320, 240, 1.047)
    u, v = cam.project(info.K, cam.body_to_optical((2.0, 0.0, 0.0)))
    assert (u, v) == (160.5, 120.5)
    u, v = cam.project(info.K, cam.body_to_optical((2.0, 0.5, -0.25)))  # left and down
    f = info.K[0]
    assert u == pytest.approx(160.5 - f * 0.25) and v == pytest.approx(120.5 + f * 0.125)


def test_cloud_points_by_hand():
    # 3x2 image, f = 2: pixel (i, j) = (2, 1) at depth 4 -> x = 4 (2 - 1) / 2 = 2, y = 4 (1 - 0.5) / 2 = 1.
    depth = np.array([[1.0, np.nan, 3.0], [2.0, 2.0, 4.0]], np.float32)
    pts = cam.cloud_points(depth, 2.0)
    assert pts.shape == (2, 3, 3)
    assert pts[1, 2] == pytest.approx((2.0, 1.0, 4.0))
    assert pts[0, 0] == pytest.approx((-0.5, -0.25, 1.0))
    assert pts[1, 1] == pytest.approx((0.0, 0.5, 2.0))
    assert np.isnan(pts[0, 1]).all()


def test_cloud_bytes_layout():
    pts = np.array([[[1.0, 2.0, 3.0]]], np.float32)
    data = cam.cloud_bytes(pts, np.array([[[10, 20, 30]]], np.uint8))
    assert len(data) == cam.CLOUD_POINT_STEP == 32
    assert struct.unpack_from("<3f", data, 0) == (1.0, 2.0, 3.0)
    assert data[16:19] == bytes([10, 20, 30])  # R, G, B in the rgb field's first bytes, as the plugin


def test_encodings():
    rgb = np.array([[[255, 0, 0], [0, 0, 255]]], np.uint8)
    assert cam.to_encoding(rgb, "bgr8")[0, 0].tolist() == [0, 0, 255]
    assert cam.to_encoding(rgb, "mono8").tolist() == [[76, 29]]


def test_image_noise_is_seeded_and_clamped():
    rgb = np.full((4, 4, 3), 250, np.uint8)
    a = cam.image_noise(rgb, 0.0, 0.1, np.random.default_rng(1))
    b = cam.image_noise(rgb, 0.0, 0.1, np.random.default_rng(1))
    assert (a == b).all() and a.max() <= 255 and (a != rgb).any()
    assert cam.image_noise(rgb, 0.0, 0.0, None) is rgb


def test_read_plugin_ros1_and_ros2():
    tags = cam.read_plugin(ET.fromstring("""<plugin filename="libgazebo_ros_camera.so"><alwaysOn>true</alwaysOn>
      <cameraName>cam</cameraName><imageTopicName>img</imageTopicName><frameName>cam_optical</frameName>
      <hackBaseline>0.07</hackBaseline><distortionK1>0.1</distortionK1><bogus/></plugin>"""), PATH)
    assert tags.dialect == "ros1" and tags.values["camera_name"] == "cam" and tags.values["hack_baseline"] == 0.07
    assert tags.values["k1"] == 0.1 and tags.unknown == ["bogus"]
    tags = cam.read_plugin(ET.fromstring("""<plugin filename="libgazebo_ros_camera.so"><ros><namespace>demo</namespace>
      <remapping>~/image_raw:=image_demo</remapping></ros><camera_name>c1</camera_name>
      <frame_name>f</frame_name></plugin>"""), PATH)
    assert tags.dialect == "ros2" and tags.values["namespace"] == "demo"
    assert cam.remapped(tags, "image_raw") == "image_demo" and tags.values["frame"] == "f"


def test_effective_period():
    assert cam.effective_period(10.0, 0.0) == pytest.approx(0.1)
    assert cam.effective_period(30.0, 5.0) == pytest.approx(0.2)
    assert cam.effective_period(0.0, 0.0) == 0.0
