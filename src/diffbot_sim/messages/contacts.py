"""gazebo_msgs/ContactsState of a contact sensor (message module only, no rospy), from
:class:`diffbot_sim.sensors.contact.ContactState` tuples."""
from gazebo_msgs.msg import ContactsState, ContactState
from geometry_msgs.msg import Vector3, Wrench


def _vector(v):
    return Vector3(float(v[0]), float(v[1]), float(v[2]))


def _wrench(force, torque):
    return Wrench(force=_vector(force), torque=_vector(torque))


def contacts_state(stamp, frame, states):
    """``ContactsState`` as gazebo_ros_bumper fills it: one ContactState per colliding pair, ``info`` its text."""
    msg = ContactsState()
    msg.header.stamp, msg.header.frame_id = stamp, frame
    for s in states:
        msg.states.append(ContactState(
            info=f"Debug:  my geom:{s.collision1}   other geom:{s.collision2}",
            collision1_name=s.collision1, collision2_name=s.collision2,
            wrenches=[_wrench(f, t) for f, t in s.wrenches], total_wrench=_wrench(*s.total),
            contact_positions=[_vector(p) for p in s.positions], contact_normals=[_vector(n) for n in s.normals],
            depths=[float(d) for d in s.depths]))
    return msg
