"""Shared set-up for the unit tests: import path, the ``slow`` marker, the seed model and a URDF builder.

No ROS master and no ``rospy.init_node``: everything here is plain Python (and PyBullet DIRECT in
test_physics.py).
"""
import os
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SRC = os.path.join(ROOT, "src")
DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data")
SEED_XACRO = os.path.join(ROOT, "urdf", "diffbot.urdf.xacro")

# Test this tree's sources, also when run from a plain virtualenv without the catkin devel space.
if SRC not in sys.path:
    sys.path.insert(0, SRC)


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: longer physics runs; `make test` skips them (-m 'not slow')")


@pytest.fixture(scope="session")
def seed_urdf():
    """The seed robot (urdf/diffbot.urdf.xacro) run through xacro once per session: URDF text."""
    from diffbot_sim.description.model_files import load_file

    return load_file(SEED_XACRO)


@pytest.fixture
def seed_model(seed_urdf):
    """A fresh RobotModel of the seed robot (cheap to parse; fresh so no test can leak changes)."""
    from diffbot_sim.description.urdf_model import parse_urdf

    return parse_urdf(seed_urdf, SEED_XACRO)


@pytest.fixture(scope="session")
def data_dir():
    return DATA


VELOCITY = "hardware_interface/VelocityJointInterface"


def _transmission(joint, interface=VELOCITY, reduction="1"):
    red = f"<mechanicalReduction>{reduction}</mechanicalReduction>" if reduction is not None else ""
    return f"""
  <transmission name="{joint}_trans">
    <type>transmission_interface/SimpleTransmission</type>
    <joint name="{joint}"><hardwareInterface>{interface}</hardwareInterface></joint>
    <actuator name="{joint}_motor"><hardwareInterface>{interface}</hardwareInterface>{red}</actuator>
  </transmission>"""


def build_urdf(separation=0.3, wheel_radius=0.05, wheel_geometry=None, left_interface=VELOCITY,
               right_interface=VELOCITY, transmissions=None, gazebo="", extra="", base_mass="2.0"):
    """A small two-wheeled robot, deliberately unlike the seed (separation 0.3 m, wheel radius 0.05 m).

    Args:
        wheel_geometry: the wheels' collision geometry element (default a cylinder of ``wheel_radius``).
        transmissions: XML replacing the two default wheel transmissions.
        gazebo: ``<gazebo>`` blocks to append. extra: any other elements to append.
    """
    geom = wheel_geometry or f'<cylinder radius="{wheel_radius}" length="0.03"/>'
    if transmissions is None:
        transmissions = (_transmission("left_wheel_joint", left_interface)
                         + _transmission("right_wheel_joint", right_interface))
    wheels = ""
    for side, sign in (("left", 1), ("right", -1)):
        wheels += f"""
  <link name="{side}_wheel_link">
    <collision><origin xyz="0 0 0" rpy="1.5708 0 0"/><geometry>{geom}</geometry></collision>
    <inertial><mass value="0.3"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>
  </link>
  <joint name="{side}_wheel_joint" type="continuous">
    <parent link="base_link"/><child link="{side}_wheel_link"/>
    <origin xyz="0 {sign * separation / 2.0} 0.0" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit effort="10" velocity="20"/>
  </joint>"""
    return f"""<?xml version="1.0"?>
<robot name="mini">
  <link name="base_footprint"/>
  <joint name="base_joint" type="fixed">
    <parent link="base_footprint"/><child link="base_link"/><origin xyz="0 0 0.05" rpy="0 0 0"/>
  </joint>
  <link name="base_link">
    <collision><geometry><box size="0.3 0.2 0.05"/></geometry></collision>
    <inertial><mass value="{base_mass}"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>{wheels}
  <link name="caster_link">
    <collision><geometry><sphere radius="0.02"/></geometry></collision>
    <inertial><mass value="0.05"/><inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
  </link>
  <joint name="caster_joint" type="continuous">
    <parent link="base_link"/><child link="caster_link"/><origin xyz="0.12 0 -0.03"/><axis xyz="0 1 0"/>
  </joint>{transmissions}{gazebo}{extra}
</robot>
"""


@pytest.fixture(scope="session")
def make_urdf():
    """``make_urdf(**kwargs)`` -> URDF text of the small test robot (see ``build_urdf``)."""
    return build_urdf


@pytest.fixture(scope="session")
def make_transmission():
    """``make_transmission(joint, interface=..., reduction='1')`` -> one <transmission> element as text."""
    return _transmission


@pytest.fixture(scope="session")
def parse():
    """``parse(text, source='test.urdf')`` -> RobotModel."""
    from diffbot_sim.description.urdf_model import parse_urdf

    def _parse(text, source="test.urdf"):
        return parse_urdf(text, source)

    return _parse
