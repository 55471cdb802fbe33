"""tests/data/robots/mistakes.urdf, loaded the way bullet_sim loads a model (without ROS): every mistake found in
published robots (listed in its header) is survived, those Gazebo warns about with exactly one line naming it, the
ones Gazebo reads silently with none, and PyBullet loads the result with the URDF's mass."""
import os

import pybullet
import pytest

from diffbot_sim import config
from diffbot_sim.description import mesh_formats, meshes
from diffbot_sim.description.model_files import load_file
from diffbot_sim.description.plugin_tags import read_plugins
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.physics import World
from diffbot_sim.plugins import registry
from diffbot_sim.plugins.base import RobotContext

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
MISTAKES = os.path.join(ROOT, "tests", "data", "robots", "mistakes.urdf")
URDF_MASS = 0.8 + 2 * 0.1 + 0.0017 + 0.05  # base, wheels, caster, laser (the fixture's comment)


def _no_package(name):
    raise LookupError(name)


class Loaded:
    """What bullet_sim's _build_robot and diff_drive.create learn from the model, before any ROS call."""

    def __init__(self, cache_dir):
        self.source_text = load_file(MISTAKES)
        self.model = parse_urdf(self.source_text, MISTAKES)
        self.text, self.mesh_notes = meshes.prepare_meshes(self.source_text, MISTAKES, os.path.dirname(MISTAKES),
                                                           cache_dir, _no_package)
        self.found = read_plugins(self.model, known=registry.KNOWN)
        for trans in self.model.transmissions:
            self.model.joint(trans.joint, f"/robot/transmission[@name='{trans.name}']")
        self.drive_notes = []
        self.drive = config.gazebo_diff_drive_config(self.model, self.found.diff_drive, {}, self.drive_notes)
        ctx = RobotContext(None, config.SimConfig(), config.RobotSpec(), self.model, None, {}, None, "~")
        self.drive.odometry_frame = ctx.clean_frame(self.drive.odometry_frame, self.found.diff_drive.path)
        self.drive.robot_base_frame = ctx.clean_frame(self.drive.robot_base_frame, self.found.diff_drive.path)
        self.frame_notes = ctx.warnings


@pytest.fixture(scope="module")
def loaded(tmp_path_factory):
    return Loaded(str(tmp_path_factory.mktemp("mesh_cache")))


def _matching(lines, words):
    return [line for line in lines if all(w in line for w in words)]


# mistake -> (which list its warning lands in, words the one line must contain)
WARNED = {
    "gazebo reference naming nothing": ("model", ["/robot/gazebo[@reference='caster_{side}_1_joint']",
                                                  "names no link or joint"]),
    "a sensor block for a commented-out link": ("model", ["/robot/gazebo[@reference='imu_link']",
                                                          "names no link or joint", "ignored, as in Gazebo"]),
    "two hardwareInterface entries, left": ("model", ["transmission[@name='left_wheel_trans']",
                                                      "joint[@name='left_wheel_joint']", "2 hardware interfaces",
                                                      "VelocityJointInterface"]),
    "two hardwareInterface entries, right": ("model", ["transmission[@name='right_wheel_trans']",
                                                       "joint[@name='right_wheel_joint']", "2 hardware interfaces"]),
    "two <mesh> in one <geometry>, the second scale=''": ("mesh", ["link 'base_link'", "collision",
                                                                   "more than one shape",
                                                                   "meshes/mistakes_base.stl"]),
    "missing visual mesh file": ("mesh", ["link 'base_link'", "visual", "meshes/mistakes_cover.stl", "not found"]),
    "odometrySource ENCODER": ("drive", ["<odometrySource>", "'ENCODER'", "using world"]),
    "leading slash in odometryFrame": ("frames", ["'/odom'", "leading slash", "using 'odom'"]),
    "leading slash in robotBaseFrame": ("frames", ["'/base_footprint'", "leading slash", "using 'base_footprint'"]),
    "contact sensor without a plugin": ("unsupported", ["sensor bumper", "type contact"]),
    "ray sensor without a plugin": ("unsupported", ["sensor lds_lfcd_sensor", "type ray"]),
}


def _lists(loaded):
    return {"model": loaded.model.warnings, "mesh": loaded.mesh_notes, "drive": loaded.drive_notes,
            "frames": loaded.frame_notes, "unsupported": loaded.found.unsupported}


@pytest.mark.parametrize("mistake", sorted(WARNED))
def test_each_warned_mistake_gives_exactly_one_line_naming_it(loaded, mistake):
    where, words = WARNED[mistake]
    lines = _lists(loaded)[where]
    assert len(_matching(lines, words)) == 1, f"{mistake}: {lines}"


def test_no_other_warnings(loaded):
    """Every line is one of the mistakes above: the silently-read ones (link type, joint_properties,
    k_velocity, the transmission's type attribute, '/../', ignored plugin tags) add none."""
    lists = _lists(loaded)
    for where, lines in lists.items():
        expected = [words for kind, words in WARNED.values() if kind == where]
        assert len(lines) == len(expected), (where, lines)
        for line in lines:
            assert any(all(w in line for w in words) for words in expected), (where, line)
    assert loaded.found.warnings == []
    assert loaded.found.diff_drive.unknown_tags == []  # legacyMode, rosDebugLevel, publishWheelTF: accepted


def test_silent_mistakes_are_read_as_urdfdom_and_ros_control_read_them(loaded):
    model = loaded.model
    assert {"left_wheel_link", "right_wheel_link"} <= set(model.links)  # <link type="wheel">
    for side in ("left", "right"):
        joint = model.joints[f"{side}_wheel_joint"]  # <joint_properties>, k_velocity in <limit>
        assert (joint.type, joint.effort_limit, joint.velocity_limit) == ("continuous", 10.0, 20.0)
    for trans in model.transmissions:  # type= attribute and <type>: the element wins; first interface used
        assert trans.type == "transmission_interface/SimpleTransmission"
        assert trans.interface == "VelocityJointInterface"
    assert model.total_mass() == pytest.approx(URDF_MASS, abs=1e-12)


def test_meshes_first_shape_kept_and_dotdot_path_resolved(loaded):
    import xml.etree.ElementTree as ET

    base = {el.get("name"): el for el in ET.fromstring(loaded.text).findall("link")}["base_link"]
    visuals, collisions = base.findall("visual"), base.findall("collision")
    assert len(visuals) == 1 and len(collisions) == 1  # the missing cover's <visual> is dropped
    for element in visuals + collisions:
        shapes = list(element.find("geometry"))
        assert len(shapes) == 1 and shapes[0].tag == "mesh"
        assert shapes[0].get("filename").endswith(".obj") and os.path.isfile(shapes[0].get("filename"))
        assert shapes[0].get("scale") == "0.001 0.001 0.001"


def test_a_plugin_naming_a_missing_link_is_not_loaded_with_one_warning(loaded):
    from types import SimpleNamespace

    class NoImuLink:
        def link_motion(self, name):
            raise KeyError(name)

    ctx = SimpleNamespace(cfg=config.SimConfig(), model=loaded.model, robot=NoImuLink(), warnings=[])
    (hector,) = [p for p in loaded.found.others if p.filename == "libhector_gazebo_ros_imu.so"]
    plugins = []
    registry._add(ctx, plugins, registry.MODEL_PLUGINS[hector.filename], hector.element, hector.path, {})
    assert plugins == []
    assert len(ctx.warnings) == 1 and "plugin[@name='imu_controller']" in ctx.warnings[0] \
        and "IMU link 'imu_link' is not a link of the model; the plugin is not loaded, as in Gazebo" \
        in ctx.warnings[0], ctx.warnings
    assert not [s for s in loaded.found.sensors if s.link == "imu_link"]  # its sensor block went with it


def test_plugin_settings_survive_the_mistakes(loaded):
    drive = loaded.drive
    assert (drive.left_joints, drive.right_joints) == (["left_wheel_joint"], ["right_wheel_joint"])
    assert (drive.odometry_frame, drive.robot_base_frame) == ("odom", "base_footprint")
    assert drive.odometry_source == "world"
    assert drive.publish_odom and drive.publish_odom_tf  # publishTf true keeps odom and its TF
    assert (drive.wheel_separation, drive.wheel_diameter, drive.max_wheel_torque) == (0.16, 0.066, 1.0)


def test_pybullet_loads_it_with_the_urdf_mass_and_the_mesh_box(loaded):
    world = World(1.0 / 240.0)
    try:
        robot = world.load_robot(loaded.text, loaded.model)
        assert robot.total_mass() == pytest.approx(URDF_MASS, abs=1e-5)
        assert set(robot.joint_index) == {"left_wheel_joint", "right_wheel_joint"}
        index = robot.link_carrier("base_link")  # lumped into the inertia-less root, as Gazebo lumps it
        (shape,) = pybullet.getCollisionShapeData(robot.body, index, physicsClientId=world.client)
        assert shape[2] == pybullet.GEOM_MESH and shape[3] == pytest.approx((0.001, 0.001, 0.001))
        vertices, _ = mesh_formats.read_obj(shape[4].decode())  # the cached .obj, in the STL's millimetres
        assert vertices.max(axis=0) - vertices.min(axis=0) == pytest.approx([200.0, 150.0, 40.0])
        # The shape sits at base_link's origin, unturned: PyBullet stores it relative to the carrier's inertial
        # frame (turned into the principal axes of base_link + the lumped laser), so compose the two; base_link
        # sits at its fixed offset in the carrier's frame.
        dyn = pybullet.getDynamicsInfo(robot.body, index, physicsClientId=world.client)
        position, orientation = pybullet.multiplyTransforms(dyn[3], dyn[4], shape[5], shape[6])
        assert position == pytest.approx(robot.frames["base_link"][1], abs=1e-6)
        assert abs(orientation[3]) == pytest.approx(1.0, abs=1e-6)
    finally:
        world.close()
