"""Helpers of the MoveIt suites (tests/integration/moveit_*.test, `make test-moveit`): the body's ground truth of a
link (/gazebo/get_link_state; a link lumped into its parent by a fixed joint, as Gazebo lumps it, through the
URDF's fixed offsets), MoveIt's own forward kinematics (/compute_fk) and state validity (/check_state_validity),
and the wait for move_group."""
import math
import os
import sys

import rospy
from gazebo_msgs.srv import GetLinkState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from simtest import wait_for

from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.transforms import compose, rpy_quaternion


def angle_between(a, b):
    """The rotation angle [rad] between two unit quaternions."""
    dot = abs(sum(x * y for x, y in zip(a, b)))
    return 2.0 * math.acos(min(1.0, dot))


class Body:
    """Ground truth of one model's links, a lumped (fixed-joint) link through its kept ancestor."""

    def __init__(self, model_name, description="/robot_description"):
        self.model_name = model_name
        self.model = parse_urdf(rospy.get_param(description))
        rospy.wait_for_service("/gazebo/get_link_state", 60)
        self.link_state = rospy.ServiceProxy("/gazebo/get_link_state", GetLinkState)

    def _kept(self, link):
        """(kept ancestor, position, orientation of ``link`` in it) through fixed joints."""
        offset, turn = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)
        while True:
            joint = next((j for j in self.model.joints.values() if j.child == link), None)
            if joint is None or joint.type != "fixed":
                return link, offset, turn
            offset, turn = compose((tuple(joint.xyz), rpy_quaternion(*joint.rpy)), (offset, turn))
            link = joint.parent

    def pose(self, link):
        """((x, y, z), (qx, qy, qz, qw)) of ``link`` in the world, from the physics."""
        kept, offset, turn = self._kept(link)
        resp = self.link_state(f"{self.model_name}::{kept}", "")
        assert resp.success, f"get_link_state {self.model_name}::{kept}: {resp.status_message}"
        p, q = resp.link_state.pose.position, resp.link_state.pose.orientation
        return compose(((p.x, p.y, p.z), (q.x, q.y, q.z, q.w)), (offset, turn))


def wait_for_move_group(timeout=120.0):
    """move_group's services and its action server up (it starts after the controllers it connects to)."""
    for service in ("/compute_fk", "/compute_ik", "/check_state_validity", "/get_planning_scene"):
        rospy.wait_for_service(service, timeout)
    import actionlib
    from moveit_msgs.msg import MoveGroupAction

    client = actionlib.SimpleActionClient("move_group", MoveGroupAction)
    assert client.wait_for_server(rospy.Duration(timeout)), "no move_group action server"


def fk(link, joint_names, positions, frame):
    """MoveIt's forward kinematics (/compute_fk) of ``link`` for the joints given (the rest at their current
    values): ((x, y, z), (qx, qy, qz, qw)) in ``frame``."""
    from moveit_msgs.msg import RobotState
    from moveit_msgs.srv import GetPositionFK

    state = RobotState()
    state.joint_state.name = list(joint_names)
    state.joint_state.position = list(positions)
    state.is_diff = True
    resp = rospy.ServiceProxy("/compute_fk", GetPositionFK)(header=_header(frame), fk_link_names=[link],
                                                              robot_state=state)
    assert resp.error_code.val == 1, f"compute_fk {link}: error code {resp.error_code.val}"
    p, q = resp.pose_stamped[0].pose.position, resp.pose_stamped[0].pose.orientation
    return (p.x, p.y, p.z), (q.x, q.y, q.z, q.w)


def state_valid(group, joint_names, positions):
    """(valid, contacts) of the state with the joints given, the rest current (/check_state_validity)."""
    from moveit_msgs.msg import RobotState
    from moveit_msgs.srv import GetStateValidity

    state = RobotState()
    state.joint_state.name = list(joint_names)
    state.joint_state.position = list(positions)
    state.is_diff = True
    resp = rospy.ServiceProxy("/check_state_validity", GetStateValidity)(robot_state=state, group_name=group)
    return resp.valid, [(c.contact_body_1, c.contact_body_2) for c in resp.contacts]


def _header(frame):
    from std_msgs.msg import Header

    return Header(frame_id=frame)


def tf_pose(buffer, parent, child, timeout=5.0):
    """((x, y, z), (qx, qy, qz, qw)) of ``child`` in ``parent`` from TF (latest)."""
    t = buffer.lookup_transform(parent, child, rospy.Time(0), rospy.Duration(timeout)).transform
    return ((t.translation.x, t.translation.y, t.translation.z),
            (t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w))


def settled_pose(body, link, band=0.0005, window=0.3, timeout=30.0):
    """The link's ground truth once it has stayed within ``band`` m over ``window`` s of sim time."""
    from traittest import settled

    reading = settled(lambda: list(body.pose(link)[0]) + list(body.pose(link)[1]), band, window, timeout,
                      what=f"{link}'s ground truth")
    return tuple(reading[:3]), tuple(reading[3:])


__all__ = ["Body", "angle_between", "fk", "settled_pose", "state_valid", "tf_pose",
           "wait_for", "wait_for_move_group"]
