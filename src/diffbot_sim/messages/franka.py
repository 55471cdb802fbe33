"""The franka_msgs and franka_gripper messages of the simulated franka_gazebo (message modules only, no rospy):
franka_msgs/FrankaState from :class:`diffbot_sim.control.franka.FrankaState`, the external wrench, and the
gripper's action results.

franka_msgs and franka_gripper are not Debian packages: they come from the overlay (``overlay/franka_msgs``,
``overlay/franka_gripper``), so this module imports them lazily and the rest of the package loads without them.
"""
from geometry_msgs.msg import WrenchStamped

#: O_ddP_O as franka_control's FrankaStateController fills it without ENABLE_BASE_ACCELERATION
O_DDP_O = (0.0, 0.0, -9.81)

#: FrankaState's fields copied from the state as they are (the rest keep the message's zeros)
STATE_FIELDS = ("cartesian_collision", "cartesian_contact", "q", "q_d", "dq", "dq_d", "ddq_d", "tau_J", "dtau_J",
                "tau_J_d", "K_F_ext_hat_K", "joint_collision", "joint_contact", "O_F_ext_hat_K",
                "tau_ext_hat_filtered", "m_ee", "F_x_Cee", "I_ee", "m_load", "F_x_Cload", "I_load", "m_total",
                "I_total", "O_T_EE", "F_T_EE", "F_T_NE", "NE_T_EE", "EE_T_K", "time", "robot_mode")


def franka_msgs():
    """The ``franka_msgs.msg`` and ``franka_msgs.srv`` modules (ImportError when the overlay is left out)."""
    from franka_msgs import msg, srv

    return msg, srv


def franka_gripper_msgs():
    """The ``franka_gripper.msg`` module (ImportError when the overlay is left out)."""
    from franka_gripper import msg

    return msg


def franka_state(stamp, seq, state):
    """franka_msgs/FrankaState of ``state`` (a :class:`diffbot_sim.control.franka.FrankaState`)."""
    msg = franka_msgs()[0].FrankaState()
    for name in STATE_FIELDS:
        value = getattr(state, name)
        setattr(msg, name, list(value) if isinstance(value, (list, tuple)) else value)
    msg.O_ddP_O = list(O_DDP_O)
    msg.control_command_success_rate = 1.0
    msg.header.stamp, msg.header.seq = stamp, seq
    return msg


def external_wrench(stamp, frame, wrench):
    """geometry_msgs/WrenchStamped of ``wrench`` (fx, fy, fz, tx, ty, tz) in ``frame`` (FrankaStateController's
    F_ext)."""
    msg = WrenchStamped()
    msg.header.stamp, msg.header.frame_id = stamp, frame
    f, t = msg.wrench.force, msg.wrench.torque
    f.x, f.y, f.z, t.x, t.y, t.z = wrench
    return msg


def gripper_result(kind, success, error):
    """The result of franka_gripper's ``kind`` action (homing, move, grasp, stop): success and error."""
    classes = {"homing": "HomingResult", "move": "MoveResult", "grasp": "GraspResult", "stop": "StopResult"}
    return getattr(franka_gripper_msgs(), classes[kind])(success=success, error=error)
