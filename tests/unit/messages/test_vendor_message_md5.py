"""The vendor message packages of the overlay are their upstreams', md5 sum for md5 sum.

ROS 1 peers refuse a connection whose md5 sum differs, so a client of four_wheel_steering_controller,
a Kobuki's event listeners, a link-attacher caller or a franka_gazebo user (FrankaState, the gripper's actions)
connects here only with upstream's definitions.

UPSTREAM_MD5 was computed with ``genmsg.compute_md5`` from the files of each pinned upstream commit (named in
each package's README.md), exported to a temporary directory, with Debian's /usr/share/<pkg>/msg for the
standard dependencies; FourWheelSteeringStamped's value also appears in code others generated from the real
package (rosserial, genlisp, gennodejs), and so do BumperEvent's, Attach's and FrankaState's. An .action is first
expanded by Debian's actionlib_msgs genaction.py (what catkin's add_action_files runs) into its seven messages.
"""
import glob
import importlib
import os

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
OVERLAY = os.path.join(ROOT, "overlay")

UPSTREAM_MD5 = {
    "four_wheel_steering_msgs/FourWheelSteering": "04dd0f55e1f168668af1e2587a7cdd2a",
    "four_wheel_steering_msgs/FourWheelSteeringStamped": "9226582df815bc6df9e3206bc05923af",
    "kobuki_msgs/AutoDockingAction": "44be114f3afc06365a090db0a5e982b5",
    "kobuki_msgs/AutoDockingActionFeedback": "6f7132467beab5153587d9ebb8d8262d",
    "kobuki_msgs/AutoDockingActionGoal": "4b30be6cd12b9e72826df56b481f40e0",
    "kobuki_msgs/AutoDockingActionResult": "3fb2b9cd9cec6b4cb23b224521dd7679",
    "kobuki_msgs/AutoDockingFeedback": "03343b6aa0067ce6251bcc08bf318388",
    "kobuki_msgs/AutoDockingGoal": "d41d8cd98f00b204e9800998ecf8427e",
    "kobuki_msgs/AutoDockingResult": "74697ed3d931f6eede8bf3a8dfeca160",
    "kobuki_msgs/BumperEvent": "ffe360cd50f14f9251d9844083e72ac5",
    "kobuki_msgs/ButtonEvent": "49eca512765dbdec759a79083ffcec8d",
    "kobuki_msgs/CliffEvent": "c5b106efbb1427a94f517c5e05f06295",
    "kobuki_msgs/ControllerInfo": "46af38e72f0640f41ed22174d43a2550",
    "kobuki_msgs/DigitalInputEvent": "93da823c8b121f8a3940ef3830c58e44",
    "kobuki_msgs/DigitalOutput": "1e97cd7f196a0270516b506e8bf29ca2",
    "kobuki_msgs/DockInfraRed": "a3d77f7d15e50579473dcc24e9b97b34",
    "kobuki_msgs/ExternalPower": "95149d524971a4c6d19e64c827307194",
    "kobuki_msgs/KeyboardInput": "9288b95cb32b48719d84d696be253401",
    "kobuki_msgs/Led": "4391183b0cf05f8f25d04220401b9f43",
    "kobuki_msgs/MotorPower": "8f77c0161e0f2021493136bb5f3f0e51",
    "kobuki_msgs/PowerSystemEvent": "f6464657d6c911b00c7bc7b43a154bf8",
    "kobuki_msgs/RobotStateEvent": "c6eccd4cb1f95df95635b56d6226ea32",
    "kobuki_msgs/ScanAngle": "06e2c839dc5c7f5c13ac09a8b4ff0a6a",
    "kobuki_msgs/SensorState": "430a4bfd78449c8740bfef32b26613a6",
    "kobuki_msgs/Sound": "dfeab0daae67749c426c1db741a4f420",
    "kobuki_msgs/VersionInfo": "3dc0ce6edd49be1fc86730f4a4a21861",
    "kobuki_msgs/WheelDropEvent": "e102837d89384d67669a0df86b63f33b",
    "gazebo_ros_link_attacher/Attach": "c91fb3be70ce66d19130d40294cf4bd5",
    "franka_gripper/GraspAction": "6f89449359949eaf1f0fef57b7e0db2a",
    "franka_gripper/GraspActionFeedback": "aae20e09065c3809e8a8e87c4c8953fd",
    "franka_gripper/GraspActionGoal": "7bd1a6e7f94ef15bb6dd05cb170e7909",
    "franka_gripper/GraspActionResult": "89dbc4e75593b525bbbea3a150532ed6",
    "franka_gripper/GraspEpsilon": "95b2c5464a6f679bd1dacaf86414f095",
    "franka_gripper/GraspFeedback": "d41d8cd98f00b204e9800998ecf8427e",
    "franka_gripper/GraspGoal": "627a0f0b10ad0c919fbd62b0b3427e63",
    "franka_gripper/GraspResult": "45872d25d65c97743cc71afc6d4e884d",
    "franka_gripper/HomingAction": "f37964fcdec026d9507d088d32b65b38",
    "franka_gripper/HomingActionFeedback": "aae20e09065c3809e8a8e87c4c8953fd",
    "franka_gripper/HomingActionGoal": "4b30be6cd12b9e72826df56b481f40e0",
    "franka_gripper/HomingActionResult": "89dbc4e75593b525bbbea3a150532ed6",
    "franka_gripper/HomingFeedback": "d41d8cd98f00b204e9800998ecf8427e",
    "franka_gripper/HomingGoal": "d41d8cd98f00b204e9800998ecf8427e",
    "franka_gripper/HomingResult": "45872d25d65c97743cc71afc6d4e884d",
    "franka_gripper/MoveAction": "85e8e11f508e446b706022926779afee",
    "franka_gripper/MoveActionFeedback": "aae20e09065c3809e8a8e87c4c8953fd",
    "franka_gripper/MoveActionGoal": "f8907a1e7bb902f2e4c7db8e1cf3d24f",
    "franka_gripper/MoveActionResult": "89dbc4e75593b525bbbea3a150532ed6",
    "franka_gripper/MoveFeedback": "d41d8cd98f00b204e9800998ecf8427e",
    "franka_gripper/MoveGoal": "d16050a0fe85f1c2cb8347c99678362e",
    "franka_gripper/MoveResult": "45872d25d65c97743cc71afc6d4e884d",
    "franka_gripper/StopAction": "f37964fcdec026d9507d088d32b65b38",
    "franka_gripper/StopActionFeedback": "aae20e09065c3809e8a8e87c4c8953fd",
    "franka_gripper/StopActionGoal": "4b30be6cd12b9e72826df56b481f40e0",
    "franka_gripper/StopActionResult": "89dbc4e75593b525bbbea3a150532ed6",
    "franka_gripper/StopFeedback": "d41d8cd98f00b204e9800998ecf8427e",
    "franka_gripper/StopGoal": "d41d8cd98f00b204e9800998ecf8427e",
    "franka_gripper/StopResult": "45872d25d65c97743cc71afc6d4e884d",
    "franka_msgs/ErrorRecoveryAction": "d5a016b49f278075666fbc901debbd08",
    "franka_msgs/ErrorRecoveryActionFeedback": "aae20e09065c3809e8a8e87c4c8953fd",
    "franka_msgs/ErrorRecoveryActionGoal": "4b30be6cd12b9e72826df56b481f40e0",
    "franka_msgs/ErrorRecoveryActionResult": "1eb06eeff08fa7ea874431638cb52332",
    "franka_msgs/ErrorRecoveryFeedback": "d41d8cd98f00b204e9800998ecf8427e",
    "franka_msgs/ErrorRecoveryGoal": "d41d8cd98f00b204e9800998ecf8427e",
    "franka_msgs/ErrorRecoveryResult": "d41d8cd98f00b204e9800998ecf8427e",
    "franka_msgs/Errors": "082e9a670c96d8bc64b53e32777458e7",
    "franka_msgs/FrankaState": "431567d5df6caf4e4dd7385f25cb71ee",
    "franka_msgs/SetCartesianImpedance": "c648a0b1340a53eac0c535568e9b5c60",
    "franka_msgs/SetEEFrame": "459aea8fa6dbdd34ba4bc52d3eddbacf",
    "franka_msgs/SetForceTorqueCollisionBehavior": "b1e592d1b6960bc05e6e3cba1eb02349",
    "franka_msgs/SetFullCollisionBehavior": "c6fef9a8ad446db9a39cca3b7bc200d8",
    "franka_msgs/SetJointImpedance": "f11c4defa2a13040512214f9d77dc982",
    "franka_msgs/SetKFrame": "11b22d30e6a11a7b51828be575a77359",
    "franka_msgs/SetLoad": "c9a8ec436164dd9cbc1e5e137d358e0b",
}
PACKAGES = sorted({name.split("/")[0] for name in UPSTREAM_MD5})
GENACTION = "/usr/lib/actionlib_msgs/genaction.py"
ACTION_SUFFIXES = ("Action", "ActionGoal", "ActionResult", "ActionFeedback", "Goal", "Result", "Feedback")


def _overlay_types(pkg):
    out = set()
    for kind in ("msg", "srv"):
        for path in glob.glob(os.path.join(OVERLAY, pkg, kind, "*." + kind)):
            out.add(f"{pkg}/{os.path.basename(path)[:-len(kind) - 1]}")
    for path in glob.glob(os.path.join(OVERLAY, pkg, "action", "*.action")):
        out.update(f"{pkg}/{os.path.basename(path)[:-7]}{suffix}" for suffix in ACTION_SUFFIXES)
    return out


@pytest.fixture(scope="module")
def action_dirs(tmp_path_factory):
    """{package: the messages genaction makes of the overlay's .action text}."""
    import subprocess
    import sys

    dirs = {}
    for pkg in PACKAGES:
        actions = glob.glob(os.path.join(OVERLAY, pkg, "action", "*.action"))
        if actions and os.path.isfile(GENACTION):
            out = str(tmp_path_factory.mktemp(pkg))
            for action in actions:
                subprocess.run([sys.executable, GENACTION, action, "-o", out], check=True, capture_output=True)
            dirs[pkg] = out
    return dirs


def test_table_covers_every_definition():
    assert set().union(*(_overlay_types(pkg) for pkg in PACKAGES)) == set(UPSTREAM_MD5)


@pytest.mark.parametrize("full_type", sorted(UPSTREAM_MD5))
def test_overlay_text_hashes_to_upstreams_md5(full_type, action_dirs):
    pytest.importorskip("genmsg")
    import genmsg.gentools
    import genmsg.msg_loader

    pkg, name = full_type.split("/")
    search = {p: [os.path.join(OVERLAY, p, "msg")] + ([action_dirs[p]] if p in action_dirs else []) for p in PACKAGES}
    for dep in ("std_msgs", "geometry_msgs", "sensor_msgs", "actionlib_msgs"):
        search[dep] = [f"/usr/share/{dep}/msg"]
    ctx = genmsg.MsgContext.create_default()
    if os.path.exists(os.path.join(OVERLAY, pkg, "srv", name + ".srv")):
        spec = genmsg.msg_loader.load_srv_from_file(ctx, os.path.join(OVERLAY, pkg, "srv", name + ".srv"),
                                                    full_type)
        genmsg.msg_loader.load_depends(ctx, spec.request, search)
        genmsg.msg_loader.load_depends(ctx, spec.response, search)
    else:
        spec = genmsg.msg_loader.load_msg_by_type(ctx, full_type, search)
        genmsg.msg_loader.load_depends(ctx, spec, search)
    assert genmsg.gentools.compute_md5(ctx, spec) == UPSTREAM_MD5[full_type]


@pytest.mark.parametrize("full_type", sorted(UPSTREAM_MD5))
def test_built_classes_carry_upstreams_md5(full_type):
    pkg, name = full_type.split("/")
    sub = "srv" if os.path.exists(os.path.join(OVERLAY, pkg, "srv", name + ".srv")) else "msg"
    try:
        module = importlib.import_module(f"{pkg}.{sub}")
    except ImportError:
        if os.environ.get("DIFFBOT_SIM_OVERLAY") == "0":
            pytest.skip(f"{pkg} is not installed and DIFFBOT_SIM_OVERLAY=0 leaves the overlay out")
        raise AssertionError(f"{pkg}.{sub} does not import: run `make setup` and the tests through "
                             "tools/rosenv.sh") from None
    assert getattr(module, name)._md5sum == UPSTREAM_MD5[full_type]
