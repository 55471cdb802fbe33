"""franka_gazebo's FrankaGripperSim without ROS (control/franka_gripper): two fingers of 15 g on prismatic
joints integrated here (semi-implicit Euler at 1 ms, an optional block that stops them), driven by the core's
efforts; each goal judged by the width the fingers reach and the answer upstream's callbacks give."""
import pytest

from diffbot_sim.control import franka_gripper as fg
from diffbot_sim.control.pid import PidGains
from diffbot_sim.errors import ConfigError

DT, MASS = 0.001, 0.015


def core():
    params = {"arm_id": "panda", "finger1": {"gains": {"p": 100, "d": 1.0}}, "finger2": {"gains": {"p": 100, "d": 1.0}}}
    cfg = fg.gripper_config(params, "/franka_gripper", {"panda_finger_joint1", "panda_finger_joint2"})
    gripper = fg.FrankaGripperCore(cfg)
    gripper.starting()
    return gripper


def run(gripper, q, seconds, block=None):
    """The fingers under the core's efforts for ``seconds``; a block of width ``block`` stops them closing."""
    v = [0.0, 0.0]
    done = []
    for _ in range(round(seconds / DT)):
        efforts = gripper.update(DT, q, v)
        for i in range(2):
            v[i] += efforts[i] / MASS * DT
            q[i] = min(max(q[i] + v[i] * DT, 0.0), 0.04)
            if block is not None and q[i] < block / 2:
                q[i], v[i] = block / 2, 0.0
            if q[i] in (0.0, 0.04):
                v[i] = 0.0
        done += gripper.take_finished()
    return q, done


def test_a_move_reaches_its_width_and_succeeds():
    gripper = core()
    assert gripper.move("m", 0.06, 0.1) is None
    q, done = run(gripper, [0.001, 0.001], 1.0)
    assert sum(q) == pytest.approx(0.06, abs=0.001) and gripper.state == fg.IDLE
    assert [(d.goal_id, d.outcome, d.success) for d in done] == [("m", "succeeded", True)]


def test_a_grasp_holds_the_block_with_its_force_and_succeeds_within_epsilon():
    gripper = core()
    q, _ = run(gripper, [0.04, 0.04], 0.01)
    assert gripper.grasp("g", 0.03, 0.05, 20.0, 0.005, 0.005, sum(q)) is None
    q, done = run(gripper, q, 1.5, block=0.03)
    assert gripper.state == fg.HOLDING and gripper.target.force == -20.0  # closing: pushing inwards
    assert [(d.outcome, d.success) for d in done] == [("succeeded", True)]
    wrong = core()
    wrong.grasp("w", 0.05, 0.05, 20.0, 0.002, 0.002, 0.08)
    _, done = run(wrong, [0.04, 0.04], 1.5, block=0.03)
    assert (done[0].outcome, done[0].success) == ("succeeded", False) and "but at 0.030000m" in done[0].error
    assert wrong.state == fg.IDLE


def test_homing_closes_and_opens_fully_and_stop_interrupts():
    gripper = core()
    gripper.homing("h")
    q, done = run(gripper, [0.02, 0.02], 6.0)
    assert [(d.goal_id, d.outcome) for d in done] == [("h", "succeeded")] and sum(q) == pytest.approx(0.08, abs=0.002)
    gripper.move("m", 0.0, 0.01)
    gripper.stop("s")
    assert [(d.goal_id, d.outcome) for d in gripper.take_finished()] == [("m", "aborted"), ("s", "succeeded")]


def test_refusals_in_upstreams_words():
    gripper = core()
    assert gripper.move("m", 0.09, 0.1) == "Target width has to lie between 0 .. 0.080000"
    assert gripper.move("m", 0.05, -1) == "Only positive speeds allowed"
    assert gripper.grasp("g", 0.08, 0.1, 1, 0, 0, 0.0).startswith("Can only grasp inside finger width")
    assert "Commanding out of range position!" in gripper.gripper_command("c", 0.05, 1.0, 0.0)
    with pytest.raises(ConfigError, match="finger1/gains"):
        fg.gripper_config({"arm_id": "panda"}, "/g", {"panda_finger_joint1", "panda_finger_joint2"})
    assert isinstance(gripper.cfg.gains1, PidGains)
