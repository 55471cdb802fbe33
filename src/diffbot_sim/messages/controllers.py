"""The control_msgs and trajectory_msgs the simulated ros_controllers read and build (message modules only, no
rospy): trajectories and tolerances into the plain data of :mod:`diffbot_sim.control`, and the state, feedback,
result and query answers out of it.

control_msgs is not a Debian package: it comes from the overlay (``overlay/control_msgs``), so this module
imports it lazily and the rest of the package loads without it.
"""
import math

import genpy
from std_msgs.msg import Header

from diffbot_sim.control.trajectory import TrajectoryPoint


def control_msgs():
    """The ``control_msgs.msg`` and ``control_msgs.srv`` modules (ImportError when the overlay is left out)."""
    from control_msgs import msg, srv

    return msg, srv


def trajectory_points(trajectory):
    """A ``trajectory_msgs/JointTrajectory``'s points as :class:`TrajectoryPoint` (time_from_start in s)."""
    return [TrajectoryPoint(tuple(p.positions), tuple(p.velocities), tuple(p.accelerations),
                            p.time_from_start.to_sec()) for p in trajectory.points]


def tolerances(entries):
    """``control_msgs/JointTolerance[]`` as ``(name, position, velocity, acceleration)`` entries."""
    return [(t.name, t.position, t.velocity, t.acceleration) for t in entries]


def finite_trajectory(trajectory):
    """None when every number of the trajectory is finite, else a sentence naming the first bad one (a NaN
    must never reach a joint; upstream would follow it)."""
    for k, point in enumerate(trajectory.points):
        for field in ("positions", "velocities", "accelerations", "effort"):
            for j, value in enumerate(getattr(point, field)):
                if not math.isfinite(value):
                    return f"point {k} {field}[{j}] is {value} (not a finite number)"
        if not math.isfinite(point.time_from_start.to_sec()):
            return f"point {k} time_from_start is not finite"
    return None


def _fill(state, values):
    state.positions, state.velocities, state.accelerations = (list(v) for v in values[:3])


def trajectory_state(stamp, joints, update):
    """``control_msgs/JointTrajectoryControllerState`` of one update (a :class:`JtcUpdate`)."""
    msg, _ = control_msgs()
    out = msg.JointTrajectoryControllerState(header=Header(stamp=stamp), joint_names=list(joints))
    _fill_update(out, update)
    return out


def _fill_update(out, update):
    for name in ("desired", "actual", "error"):
        state, values = getattr(out, name), getattr(update, name)
        _fill(state, values)
        state.time_from_start = genpy.Duration.from_sec(values.time_from_start)


def trajectory_feedback(stamp, joints, update):
    """``FollowJointTrajectoryFeedback`` of one update."""
    msg, _ = control_msgs()
    out = msg.FollowJointTrajectoryFeedback(header=Header(stamp=stamp), joint_names=list(joints))
    _fill_update(out, update)
    return out


def trajectory_result(error_code, error_string=""):
    msg, _ = control_msgs()
    return msg.FollowJointTrajectoryResult(error_code=error_code, error_string=error_string)


def query_state_response(names, values):
    """``QueryTrajectoryState`` response: ``values`` (positions, velocities, accelerations)."""
    _, srv = control_msgs()
    positions, velocities, accelerations = values
    return srv.QueryTrajectoryStateResponse(name=list(names), position=list(positions),
                                            velocity=list(velocities), acceleration=list(accelerations))


def gripper_result(result):
    """``GripperCommandResult`` from a :class:`diffbot_sim.control.gripper_action_controller.GripperResult`."""
    msg, _ = control_msgs()
    return msg.GripperCommandResult(position=result.position, effort=result.effort, stalled=result.stalled,
                                    reached_goal=result.reached_goal)


def joint_controller_state(stamp, state):
    """``control_msgs/JointControllerState`` of a PID forward controller (its ``state`` fields)."""
    msg, _ = control_msgs()
    out = msg.JointControllerState(header=Header(stamp=stamp))
    for key, value in vars(state).items():
        if hasattr(out, key):
            setattr(out, key, value)
    return out
