"""franka_gazebo's FrankaHWSim without ROS (control/franka): its parameters as readParameters reads them, the
robot mode's state machine (statemachine.h's table), the controller check of prepareSwitch
(controller_verifier.cpp), and the FrankaModelInterface chain's flange pose and Jacobian against the URDF tree
as robot_state_publisher walks it (check.arm_check) and against finite differences."""
import math
import os

import numpy as np
import pytest

from diffbot_sim.check.arm_check import forward_kinematics
from diffbot_sim.control import franka as fk
from diffbot_sim.description.model_files import load_file
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.errors import ConfigError

FRANKA_WAY = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "data",
                          "franka_way")
ARM = [f"panda_joint{i}" for i in range(1, 8)]
START = [0.0, -0.785398163, 0.0, -2.35619449, 0.0, 1.57079632679, 0.785398163397]


@pytest.fixture(scope="module")
def panda(tmp_path_factory):
    """The franka_way fixture arm's URDF with gazebo:=true, as its launch file makes it."""
    os.environ["ROS_PACKAGE_PATH"] = os.pathsep.join(filter(None, [os.environ.get("ROS_PACKAGE_PATH"), FRANKA_WAY]))
    text = load_file(os.path.join(FRANKA_WAY, "pandalike_description", "robots", "pandalike.urdf.xacro"),
                     {"gazebo": "true"})
    return parse_urdf(text if isinstance(text, str) else text[0], "pandalike")


def test_parameters_default_as_upstream_and_are_checked(panda):
    cfg = fk.franka_hw_config({"arm_id": "panda"}, "/", "", set(panda.joints), 0.68)
    assert cfg.arm_joints == ARM and cfg.finger_joints == ["panda_finger_joint1", "panda_finger_joint2"]
    assert cfg.m_ee == 0.68 and cfg.F_T_NE == fk.HAND_F_T_NE  # guessEndEffector: the hand's link
    assert cfg.tau_ext_lowpass_filter == 1.0 and cfg.lower_torque_thresholds == fk.DEFAULT_TORQUE_THRESHOLDS
    assert cfg.position_gains == {} and "no p gain" in cfg.warnings[-1]
    cfg = fk.franka_hw_config({"arm_id": "panda", "NE_T_EE": "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0.1 1",
                               "motion_generators": {"position": {"gains": {j: {"p": 600, "d": 30} for j in ARM}}}},
                              "/", "panda", set(panda.joints), None)
    assert cfg.NE_T_EE[14] == 0.1 and cfg.F_T_NE == fk.IDENTITY16 and cfg.m_ee == 0.0 and cfg.warnings == []
    assert cfg.position_gains["panda_joint7"].d == 30
    with pytest.raises(ConfigError, match="/I_ee"):
        fk.franka_hw_config({"arm_id": "panda", "I_ee": "1 2 3"}, "/", "", set(panda.joints), None)
    with pytest.raises(ConfigError, match="missing: fr3_joint1"):
        fk.franka_hw_config({"arm_id": "fr3"}, "/", "", set(panda.joints), None)


def test_the_robot_mode_follows_upstreams_transition_table():
    mode = fk.RobotMode()
    assert mode.mode == fk.IDLE and not mode.switch_control(False)
    assert mode.switch_control(True) and mode.mode == fk.MOVE
    assert mode.user_stop(True) and mode.mode == fk.USER_STOPPED
    mode.error_recovery()
    assert mode.mode == fk.USER_STOPPED  # nothing recovers while the stop is pressed
    mode.user_stop(False)
    assert mode.mode == fk.IDLE
    mode.error_recovery()
    assert mode.mode == fk.MOVE and mode.switch_control(False) and mode.mode == fk.IDLE


def test_a_switch_takes_arm_controllers_of_all_seven_joints_or_the_fingers_by_effort():
    fingers = ["panda_finger_joint1", "panda_finger_joint2"]
    fk.verify_switch({"jtc": [(fk.EFFORT, ARM)], "gripper": [(fk.EFFORT, fingers)], "state": []}, ARM, fingers)
    with pytest.raises(fk.SwitchRefused, match="one claims"):
        fk.verify_switch({"one": [(fk.POSITION, ARM[:1])]}, ARM, fingers)
    with pytest.raises(fk.SwitchRefused, match="fingers by effort"):
        fk.verify_switch({"g": [(fk.POSITION, fingers)]}, ARM, fingers)


def test_the_flange_pose_is_the_urdf_trees_and_the_jacobian_its_derivative(panda):
    chain = fk.Chain(panda, "panda_link0", "panda_link8")
    assert chain.movable == ARM
    positions = dict(zip(ARM, START))
    pose = chain.pose(positions)
    tree = forward_kinematics(panda, positions)
    assert np.allclose(pose[:3, 3], tree["panda_link8"][0], atol=1e-9)
    tcp = chain.pose(positions, fk.matrix(fk.HAND_F_T_NE))  # F_T_NE: the hand's TCP, as the URDF has it
    assert np.allclose(tcp[:3, 3], tree["panda_hand_tcp"][0], atol=1e-4)
    jac = chain.zero_jacobian(positions)
    for k, name in enumerate(ARM):
        moved = dict(positions, **{name: positions[name] + 1e-6})
        assert np.allclose((chain.pose(moved)[:3, 3] - pose[:3, 3]) / 1e-6, jac[:3, k], atol=1e-5)


def test_a_steiner_shift_and_the_frames_product():
    shifted = fk.shift_inertia((0.0,) * 9, 2.0, (0.0, 0.0, 0.5))
    assert shifted[0] == pytest.approx(0.5) and shifted[4] == pytest.approx(0.5) and shifted[8] == 0.0
    state = fk.FrankaState(F_T_NE=fk.HAND_F_T_NE, NE_T_EE=fk.array16(np.diag([1.0, 1.0, 1.0, 1.0])), m_ee=0.7,
                           m_load=0.3)
    state.update_dynamics()
    assert state.m_total == pytest.approx(1.0) and pytest.approx(fk.HAND_F_T_NE) == state.F_T_EE
    assert fk.low_pass(0.0, 1.0, 0.25) == 0.25 and math.isclose(fk.low_pass(2.0, 1.0, 1.0), 1.0)
