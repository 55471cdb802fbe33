"""Joint wrenches for force-torque sensors, as Gazebo's Joint::GetForceTorque gives them.

Gazebo (ODEJoint::GetForceTorque) reports ``body2Force``/``body2Torque``: the force the joint applies on its
child link, in the child link's frame, the torque about the joint's origin. PyBullet's joint force-torque
sensor (``enableJointForceTorqueSensor``) gives the same force on the child, but in the child's centre-of-mass
(inertial) frame and the torque about the centre of mass (measured: a 2 kg load hanging 0.1 m beside the
joint reads (0, 0, 19.62) N and no torque). This module converts: the force rotated into the link frame,
the torque moved to the joint's origin (``tau_O = tau_C + (C - O) x F``; the URDF joint origin is the child
frame's origin).
"""
from diffbot_sim.physics.client import pybullet


def joint_by_name(robot, name):
    """PyBullet index of the joint ``name`` (fixed joints too: sdformat's kept ones), or None."""
    for index in range(pybullet.getNumJoints(robot.body, physicsClientId=robot.client)):
        if pybullet.getJointInfo(robot.body, index, physicsClientId=robot.client)[1].decode() == name:
            return index
    return None


def enable_sensor(robot, index):
    pybullet.enableJointForceTorqueSensor(robot.body, index, True, physicsClientId=robot.client)


def joint_wrench(robot, index):
    """(force, torque) the joint ``index`` applied on its child link in the last step: child link frame, torque
    about the joint's origin."""
    c = robot.client
    reaction = pybullet.getJointState(robot.body, index, physicsClientId=c)[2]
    com_position, com_orientation = pybullet.getDynamicsInfo(robot.body, index, physicsClientId=c)[3:5]
    rows = pybullet.getMatrixFromQuaternion(com_orientation)
    rot = [rows[0:3], rows[3:6], rows[6:9]]
    force = tuple(sum(rot[r][k] * reaction[k] for k in range(3)) for r in range(3))
    torque_c = tuple(sum(rot[r][k] * reaction[3 + k] for k in range(3)) for r in range(3))
    p = com_position
    moment = (p[1] * force[2] - p[2] * force[1], p[2] * force[0] - p[0] * force[2], p[0] * force[1] - p[1] * force[0])
    return force, tuple(torque_c[i] + moment[i] for i in range(3))
