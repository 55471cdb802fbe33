"""messages/gazebo.py: gazebo_msgs states and geometry_msgs poses and twists to and from plain tuples."""
import io

import genpy
from gazebo_msgs import msg as gmsg
from geometry_msgs.msg import Pose, Twist

from diffbot_sim.messages import gazebo

POSE = ((1.0, -2.0, 0.5), (0.0, 0.0, 0.6, 0.8))
TWIST = ((0.1, 0.2, 0.3), (-0.4, -0.5, -0.6))


def test_pose_and_twist_round_trip():
    msg = gazebo.pose_msg(POSE)
    assert isinstance(msg, Pose) and (msg.position.y, msg.orientation.z, msg.orientation.w) == (-2.0, 0.6, 0.8)
    assert gazebo.pose_tuple(msg) == POSE
    msg = gazebo.twist_msg(TWIST)
    assert isinstance(msg, Twist) and (msg.linear.z, msg.angular.x) == (0.3, -0.4)
    assert gazebo.twist_tuple(msg) == TWIST


def test_pose_tuple_keeps_what_was_sent():
    """The request's numbers are checked by world_api, not mended here: an unnormalised quaternion passes."""
    msg = Pose()
    msg.orientation.w = 2.0
    assert gazebo.pose_tuple(msg) == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 2.0))


def test_model_states_keep_the_order_and_pair_names_with_states():
    states = [("ground", ((0, 0, 0), (0, 0, 0, 1)), (0, 0, 0), (0, 0, 0)),
              ("robot", POSE, TWIST[0], TWIST[1])]
    msg = gazebo.model_states(iter(states))
    assert isinstance(msg, gmsg.ModelStates)
    assert msg.name == ["ground", "robot"]
    assert gazebo.pose_tuple(msg.pose[1]) == POSE and gazebo.twist_tuple(msg.twist[1]) == TWIST
    assert gazebo.pose_tuple(msg.pose[0])[1] == (0, 0, 0, 1)
    buff = io.BytesIO()
    msg.serialize(buff)  # every field of the right type
    assert len(buff.getvalue()) > 2 * 13 * 8


def test_link_states_and_an_empty_world():
    msg = gazebo.link_states([("robot::base_link", POSE, *TWIST)])
    assert isinstance(msg, gmsg.LinkStates) and msg.name == ["robot::base_link"]
    assert gazebo.twist_tuple(msg.twist[0]) == TWIST
    assert gazebo.model_states([]).name == [] and gazebo.link_states(()).pose == []


def test_link_state_and_header_of_the_get_services():
    state = gazebo.link_state("robot::wheel", POSE, TWIST, "map")
    assert isinstance(state, gmsg.LinkState)
    assert (state.link_name, state.reference_frame) == ("robot::wheel", "map")
    assert gazebo.pose_tuple(state.pose) == POSE and gazebo.twist_tuple(state.twist) == TWIST
    header = gazebo.state_header(3, genpy.Time(5, 7), "world")
    assert (header.seq, header.stamp, header.frame_id) == (3, genpy.Time(5, 7), "world")
    gravity = gazebo.vector3((0.0, 0.0, -9.8))
    assert (gravity.x, gravity.z) == (0.0, -9.8)
