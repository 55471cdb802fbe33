"""joint_trajectory_controller: parameters (joint_trajectory_config), the per-update core and its
action/topic/service answers, run closed loop against simulated joints (a position interface that reaches each
command one update later, and a double integrator driven by effort), at a fixed 0.01 s control period from sim
time 100 s.
"""
import math

import pytest

from diffbot_sim.control import joint_trajectory_controller as jtc, trajectory as tr
from diffbot_sim.control.joint_trajectory_config import jtc_config
from diffbot_sim.control.joint_trajectory_controller import ControllerCrash, JointTrajectoryControllerCore
from diffbot_sim.control.trajectory import TrajectoryPoint as P
from diffbot_sim.errors import ConfigError

NS = "/arm_controller"
DT = 0.01
T0 = 100.0
URDF = {"shoulder": ("revolute", -3.0, 3.0), "wrist": ("continuous", 0.0, 0.0), "slide": ("prismatic", 0.0, 1.0)}
JOINTS = ["shoulder", "wrist"]


def params(kind="position", **extra):
    value = {"type": f"{kind}_controllers/JointTrajectoryController", "joints": list(JOINTS)}
    if kind in ("effort", "velocity"):
        value["gains"] = {joint: {"p": 100.0, "d": 10.0} for joint in JOINTS}
    value.update(extra)
    return value


def controller(kind="position", **extra):
    return JointTrajectoryControllerCore(jtc_config(params(kind, **extra), NS, URDF))


class PositionArm:
    """Joints whose position becomes the command at the next update; ``stuck`` joints ignore commands and
    ``offset`` joints settle that far from them."""

    def __init__(self, core, positions=(0.0, 0.0)):
        self.core, self.t = core, T0
        self.pos, self.vel = list(positions), [0.0] * len(positions)
        self.stuck, self.offset = set(), [0.0] * len(positions)
        self.first_commands = core.starting(self.t, self.pos, self.vel)

    def step(self):
        self.t += DT
        update = self.core.update(self.t, DT, self.pos, self.vel)
        for joint, command in enumerate(update.commands):
            if joint not in self.stuck:
                target = command + self.offset[joint]
                self.vel[joint], self.pos[joint] = (target - self.pos[joint]) / DT, target
        return update

    def run(self, seconds):
        return [self.step() for _ in range(round(seconds / DT))]


def events(updates):
    return [(u_index, event) for u_index, update in enumerate(updates) for event in update.events]


def goal(core, goal_id, points, joints=JOINTS, **kw):
    return core.goal(goal_id, joints, points, **kw)


# --- parameters --------------------------------------------------------------------------------------------

def test_defaults_and_constraints():
    cfg = jtc_config(params(constraints={"goal_time": 0.6, "stopped_velocity_tolerance": 0.02,
                                         "shoulder": {"trajectory": 0.05, "goal": 0.03}}), NS, URDF)
    assert (cfg.variant, cfg.joints, cfg.wraparound) == ("position", ("shoulder", "wrist"), (False, True))
    assert (cfg.state_publish_rate, cfg.action_monitor_rate, cfg.stop_trajectory_duration,
            cfg.allow_partial_joints_goal) == (50.0, 20.0, 0.0, False)
    shoulder, wrist = cfg.default_tolerances
    assert (shoulder.path.position, shoulder.goal.position, shoulder.goal.velocity, shoulder.goal_time) == \
        (0.05, 0.03, 0.02, 0.6)
    assert (wrist.path.position, wrist.goal.position, wrist.goal.velocity) == (0.0, 0.0, 0.02)
    assert jtc_config(params(), NS, URDF).default_tolerances[0].goal.velocity == 0.01


@pytest.mark.parametrize("kind, variant", [("position", "position"), ("velocity", "velocity"),
                                           ("effort", "effort"), ("pos_vel", "position"), ("pos_vel_acc", "position")])
def test_the_variant_comes_from_the_type(kind, variant):
    assert jtc_config(params(kind), NS, URDF).variant == variant


@pytest.mark.parametrize("change, name", [
    ({"type": "effort_controllers/JointPositionController"}, NS + "/type"),
    ({"joints": []}, NS + "/joints"),
    ({"joints": "shoulder"}, NS + "/joints"),
    ({"joints": ["shoulder", 3]}, NS + "/joints"),
    ({"joints": ["elbow"]}, NS + "/joints"),
    ({"stop_trajectory_duration": -1.0}, NS + "/stop_trajectory_duration"),
    ({"state_publish_rate": 0.0}, NS + "/state_publish_rate"),
    ({"constraints": {"shoulder": {"goal": "tight"}}}, NS + "/constraints/shoulder/goal"),
    ({"allow_partial_joints_goal": "maybe"}, NS + "/allow_partial_joints_goal"),
])
def test_bad_parameters_name_the_parameter(change, name):
    with pytest.raises(ConfigError) as info:
        jtc_config(params(**change), NS, URDF)
    assert info.value.name == name


def test_an_effort_controller_without_gains_loads_with_upstreams_messages_but_cannot_start():
    cfg = jtc_config(params("effort", gains={"shoulder": {"p": 5.0}}), NS, URDF)
    assert cfg.log == (("error", "No p gain specified for pid.  Namespace: /arm_controller/gains/wrist"),
                       ("warn", "Failed to initialize PID gains from ROS parameter server."))
    assert "wrist" in cfg.start_crash and cfg.velocity_ff == ()
    core = JointTrajectoryControllerCore(cfg)
    assert core.take_log() == list(cfg.log)
    with pytest.raises(ControllerCrash, match="crashes"):
        core.starting(T0, [0.0, 0.0], [0.0, 0.0])
    assert jtc_config(params("position", gains={}), NS, URDF).start_crash is None  # gains unused there
    assert jtc_config(params("effort", velocity_ff={"wrist": 2.0}), NS, URDF).velocity_ff == (0.0, 2.0)


# --- starting and holding ----------------------------------------------------------------------------------

def test_starting_holds_the_measured_position():
    arm = PositionArm(controller(), [0.3, -1.0])
    assert arm.first_commands == (0.3, -1.0)
    update = arm.step()
    assert update.commands == (0.3, -1.0) and update.desired.velocities == (0.0, 0.0) and update.events == ()
    assert JointTrajectoryControllerCore(jtc_config(params("effort"), NS, URDF)).starting(
        T0, [0.3, 0.0], [0.0, 0.0]) == (0.0, 0.0)


def test_starting_while_moving_with_a_stop_duration_ramps_down():
    core = controller(stop_trajectory_duration=0.5)
    core.starting(T0, [0.2, 0.0], [1.0, 0.0])
    first = core.update(T0 + DT, DT, [0.21, 0.0], [1.0, 0.0])
    assert 0.9 < first.desired.velocities[0] < 1.0 and first.desired.positions[0] > 0.2
    last = core.update(T0 + 0.5, 0.49, [0.3, 0.0], [0.0, 0.0]).desired  # the end of the ramp
    assert last.positions == pytest.approx((0.2 + 0.3125 * 1.0 * 1.0, 0.0))  # p + 5vT/16, T = 2 × 0.5 s
    assert last.velocities == pytest.approx((0.0, 0.0), abs=1e-12)


def test_a_goal_succeeds_once_inside_the_goal_tolerance():
    core = controller(constraints={"shoulder": {"goal": 0.01}, "wrist": {"goal": 0.01}})
    arm = PositionArm(core)
    arm.step()
    answer = goal(core, "g1", [P([0.5, -0.5], time_from_start=1.0)])
    assert answer == jtc.GoalAnswer(True, jtc.SUCCESSFUL, "", None) and core.active_goal == "g1"
    updates = arm.run(1.5)
    done = events(updates)
    # the trajectory ends at uptime 1.02 s (update 100): at its very end the segment still reports its
    # velocity, which the following joint matches, and the joint is within 0.01 rad
    assert done == [(100, jtc.GoalEvent("g1", "SUCCEEDED", jtc.SUCCESSFUL, ""))]
    assert updates[100].feedback_goal_id is None and updates[99].feedback_goal_id == "g1"
    assert arm.pos == pytest.approx([0.5, -0.5]) and core.active_goal is None


def test_a_path_violation_aborts_with_minus_4_and_the_trajectory_goes_on():
    core = controller(constraints={"shoulder": {"trajectory": 0.05}})
    arm = PositionArm(core)
    arm.step()
    goal(core, "g1", [P([1.0, 0.0], time_from_start=1.0)])
    arm.stuck.add(0)
    updates = arm.run(1.0)
    (index, event), = events(updates)
    error = updates[index].error.positions[0]
    assert event == jtc.GoalEvent("g1", "ABORTED", jtc.PATH_TOLERANCE_VIOLATED, f"shoulder path error {error:f}")
    assert error > 0.05 >= updates[index - 1].error.positions[0]
    assert updates[-1].desired.positions[0] > updates[index].desired.positions[0]  # not replaced by a hold


def test_a_goal_starting_later_checks_nothing_until_its_own_segments_run():
    core = controller(constraints={"shoulder": {"trajectory": 0.05}})
    arm = PositionArm(core)
    arm.step()
    goal(core, "g0", [P([1.0, 0.0], time_from_start=1.0)])
    arm.run(0.3)
    arm.stuck.add(0)  # goal 0's trajectory, still running, goes away from the shoulder
    start = arm.t + 0.5
    assert goal(core, "g1", [P([1.0, 0.0], time_from_start=0.5)], stamp=start).preempted_goal_id == "g0"
    updates = arm.run(1.0)
    (index, event), = events(updates)
    assert event.error_code == jtc.PATH_TOLERANCE_VIOLATED
    assert index == 49  # the update at `start` (50 × 0.01 s later): the first one in the goal's bridge
    assert updates[index - 1].error.positions[0] > 0.4  # far off before, but not the goal's segment


def test_a_goal_missed_aborts_with_minus_5_after_goal_time():
    core = controller(constraints={"goal_time": 0.5, "shoulder": {"goal": 0.01}})
    arm = PositionArm(core)
    arm.step()
    goal(core, "g1", [P([1.0, 0.0], time_from_start=1.0)])  # ends at uptime 1.02 s
    arm.offset[0] = -0.05
    updates = arm.run(2.0)
    (index, event), = events(updates)
    assert index == 150  # uptime 1.52 = end + goal_time: no longer "< end + goal_time"
    assert event == jtc.GoalEvent("g1", "ABORTED", jtc.GOAL_TOLERANCE_VIOLATED, "shoulder goal error 0.050000")


def test_goal_time_from_the_goal_overrides_and_zero_decides_at_once():
    core = controller(constraints={"goal_time": 0.5, "shoulder": {"goal": 0.01}})
    arm = PositionArm(core)
    arm.step()
    goal(core, "g1", [P([1.0, 0.0], time_from_start=1.0)], goal_time_tolerance=-1.0)
    arm.offset[0] = -0.05
    (index, event), = events(arm.run(2.0))
    assert index == 100 and event.error_code == jtc.GOAL_TOLERANCE_VIOLATED


def test_a_new_goal_preempts_the_active_one_and_an_invalid_one_does_not():
    core = controller()
    arm = PositionArm(core)
    arm.step()
    goal(core, "g1", [P([1.0, 0.0], time_from_start=1.0)])
    arm.run(0.2)
    assert goal(core, "g2", [P([0.0, 0.0], time_from_start=1.0)]) == jtc.GoalAnswer(True, 0, "", "g1")
    assert goal(core, "g3", [P([0.0], time_from_start=1.0)], joints=["shoulder"]) == \
        jtc.GoalAnswer(False, jtc.INVALID_JOINTS, "")
    assert goal(core, "g4", [P([0.0, 0.0], time_from_start=1.0)], joints=["shoulder", "elbow"]).error_code == \
        jtc.INVALID_JOINTS
    late = goal(core, "g5", [P([0.0, 0.0], time_from_start=1.0)], stamp=T0 - 1.0)
    assert late == jtc.GoalAnswer(False, jtc.INVALID_GOAL, "Dropping all 1 trajectory point(s), as they occur "
                                  "before the current time.\nLast point is 0.220000s in the past.")
    assert core.active_goal == "g2"
    assert ("error", "Joints on incoming goal don't match the controller joints.") in core.take_log()


def test_a_topic_command_preempts_the_goal():
    core = controller()
    arm = PositionArm(core)
    arm.step()
    goal(core, "g1", [P([1.0, 0.0], time_from_start=1.0)])
    arm.run(0.2)
    assert core.command(["shoulder"], [P([1.0], time_from_start=1.0)]) == tr.WRONG_JOINTS
    assert core.active_goal == "g1"
    assert core.command(JOINTS, [P([-1.0, 0.0], time_from_start=1.0)]) is None
    assert core.active_goal is None
    assert arm.step().events == (jtc.GoalEvent("g1", "PREEMPTED", jtc.SUCCESSFUL, ""),)
    arm.run(1.1)
    assert arm.pos[0] == pytest.approx(-1.0)


def test_cancel_holds_where_the_joints_are():
    core = controller()
    arm = PositionArm(core)
    arm.step()
    goal(core, "g1", [P([1.0, 0.0], time_from_start=1.0)])
    arm.run(0.5)
    assert not core.cancel("g0")
    where = arm.run(0.01)[-1].actual.positions[0]  # upstream reads the joint handles: the last measurement
    assert core.cancel("g1") and core.active_goal is None
    updates = arm.run(0.5)
    assert {u.commands[0] for u in updates} == {where} and not events(updates)


@pytest.mark.parametrize("stop", ["cancel", "empty command"])
def test_a_stop_duration_ramps_down_from_the_desired_state(stop):
    core = controller(stop_trajectory_duration=0.3)
    arm = PositionArm(core)
    arm.step()
    goal(core, "g1", [P([2.0, 0.0], [2.0, 0.0], time_from_start=1.0)])
    moving = arm.run(0.6)[-1].desired
    assert core.cancel("g1") if stop == "cancel" else core.command(JOINTS, []) is None
    updates = arm.run(0.5)
    assert updates[0].desired.velocities[0] == pytest.approx(moving.velocities[0], rel=0.1)
    assert updates[0].desired.positions[0] > moving.positions[0]  # no jump back to the measured position
    speeds = [u.desired.velocities[0] for u in updates]
    assert all(a >= b - 1e-12 for a, b in zip(speeds, speeds[1:]))  # slowing down
    assert speeds[29] == pytest.approx(0.0, abs=0.05) and speeds[31] == 0.0


def test_empty_points_hold_and_an_empty_goal_succeeds_at_the_next_update():
    core = controller()
    arm = PositionArm(core)
    arm.step()
    goal(core, "g1", [P([1.0, 0.0], time_from_start=1.0)])
    held = arm.run(0.5)[-1].actual.positions[0]
    assert core.command(["anything"], []) is None  # checked before the joints
    first = arm.step()
    assert first.commands[0] == held
    assert goal(core, "g2", []).accepted
    update = arm.step()
    assert update.events == (jtc.GoalEvent("g2", "SUCCEEDED", 0, ""),)
    assert update.commands[0] == first.actual.positions[0]


def test_partial_goals():
    assert not goal(controller(), "g", [P([1.0])], joints=["shoulder"]).accepted
    core = controller(allow_partial_joints_goal=True)
    with pytest.raises(RuntimeError):
        core.update(T0, DT, [0.0, 0.0], [0.0, 0.0])
    arm = PositionArm(core, [0.0, 0.4])
    arm.step()
    assert goal(core, "g1", [P([1.0], time_from_start=0.5)], joints=["wrist"]).accepted
    updates = arm.run(1.0)
    assert arm.pos == pytest.approx([0.0, 1.0])
    assert [event.outcome for _, event in events(updates)] == ["SUCCEEDED"]


def test_stale_successful_joints_are_kept_across_goals_as_upstream():
    """successful_joint_traj_ is only cleared on success or abort: a joint that met goal 1's tolerance still
    counts for goal 2 when goal 1 is preempted first."""
    core = controller(constraints={"goal_time": 5.0, "shoulder": {"goal": 0.01}, "wrist": {"goal": 0.01}})
    arm = PositionArm(core)
    arm.step()
    goal(core, "g1", [P([0.5, 0.5], time_from_start=0.5)])
    arm.offset[1] = 0.1  # wrist misses goal 1
    arm.run(1.0)
    assert core.active_goal == "g1"
    goal(core, "g2", [P([1.0, 0.0], time_from_start=0.5)])
    arm.offset = [0.1, 0.0]  # now the shoulder misses goal 2, the wrist makes it
    (_, event), = events(arm.run(1.0))
    assert event.outcome == "SUCCEEDED" and abs(arm.pos[0] - 1.0) > 0.05


def test_errors_use_the_angular_distance_for_every_joint_type():
    core = JointTrajectoryControllerCore(jtc_config(params(joints=["slide"]), NS, URDF))
    core.starting(T0, [0.0], [0.0])
    core.goal("g", ["slide"], [P([4.0], time_from_start=0.01)])
    update = core.update(T0 + DT, DT, [0.0], [0.0])
    assert update.desired.positions == (4.0,) and update.error.positions[0] == pytest.approx(4.0 - 2 * math.pi)


# --- closed-loop variants ----------------------------------------------------------------------------------

def test_effort_command_pushes_towards_the_desired_position_and_reaches_it():
    core = controller("effort", constraints={"goal_time": 2.0, "shoulder": {"goal": 0.02}})
    positions, velocities, t = [0.0, 0.0], [0.0, 0.0], T0
    core.starting(t, positions, velocities)
    goal(core, "g1", [P([1.0, -0.5], time_from_start=1.0)])
    outcomes = []
    for step in range(300):
        t += DT
        update = core.update(t, DT, positions, velocities)
        if step == 0:  # p 100 * 0.01 rad + d 10 * 1 rad/s of velocity error: 11 N·m
            assert update.commands == pytest.approx((11.0, -5.5))
        outcomes += [event.outcome for event in update.events]
        for joint, effort in enumerate(update.commands):  # unit inertia, semi-implicit Euler
            velocities[joint] += effort * DT
            positions[joint] += velocities[joint] * DT
    assert outcomes == ["SUCCEEDED"] and positions == pytest.approx([1.0, -0.5], abs=0.02)


def test_velocity_command_is_feed_forward_plus_pid():
    gains = {"shoulder": {"p": 2.0, "d": 0.5}, "wrist": {"p": 1.0}}
    core = controller("velocity", gains=gains, velocity_ff={"shoulder": 1.0})
    core.starting(T0, [0.0, 0.0], [0.0, 0.0])
    core.goal("g", JOINTS, [P([1.0, 1.0], time_from_start=1.0)])
    update = core.update(T0 + DT, DT, [0.0, 0.0], [0.0, 0.0])  # the linear bridge starts now: v = 1 rad/s
    assert update.desired.velocities == pytest.approx((1.0, 1.0))
    assert update.commands == pytest.approx((1.0 * 1.0 + 2.0 * 0.01 + 0.5 * 1.0, 1.0 * 0.01))
    update = core.update(T0 + 2 * DT, DT, [0.0, 0.0], [0.0, 0.0])
    assert update.commands == pytest.approx((1.0 + 2.0 * 0.02 + 0.5 * 1.0, 0.02))


# --- service, state topic, lifecycle -----------------------------------------------------------------------

def test_query_state_samples_the_trajectory_at_a_time():
    core = controller()
    assert core.query_state(T0) is None
    arm = PositionArm(core)
    arm.step()
    goal(core, "g1", [P([1.0, 2.0], time_from_start=1.0)])  # from 100.02 s to 101.02 s
    positions, velocities, accelerations = core.query_state(T0 + 0.52)
    assert positions == pytest.approx((0.5, 1.0)) and velocities == pytest.approx((1.0, 2.0))
    assert accelerations == (0.0, 0.0)
    assert core.query_state(T0 + 5.0)[0] == pytest.approx((1.0, 2.0))
    assert core.query_state(T0 - 1.0) is None  # before the hold segment the controller started with


def test_the_state_topic_is_due_at_the_publish_rate():
    arm = PositionArm(controller(state_publish_rate=50.0))
    assert [arm.step().state_due for _ in range(7)] == [False, False, True, False, True, False, True]


def test_nothing_is_accepted_before_starting_and_stopping_preempts():
    core = controller()
    assert goal(core, "g", [P([1.0, 0.0], time_from_start=1.0)]) == jtc.GoalAnswer(False, jtc.INVALID_GOAL, "")
    assert core.command(JOINTS, [P([1.0, 0.0], time_from_start=1.0)]) == \
        "Can't accept new commands. Controller is not running."
    with pytest.raises(ValueError, match="2 joints"):
        core.starting(T0, [0.0], [0.0])
    arm = PositionArm(core)
    goal(core, "g", [P([1.0, 0.0], time_from_start=1.0)])
    arm.step()
    assert core.stopping(T0 + 0.1) == (jtc.GoalEvent("g", "PREEMPTED", 0, ""),)
    assert core.active_goal is None and core.query_state(T0) is None
