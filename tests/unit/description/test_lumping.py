"""lumping.py: Gazebo's lumping of fixed joints, checked against hand-computed inertials and transforms, and
on PyBullet DIRECT: loaded mass, per-link friction and contact parameters, lumped frames' poses."""
import glob
import math
import os
import xml.etree.ElementTree as ET

import numpy as np
import pybullet
import pytest

from diffbot_sim import physics
from diffbot_sim.description import lumping, meshes
from diffbot_sim.description.model_files import load_file
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.physics import World

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
ROBOTS = os.path.join(ROOT, "tests", "data", "robots")
FIXED_CASTER = os.path.join(ROBOTS, "fixed_caster.urdf")
SEED_XACRO = os.path.join(ROOT, "urdf", "diffbot.urdf.xacro")


def robot(body):
    return f'<?xml version="1.0"?>\n<robot name="t">{body}</robot>'


def inertial(mass, xyz="0 0 0", rpy="0 0 0", ixx=1e-6, iyy=1e-6, izz=1e-6, ixy=0.0):
    return (f'<inertial><origin xyz="{xyz}" rpy="{rpy}"/><mass value="{mass}"/>'
            f'<inertia ixx="{ixx}" ixy="{ixy}" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial>')


def joint(name, parent, child, kind="fixed", xyz="0 0 0", rpy="0 0 0"):
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="0 1 0"/></joint>')


def lump_text(text):
    model = parse_urdf(text, "test.urdf")
    return lumping.lump(text, model.root, model.surface)


def links_of(text):
    return {el.get("name"): el for el in ET.fromstring(text).findall("link")}


def joints_of(text):
    return {el.get("name"): el for el in ET.fromstring(text).findall("joint")}


def floats(text):
    return [float(v) for v in text.split()]


def written_inertial(link):
    """(mass, com, rpy, principal moments) of a link's <inertial> as lumping wrote it."""
    el = link.find("inertial")
    origin, inertia = el.find("origin"), el.find("inertia")
    assert all(float(inertia.get(k)) == 0.0 for k in ("ixy", "ixz", "iyz")), "not written in principal axes"
    return (float(el.find("mass").get("value")), np.array(floats(origin.get("xyz"))), floats(origin.get("rpy")),
            np.array([float(inertia.get(k)) for k in ("ixx", "iyy", "izz")]))


def total_written_mass(text):
    return sum(float(el.find("inertial/mass").get("value")) for el in links_of(text).values()
               if el.find("inertial") is not None)


def same_rotation(q1, q2, tol=1e-9):
    """Quaternions (x, y, z, w) of the same rotation (q and -q are one rotation)."""
    return abs(abs(float(np.dot(q1, q2))) - 1.0) < tol


# ------------------------------------------------------------------------------------ inertial lumping

# Two point-ish boxes (1 cm cubes): a base of 2 kg with its centre of mass at (0.1, 0, 0) and, on a fixed
# joint at (0, 0.3, 0), a payload of 1 kg without collision. Each cube's own inertia is m*(2*0.01^2)/12 about
# every axis. By hand:
#   com = (2*(0.1, 0, 0) + 1*(0, 0.3, 0)) / 3 = (1/15, 0.1, 0)
#   d_base = (1/30, -0.1, 0), d_payload = (-1/15, 0.2, 0)
#   Ixx = 2*0.1^2 + 1*0.2^2 = 0.06;  Iyy = 2/900 + 1/225 = 1/150;  Izz = Ixx + Iyy = 1/15
#   Ixy = -(2*(1/30)*(-0.1) + 1*(-1/15)*0.2) = 0.02;  Ixz = Iyz = 0;   plus the cubes' own 2e-4/12 + 1e-4/12.
# The two points lie on one line in the xy plane: about that line (direction (-0.1, 0.3, 0)) the points add
# nothing, so the principal moments are own, 1/15 + own, 1/15 + own.
OWN = 2.0 * 2e-4 / 12 + 1.0 * 2e-4 / 12  # sum of the two cubes' isotropic moments (2 kg, 1 kg)
HAND_TENSOR = np.array([[0.06, 0.02, 0.0], [0.02, 1.0 / 150, 0.0], [0.0, 0.0, 1.0 / 15]]) + OWN * np.eye(3)
TWO_BOXES = robot(
    f'<link name="base"><collision><geometry><box size="0.01 0.01 0.01"/></geometry></collision>'
    f'{inertial(2.0, "0.1 0 0", ixx=2 * 2e-4 / 12, iyy=2 * 2e-4 / 12, izz=2 * 2e-4 / 12)}</link>'
    f'<link name="payload">{inertial(1.0, ixx=2e-4 / 12, iyy=2e-4 / 12, izz=2e-4 / 12)}</link>'
    + joint("payload_joint", "base", "payload", xyz="0 0.3 0"))


def test_fixed_child_without_collision_is_lumped_with_combined_inertial():
    out = lump_text(TWO_BOXES)
    assert out.lumped == ["payload"]
    links = links_of(out.text)
    assert set(links) == {"base"} and "payload_joint" not in joints_of(out.text)
    mass, com, rpy, moments = written_inertial(links["base"])
    assert mass == pytest.approx(3.0)
    assert com == pytest.approx([1.0 / 15, 0.1, 0.0], abs=1e-12)
    assert sorted(moments) == pytest.approx([OWN, 1.0 / 15 + OWN, 1.0 / 15 + OWN], rel=1e-9, abs=1e-12)
    rotation = lumping.rpy_matrix(rpy)
    assert rotation @ np.diag(moments) @ rotation.T == pytest.approx(HAND_TENSOR, abs=1e-12)
    # The smallest moment's principal axis is the line through the two points.
    axis = rotation[:, int(np.argmin(moments))]
    line = np.array([-0.1, 0.3, 0.0]) / math.hypot(0.1, 0.3)
    assert abs(float(np.dot(axis, line))) == pytest.approx(1.0, abs=1e-9)


def test_parallel_axis_about_a_rotated_child_inertial():
    """The child's tensor is rotated into the parent's axes before it is added: a thin rod along the child's
    x, on a joint turned 90 deg about z, lies along the parent's y."""
    text = robot(f'<link name="base">{inertial(1.0, ixx=1e-6, iyy=1e-6, izz=1e-6)}</link>'
                 f'<link name="rod">{inertial(1.0, ixx=0.0, iyy=0.01, izz=0.01)}</link>'
                 + joint("rod_joint", "base", "rod", rpy=f"0 0 {math.pi / 2}"))
    mass, com, rpy, moments = written_inertial(links_of(lump_text(text).text)["base"])
    rotation = lumping.rpy_matrix(rpy)
    expected = np.diag([0.01, 0.0, 0.01]) + 1e-6 * np.eye(3)
    assert rotation @ np.diag(moments) @ rotation.T == pytest.approx(expected, abs=1e-12)


# --------------------------------------------------------------------------------- collisions and frames

# base -> mid (fixed: 0.1 0 0, yaw 90 deg) -> tip (fixed: 0.2 0 0, pitch 45 deg); tip's collision at (0 0 0.05).
# By hand, in base: (0.1, 0, 0) + Rz(90) * ((0.2, 0, 0) + Ry(45) * (0, 0, 0.05))
#   = (0.1, 0, 0) + Rz(90) * (0.2 + 0.05 sin 45, 0, 0.05 cos 45) = (0.1, 0.2 + 0.05 sin 45, 0.05 cos 45),
# orientation Rz(90) Ry(45): rpy (0, pi/4, pi/2).
S45 = math.sin(math.pi / 4)
CHAIN = robot(
    f'<link name="base"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>{inertial(1.0)}</link>'
    f'<link name="mid"><collision><geometry><sphere radius="0.01"/></geometry></collision>{inertial(0.1)}</link>'
    f'<link name="tip"><collision><origin xyz="0 0 0.05"/><geometry><cylinder radius="0.01" length="0.02"/>'
    f'</geometry></collision>{inertial(0.1)}</link>'
    f'<link name="wheel"><collision><geometry><sphere radius="0.03"/></geometry></collision>{inertial(0.2)}</link>'
    + joint("mid_joint", "base", "mid", xyz="0.1 0 0", rpy=f"0 0 {math.pi / 2}")
    + joint("tip_joint", "mid", "tip", xyz="0.2 0 0", rpy=f"0 {math.pi / 4} 0")
    + joint("wheel_joint", "mid", "wheel", kind="continuous", xyz="0.2 0.1 0")
    + "".join(f'<gazebo reference="{name}"><mu1>0.5</mu1></gazebo>' for name in ("base", "mid", "tip")))


def test_fixed_children_with_the_same_surface_move_their_collisions_into_the_parent():
    out = lump_text(CHAIN)
    assert sorted(out.lumped) == ["mid", "tip"]
    base = links_of(out.text)["base"]
    shapes = {c.find("geometry")[0].tag: c for c in base.findall("collision")}
    assert set(shapes) == {"box", "sphere", "cylinder"}
    cylinder = shapes["cylinder"].find("origin")
    assert floats(cylinder.get("xyz")) == pytest.approx([0.1, 0.2 + 0.05 * S45, 0.05 * S45], abs=1e-12)
    assert floats(cylinder.get("rpy")) == pytest.approx([0.0, math.pi / 4, math.pi / 2], abs=1e-12)
    sphere = shapes["sphere"].find("origin")
    assert floats(sphere.get("xyz")) == pytest.approx([0.1, 0.0, 0.0], abs=1e-12)
    assert floats(sphere.get("rpy")) == pytest.approx([0.0, 0.0, math.pi / 2], abs=1e-12)


def test_frames_give_each_lumped_link_its_pose_in_the_carrier():
    frames = lump_text(CHAIN).frames
    q = pybullet.getQuaternionFromEuler
    mid = ((0.1, 0, 0), q((0, 0, math.pi / 2)))
    tip = pybullet.multiplyTransforms(*mid, (0.2, 0, 0), q((0, math.pi / 4, 0)))
    for name, expected in (("mid", mid), ("tip", tip)):
        carrier, xyz, quat = frames[name]
        assert carrier == "base"
        assert xyz == pytest.approx(expected[0], abs=1e-7)  # PyBullet computes in float32
        assert same_rotation(quat, expected[1], tol=1e-7), (name, quat, expected[1])
    assert frames["base"] == ("base", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    assert frames["wheel"] == ("wheel", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def test_joint_of_a_lumped_link_is_reparented_with_its_origin_composed():
    wheel_joint = joints_of(lump_text(CHAIN).text)["wheel_joint"]
    assert wheel_joint.find("parent").get("link") == "base"
    origin = wheel_joint.find("origin")
    # (0.1, 0, 0) + Rz(90) * (0.2, 0.1, 0) = (0.1 - 0.1, 0.2, 0)
    assert floats(origin.get("xyz")) == pytest.approx([0.0, 0.2, 0.0], abs=1e-12)
    assert floats(origin.get("rpy")) == pytest.approx([0.0, 0.0, math.pi / 2], abs=1e-12)


def test_fixed_child_with_a_surface_of_its_own_stays_a_link():
    text = robot(
        f'<link name="base"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>{inertial(1.0)}</link>'
        f'<link name="caster"><collision><geometry><box size="0.02 0.02 0.02"/></geometry></collision>'
        f'{inertial(0.01)}</link>' + joint("caster_joint", "base", "caster", xyz="-0.1 0 -0.05")
        + '<gazebo reference="caster"><mu1>0.1</mu1></gazebo>')
    out = lump_text(text)
    assert out.lumped == []
    assert set(links_of(out.text)) == {"base", "caster"}
    kept = joints_of(out.text)["caster_joint"]
    assert kept.get("type") == "fixed" and kept.find("parent").get("link") == "base"
    assert out.frames["caster"] == ("caster", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    assert len(links_of(out.text)["base"].findall("collision")) == 1


# ---------------------------------------------------------------------------------------- mass and roots

def test_inertialess_links_add_no_mass_beyond_their_placeholders():
    text = robot(
        '<link name="base_footprint"/>'
        f'<link name="base_link"><collision><geometry><box size="0.2 0.2 0.05"/></geometry></collision>'
        f'{inertial(2.0)}</link>'
        '<link name="imu_link"/><link name="wheel"><collision><geometry><sphere radius="0.03"/></geometry>'
        '</collision></link>'
        + joint("base_joint", "base_footprint", "base_link", xyz="0 0 0.05")
        + joint("imu_joint", "base_link", "imu_link", xyz="0.05 0 0.02")
        + joint("wheel_joint", "base_link", "wheel", kind="continuous", xyz="0 0.1 0"))
    out = lump_text(text)
    assert out.lumped == ["base_link", "imu_link"]  # into the inertia-less root, which takes base_link's mass
    assert out.placeholders == ["wheel"]
    links = links_of(out.text)
    # 0.1 g on the inertia-less link of a movable joint; nothing for imu_link.
    assert float(links["wheel"].find("inertial/mass").get("value")) == 1e-4
    assert total_written_mass(out.text) == pytest.approx(2.0 + 1e-4, abs=1e-15)


def test_a_link_kept_for_its_own_surface_adds_no_mass():
    # An inertia-less root whose only child on a fixed joint has a collision of another friction: kept as a
    # link of its own (for the friction), with no mass, as Gazebo (which lumps it) gives it none.
    text = robot(
        f'<link name="base_link"><collision><geometry><box size="0.2 0.2 0.05"/></geometry></collision>'
        f'{inertial(2.0)}</link>'
        '<link name="plate"><collision><geometry><box size="0.2 0.2 0.01"/></geometry></collision></link>'
        + joint("plate_joint", "base_link", "plate", xyz="0 0 0.05")
        + '<gazebo reference="plate"><mu1>0.3</mu1></gazebo>')
    out = lump_text(text)
    assert out.lumped == [] and out.placeholders == ["plate"]
    assert total_written_mass(out.text) == pytest.approx(2.0, abs=1e-15)


def test_root_with_mass_gets_no_placeholder():
    text = robot(f'<link name="base_link">{inertial(2.0)}</link><link name="imu_link"/>'
                 + joint("imu_joint", "base_link", "imu_link", xyz="0.05 0 0.02"))
    out = lump_text(text)
    assert out.placeholders == [] and out.lumped == ["imu_link"]
    assert total_written_mass(out.text) == pytest.approx(2.0, abs=1e-15)


def test_an_inertialess_root_takes_its_fixed_children_as_gazebo_lumps_them():
    # The published traits: base_footprint or base_link without <inertial>, the mass in a child on a fixed
    # joint (base_link, chassis_link, inertial_link). Gazebo makes them one body; so do we (kept as links of
    # their own, a 1e-6 kg root carried the robot through Featherstone joints).
    text = robot('<link name="base_footprint"/>'
                 f'<link name="base_link">{inertial(2.0)}</link><link name="laser">{inertial(0.1)}</link>'
                 + joint("base_joint", "base_footprint", "base_link", xyz="0 0 0.05")
                 + joint("laser_joint", "base_link", "laser", xyz="0 0 0.1"))
    out = lump_text(text)
    assert out.lumped == ["base_link", "laser"]
    assert set(links_of(out.text)) == {"base_footprint"}
    assert links_of(out.text)["base_footprint"].find("inertial/mass").get("value") == "2.1"
    assert out.frames["base_link"][0] == out.frames["laser"][0] == "base_footprint"
    assert out.frames["base_link"][1] == pytest.approx((0.0, 0.0, 0.05))
    assert out.frames["laser"][1] == pytest.approx((0.0, 0.0, 0.15))


def test_untouched_link_keeps_its_inertial_as_written():
    written = ('<inertial><origin xyz="0.01 0.02 0.03" rpy="1.5707963 0 0"/><mass value="0.3"/>'
               '<inertia ixx="1e-4" ixy="2e-5" ixz="0" iyy="3e-4" iyz="0" izz="5e-4"/></inertial>')
    text = robot(f'<link name="base">{inertial(1.0)}</link><link name="wheel">{written}</link>'
                 + joint("wheel_joint", "base", "wheel", kind="continuous", xyz="0 0.1 0"))
    out = links_of(lump_text(text).text)["wheel"].find("inertial")
    assert ET.tostring(out, encoding="unicode") == ET.tostring(ET.fromstring(written), encoding="unicode")


# ------------------------------------------------------------------------------------------- rotations

@pytest.mark.parametrize("rpy", [(0.0, 0.0, 0.0), (0.3, -0.2, 1.1), (-2.9, 1.2, -0.4), (3.0, -1.5, 2.5),
                                 (0.1, math.pi / 2 - 1e-3, -0.7)])
def test_matrix_rpy_inverts_rpy_matrix(rpy):
    assert lumping.matrix_rpy(lumping.rpy_matrix(rpy)) == pytest.approx(rpy, abs=1e-9)
    pb = np.array(pybullet.getMatrixFromQuaternion(pybullet.getQuaternionFromEuler(rpy))).reshape(3, 3)
    assert lumping.rpy_matrix(rpy) == pytest.approx(pb, abs=1e-7)


@pytest.mark.parametrize("pitch", [math.pi / 2, -math.pi / 2])
@pytest.mark.parametrize("roll, yaw", [(0.0, 0.0), (0.4, -1.0), (-2.0, 2.5)])
@pytest.mark.parametrize("composed", [False, True])
def test_matrix_rpy_at_gimbal_lock_gives_the_same_rotation(roll, pitch, yaw, composed):
    """Also for a matrix composed of two half pitches, as lumping a chain makes: there rounding leaves
    |sin pitch| a hair above 1 and roll/yaw's atan2 arguments pure noise."""
    if composed:
        m = lumping.rpy_matrix((0.0, pitch / 2, yaw)) @ lumping.rpy_matrix((roll, pitch / 2, 0.0))
    else:
        m = lumping.rpy_matrix((roll, pitch, yaw))
    out = lumping.matrix_rpy(m)
    assert out[1] == pytest.approx(pitch, abs=1e-12)
    assert all(math.isfinite(v) for v in out)
    assert lumping.rpy_matrix(out) == pytest.approx(m, abs=1e-9)


@pytest.mark.parametrize("rpy", [(0.0, 0.0, 0.0), (0.3, -0.2, 1.1),  # trace > 0
                                 (3.0, 0.1, 0.0), (0.0, 3.0, 0.1), (0.1, 0.0, 3.0),  # each diagonal largest
                                 (math.pi, 0.0, 0.0), (0.0, math.pi / 2, 0.0), (2.0, -1.0, -2.5)])
def test_matrix_quaternion_matches_pybullet(rpy):
    q = lumping.matrix_quaternion(lumping.rpy_matrix(rpy))
    assert math.fsum(v * v for v in q) == pytest.approx(1.0, abs=1e-12)
    assert same_rotation(q, pybullet.getQuaternionFromEuler(rpy), tol=1e-7), (q, pybullet.getQuaternionFromEuler(rpy))


# --------------------------------------------------------------------------------------------- PyBullet

@pytest.fixture
def world():
    w = World(1.0 / 240.0)
    yield w
    w.close()


def _no_package(name):
    raise LookupError(name)


def load(world, path, tmp_path, **pose):
    text = load_file(path)
    model = parse_urdf(text, path)
    text, _ = meshes.prepare_meshes(text, path, os.path.dirname(path), str(tmp_path / "mesh_cache"), _no_package)
    return model, world.load_robot(text, model, **pose)


def link_indices(robot):
    out = {pybullet.getBodyInfo(robot.body, physicsClientId=robot.client)[0].decode(): -1}
    for i in range(pybullet.getNumJoints(robot.body, physicsClientId=robot.client)):
        out[pybullet.getJointInfo(robot.body, i, physicsClientId=robot.client)[12].decode()] = i
    return out


def dynamics(robot, link):
    return pybullet.getDynamicsInfo(robot.body, link_indices(robot)[link], physicsClientId=robot.client)


FIXTURES = sorted(glob.glob(os.path.join(ROBOTS, "*.urdf"))) + [SEED_XACRO]


@pytest.mark.parametrize("path", FIXTURES, ids=os.path.basename)
def test_loaded_mass_equals_the_urdf_sum(world, tmp_path, path):
    model, loaded = load(world, path, tmp_path)
    assert model.total_mass() > 0
    assert loaded.total_mass() == pytest.approx(model.total_mass(), abs=1e-5)


def test_fixed_caster_keeps_its_own_friction_and_links_without_mu_get_gazebos_default(world, tmp_path):
    _, loaded = load(world, FIXED_CASTER, tmp_path)
    assert "caster_link" in link_indices(loaded) and "imu_link" not in link_indices(loaded)
    assert "base_link" not in link_indices(loaded)  # lumped into the inertia-less base_footprint
    assert dynamics(loaded, "caster_link")[1] == pytest.approx(0.1)  # text form
    assert dynamics(loaded, "left_wheel_link")[1] == pytest.approx(0.1)  # attribute form
    assert dynamics(loaded, "right_wheel_link")[1] == pytest.approx(0.1)
    assert dynamics(loaded, "base_footprint")[1] == pytest.approx(1.0)


def erp(stiffness, damping, dt=1 / 240):
    """The contact ERP Bullet derives from a link's contact stiffness and damping."""
    return dt * stiffness / (dt * stiffness + damping)


def set_down(world, robot, seconds=1.0):
    """Step until ``robot`` rests and has its own contacts back (World.lift_out damps them while it lands)."""
    for _ in range(round(seconds / world.time_step)):
        world.step()
    assert robot not in world.landing


def test_kp_kd_become_contact_stiffness_and_damping(world, tmp_path):
    _, loaded = load(world, FIXED_CASTER, tmp_path)
    set_down(world, loaded)
    info = dynamics(loaded, "left_wheel_link")
    assert (info[9], info[8]) == pytest.approx((500000.0, 10.0))  # contactStiffness, contactDamping
    assert dynamics(loaded, "caster_link")[9] != pytest.approx(500000.0)


def test_while_set_down_the_damping_keeps_the_erp_within_0_2(world, tmp_path):
    _, loaded = load(world, FIXED_CASTER, tmp_path)
    info = dynamics(loaded, "left_wheel_link")  # kp 5e5, kd 10: ERP 0.995 as given
    assert info[9] == pytest.approx(500000.0)  # contactStiffness kept
    assert info[8] == pytest.approx(500000.0 / 240 * (1 / 0.2 - 1))  # contactDamping raised
    assert erp(info[9], info[8]) == pytest.approx(0.2)


def test_contact_damping_raises_only_what_exceeds_the_erp():
    # kp 100, kd 50 at 240 Hz: ERP 0.008, below the cap: nothing to raise.
    assert physics.contact_damping(100.0, 50.0, 1 / 240, 0.2) == 50.0
    assert physics.contact_damping(1e7, 1.0, 1 / 240, 0.2) == pytest.approx(1e7 / 240 * 4)
    assert physics.contact_damping(1e7, 1.0, 1 / 240, 1.0) == 1.0


@pytest.mark.parametrize("tags, expected", [("<kp>2e5</kp>", (2e5, 1.0)), ("<kd>3</kd>", (1e12, 3.0))])
def test_a_missing_kp_or_kd_takes_gazebos_default(world, make_urdf, tags, expected):
    text = make_urdf(gazebo=f'<gazebo reference="left_wheel_link">{tags}</gazebo>')
    loaded = world.load_robot(text, parse_urdf(text, "test.urdf"))
    set_down(world, loaded)
    info = dynamics(loaded, "left_wheel_link")
    assert (info[9], info[8]) == pytest.approx(expected)


def test_lumped_imu_link_pose_is_the_base_pose_times_its_fixed_offset(world, tmp_path):
    _, loaded = load(world, FIXED_CASTER, tmp_path, position=(1.0, -2.0, 0.0), yaw=0.7)
    for _ in range(30):  # let it fall onto the ground a little: the pose is not the spawn pose any more
        world.step()
    q = pybullet.getQuaternionFromEuler
    base_link = pybullet.multiplyTransforms(*loaded.base_pose(), (0, 0, 0.033), (0, 0, 0, 1))
    expected = pybullet.multiplyTransforms(*base_link, (0.03, 0, 0.03), q((0, 0, 1.5707963)))
    position, orientation = loaded.link_pose("imu_link")
    assert position == pytest.approx(expected[0], abs=1e-6)
    assert same_rotation(orientation, expected[1], tol=1e-6)
    assert position[0] == pytest.approx(1.0 + 0.03 * math.cos(0.7), abs=2e-3)  # sanity: really moved/turned
