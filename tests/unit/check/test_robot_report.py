"""robot_report, report_text and drive_check: what robot_check says about the fixture robots, and how it judges a
drive. No master: the report is built in-process (PyBullet DIRECT for the loaded mass)."""
import os

import pytest
import yaml

from diffbot_sim.check import drive_check, report_text, robot_report
from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.plugins.registry import KNOWN, KNOWN_SENSORS

ROBOTS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "data", "robots")


def robot(name):
    return os.path.join(ROBOTS, name)


def controllers(*names):
    out = []
    for name in names:
        with open(robot(name)) as handle:
            out.append((robot(name), yaml.safe_load(handle)))
    return out


@pytest.fixture
def report(tmp_path):
    def build(model, *yamls, text=None):
        path = robot(model)
        if text is not None:
            path = str(tmp_path / model)
            with open(path, "w") as handle:
                handle.write(text)
        return robot_report.build_report(path, "", controllers(*yamls), KNOWN, KNOWN_SENSORS,
                                         cache_dir=str(tmp_path / "cache"))
    return build


def test_fixed_caster_diff_drive_from_its_tags(report):
    r = report("fixed_caster.urdf")
    assert r.name == "fixed_caster" and r.source == robot("fixed_caster.urdf")
    assert r.urdf_mass == pytest.approx(1.0017) and r.loaded_mass == pytest.approx(1.0017, abs=1e-3)
    drive = r.drive
    assert drive.kind == "libgazebo_ros_diff_drive.so"
    assert drive.where == "/robot/gazebo[5]/plugin[@name='differential_drive_controller']"
    assert (drive.left, drive.right) == (["left_wheel_joint"], ["right_wheel_joint"])
    assert drive.separation == pytest.approx(0.16) and drive.separation_from == "<wheelSeparation> tag"
    assert drive.radius == pytest.approx(0.033) and drive.radius_from == "<wheelDiameter> tag / 2"
    sensors = [i for i in r.items if i.kind == "sensor"]
    assert [(s.name, s.what, s.simulated) for s in sensors] == [("imu", "imu", False)]
    assert sensors[0].where == "/robot/gazebo[@reference='imu_link']/sensor[@name='imu']"
    assert r.warnings == ["not simulated (ignored): sensor imu (type imu)"]


def test_ros_control_drive_from_the_yaml_and_measured_geometry(report):
    r = report("ros_control_4wd.urdf", "ros_control_4wd.yaml")
    drive = r.drive
    assert drive.kind == "diff_drive_controller/DiffDriveController"
    assert drive.where == "/mobile_base_controller from ros_control_4wd.yaml"
    assert drive.left == ["front_left_wheel_joint", "rear_left_wheel_joint"]
    # 0.32 m between the front joints' origins, times the YAML's wheel_separation_multiplier 1.5
    assert drive.separation == pytest.approx(0.48)
    assert drive.separation_from == ("measured: origins of front_left_wheel_joint and front_right_wheel_joint, "
                                     "x wheel_separation_multiplier 1.5")
    assert drive.radius == pytest.approx(0.06)
    assert drive.radius_from == "measured: cylinder collision of front_left_wheel_link"
    kinds = {(i.kind, i.name): i.simulated for i in r.items}
    assert kinds == {("plugin", "gazebo_ros_control"): True, ("controller", "/joint_state_controller"): True,
                     ("controller", "/mobile_base_controller"): True}
    assert r.warnings == ["/mobile_base_controller: parameters DiffDriveController does not read, ignored: "
                          "/mobile_base_controller/k_l"]
    assert r.urdf_mass == pytest.approx(6.2) and r.loaded_mass == pytest.approx(6.2, abs=1e-3)


def test_ros_control_without_its_yaml_has_no_drive(report):
    r = report("ros_control_4wd.urdf")
    assert r.drive is None
    assert any("no controller found on the parameter server under /" in w for w in r.warnings)
    assert r.warnings[-1] == robot_report.NO_DRIVE


def test_pid_robot_warns_about_its_sim_type_and_frame(report):
    r = report("pid_robot.urdf", "pid_robot.yaml")
    assert r.drive.where == "/diff_controller from pid_robot.yaml"
    assert r.drive.separation == pytest.approx(0.26)
    assert any("robotSimType 'vendor_hw_sim/VendorRobotHWSim' is not simulated" in w for w in r.warnings)
    assert any("/diff_controller/base_frame_id '/base_footprint'" in w for w in r.warnings)


def test_yaml_geometry_is_named_with_its_file(report, tmp_path):
    tree = yaml.safe_load(open(robot("pid_robot.yaml")))
    tree["diff_controller"].update(wheel_separation=0.3, wheel_radius=0.04)
    r = robot_report.build_report(robot("pid_robot.urdf"), "", [("/x/mine.yaml", tree)], KNOWN, KNOWN_SENSORS,
                                  cache_dir=str(tmp_path))
    assert r.drive.separation == pytest.approx(0.3)
    assert r.drive.separation_from == "/diff_controller/wheel_separation in mine.yaml"
    assert r.drive.radius_from == "/diff_controller/wheel_radius in mine.yaml"


def test_kobuki_skid_steer_and_planar_move(report):
    kobuki = report("kobuki_style.urdf").drive
    assert kobuki.kind == "libgazebo_ros_kobuki.so"
    assert (kobuki.separation, kobuki.radius) == (pytest.approx(0.23), pytest.approx(0.035))
    skid = report("skid_steer.urdf").drive
    assert skid.kind == "libgazebo_ros_skid_steer_drive.so"
    assert skid.right == ["front_right_wheel_joint", "rear_right_wheel_joint"]
    assert skid.separation_from == "<wheelSeparation> tag"
    planar = report("planar_robot.urdf").drive
    assert planar.kind == "libgazebo_ros_planar_move.so" and "holonomic" in planar.note


def test_geometry_measured_when_the_plugin_gives_none(report, make_urdf):
    gazebo = """<gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so">
      <leftJoint>left_wheel_joint</leftJoint><rightJoint>right_wheel_joint</rightJoint>
      <wheelTorque>5</wheelTorque><fancyTag>1</fancyTag></plugin></gazebo>"""
    r = report("measured.urdf", text=make_urdf(separation=0.3, wheel_radius=0.05, gazebo=gazebo))
    assert r.drive.separation == pytest.approx(0.3)
    assert r.drive.separation_from == "measured: origins of left_wheel_joint and right_wheel_joint"
    assert r.drive.radius == pytest.approx(0.05)
    assert r.drive.radius_from == "measured: cylinder collision of left_wheel_link"
    assert "/robot/gazebo[1]/plugin[@name='dd']: unknown tags ignored: fancyTag" in r.warnings


def test_no_drive_fixture(report):
    r = report("no_drive.urdf")
    assert r.drive is None and r.urdf_mass == pytest.approx(1.4)
    lines = report_text.format_report(r)
    assert any(line.startswith("drive: none found") for line in lines)
    # its camera has a plugin bullet_sim simulates (libgazebo_ros_camera.so); the fixed caster's bare IMU has none
    assert [(i.kind, i.name, i.simulated) for i in r.items] == [("sensor", "front_camera", True)]


def test_a_bad_model_names_file_and_element(report, make_urdf):
    bad = make_urdf(gazebo="""<gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so">
      <leftJoint>nope</leftJoint><rightJoint>right_wheel_joint</rightJoint></plugin></gazebo>""")
    with pytest.raises(ModelError) as err:
        report("bad.urdf", text=bad)
    assert "bad.urdf" in str(err.value) and "/robot/gazebo[1]/plugin[@name='dd']" in str(err.value)
    assert "'nope'" in str(err.value) and "\n" not in str(err.value)
    with pytest.raises(ModelError, match="no such file"):
        robot_report.build_report(robot("missing.urdf"))


def test_a_bad_controller_parameter_is_named(report, tmp_path):
    tree = yaml.safe_load(open(robot("pid_robot.yaml")))
    tree["diff_controller"]["wheel_radius"] = -1
    with pytest.raises(ConfigError, match="/diff_controller/wheel_radius"):
        robot_report.build_report(robot("pid_robot.urdf"), "", [("c.yaml", tree)], KNOWN, KNOWN_SENSORS,
                                  cache_dir=str(tmp_path))


@pytest.mark.parametrize("model, yamls", [("fixed_caster.urdf", ()), ("kobuki_style.urdf", ()),
                                          ("ros_control_4wd.urdf", ("ros_control_4wd.yaml",)),
                                          ("pid_robot.urdf", ("pid_robot.yaml",)), ("skid_steer.urdf", ()),
                                          ("no_drive.urdf", ())])
def test_the_report_fits_one_screen(report, model, yamls):
    lines = report_text.format_report(report(model, *yamls))
    assert len(lines) + 6 <= 40  # the drive test adds at most six lines
    assert lines[0].startswith("model: ") and lines[1].startswith("mass: URDF ")


def test_mass_difference_is_shown():
    r = robot_report.Report("/m.urdf", "m", 1.0, 2.0)
    assert "differs by +1.0000 kg" in report_text.format_report(r)[1]
    r.loaded_mass = 1.0000001
    assert "differs" not in report_text.format_report(r)[1]


def test_warnings_are_capped():
    r = robot_report.Report("/m.urdf", "m", 1.0, 1.0, warnings=[f"w{i}" for i in range(25)])
    lines = report_text.format_report(r)
    assert "  ... and 15 more" in lines and "warnings bullet_sim logs at start: 25" in lines


def test_merge_params_updates_key_by_key_as_rosparam_load():
    tree = robot_report.merge_params({}, "/", {"c": {"type": "a/B", "x": 1, "limits": {"v": 1}}})
    robot_report.merge_params(tree, "/", {"c": {"x": 2, "limits": {"a": 3}}})
    assert tree == {"c": {"type": "a/B", "x": 2, "limits": {"v": 1, "a": 3}}}
    robot_report.merge_params(tree, "/robot1/", {"d": {"type": "a/B"}})
    assert tree["robot1"] == {"d": {"type": "a/B"}}


def test_find_controllers_looks_under_the_namespace_then_everywhere():
    tree = {"robot1": {"c": {"type": "a/B"}}, "gazebo_ros_control": {"pid_gains": {"type": "x/Y"}},
            "d": {"type": "c/D", "nested": {"type": "e/F"}}}
    assert set(robot_report.find_controllers(tree, "/")) == {"/robot1/c", "/d"}
    assert set(robot_report.find_controllers(tree, "/robot1")) == {"/robot1/c"}
    assert set(robot_report.find_controllers(tree, "/elsewhere")) == {"/robot1/c", "/d"}


# -------------------------------------------------------------------------------------------- drive_check

def test_a_good_straight_run_passes_on_odometry_and_truth():
    s = drive_check.straight((0, 0, 0), (0.79, 0.01, 0.01), (1, 1, 0), (1.8, 1.0, 0.0))
    assert s.passed and s.odom_distance == pytest.approx(0.7901, abs=1e-3) and s.truth_distance == pytest.approx(0.8)


@pytest.mark.parametrize("end_odom, end_truth, culprit", [
    ((0.60, 0, 0), (0.8, 0, 0), "odometry: drove 0.600 m"),
    ((0.8, 0, 0), (0.95, 0, 0), "ground truth: drove 0.950 m"),
    ((0.8, 0, 0.2), (0.8, 0, 0), "odometry: heading changed 0.200 rad"),
])
def test_a_bad_straight_run_fails_naming_the_source(end_odom, end_truth, culprit):
    s = drive_check.straight((0, 0, 0), end_odom, (0, 0, 0), end_truth)
    assert not s.passed and any(f.startswith(culprit) for f in s.failures)


def test_turn_judged_on_odometry_across_the_wrap():
    # from 2.5 rad to -2.283 (= 2.5 + 1.5 - 2 pi): 1.5 rad turned through +-pi, 25 % short of 2.0: fails
    t = drive_check.turn((0, 0, 2.5), (0, 0, 2.5 + 1.5 - 2 * 3.141592653589793), (0, 0, 0), (0, 0, 0.1))
    assert t.odom_yaw == pytest.approx(1.5) and not t.passed
    t = drive_check.turn((0, 0, 2.5), (0, 0, 2.5 + 1.9 - 2 * 3.141592653589793), (0, 0, 0), (0, 0, 1.9))
    assert t.passed


def test_turn_judged_on_the_body_whatever_the_odometry_says():
    # The encoders read a perfect turn; the body turned 0.1 rad and slid 0.15 m: both are failures.
    t = drive_check.turn((0, 0, 0), (0, 0, 2.0), (0, 0, 0), (0.15, 0, 0.1))
    assert [f.split(":")[0] for f in t.failures] == ["ground truth", "ground truth"]
    # A skid-steer body turning at 0.75 of the command passes when the caller allows it, not by default.
    assert drive_check.turn((0, 0, 0), (0, 0, 2.0), (0, 0, 0), (0, 0, 1.5), truth_fraction=0.7).passed
    assert drive_check.turn((0, 0, 0), (0, 0, 2.0), (0, 0, 0), (0, 0, 0.9)).failures[0].startswith("ground truth")
    assert not drive_check.turn((0, 0, 0), (0, 0, 2.0), (0, 0, 0), (0, 0, 2.6)).passed  # spun too far


def samples(heights, tilt=0.0, dt=0.1, x=0.0):
    return [drive_check.BodySample(i * dt, x, 0.0, z, tilt, 0.0, 0.0) for i, z in enumerate(heights)]


def test_a_body_resting_upright_at_its_height_passes():
    r = drive_check.rest(samples([0.0635, 0.0636, 0.0635]), expected=0.0635)
    assert r.passed and r.height == pytest.approx(0.0635, abs=1e-4) and r.tilt == 0.0


@pytest.mark.parametrize("body, culprit", [
    (samples([6.1, 6.0, 5.9]), "rests at height 6.000 m"),  # thrown into the air at spawn
    (samples([-0.2, -0.21, -0.2]), "rests at height -0.200 m"),  # sunk into the ground
    (samples([0.0635] * 3, tilt=1.5), "tilted 1.500 rad at rest"),  # on its side
    (samples([0.06, 0.09, 0.06]), "height varied 0.030 m"),  # bouncing
])
def test_a_body_flying_sunk_tipped_or_bouncing_fails_at_rest(body, culprit):
    r = drive_check.rest(body, expected=0.0635)
    assert not r.passed and any(culprit in f for f in r.failures), r.failures


def test_a_body_sliding_at_rest_fails():
    body = [drive_check.BodySample(t, 0.1 * t, 0.0, 0.0635, 0.0, 0.0, 0.0) for t in (0.0, 0.5, 1.0)]
    assert any("moved 0.100 m" in f for f in drive_check.rest(body, 0.0635).failures)


def test_ride_holds_the_body_to_its_rest_height_and_upright():
    assert drive_check.ride(samples([0.064, 0.070, 0.060]), 0.0635).passed
    sinks = drive_check.ride(samples([0.06, -0.2]), 0.0635)
    assert not sinks.passed and "height -0.200..0.060 m" in sinks.failures[0]
    tips = drive_check.ride(samples([0.0635], tilt=0.3), 0.0635)
    assert "tilted 0.300 rad while driving" in tips.failures[0]
    assert not drive_check.ride([], 0.0635).passed


def test_body_sample_from_a_quaternion():
    import math
    s = drive_check.body_sample(1.0, (1, 2, 3), (math.sin(0.25), 0, 0, math.cos(0.25)))  # roll 0.5
    assert (s.roll, s.pitch, s.yaw) == pytest.approx((0.5, 0.0, 0.0)) and s.tilt == pytest.approx(0.5)
    s = drive_check.body_sample(1.0, (1, 2, 3), (0, math.sin(0.15), 0, math.cos(0.15)))  # pitch 0.3
    assert (s.roll, s.pitch) == pytest.approx((0.0, 0.3)) and s.tilt == pytest.approx(0.3)
