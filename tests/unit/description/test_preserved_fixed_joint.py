"""A fixed joint <gazebo reference> keeps (preserveFixedJoint, disableFixedJointLumping) is not lumped: the joint of
a force-torque sensor must exist to be measured, as sdformat keeps it."""
from diffbot_sim.description.lumping import lump

URDF = """<robot name="r">
  <link name="a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="b"><inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="ft_joint" type="fixed"><parent link="a"/><child link="b"/></joint>
  <link name="c"><inertial><mass value="3"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="plain_joint" type="fixed"><parent link="a"/><child link="c"/></joint>
  {keep}
</robot>"""


def test_kept_joint_stays_and_others_lump():
    for tag in ("preserveFixedJoint", "disableFixedJointLumping"):
        out = lump(URDF.format(keep=f"<gazebo reference='ft_joint'><{tag}>true</{tag}></gazebo>"), "a", lambda n: {})
        assert out.lumped == ["c"] and "ft_joint" in out.text
    out = lump(URDF.format(keep=""), "a", lambda n: {})
    assert sorted(out.lumped) == ["b", "c"]
