"""messages/controllers.py: control_msgs and trajectory_msgs of the simulated ros_controllers, to and from the
plain data of control/."""
import math

import genpy
import pytest
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from diffbot_sim.control.gripper_action_controller import GripperResult
from diffbot_sim.control.trajectory import TrajectoryPoint
from diffbot_sim.messages import controllers

pytest.importorskip("control_msgs.msg", reason="the control_msgs overlay is not built")


def trajectory(*points):
    return JointTrajectory(joint_names=["a", "b"], points=[
        JointTrajectoryPoint(positions=p, velocities=v, time_from_start=genpy.Duration.from_sec(t))
        for p, v, t in points])


def test_points_become_plain_trajectory_points_in_seconds():
    points = controllers.trajectory_points(trajectory(([0.1, 0.2], [], 0.5), ([0.3, 0.4], [1.0, 2.0], 1.25)))
    assert points == [TrajectoryPoint((0.1, 0.2), (), (), 0.5), TrajectoryPoint((0.3, 0.4), (1.0, 2.0), (), 1.25)]


def test_a_non_finite_number_is_named():
    assert controllers.finite_trajectory(trajectory(([0.1, 0.2], [], 0.5))) is None
    reason = controllers.finite_trajectory(trajectory(([0.1, 0.2], [], 0.5), ([0.3, math.nan], [], 1.0)))
    assert reason == "point 1 positions[1] is nan (not a finite number)"
    reason = controllers.finite_trajectory(trajectory(([0.1, 0.2], [0.0, math.inf], 0.5)))
    assert reason == "point 0 velocities[1] is inf (not a finite number)"


def test_tolerances_and_results():
    from control_msgs.msg import JointTolerance

    assert controllers.tolerances([JointTolerance(name="a", position=0.1, velocity=-1.0, acceleration=0.0)]) == [
        ("a", 0.1, -1.0, 0.0)]
    result = controllers.trajectory_result(-4, "path tolerance violated")
    assert (result.error_code, result.error_string) == (-4, "path tolerance violated")
    gripper = controllers.gripper_result(GripperResult(0.02, 1.5, True, False))
    assert (gripper.position, gripper.effort, gripper.stalled, gripper.reached_goal) == (0.02, 1.5, True, False)


def test_query_state_response_lists_each_joint():
    response = controllers.query_state_response(("a", "b"), ((0.1, 0.2), (0.0, 1.0), (0.0, 0.0)))
    assert response.name == ["a", "b"] and response.position == [0.1, 0.2] and response.velocity == [0.0, 1.0]
