"""world_api: gazebo_ros's world-API semantics (frames, twists, model XML, wrench timing), no ROS, no PyBullet.

Geometry is checked against numbers worked out by hand; XML edits against the exact expected text (every
byte not edited must survive); wrench timing step by step with sim times built as the simulator builds them
(``steps * dt``).
"""
import math
import random
import xml.etree.ElementTree as ET

import pytest

from diffbot_sim.errors import ModelError
from diffbot_sim.gazebo import model_xml, world_api as api
from diffbot_sim.gazebo.ignition import IDENTITY
from diffbot_sim.transforms import compose, quaternion_rpy, rpy_quaternion

S = math.sqrt(0.5)
YAW90 = (0.0, 0.0, S, S)
AT_REST = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


def close(a, b, tol=1e-9):
    """Nested tuples of numbers equal within ``tol``."""
    if isinstance(a, (tuple, list)):
        return len(a) == len(b) and all(close(x, y, tol) for x, y in zip(a, b))
    return abs(a - b) <= tol


def same_rotation(q1, q2, tol=1e-9):
    return close(q1, q2, tol) or close(q1, tuple(-c for c in q2), tol)


def random_pose(rng):
    q = tuple(rng.uniform(-1, 1) for _ in range(4))
    n = math.sqrt(sum(c * c for c in q))
    return tuple(rng.uniform(-5, 5) for _ in range(3)), tuple(c / n for c in q)


def random_twist(rng):
    return tuple(rng.uniform(-2, 2) for _ in range(3)), tuple(rng.uniform(-2, 2) for _ in range(3))


# ------------------------------------------------------------------------------------------ frames

@pytest.mark.parametrize("name", ["", "world", "map", "/map"])
def test_world_frame_names(name):
    assert api.is_world_frame(name)


@pytest.mark.parametrize("name", ["World", "/world", "map2", "odom", "robot", "robot::base_link"])
def test_other_names_are_not_world(name):
    assert not api.is_world_frame(name)


def test_split_link_name():
    assert api.split_link_name("robot::base_link") == ("robot", "base_link")
    assert api.split_link_name("outer::inner::wheel") == ("outer::inner", "wheel")


@pytest.mark.parametrize("name", ["base_link", "", "::link", "model::", "a::::b"])
def test_split_link_name_refuses_unscoped_or_empty_parts(name):
    with pytest.raises(ValueError, match="not a scoped link name"):
        api.split_link_name(name)


def test_find_entity_takes_scoped_or_plain_names_first_match_wins():
    names = ["ground::link", "robot", "robot::base_link", "robot::wheel", "box::base_link"]
    assert api.find_entity("box::base_link", names) == "box::base_link"
    assert api.find_entity("base_link", names) == "robot::base_link"  # depth-first: the first one
    assert api.find_entity("robot", names) == "robot"
    assert api.find_entity("nothing", names) is None


# ------------------------------------------------------------------------------------------ states

FRAME = ((1.0, 2.0, 0.0), YAW90)  # at (1, 2, 0), turned 90 degrees about z: its x is the world's y


def test_relative_pose_in_a_turned_frame():
    pose, _ = api.relative_state(((1.0, 3.0, 0.0), (0, 0, 0, 1)), AT_REST, FRAME, AT_REST)
    assert close(pose[0], (1.0, 0.0, 0.0))
    assert same_rotation(pose[1], (0.0, 0.0, -S, S))  # the world's axes are -90 degrees from the frame's


def test_relative_twist_is_rotated_into_the_frame():
    _, (v, w) = api.relative_state(((1.0, 3.0, 0.0), (0, 0, 0, 1)), ((0.0, 1.0, 0.0), (0.0, 0.0, 0.5)),
                                   FRAME, AT_REST)
    assert close(v, (1.0, 0.0, 0.0))  # world +y is the frame's +x
    assert close(w, (0.0, 0.0, 0.5))


def test_relative_twist_subtracts_the_frame_velocity():
    _, (v, w) = api.relative_state(((1.0, 3.0, 0.0), (0, 0, 0, 1)), ((0.0, 1.0, 0.0), (0.0, 0.0, 0.0)),
                                   FRAME, ((0.0, 1.0, 0.0), (0.0, 0.0, 0.0)))
    assert close(v, (0.0, 0.0, 0.0))


def test_relative_twist_has_no_transport_term_for_a_spinning_frame():
    """gazebo_ros subtracts velocities and rotates, nothing more: a point at rest seen from a spinning frame
    reports zero linear velocity (a rigid transform would give -w x r)."""
    _, (v, w) = api.relative_state(((1.0, 3.0, 0.0), (0, 0, 0, 1)), AT_REST, FRAME,
                                   ((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    assert close(v, (0.0, 0.0, 0.0))
    assert close(w, (0.0, 0.0, -1.0))


def test_world_state_inverse_places_and_turns():
    pose, (v, w) = api.world_state(((1.0, 0.0, 0.0), (0, 0, 0, 1)), ((1.0, 0.0, 0.0), (0.0, 0.0, 0.5)),
                                   FRAME, ((0.0, 0.0, 1.0), (0.0, 0.0, 0.25)))
    assert close(pose[0], (1.0, 3.0, 0.0))
    assert same_rotation(pose[1], YAW90)
    assert close(v, (0.0, 1.0, 1.0))  # rotated, plus the frame's own velocity
    assert close(w, (0.0, 0.0, 0.75))


def test_round_trips_are_identity():
    rng = random.Random(7)
    for _ in range(50):
        pose, twist, fpose, ftwist = random_pose(rng), random_twist(rng), random_pose(rng), random_twist(rng)
        rel_pose, rel_twist = api.relative_state(pose, twist, fpose, ftwist)
        back_pose, back_twist = api.world_state(rel_pose, rel_twist, fpose, ftwist)
        assert close(back_pose[0], pose[0]) and same_rotation(back_pose[1], pose[1])
        assert close(back_twist, twist)
        abs_pose, abs_twist = api.world_state(pose, twist, fpose, ftwist)
        again_pose, again_twist = api.relative_state(abs_pose, abs_twist, fpose, ftwist)
        assert close(again_pose[0], pose[0]) and same_rotation(again_pose[1], pose[1])
        assert close(again_twist, twist)


def test_set_model_state_convention_rotates_but_ignores_frame_velocity():
    _, (v, w) = api.world_state(((0.0, 0.0, 0.0), (0, 0, 0, 1)), ((1.0, 0.0, 0.0), (0.0, 0.0, 0.5)),
                                FRAME, ((5.0, 5.0, 5.0), (1.0, 1.0, 1.0)), convention=api.SET_MODEL_STATE)
    assert close(v, (0.0, 1.0, 0.0))
    assert close(w, (0.0, 0.0, 0.5))


def test_set_link_state_convention_subtracts_unrotated():
    pose, (v, w) = api.world_state(((1.0, 0.0, 0.0), (0, 0, 0, 1)), ((1.0, 0.0, 0.0), (0.0, 0.0, 0.5)),
                                   FRAME, ((0.5, 0.0, 0.0), (0.0, 0.0, 0.25)), convention=api.SET_LINK_STATE)
    assert close(pose[0], (1.0, 3.0, 0.0))  # the pose is composed as in every convention
    assert close(v, (0.5, 0.0, 0.0))
    assert close(w, (0.0, 0.0, 0.25))


def test_world_state_unknown_convention():
    with pytest.raises(ValueError, match="convention"):
        api.world_state(IDENTITY, AT_REST, FRAME, AT_REST, convention="tf")


# ------------------------------------------------------------------------------------------ checks

@pytest.mark.parametrize("index,field", [(0, "position.x"), (1, "position.y"), (2, "position.z")])
def test_check_pose_names_a_nan_position(index, field):
    position = [0.0, 0.0, 0.0]
    position[index] = math.nan
    with pytest.raises(ValueError, match=rf"^initial_pose\.{field} is nan$"):
        api.check_pose((tuple(position), (0, 0, 0, 1)), "initial_pose")


def test_check_pose_names_an_infinite_orientation():
    with pytest.raises(ValueError, match=r"^pose\.orientation\.w is -inf$"):
        api.check_pose(((0, 0, 0), (0, 0, 0, -math.inf)), "pose")


def test_check_pose_zero_quaternion_is_identity_as_ignition_normalize_makes_it():
    assert api.check_pose(((1, 2, 3), (0, 0, 0, 0)), "pose") == ((1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0))
    assert api.check_pose(((0, 0, 0), (1e-7, 0, 0, 0)), "pose")[1] == (0.0, 0.0, 0.0, 1.0)


def test_check_pose_normalizes():
    p, q = api.check_pose(((1, 2, 3), (0, 0, 2, 2)), "pose")
    assert all(isinstance(v, float) for v in p + q)
    assert close(q, (0.0, 0.0, S, S))
    assert close(api.check_pose(((0, 0, 0), (0, 0, 1e200, 1e200)), "pose")[1], (0.0, 0.0, S, S))


def test_check_twist():
    assert api.check_twist(((1, 0, 0), (0, 0, 1)), "twist") == ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    with pytest.raises(ValueError, match=r"^model_state\.twist\.angular\.z is inf$"):
        api.check_twist(((0, 0, 0), (0, 0, math.inf)), "model_state.twist")
    with pytest.raises(ValueError, match=r"^twist\.linear\.y is nan$"):
        api.check_twist(((0, math.nan, 0), (0, 0, 0)), "twist")


def test_quaternion_rpy_inverts_rpy_quaternion():
    for rpy in [(0.1, -0.2, 0.3), (0.0, 0.0, math.pi / 2), (-1.0, 1.2, 3.0), (0.0, math.pi / 2, 0.0),
                (0.3, -math.pi / 2, 0.0)]:
        assert same_rotation(rpy_quaternion(*quaternion_rpy(rpy_quaternion(*rpy))), rpy_quaternion(*rpy))
    assert close(quaternion_rpy(YAW90), (0.0, 0.0, math.pi / 2))
    rng = random.Random(3)
    for _ in range(200):
        q = random_pose(rng)[1]
        assert same_rotation(rpy_quaternion(*quaternion_rpy(q)), q)


# ------------------------------------------------------------------------------------------ URDF text

PACKAGES = {"diffbot_description": "/opt/ws/src/diffbot_description", "meshes": "/m/"}


def resolve(name):
    if name == "raises":
        raise LookupError(name)
    return PACKAGES.get(name)


def test_prepare_urdf_strips_declaration_and_comments_and_resolves_packages():
    text = ('<?xml version="1.0" encoding="utf-8"?>\n'
            '<!-- generated by xacro from package://not_a_package/x.xacro -->\n'
            '<robot name="r">\n'
            '  <link name="base"><visual><geometry>'
            '<mesh filename="package://diffbot_description/meshes/base.stl" scale="1 1 1"/></geometry></visual>'
            '<!-- two\n lines --></link>\n'
            '  <link name="w"><visual><geometry><mesh filename="package://meshes/w.dae"/></geometry></visual></link>\n'
            '</robot>\n')
    expected = ('\n\n<robot name="r">\n'
                '  <link name="base"><visual><geometry>'
                '<mesh filename="/opt/ws/src/diffbot_description/meshes/base.stl" scale="1 1 1"/></geometry>'
                '</visual></link>\n'
                '  <link name="w"><visual><geometry><mesh filename="/m/w.dae"/></geometry></visual></link>\n'
                '</robot>\n')
    assert model_xml.prepare_urdf(text, resolve) == expected


@pytest.mark.parametrize("package", ["missing", "raises"])
def test_prepare_urdf_unknown_package(package):
    text = f'<robot name="r"><link name="a"><visual><geometry><mesh filename="package://{package}/a.stl"/>' \
           f'</geometry></visual></link></robot>'
    with pytest.raises(ValueError, match=rf"^urdf reference package name does not exist: {package}$"):
        model_xml.prepare_urdf(text, resolve)


def test_prepare_urdf_without_a_slash_stops_replacing():
    text = '<robot name="r"><x a="package://diffbot_description"></x></robot>'
    # upstream takes the next "/" anywhere (here the one of "</x>"), so the "name" is garbage: unknown
    with pytest.raises(ValueError, match="does not exist"):
        model_xml.prepare_urdf(text, resolve)
    tail = '<robot name="r"/><!-- c -->package://diffbot_description'
    assert model_xml.prepare_urdf(tail, resolve) == '<robot name="r"/>package://diffbot_description'


def test_prepare_urdf_unterminated_comment():
    with pytest.raises(ValueError, match="line 2.*never closed"):
        model_xml.prepare_urdf('<robot name="r">\n<!-- oops\n</robot>', resolve)


def test_prepare_urdf_keeps_everything_else():
    text = '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n\t<link  name = "a" />\n</robot>'
    assert model_xml.prepare_urdf(text, resolve) == text


# ------------------------------------------------------------------------------------------ namespaces

URDF = """<?xml version="1.0"?>
<!-- a comment that stays -->
<robot name="diffbot" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="base_link"/>
  <gazebo>
    <plugin name="diff_drive" filename="libgazebo_ros_diff_drive.so">
      <commandTopic>cmd_vel</commandTopic>
    </plugin>
  </gazebo>
  <gazebo reference="laser">
    <sensor type="ray" name="lidar"><plugin name="scan" filename="libgazebo_ros_laser.so"/></sensor>
  </gazebo>
  <gazebo>
    <plugin name="control" filename="libgazebo_ros_control.so"><robotNamespace>/fixed</robotNamespace></plugin>
  </gazebo>
</robot>
"""

NS = "<robotNamespace>/r1</robotNamespace>"


def test_inject_namespace_urdf_adds_where_missing_and_keeps_an_existing_one():
    out = model_xml.inject_robot_namespace(URDF, "/r1")
    expected = (URDF
                .replace("</commandTopic>\n    </plugin>", f"</commandTopic>\n    {NS}</plugin>")
                .replace('libgazebo_ros_laser.so"/>', f'libgazebo_ros_laser.so">{NS}</plugin>'))
    assert out == expected  # byte for byte: declaration, comment, xmlns:xacro, layout all kept
    assert "<robotNamespace>/fixed</robotNamespace>" in out


def test_inject_namespace_urdf_replacing_existing():
    out = model_xml.inject_robot_namespace(URDF, "/r1", replace_existing=True)
    assert "/fixed" not in out
    root = ET.fromstring(out.split("?>", 1)[1])
    plugins = root.findall(".//plugin")
    assert len(plugins) == 3
    assert all([e.text for e in p.findall("robotNamespace")] == ["/r1"] for p in plugins)
    assert 'xmlns:xacro="http://www.ros.org/wiki/xacro"' in out


SDF = """<sdf version="1.6">
  <model name="box">
    <plugin name="p1" filename="libone.so"></plugin>
    <link name="body">
      <sensor name="cam" type="camera">
        <plugin name="p2" filename="libtwo.so">
          <robotNamespace>old</robotNamespace>
          <robotNamespace>older</robotNamespace>
        </plugin>
      </sensor>
    </link>
  </model>
</sdf>"""


def test_inject_namespace_sdf():
    out = model_xml.inject_robot_namespace(SDF, "/r1")
    assert out == SDF.replace('libone.so"></plugin>', f'libone.so">{NS}</plugin>')
    replaced = model_xml.inject_robot_namespace(SDF, "/r1", replace_existing=True)
    root = ET.fromstring(replaced)
    assert [e.text for e in root.find(".//sensor/plugin").findall("robotNamespace")] == ["/r1"]
    assert [e.text for e in root.find("model/plugin").findall("robotNamespace")] == ["/r1"]


def test_inject_namespace_empty_is_a_no_op_and_text_is_escaped():
    assert model_xml.inject_robot_namespace(URDF, "") is URDF
    out = model_xml.inject_robot_namespace(SDF, "a&b<c")
    assert ET.fromstring(out).find("model/plugin/robotNamespace").text == "a&b<c"


def test_inject_namespace_invalid_xml():
    with pytest.raises(ValueError, match=r"^model_xml is not valid XML: mismatched tag: line 2, column"):
        model_xml.inject_robot_namespace('<robot name="r">\n<plugin></robot>', "/r1")


# ------------------------------------------------------------------------------------------ kinds, names

def test_model_xml_kind():
    assert model_xml.model_xml_kind(URDF) == "urdf"
    assert model_xml.model_xml_kind(SDF) == "sdf"
    assert model_xml.model_xml_kind('\n  <?xml version="1.0"?>\n<robot name="r"/>') == "urdf"


def test_model_xml_kind_errors():
    with pytest.raises(ValueError, match=r"^model_xml is not valid XML: .*line 3, column"):
        model_xml.model_xml_kind('\n\n<robot name="r"><link></robot>')
    with pytest.raises(ValueError, match=r"^model_xml is not valid XML: no element found"):
        model_xml.model_xml_kind("")
    with pytest.raises(ValueError, match=r"root element <model> is neither <robot> \(URDF\) nor <sdf> \(SDF\)"):
        model_xml.model_xml_kind('<model name="m"/>')
    with pytest.raises(ValueError, match="pre-SDF"):
        model_xml.model_xml_kind("<gazebo><model name='m'/></gazebo>")


def test_rename_urdf():
    assert model_xml.rename_model(URDF, "urdf", "r1") == URDF.replace('<robot name="diffbot"', '<robot name="r1"')
    assert model_xml.rename_model("<robot><link name='a'/></robot>", "urdf", 'x"y') == \
        "<robot name=\"x&quot;y\"><link name='a'/></robot>"
    tricky = "<robot doc='name=\"no\"' name='old'/>"
    assert model_xml.rename_model(tricky, "urdf", "new") == "<robot doc='name=\"no\"' name=\"new\"/>"


def test_rename_sdf_model_and_include():
    assert model_xml.rename_model(SDF, "sdf", "crate") == SDF.replace('<model name="box">', '<model name="crate">')
    include = '<sdf version="1.6"><world name="w"><include><uri>model://box</uri><name>old</name></include>' \
              '</world></sdf>'
    assert model_xml.rename_model(include, "sdf", "b2") == include.replace("<name>old</name>", "<name>b2</name>")
    bare = '<sdf version="1.6"><world name="w"><include><uri>model://box</uri></include></world></sdf>'
    assert model_xml.rename_model(bare, "sdf", "b2") == bare.replace("</include>", "<name>b2</name></include>")


def test_rename_errors():
    with pytest.raises(ValueError, match="holds no <model>"):
        model_xml.rename_model('<sdf version="1.6"><light name="l"/></sdf>', "sdf", "x")
    with pytest.raises(ValueError, match="not <robot>"):
        model_xml.rename_model(SDF, "urdf", "x")


def _pose_of(model_text):
    values = [float(v) for v in ET.fromstring(model_text).find("pose").text.split()]
    return tuple(values[:3]), rpy_quaternion(*values[3:])


def test_sdf_model_at_composes_the_file_pose_on_the_request():
    sdf = '<sdf version="1.6"><model name="m"><pose>1 0 0 0 0 0</pose><link name="l"/></model></sdf>'
    out = model_xml.sdf_model_at(sdf, ((0.0, 0.0, 0.5), YAW90))
    assert out.startswith('<model name="m"><pose>') and out.endswith('<link name="l"/></model>')
    p, q = _pose_of(out)
    assert close(p, (0.0, 1.0, 0.5)) and same_rotation(q, YAW90)


def test_sdf_model_at_adds_a_pose_and_reads_sdf_1_9_forms():
    out = model_xml.sdf_model_at('<sdf version="1.6"><model name="m"><link name="l"/></model></sdf>',
                           ((1.0, 2.0, 3.0), (0, 0, 0, 1)))
    assert close(_pose_of(out)[0], (1.0, 2.0, 3.0))
    degrees = '<sdf version="1.9"><model name="m"><pose degrees="true">0 0 0 0 0 90</pose></model></sdf>'
    assert same_rotation(_pose_of(model_xml.sdf_model_at(degrees, IDENTITY))[1], YAW90)
    quat = f'<sdf version="1.9"><model name="m"><pose rotation_format="quat_xyzw">0 0 0 0 0 {S} {S}</pose>' \
           f'</model></sdf>'
    composed = _pose_of(model_xml.sdf_model_at(quat, (IDENTITY[0], YAW90)))[1]
    assert same_rotation(composed, compose((IDENTITY[0], YAW90), (IDENTITY[0], YAW90))[1])


def test_sdf_model_at_include_and_errors():
    include = '<sdf version="1.6"><world name="w"><include><uri>model://box</uri></include></world></sdf>'
    out = model_xml.sdf_model_at(include, ((1.0, 0.0, 0.0), (0, 0, 0, 1)))
    assert out.startswith("<include><uri>model://box</uri><pose>")
    with pytest.raises(ModelError, match=r"^model_xml: <model>/pose: <pose> '1 2 3' is not 6 finite numbers$"):
        model_xml.sdf_model_at('<sdf version="1.6"><model name="m"><pose>1 2 3</pose></model></sdf>', IDENTITY)
    # an empty <pose/> is SDF's default, the identity (Gazebo reads it as zeros), as in a world file
    out = model_xml.sdf_model_at('<sdf version="1.6"><model name="m"><pose/></model></sdf>', ((1.0, 0.0, 0.0), YAW90))
    assert close(_pose_of(out)[0], (1.0, 0.0, 0.0)) and same_rotation(_pose_of(out)[1], YAW90)


# ------------------------------------------------------------------------------------------ wrenches

def test_wrench_in_the_world_frame_moves_the_point_into_the_torque():
    f, t, point = api.wrench_to_world((1.0, 0.0, 0.0), (0.0, 0.0, 0.5), (0.0, 1.0, 0.0), None)
    assert close(f, (1.0, 0.0, 0.0))
    assert close(t, (0.0, 0.0, -0.5))  # 0.5 + (0, 1, 0) x (1, 0, 0) = 0.5 - 1
    assert point is None  # at the link's centre of mass


def test_wrench_in_the_bodys_own_frame_is_applied_unrotated_as_upstream():
    """gazebo_ros#310: reference_frame = the body itself gives the identity transform, and the numbers are
    then applied as world-axes force: a body turned 90 degrees is still pushed along world x."""
    body = ((3.0, 4.0, 0.0), YAW90)
    f, t, _ = api.wrench_to_world((1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), body, body)
    assert close(f, (1.0, 0.0, 0.0)) and close(t, (0.0, 0.0, 0.0))


def test_wrench_in_another_frame_uses_the_frame_seen_from_the_body():
    body = ((0.0, 0.0, 0.0), (0, 0, 0, 1))
    f, t, _ = api.wrench_to_world((1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0),
                                  ((0.0, 0.0, 1.0), (0, 0, 0, 1)), body)
    assert close(f, (1.0, 0.0, 0.0)) and close(t, (0.0, 1.0, 0.0))  # (0, 0, 1) x (1, 0, 0)
    f, t, _ = api.wrench_to_world((1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0),
                                  ((0.0, 0.0, 0.0), YAW90), body)
    assert close(f, (0.0, 1.0, 0.0))
    with pytest.raises(ValueError, match="body_pose"):
        api.wrench_to_world((1, 0, 0), (0, 0, 0), (0, 0, 0), body)


DT = 0.001


def step_time(steps):
    return steps * DT  # as the simulator computes sim time


def bodies(schedule, steps):
    return [body for body, *_ in schedule.active(step_time(steps))]


def test_wrench_starting_in_the_future():
    s = api.WrenchSchedule()
    s.add("r::base", (1, 0, 0), (0, 0, 0), None, 1.0, 0.5, 0.0)
    assert bodies(s, 999) == []
    assert bodies(s, 1000) == ["r::base"]
    assert bodies(s, 1500) == ["r::base"]  # start + duration still applies
    assert len(s) == 1
    assert bodies(s, 1501) == [] and len(s) == 0  # past its end: dropped


def test_wrench_started_in_the_past_runs_duration_over_step_steps():
    s = api.WrenchSchedule()
    s.add("r::base", (1, 0, 0), (0, 0, 0), None, 0.0, 0.01, step_time(2000))  # start 0 = now
    applied = sum(bool(bodies(s, 2000 + k)) for k in range(1, 30))
    assert applied == 10 and len(s) == 0


def test_wrench_duration_zero_from_now_does_nothing_and_on_a_future_step_once():
    s = api.WrenchSchedule()
    s.add("r::base", (1, 0, 0), (0, 0, 0), None, 0.0, 0.0, step_time(10))
    assert bodies(s, 11) == [] and len(s) == 0
    s.add("r::base", (1, 0, 0), (0, 0, 0), None, step_time(20), 0.0, step_time(10))
    assert [bool(bodies(s, k)) for k in range(11, 23)] == [False] * 9 + [True, False, False]


def test_wrench_negative_duration_is_forever():
    s = api.WrenchSchedule()
    s.add("r::base", (1, 0, 0), (0, 0, 0), None, 0.0, -1.0, 0.0)
    assert bodies(s, 1) == ["r::base"]
    assert bodies(s, 10 ** 9) == ["r::base"] and len(s) == 1


def test_wrench_last_added_wins_per_body():
    s = api.WrenchSchedule()
    s.add("r::base", (1, 0, 0), (0, 0, 0), None, 0.0, -1.0, 0.0)
    s.add("r::wheel", (0, 1, 0), (0, 0, 0), None, 0.0, -1.0, 0.0)
    s.add("r::base", (2, 0, 0), (0, 0, 3), (0.0, 0.0, 1.0), 0.0, -1.0, 0.0)
    active = s.active(step_time(1))
    assert active == [("r::base", (2.0, 0.0, 0.0), (0.0, 0.0, 3.0), (0.0, 0.0, 1.0)),
                      ("r::wheel", (0.0, 1.0, 0.0), (0.0, 0.0, 0.0), None)]


def test_wrench_clear():
    s = api.WrenchSchedule()
    for body in ("r::base", "r::base", "r::wheel", "r2::base", "r::inner::link", "rr::base"):
        s.add(body, (1, 0, 0), (0, 0, 0), None, 0.0, -1.0, 0.0)
    assert s.clear("r::base") == 2
    assert s.clear("base") == 0  # scoped names only, as upstream compares GetScopedName()
    assert s.clear_model("r") == 2  # r::wheel and the nested r::inner::link, not rr::base
    assert sorted(bodies(s, 1)) == ["r2::base", "rr::base"]
    assert s.clear_all() == 2 and len(s) == 0


def test_wrench_refuses_non_finite_times():
    with pytest.raises(ValueError, match="duration is nan"):
        api.WrenchSchedule().add("r::b", (0, 0, 0), (0, 0, 0), None, 0.0, math.nan, 0.0)


# ------------------------------------------------------------------------------------------ physics

ODE_FIELDS = {"auto_disable_bodies", "sor_pgs_precon_iters", "sor_pgs_iters", "sor_pgs_w", "sor_pgs_rms_error_tol",
              "contact_surface_layer", "contact_max_correcting_vel", "cfm", "erp", "max_contacts"}


def test_physics_properties():
    values = api.physics_properties(0.001, 1.0, True, False, -9.81)
    assert values["time_step"] == 0.001 and values["pause"] is False
    assert close(values["max_update_rate"], 1000.0)
    assert values["gravity"] == (0.0, 0.0, -9.81)
    assert set(values["ode_config"]) == ODE_FIELDS
    assert values["ode_config"]["sor_pgs_iters"] == 50
    paced_faster = api.physics_properties(0.004, 2.0, True, True, -9.8)
    assert close(paced_faster["max_update_rate"], 500.0) and paced_faster["pause"] is True
    assert api.physics_properties(0.001, 1.0, False, False, -9.81)["max_update_rate"] == 0.0
