"""check.arm_check: the forward kinematics robot_state_publisher would draw agree with the physics' link poses
(both from one URDF), and a pose error is measured as it should be."""
import math

import pytest

from diffbot_sim.check.arm_check import forward_kinematics, pose_error, pose_errors
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.physics import World

ARM = """<robot name="arm">
  <link name="base"><inertial><mass value="5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>
    </inertial></link>
  <link name="upper"><inertial><origin xyz="0 0 0.1"/><mass value="0.3"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-4"/></inertial></link>
  <link name="fore"><inertial><mass value="0.2"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-4"/>
    </inertial></link>
  <link name="hand"/>
  <link name="finger"><inertial><mass value="0.02"/>
    <inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"/></inertial></link>
  <link name="finger2"><inertial><mass value="0.02"/>
    <inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"/></inertial></link>
  <joint name="yaw" type="continuous"><parent link="base"/><child link="upper"/><origin xyz="0 0 0.2"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><origin xyz="0 0 0.25" rpy="0 0.3 0"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="5" velocity="2"/></joint>
  <joint name="wrist_fixed" type="fixed"><parent link="fore"/><child link="hand"/>
    <origin xyz="0.2 0 0" rpy="0.1 0 0.2"/></joint>
  <joint name="slide" type="prismatic"><parent link="hand"/><child link="finger"/><origin xyz="0 0.02 0"/>
    <axis xyz="0 1 0"/><limit lower="0" upper="0.05" effort="5" velocity="1"/></joint>
  <joint name="slide2" type="prismatic"><parent link="hand"/><child link="finger2"/><origin xyz="0 -0.02 0"/>
    <axis xyz="0 -1 0"/><limit lower="0" upper="0.05" effort="5" velocity="1"/><mimic joint="slide" multiplier="1"/>
      </joint>
</robot>"""


def physics_poses(positions):
    world = World(1 / 240, gravity=0.0)
    try:
        model = parse_urdf(ARM)
        robot = world.load_robot(ARM, model, (0.3, -0.2, 0.1), yaw=0.7)
        names = [n for n in positions if n in robot.joint_index]
        robot.set_joint_positions(robot.indices(names), [positions[n] for n in names])
        return model, {link: robot.link_pose(link) for link in model.links}
    finally:
        world.close()


def test_forward_kinematics_matches_the_physics():
    positions = {"yaw": 1.1, "elbow": -0.7, "slide": 0.03, "slide2": 0.03}
    model, measured = physics_poses(positions)
    errors = pose_errors(model, positions, measured)
    assert set(errors) == {"base", "upper", "fore", "hand", "finger", "finger2"}
    assert max(e.distance for e in errors.values()) < 1e-6
    assert max(e.angle for e in errors.values()) < 1e-6


def test_a_wrong_joint_value_shows_in_the_links_beyond_it():
    model, measured = physics_poses({"yaw": 1.1, "elbow": -0.7})
    errors = pose_errors(model, {"yaw": 1.1, "elbow": -0.6}, measured)
    assert errors["upper"].distance < 1e-6
    assert errors["fore"].angle == pytest.approx(0.1, abs=1e-6)
    assert errors["hand"].distance == pytest.approx(0.2 * 2 * math.sin(0.05), abs=1e-6)


def test_mimic_joint_follows_its_master_when_not_given():
    model = parse_urdf(ARM)
    fk = forward_kinematics(model, {"slide": 0.04})
    assert pose_error(fk["finger2"], fk["finger"]).distance == pytest.approx(0.12, abs=1e-9)  # 2 x (0.02 + 0.04)
