"""Gazebo's collision names after sdformat's lumping, and what a contact sensor's <collision> names."""
from diffbot_sim.description.gazebo_collisions import gazebo_links, sensor_collision
from diffbot_sim.description.urdf_model import parse_urdf

BOX = "<collision><geometry><box size='0.1 0.1 0.1'/></geometry></collision>"
URDF = f"""<robot name="r">
  <link name="base_footprint"/>
  <link name="base_link">{BOX}{BOX}</link>
  <joint name="base_joint" type="fixed"><parent link="base_footprint"/><child link="base_link"/></joint>
  <link name="bumper_link">{BOX}</link>
  <joint name="bumper_joint" type="fixed"><parent link="base_link"/><child link="bumper_link"/></joint>
  <link name="wheel_link">{BOX}</link>
  <joint name="wheel_joint" type="continuous"><parent link="base_link"/><child link="wheel_link"/></joint>
  <link name="ft_link">{BOX}</link>
  <joint name="ft_joint" type="fixed"><parent link="wheel_link"/><child link="ft_link"/></joint>
  <gazebo reference="ft_joint"><preserveFixedJoint>true</preserveFixedJoint></gazebo>
</robot>"""


def test_lumped_names_as_sdformat_writes_them():
    owner, named = gazebo_links(parse_urdf(URDF))
    assert owner["bumper_link"] == owner["base_link"] == "base_footprint" and owner["wheel_link"] == "wheel_link"
    assert [c.name for c in named["base_footprint"]] == [
        "base_footprint_fixed_joint_lump__base_link_collision",
        "base_footprint_fixed_joint_lump__base_link_collision_1",
        "base_footprint_fixed_joint_lump__bumper_link_collision_2"]
    assert [c.name for c in named["wheel_link"]] == ["wheel_link_collision"]
    assert [c.name for c in named["ft_link"]] == ["ft_link_collision"]  # preserveFixedJoint keeps it


def test_contact_sensor_collision_and_sdformats_rewrite():
    model = parse_urdf(URDF)
    found, name = sensor_collision(model, "base_link", "base_footprint_fixed_joint_lump__bumper_link_collision_2")
    assert found.urdf_link == "bumper_link" and name.endswith("_2")
    found, name = sensor_collision(model, "bumper_link", "bumper_link_collision")
    assert found is None and name == "base_footprint_collision_bumper_link"  # names nothing, as in Gazebo
    found, _ = sensor_collision(model, "wheel_link", "wheel_link_collision")
    assert found.link == "wheel_link"
