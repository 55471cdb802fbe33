"""Where a ray sensor sits on its link (diffbot_sim.sensors.ray.mounted_pose): its <pose> on a moving link, the
link's own frame when sdformat lumps the link into its parent by a fixed joint (with a warning when a non-zero
pose is dropped), and an error for a link the model does not have. plugins/ray_base.py decides the same."""
import xml.etree.ElementTree as ET

import pytest

from diffbot_sim.errors import ConfigError
from diffbot_sim.sensors import ray as rs

URDF = """<robot name="r">
  <link name="base_link"/>
  <link name="fixed_link"/><joint name="f" type="fixed"><parent link="base_link"/><child link="fixed_link"/></joint>
  <link name="turning_link"/>
  <joint name="t" type="continuous"><parent link="base_link"/><child link="turning_link"/><axis xyz="0 0 1"/></joint>
</robot>"""


def laser(pose="0.1 0 0.2 0 0 0.5"):
    body = f"<pose>{pose}</pose>" if pose is not None else ""
    element = ET.fromstring(f'<sensor type="ray" name="s">{body}<ray><range><min>0.1</min><max>5</max></range>'
                            "</ray></sensor>")
    return rs.parse_sensor(element, "/robot/gazebo[@reference='x']/sensor[@name='s']")


def test_pose_kept_on_a_link_of_its_own(parse):
    pose, warning = rs.mounted_pose(laser(), parse(URDF), "turning_link")
    assert pose == ((0.1, 0.0, 0.2), (0.0, 0.0, 0.5)) and warning is None
    pose, warning = rs.mounted_pose(laser(), parse(URDF), "base_link")  # the root: no parent joint
    assert pose == ((0.1, 0.0, 0.2), (0.0, 0.0, 0.5)) and warning is None


def test_pose_dropped_on_a_lumped_link_with_a_warning(parse):
    pose, warning = rs.mounted_pose(laser(), parse(URDF), "fixed_link")
    assert pose == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    assert "<pose> dropped" in warning and "fixed_link" in warning and "sensor[@name='s']" in warning
    assert rs.mounted_pose(laser("0 0 0 0 0 0"), parse(URDF), "fixed_link")[1] is None  # nothing dropped
    assert rs.mounted_pose(laser(None), parse(URDF), "fixed_link")[1] is None


@pytest.mark.parametrize("link", ["", None, "no_such_link"])
def test_unknown_link_is_refused(parse, link):
    with pytest.raises(ConfigError, match="gazebo reference"):
        rs.mounted_pose(laser(), parse(URDF), link)
