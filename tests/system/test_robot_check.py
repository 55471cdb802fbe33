"""``rosrun diffbot_sim robot_check`` as a user runs it, in a fresh bash that sources the workspace: the fixture
robots drive (exit 0), a robot without a drive does not (exit 1), bad usage is 2, a bad model one line.

Each run gets its own TMPDIR, which the tool's private master and simulator inherit: afterwards no live
process may still carry it (nothing left behind) and the tool's temporary directory must be gone.
"""
import os
import subprocess

import pytest
from proctools import ROOT, SETUP, base_env, environ

ROBOTS = os.path.join(ROOT, "tests", "data", "robots")


def run_check(tmp_path, *args, timeout=60):
    tmp = tmp_path / "tmp"
    tmp.mkdir(exist_ok=True)
    env = base_env(tmp_path / "ros_home", TMPDIR=str(tmp))
    quoted = " ".join(f"'{a}'" for a in args)
    proc = subprocess.run(["bash", "-c", f"source {SETUP} && exec rosrun diffbot_sim robot_check {quoted}"],
                          env=env, stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=timeout)
    left = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                if environ(int(entry)).get("TMPDIR") == str(tmp):
                    left.append(int(entry))
            except OSError:
                continue
    assert not left, f"processes left behind: {left}"
    assert not [p for p in tmp.iterdir() if p.name.startswith("robot_check_")], "temporary directory left"
    return proc


def test_fixed_caster_drives(tmp_path):
    proc = run_check(tmp_path, os.path.join(ROBOTS, "fixed_caster.urdf"))
    out = proc.stdout
    assert proc.returncode == 0, out + proc.stderr
    lines = out.splitlines()
    assert len(lines) <= 40, out
    assert "mass: URDF 1.0017 kg, loaded in PyBullet 1.0017 kg" in lines
    assert ("drive: libgazebo_ros_diff_drive.so at /robot/gazebo[5]/plugin[@name='differential_drive_controller']"
            in lines)
    assert "  separation 0.16 m (<wheelSeparation> tag)" in lines
    assert any(line.startswith("  NOT simulated  sensor imu (type imu)") for line in lines)
    assert any(line.startswith("straight 0.2 m/s x 4 s: ") and line.endswith(": PASS") for line in lines), out
    assert any(line.startswith("turn 0.5 rad/s x 4 s: ") and line.endswith(": PASS") for line in lines), out
    assert any(line.startswith("at rest (ground truth): height 0.000 m") for line in lines), out
    assert lines[-1] == "result: PASS: the robot drives"


def test_ros_control_4wd_with_its_yaml_drives(tmp_path):
    proc = run_check(tmp_path, os.path.join(ROBOTS, "ros_control_4wd.urdf"),
                     os.path.join(ROBOTS, "ros_control_4wd.yaml"))
    out = proc.stdout
    assert proc.returncode == 0, out + proc.stderr
    lines = out.splitlines()
    assert len(lines) <= 40, out
    assert "mass: URDF 6.2000 kg, loaded in PyBullet 6.2000 kg" in lines
    assert ("drive: diff_drive_controller/DiffDriveController at /mobile_base_controller from ros_control_4wd.yaml"
            in lines)
    assert any(line.startswith("  separation 0.48 m (measured: origins of front_left_wheel_joint") for line in lines)
    assert any("/mobile_base_controller/k_l" in line for line in lines)
    assert any(line.startswith("drive test (") and "/mobile_base_controller/cmd_vel -> /mobile_base_controller/odom"
               in line for line in lines), out
    assert sum(line.endswith(": PASS") for line in lines) == 5, out  # at rest, 2 motions, the body in each
    assert lines[-1] == "result: PASS: the robot drives"


def test_an_outdoor_4wd_spawned_into_the_ground_rests_on_it_and_drives(tmp_path):
    # inertial_link_4wd: an inertia-less base_link, its mass in an inertial_link, wheels 0.132 m into the ground
    # at z 0 (where robot_check spawns it); it used to be thrown metres up while its encoder odometry said PASS.
    proc = run_check(tmp_path, os.path.join(ROBOTS, "inertial_link_4wd.urdf"),
                     os.path.join(ROBOTS, "inertial_link_4wd.yaml"), timeout=90)
    out = proc.stdout
    assert proc.returncode == 0, out + proc.stderr
    rest = [line for line in out.splitlines() if line.startswith("at rest (ground truth): ")]
    assert len(rest) == 1 and rest[0].startswith("at rest (ground truth): height 0.132 m (its geometry rests at "
                                                 "0.132 m), tilt 0.000 rad") and rest[0].endswith(": PASS"), out
    assert sum(line.startswith("  body (ground truth): height 0.13") for line in out.splitlines()) == 2, out


def test_a_robot_without_a_drive_fails(tmp_path):
    proc = run_check(tmp_path, os.path.join(ROBOTS, "no_drive.urdf"))
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "result: FAIL: no drive was found, so there is nothing to drive" in proc.stdout.splitlines()
    assert any(line.startswith("drive: none found") for line in proc.stdout.splitlines())


def test_bad_usage_is_status_2(tmp_path):
    proc = run_check(tmp_path)
    assert proc.returncode == 2 and "usage: rosrun diffbot_sim robot_check" in proc.stderr
    proc = run_check(tmp_path, "--fast", os.path.join(ROBOTS, "no_drive.urdf"))
    assert proc.returncode == 2 and "unknown option --fast" in proc.stderr


@pytest.mark.parametrize("args, culprit", [
    (("missing.urdf",), "missing.urdf: no such file"),
    (("tests/data/truncated.urdf",), "truncated.urdf: malformed XML"),
    (("tests/data/robots/pid_robot.urdf", "nope.yaml"), "nope.yaml: no such file"),
])
def test_a_bad_model_is_one_line_and_status_1(tmp_path, args, culprit):
    proc = run_check(tmp_path, *[os.path.join(ROOT, a) for a in args])
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert proc.stderr.count("\n") == 1 and proc.stderr.startswith("robot_check: ") and culprit in proc.stderr, \
        proc.stderr
    assert "Traceback" not in proc.stdout + proc.stderr


def test_the_mobile_manipulator_drives_and_moves_its_arm(tmp_path):
    proc = run_check(tmp_path, os.path.join(ROOT, "urdf", "diffbot_arm.urdf.xacro"),
                     os.path.join(ROOT, "config", "diffbot_arm_control.yaml"), timeout=120)
    out = proc.stdout
    assert proc.returncode == 0, out + proc.stderr
    lines = out.splitlines()
    assert len(lines) <= 50, out
    # each transmission joint: interface and control method, limits (URDF), controller (YAML), role
    assert "joints with a transmission: 8" in lines
    assert ("  shoulder_pitch_joint: revolute, PositionJointInterface (position, pid_gains p 20), [-1.8, 1.8] rad, "
            "1.5 rad/s, 6 N·m; arm_controller (position_controllers/JointTrajectoryController)") in lines, out
    assert ("  left_finger_joint: prismatic, EffortJointInterface (effort), [0, 0.035] m, 0.1 m/s, 10 N; "
            "gripper_controller (effort_controllers/GripperActionController)") in lines, out
    assert any(line.startswith("  right_finger_joint: ") and line.endswith("mimic of left_finger_joint (plugin)")
               for line in lines), out
    assert any(line.startswith("  left_wheel_joint: ") and line.endswith("drive wheel") for line in lines), out
    assert not any("NOT simulated  controller" in line for line in lines), out
    # every arm joint moved out and back by its controller, the body judged each time
    moves = [line for line in lines if line.startswith(("  arm_controller ", "  gripper_controller "))]
    assert len(moves) == 4 and all(line.endswith(": PASS") for line in moves), out
    assert all(joint in moves[0] for joint in ("shoulder_yaw_joint", "shoulder_pitch_joint", "elbow_joint",
                                               "wrist_joint")), out
    assert "left_finger_joint" in moves[2], out
    assert lines[-1] == "result: PASS: the robot drives and its arm joints move as commanded"


def test_an_arm_joint_that_cannot_move_fails(tmp_path):
    # arm_frozen_joint: joint_2's URDF <limit velocity="0"> rate-limits its position commands to nothing
    proc = run_check(tmp_path, os.path.join(ROBOTS, "arm_frozen_joint.urdf"),
                     os.path.join(ROBOTS, "arm_position_pid.yaml"), timeout=90)
    out = proc.stdout
    assert proc.returncode == 1, out + proc.stderr
    lines = out.splitlines()
    assert any(line.startswith("  joint_2: revolute, PositionJointInterface") and ", 0 rad/s, " in line
               for line in lines), out
    out_move = next(line for line in lines if line.startswith("  arm_controller out: "))
    assert out_move.endswith(": FAIL") and "ABORTED" in out_move, out
    assert any(line.startswith("    joint_2 at ") and "sent to" in line for line in lines), out
    assert lines[-1] == "result: FAIL: the arm does not move as commanded (ground truth)"


def test_a_force_based_mecanum_base_drives_sideways_too(tmp_path):
    """A holonomic base (a vendor force-based move plugin on frictionless wheels) is also driven sideways and
    judged by ground truth, as the holonomic drive suites judge it."""
    proc = run_check(tmp_path, os.path.join(ROBOTS, "force_based_mecanum.urdf"),
                     os.path.join(ROBOTS, "force_based_mecanum.yaml"), timeout=90)
    out = proc.stdout
    lines = out.splitlines()
    assert any(line.startswith("drive: ") and "force_based_move" in line for line in lines), out
    assert any(line.startswith("sideways 0.2 m/s x 4 s: ") and line.endswith(": PASS") for line in lines), out
    assert proc.returncode == 0, out + proc.stderr
    assert lines[-1] == "result: PASS: the robot drives"
