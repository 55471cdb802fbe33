"""IMU, p3d and GPS: tag reading and defaults, the pure maths, and what PyBullet makes an IMU read (no master)."""
import math
import statistics
import xml.etree.ElementTree as ET

import pytest

from diffbot_sim import transforms
from diffbot_sim.description.plugin_tags import SensorElement
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.physics import World
from diffbot_sim.plugins import gps, imu, p3d

PATH = "/robot/gazebo[@reference='imu_link']/sensor[@name='imu']"


def sensor(xml, link="imu_link"):
    el = ET.fromstring(xml)
    return SensorElement("imu", el.get("name"), link, el, PATH), el.find("plugin")


# ------------------------------------------------------------------------------------------ tags

def test_imu_sensor_ros1_tags_and_defaults():
    s, plugin = sensor('<sensor type="imu" name="imu"><update_rate>200</update_rate>'
                       '<plugin name="p" filename="libgazebo_ros_imu_sensor.so"><frameName>imu_link</frameName>'
                       '<topicName>imu/data</topicName><updateRateHZ>100</updateRateHZ>'
                       '<gaussianNoise>0.01</gaussianNoise><rpyOffset>0 0 0</rpyOffset></plugin></sensor>')
    st = imu.sensor_settings(s, plugin, 0, PATH)
    assert (st.dialect, st.topic, st.frame, st.link) == ("ros1", "imu/data", "imu_link", "imu_link")
    assert st.period == pytest.approx(0.01) and st.lazy
    assert st.covariance == pytest.approx((1e-4,) * 3)
    s, plugin = sensor('<sensor type="imu" name="imu"><plugin filename="libgazebo_ros_imu_sensor.so">'
                       '<frameName>imu_link</frameName></plugin></sensor>')
    st = imu.sensor_settings(s, plugin, 0, PATH)
    assert st.topic == "imu_data" and st.period == 1.0  # the original's 1 Hz default
    assert any("1 Hz" in note for note in st.unknown)


def test_imu_sensor_ros1_needs_frame_name():
    s, plugin = sensor('<sensor type="imu" name="imu"><plugin filename="libgazebo_ros_imu_sensor.so">'
                       '<topicName>imu</topicName></plugin></sensor>')
    with pytest.raises(ModelError, match="frameName"):
        imu.sensor_settings(s, plugin, 0, PATH)


def test_imu_sensor_ros2_tags_and_sdf_noise_covariance():
    s, plugin = sensor(
        '<sensor type="imu" name="imu"><update_rate>50</update_rate><imu><angular_velocity>'
        '<x><noise type="gaussian"><stddev>0.002</stddev></noise></x>'
        '<z><noise type="gaussian"><stddev>0.003</stddev></noise></z></angular_velocity>'
        '<linear_acceleration><y><noise type="gaussian"><stddev>0.1</stddev></noise></y></linear_acceleration></imu>'
        '<plugin name="bno" filename="libgazebo_ros_imu_sensor.so"><ros><namespace>/demo</namespace>'
        '<remapping>~/out:=imu</remapping></ros><initial_orientation_as_reference>false'
        '</initial_orientation_as_reference></plugin></sensor>')
    st = imu.sensor_settings(s, plugin, 0, PATH)
    assert (st.dialect, st.namespace, st.topic, st.frame) == ("ros2", "/demo", "imu", "imu_link")
    assert st.period == pytest.approx(0.02) and not st.lazy
    orientation, rate, accel = st.covariance
    assert orientation == 0.0 and rate == pytest.approx([4e-6, 0, 9e-6]) and accel == pytest.approx([0, 0.01, 0])


def test_sdf_14_noise_block():
    s, plugin = sensor('<sensor type="imu" name="imu"><imu><noise><type>gaussian</type><rate><stddev>0.01</stddev>'
                       '</rate><accel><stddev>0.2</stddev></accel></noise></imu>'
                       '<plugin filename="libgazebo_ros_imu_sensor.so"><frameName>f</frameName></plugin></sensor>')
    st = imu.sensor_settings(s, plugin, 0, PATH)
    assert [m.stddev for m in st.sdf_rate] == [0.01] * 3 and [m.stddev for m in st.sdf_accel] == [0.2] * 3


def test_gazebo_ros_imu_model_plugin_tags():
    el = ET.fromstring('<plugin name="imu_plugin" filename="libgazebo_ros_imu.so"><alwaysOn>true</alwaysOn>'
                       '<bodyName>imu_link</bodyName><topicName>imu</topicName><serviceName>imu_service</serviceName>'
                       '<gaussianNoise>0.0</gaussianNoise><updateRate>0</updateRate>'
                       '<imu><noise><type>gaussian</type></noise></imu></plugin>')
    st = imu.model_settings(el, 0, "p", "imu_plugin")
    assert (st.link, st.frame, st.topic, st.service, st.period) == ("imu_link", "imu_link", "imu", "imu_service", 0.0)
    assert st.unknown == []  # the nested <imu> TurtleBot3 pastes is accepted (never read)
    with pytest.raises(ModelError, match="bodyName"):
        imu.model_settings(ET.fromstring('<plugin filename="libgazebo_ros_imu.so"/>'), 0, "p", "x")
    with pytest.raises(ConfigError, match="rpyOffset"):
        imu.model_settings(ET.fromstring('<plugin><bodyName>a</bodyName><rpyOffset>1 2</rpyOffset></plugin>'),
                           0, "p", "x")


def test_hector_imu_tags_defaults_and_heading_tags_ignored():
    el = ET.fromstring('<plugin name="imu_controller" filename="libhector_gazebo_ros_imu.so">'
                       '<updateRate>50.0</updateRate><bodyName>base_link</bodyName><topicName>imu/data</topicName>'
                       '<accelDrift>0.005 0.005 0.005</accelDrift>'
                       '<accelGaussianNoise>0.005 0.005 0.005</accelGaussianNoise>'
                       '<rateDrift>0.005 0.005 0.005 </rateDrift>'
                       '<rateGaussianNoise>0.005 0.005 0.005</rateGaussianNoise>'
                       '<headingDrift>0.005</headingDrift><headingGaussianNoise>0.005</headingGaussianNoise></plugin>')
    st = imu.hector_settings(el, 0, "p", "imu_controller", "base_footprint")
    assert (st.link, st.frame, st.topic, st.bias_topic, st.service) == (
        "base_link", "base_link", "imu/data", "imu/data/bias", "imu/data/calibrate")
    assert st.period == pytest.approx(0.02)
    assert [m.drift for m in st.hector["accel"]] == [0.005] * 3 and st.hector["yaw"][0].gaussian_noise == 0.0
    assert any("headingDrift" in note for note in st.unknown)
    orientation, rate, accel = st.covariance
    assert orientation[2] == 0.0 and rate == pytest.approx([2.5e-5] * 3)
    assert orientation[0] == pytest.approx(2.5e-5 / 9.81 ** 2)
    st = imu.hector_settings(ET.fromstring("<plugin/>"), 0, "p", "x", "base_footprint")
    assert (st.link, st.topic, st.period) == ("base_footprint", "imu", 0.0)


# ---------------------------------------------------------------------------------------- maths

def test_reading_offsets_reference_and_noise():
    st = imu.ImuSettings(rpy_offset=(0, 0, math.pi / 2))
    r = imu.Reading(st)
    o, w, a = r((0, 0, 0, 1), (0, 0, 0.5), (0, 0, 9.81), 0.01)
    assert o == pytest.approx(transforms.rpy_quaternion(0, 0, math.pi / 2)) and w == (0, 0, 0.5)
    st = imu.ImuSettings(initial_reference=True)
    r = imu.Reading(st)
    start = transforms.rpy_quaternion(0, 0, 1.0)
    assert r(start, (0, 0, 0), (0, 0, 0), 0.01)[0] == pytest.approx((0, 0, 0, 1))
    st = imu.ImuSettings(gaussian_noise=0.1, orientation_noise=True, generator=__import__("random").Random(1))
    r = imu.Reading(st)
    rates = [r((0, 0, 0, 1), (0, 0, 0), (0, 0, 9.81), 0.01)[1][2] for _ in range(5000)]
    assert statistics.pstdev(rates) == pytest.approx(0.1, rel=0.05)


def test_hector_orientation_error_is_yaw_then_tilt():
    error = imu.hector_orientation_error(0.2, (0.0, 0.0, 0.0), 9.81)
    assert error == pytest.approx(transforms.rpy_quaternion(0, 0, 0.2))
    error = imu.hector_orientation_error(0.0, (0.0981, 0.0, 0.0), 9.81)  # x drift -> pitch error
    assert error[1] < 0 and error[0] == 0 and error[2] == 0


# ----------------------------------------------------------------------------------------- p3d

def test_p3d_tags_defaults_and_required():
    v = p3d.settings({"bodyName": "base_link", "topicName": "ground_truth/state"}, "p")
    assert (v["frame"], v["period"], v["gaussian_noise"], v["xyz"], v["rpy"]) == ("world", 0.0, 0.0, (0, 0, 0),
                                                                                (0, 0, 0))
    v = p3d.settings({"bodyName": "b", "topicName": "t", "frameName": "map", "updateRate": "50",
                      "gaussianNoise": "0.01", "xyzOffsets": "1 2 3", "rpyOffsets": "0 0 0"}, "p")
    assert (v["period"], v["gaussian_noise"], v["xyz"]) == (0.02, 0.01, (1, 2, 3))
    for missing in ("bodyName", "topicName"):
        tags = {"bodyName": "b", "topicName": "t"}
        del tags[missing]
        with pytest.raises(ModelError, match=missing):
            p3d.settings(tags, "p")


def test_p3d_relative_to_a_link():
    q90 = transforms.rpy_quaternion(0, 0, math.pi / 2)
    body = (((1.0, 1.0, 0.0), q90), (0.0, 1.0, 0.0), (0.0, 0.0, 0.5))
    ref = (((1.0, 0.0, 0.0), q90), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    (p, q), v, w = p3d.relative(body, ref)
    assert p == pytest.approx((1.0, 0.0, 0.0)) and q == pytest.approx((0, 0, 0, 1))
    assert v == pytest.approx((1.0, 0.0, 0.0)) and w == pytest.approx((0, 0, 0.5))
    assert p3d.relative(body, None) == body


# ----------------------------------------------------------------------------------------- GPS

def test_gps_tags_defaults():
    import random

    v = gps.settings({}, "p", "base_link", random.Random(0))
    assert v["reference"] == (49.9, 8.9, 0.0, 0.0) and v["body"] == "base_link"
    assert (v["frame"], v["topic"], v["velocity_topic"], v["status"], v["service"], v["period"]) == (
        "world", "fix", "fix_velocity", 0, 1, 0.0)
    v = gps.settings({"updateRate": "40", "gaussianNoise": "0.1 0.1 0.2", "velocityDrift": "0.01"}, "p", "b",
                     random.Random(0))
    assert v["period"] == 0.025 and gps.covariance(v["position"]) == pytest.approx((0.01, 0.01, 0.04))
    assert [m.drift for m in v["velocity"]] == [0.01] * 3


def test_wgs84_radii_hand_computed():
    # At the equator: M = a (1 - e2), N cos(0) = a. At 90 deg: M = N = a / sqrt(1 - e2).
    a, e2 = 6378137.0, 0.0066943799901413165
    m, east = gps.radii(0.0)
    assert m == pytest.approx(a * (1 - e2)) and east == pytest.approx(a)
    m, _ = gps.radii(90.0)
    assert m == pytest.approx(a / math.sqrt(1 - e2))
    m, east = gps.radii(45.0)  # textbook values at 45 deg: 6367381.8 m and 6388838.3 m * cos 45
    assert m == pytest.approx(6367381.8, abs=0.5) and east == pytest.approx(6388838.3 * math.sqrt(0.5), abs=0.5)


def test_enu_to_lat_lon_hand_computed():
    ref = (45.0, 8.0, 90.0, 100.0)  # heading 90: +x east, +y north (REP 103 ENU)
    lat, lon, alt = gps.to_geodetic((0.0, 1000.0, 2.0), ref)
    assert lat == pytest.approx(45.0 + math.degrees(1000.0 / 6367381.8), abs=1e-9) and lon == pytest.approx(8.0)
    assert alt == 102.0
    lat, lon, _ = gps.to_geodetic((1000.0, 0.0, 0.0), ref)
    assert lat == pytest.approx(45.0, abs=1e-12)
    assert lon == pytest.approx(8.0 + math.degrees(1000.0 / (6388838.3 * math.sqrt(0.5))), abs=1e-9)
    # hector's default heading 0: +x north, +y west
    lat, lon, _ = gps.to_geodetic((1000.0, 1000.0, 0.0), (45.0, 8.0, 0.0, 0.0))
    assert lat > 45.0 and lon < 8.0
    assert gps.north_west(1.0, 2.0, 90.0) == pytest.approx((2.0, -1.0))


# ------------------------------------------------------------------------------------ physics

IMU_URDF = """<robot name="box">
  <link name="base_link">
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
    <inertial><mass value="2"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial>
  </link>
  <link name="imu_link"/>
  <joint name="imu_joint" type="fixed"><parent link="base_link"/><child link="imu_link"/>
    <origin xyz="0.1 0 0.05" rpy="0 0 1.5707963267948966"/></joint>
  <link name="arm"><inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/>
    </inertial></link>
  <joint name="arm_joint" type="continuous"><parent link="base_link"/><child link="arm"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/></joint>
  <gazebo reference="base_link"><mu1>0</mu1><mu2>0</mu2></gazebo>
</robot>"""


@pytest.fixture
def box():
    world = World(1.0 / 240.0)
    model = parse_urdf(IMU_URDF, "box.urdf")
    robot = world.load_robot(IMU_URDF, model, (0.0, 0.0, 0.05))
    yield world, robot
    world.close()


def sample(world, robot, link, seconds, each=None, period=0.01):
    """Step for ``seconds``; read the IMU every ``period``; return the readings (after the first)."""
    steps = int(round(period / world.time_step))
    velocity, out = None, []
    for _ in range(int(round(seconds / period))):
        for _ in range(steps):
            if each:
                each()
            world.step()
        pose, w, a, velocity = robot.link_imu(link, velocity, period)
        out.append((pose, w, a))
    return out[1:]


def test_lumped_imu_at_rest_reads_plus_g_and_no_rate(box):
    world, robot = box
    sample(world, robot, "imu_link", 1.0)  # settle
    readings = sample(world, robot, "imu_link", 0.5)
    for _, w, a in readings:
        assert a == pytest.approx((0.0, 0.0, 9.81), abs=0.02)
        assert w == pytest.approx((0.0, 0.0, 0.0), abs=1e-3)
    pose = readings[-1][0]
    assert pose[0] == pytest.approx((0.1, 0.0, robot.base_pose()[0][2] + 0.05), abs=1e-6)
    assert pose[1] == pytest.approx(transforms.rpy_quaternion(0, 0, math.pi / 2), abs=1e-4)


def test_imu_in_a_known_spin_reads_the_yaw_rate_and_centripetal_acceleration(box):
    world, robot = box
    sample(world, robot, "imu_link", 0.5)
    readings = sample(world, robot, "imu_link", 1.0, each=lambda: robot.set_heading_velocity(0.0, 0.0, 0.5))
    for _, w, a in readings[5:]:
        assert w == pytest.approx((0.0, 0.0, 0.5), abs=1e-3)  # the IMU frame is yawed 90 deg: z unchanged
        # 0.1 m off the spin axis: 0.5^2 * 0.1 = 0.025 m/s^2 towards the axis (-x of base = +y of the IMU)
        assert a[1] == pytest.approx(0.025, abs=0.005) and a[0] == pytest.approx(0.0, abs=0.005)
        assert a[2] == pytest.approx(9.81, abs=0.02)


def test_link_twist_of_a_moving_link(box):
    world, robot = box
    sample(world, robot, "imu_link", 0.2)
    for _ in range(24):
        robot.set_heading_velocity(0.3, 0.0, 0.0)
        world.step()
    _, v, w = robot.link_twist("imu_link")
    # the base moves +x at 0.3 m/s; the IMU frame is yawed 90 deg, so that is -y in it
    assert v == pytest.approx((0.0, -0.3, 0.0), abs=0.01)
    _, v, w = robot.link_twist("arm")  # a real (not lumped) link
    assert v[0] == pytest.approx(0.3, abs=0.01)
