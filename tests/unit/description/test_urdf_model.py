"""description.urdf_model: parsing the URDF (seed xacro and small hand-written ones), errors naming file/element,
wheel geometry, and ros_control SimpleTransmission arithmetic."""
import math

import pytest

from diffbot_sim.description.urdf_model import Transmission, parse_urdf
from diffbot_sim.errors import ModelError

# ------------------------------------------------------------------------------------------ the seed robot

def test_seed_has_four_movable_joints(seed_model):
    movable = sorted(name for name, joint in seed_model.joints.items() if joint.movable)
    assert movable == ["back_caster_joint", "front_caster_joint", "left_wheel_joint", "right_wheel_joint"]
    assert seed_model.joints["base_joint"].type == "fixed"
    assert seed_model.root == "base_footprint"
    assert seed_model.name == "diffbot"


def test_seed_wheel_joints_limits_and_axes(seed_model):
    left = seed_model.joints["left_wheel_joint"]
    right = seed_model.joints["right_wheel_joint"]
    assert left.axis == (0.0, 1.0, 0.0) and right.axis == (0.0, 1.0, 0.0)
    assert left.xyz == pytest.approx((0.0, 0.1, 0.032 - 0.076))
    assert right.xyz == pytest.approx((0.0, -0.1, 0.032 - 0.076))
    assert left.effort_limit == 30.0 and left.velocity_limit == 40.0
    # casters give no <limit>
    assert seed_model.joints["front_caster_joint"].velocity_limit is None


def test_seed_has_two_velocity_transmissions_with_reduction_one(seed_model):
    by_joint = {t.joint: t for t in seed_model.transmissions}
    assert sorted(by_joint) == ["left_wheel_joint", "right_wheel_joint"]
    for trans in by_joint.values():
        assert trans.interface == "VelocityJointInterface"
        assert trans.reduction == 1.0
        assert trans.offset == 0.0
        assert trans.type == "transmission_interface/SimpleTransmission"
    assert by_joint["left_wheel_joint"].actuator == "left_wheel_joint_motor"
    assert by_joint["left_wheel_joint"].name == "left_wheel_joint_trans"


def test_seed_wheel_radius_and_separation_from_urdf(seed_model):
    assert seed_model.wheel_radius("left_wheel_joint", "test") == pytest.approx(0.032)
    assert seed_model.wheel_radius("right_wheel_joint", "test") == pytest.approx(0.032)
    assert seed_model.wheel_separation("left_wheel_joint", "right_wheel_joint", "test") == pytest.approx(0.2)


def test_seed_total_mass(seed_model):
    # base 1.0 + 2 wheels * 0.2 + 2 casters * 0.02; base_footprint has no <inertial>
    assert seed_model.total_mass() == pytest.approx(1.44, abs=1e-9)
    assert seed_model.links["base_footprint"].mass is None
    assert seed_model.links["base_link"].mass == pytest.approx(1.0)


def test_seed_surface_tags(seed_model):
    assert seed_model.surface("left_wheel_link") == {"mu1": 1.0, "mu2": 1.0}
    assert seed_model.surface("front_caster_link") == {"mu1": 0.0, "mu2": 0.0}
    assert seed_model.surface("base_link") == {}


def test_surface_numbers_are_read_as_gazebos_urdf_reader_reads_them(parse, make_urdf):
    # sdformat's URDF reader takes <mu1> with std::stod: the leading number; one warning names the tag.
    model = parse(make_urdf(gazebo='<gazebo reference="left_wheel_link"><mu1>0.5abc</mu1><mu2>0.4</mu2>'
                                   '<kp>none</kp></gazebo>'))
    assert model.surface("left_wheel_link") == {"mu1": 0.5, "mu2": 0.4}
    assert [w for w in model.warnings if "mu1" in w] == [
        "test.urdf: /robot/gazebo[@reference='left_wheel_link']/mu1: took 0.5 from '0.5abc', as Gazebo's SDF "
        "reader (std::stod) does"]
    assert len([w for w in model.warnings if "/kp" in w and "Gazebo's default applies" in w]) == 1


def test_a_gazebo_block_naming_nothing_is_dropped_with_one_warning(parse, make_urdf):
    model = parse(make_urdf(gazebo='<gazebo reference="imu_link"><sensor type="imu" name="imu"/></gazebo>'))
    assert all(block.reference != "imu_link" for block in model.gazebo)
    assert len([w for w in model.warnings if "gazebo[@reference='imu_link']" in w and "ignored" in w]) == 1


def test_small_robot_geometry_differs_from_seed(parse, make_urdf):
    model = parse(make_urdf(separation=0.34, wheel_radius=0.045))
    assert model.wheel_radius("left_wheel_joint", "x") == pytest.approx(0.045)
    assert model.wheel_separation("left_wheel_joint", "right_wheel_joint", "x") == pytest.approx(0.34)
    assert model.total_mass() == pytest.approx(2.65)


def test_sphere_wheel_gives_radius(parse, make_urdf):
    model = parse(make_urdf(wheel_geometry='<sphere radius="0.07"/>'))
    assert model.wheel_radius("right_wheel_joint", "x") == pytest.approx(0.07)


# ------------------------------------------------------------------------------------------------ errors

def _error(text, source="bad.urdf"):
    with pytest.raises(ModelError) as info:
        parse_urdf(text, source)
    return info.value


def test_malformed_xml_names_the_source():
    err = _error("<robot name='r'><link name='a'></robot>", "broken.urdf")
    assert str(err).startswith("broken.urdf: ")
    assert "malformed XML" in str(err)
    assert err.source == "broken.urdf"


def test_root_element_must_be_robot():
    err = _error("<sdf><link name='a'/></sdf>")
    assert "/sdf" in str(err) and "robot" in str(err)


def test_transmission_naming_missing_joint(make_urdf, make_transmission):
    text = make_urdf(transmissions=make_transmission("left_wheel_joint") + make_transmission("ghost_joint"))
    err = _error(text, "robot.urdf")
    message = str(err)
    assert "ghost_joint" in message
    assert "transmission[@name=" in message
    assert "/robot/transmission[@name='ghost_joint_trans']/joint[@name='ghost_joint']" in message
    assert message.startswith("robot.urdf: ")
    # it lists what the model does have, so the user sees the typo
    assert "left_wheel_joint" in message


def test_unknown_hardware_interface_is_kept_apart(parse, make_urdf):
    # DefaultRobotHWSim skips it with a warning (plugins/ros_control/hardware.py); the robot loads
    model = parse(make_urdf(left_interface="hardware_interface/FooJointInterface"))
    assert [t.joint for t in model.transmissions] == ["right_wheel_joint"]
    (other,) = model.other_transmissions
    assert (other.name, other.joints, other.interfaces) == ("left_wheel_joint_trans", ["left_wheel_joint"],
                                                            ["hardware_interface/FooJointInterface"])
    assert "'hardware_interface/FooJointInterface' is not one it simulates" in other.warning


@pytest.mark.parametrize("interface", ["hardware_interface/EffortJointInterface", "EffortJointInterface"])
def test_interface_with_and_without_prefix(parse, make_urdf, interface):
    model = parse(make_urdf(left_interface=interface))
    by_joint = {t.joint: t for t in model.transmissions}
    assert by_joint["left_wheel_joint"].interface == "EffortJointInterface"
    assert by_joint["right_wheel_joint"].interface == "VelocityJointInterface"


def test_interface_only_on_actuator_is_accepted(parse, make_urdf):
    trans = """
  <transmission name="t">
    <type>transmission_interface/SimpleTransmission</type>
    <joint name="left_wheel_joint"/>
    <actuator name="m"><hardwareInterface>PositionJointInterface</hardwareInterface></actuator>
  </transmission>"""
    model = parse(make_urdf(transmissions=trans))
    assert model.transmissions[0].interface == "PositionJointInterface"
    assert model.transmissions[0].reduction == 1.0  # no mechanicalReduction: 1


def test_mechanical_reduction_zero(make_urdf, make_transmission):
    text = make_urdf(transmissions=make_transmission("left_wheel_joint", reduction="0"))
    err = _error(text)
    assert "mechanicalReduction" in str(err)
    assert "transmission[@name='left_wheel_joint_trans']" in str(err)


def test_mechanical_reduction_negative_is_kept(parse, make_urdf, make_transmission):
    model = parse(make_urdf(transmissions=make_transmission("left_wheel_joint", reduction="-2.5")))
    assert model.transmissions[0].reduction == -2.5


def test_non_numeric_mass(make_urdf):
    err = _error(make_urdf(base_mass="heavy"))
    assert "'heavy' is not a number" in str(err)
    assert "/robot/link[@name='base_link']/inertial/mass[@value]" in str(err)


def test_negative_mass(make_urdf):
    err = _error(make_urdf(base_mass="-1"))
    assert "link[@name='base_link']" in str(err) and ">= 0" in str(err)


def test_joint_naming_missing_link(make_urdf):
    text = make_urdf().replace('<child link="caster_link"/>', '<child link="castor_link"/>')
    err = _error(text)
    assert "castor_link" in str(err)
    assert "/robot/joint[@name='caster_joint']/child" in str(err)


def test_two_roots_rejected(make_urdf):
    err = _error(make_urdf(extra='<link name="floating_link"/>'))
    assert "root" in str(err) and "floating_link" in str(err)


def test_box_wheel_has_no_radius(parse, make_urdf):
    model = parse(make_urdf(wheel_geometry='<box size="0.1 0.03 0.1"/>'), "boxy.urdf")
    with pytest.raises(ModelError) as info:
        model.wheel_radius("left_wheel_joint", "/robot/gazebo[1]/plugin")
    assert "left_wheel_link" in str(info.value)
    assert "cylinder or sphere" in str(info.value)
    assert str(info.value).startswith("boxy.urdf: ")


def test_zero_radius_cylinder_wheel(parse, make_urdf):
    model = parse(make_urdf(wheel_radius=0))
    with pytest.raises(ModelError) as info:
        model.wheel_radius("right_wheel_joint", "x")
    assert "/robot/link[@name='right_wheel_link']/collision/geometry/cylinder" in str(info.value)
    assert "> 0" in str(info.value)


def test_non_numeric_cylinder_radius(make_urdf):
    err = _error(make_urdf(wheel_geometry='<cylinder radius="big" length="0.03"/>'))
    assert "geometry/cylinder[@radius]" in str(err)


def test_model_joint_lookup_names_referrer(seed_model):
    with pytest.raises(ModelError) as info:
        seed_model.joint("nope_joint", "/robot/gazebo[5]/plugin")
    assert "nope_joint" in str(info.value)
    assert info.value.element == "/robot/gazebo[5]/plugin"


# ------------------------------------------------------------------------------------- transmission math

def _trans(n, offset=0.0):
    return Transmission("t", "transmission_interface/SimpleTransmission", "j", "VelocityJointInterface",
                        "m", n, offset)


def test_velocity_divides_by_reduction():
    trans = _trans(4.0)
    assert trans.actuator_to_joint_velocity(10.0) == pytest.approx(2.5)
    assert trans.joint_to_actuator_velocity(2.5) == pytest.approx(10.0)


def test_effort_multiplies_by_reduction():
    trans = _trans(4.0)
    assert trans.actuator_to_joint_effort(0.5) == pytest.approx(2.0)
    assert trans.joint_to_actuator_effort(2.0) == pytest.approx(0.5)


def test_position_with_offset():
    trans = _trans(2.0, offset=0.3)
    assert trans.actuator_to_joint_position(4.0) == pytest.approx(2.3)
    assert trans.joint_to_actuator_position(2.3) == pytest.approx(4.0)


def test_negative_reduction_flips_direction():
    trans = _trans(-2.0)
    assert trans.actuator_to_joint_velocity(6.0) == pytest.approx(-3.0)
    assert trans.actuator_to_joint_effort(1.5) == pytest.approx(-3.0)
    assert trans.actuator_to_joint_position(1.0) == pytest.approx(-0.5)


@pytest.mark.parametrize("n, offset", [(1.0, 0.0), (3.5, -0.2), (-7.0, 1.1), (0.25, 0.0)])
def test_transmission_round_trips(n, offset):
    trans = _trans(n, offset)
    for value in (-3.0, 0.0, 0.7, 12.5):
        assert trans.joint_to_actuator_velocity(trans.actuator_to_joint_velocity(value)) == pytest.approx(value)
        assert trans.joint_to_actuator_effort(trans.actuator_to_joint_effort(value)) == pytest.approx(value)
        assert trans.joint_to_actuator_position(trans.actuator_to_joint_position(value)) == pytest.approx(value)
    # power is conserved: joint effort * joint velocity == actuator effort * actuator velocity
    assert (trans.actuator_to_joint_effort(2.0) * trans.actuator_to_joint_velocity(3.0)
            == pytest.approx(2.0 * 3.0))
    assert math.isfinite(trans.actuator_to_joint_velocity(1.0))


@pytest.mark.parametrize("extra, culprit", [
    ('<link name="a"/>', "/robot/link[@name='a']"),
    ('<link name="c"/><joint name="j" type="fixed"><parent link="a"/><child link="c"/></joint>',
     "/robot/joint[@name='j']"),
])
def test_a_duplicate_link_or_joint_name_is_refused_by_name(extra, culprit):
    """urdfdom refuses a second link or joint of one name (PyBullet would crash on it): one line naming it."""
    text = ('<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="fixed"><parent link="a"/>'
            f'<child link="b"/></joint>{extra}</robot>')
    with pytest.raises(ModelError) as err:
        parse_urdf(text, "dup.urdf")
    assert "not unique" in str(err.value) and culprit in str(err.value) and "dup.urdf" in str(err.value)
