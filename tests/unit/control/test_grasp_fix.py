"""grasp_fix.py: gazebo_grasp_fix's tags, CheckGrip, grip counting, attachment and release."""
import math
import xml.etree.ElementTree as ET

import pytest

from diffbot_sim.control.grasp_fix import GraspContact, GraspFixCore, check_grip, grasp_contact, grasp_fix_config
from diffbot_sim.errors import ConfigError, PluginNotLoaded

PATH = "/robot/gazebo[4]/plugin[@name='gazebo_grasp_fix']"
IDENTITY = (0.0, 0.0, 0.0, 1.0)
ARM = ("<arm><arm_name>arm</arm_name><palm_link>palm</palm_link>"
       "<gripper_link>left</gripper_link><gripper_link>right</gripper_link></arm>")


def plugin(body):
    return ET.fromstring(f'<plugin name="gazebo_grasp_fix" filename="libgazebo_grasp_fix.so">{body}</plugin>')


def deg(angle):
    return math.radians(angle)


# ------------------------------------------------------------------------------------------------ config

def test_defaults():
    cfg = grasp_fix_config(plugin(ARM), PATH)
    (arm,) = cfg.arms
    assert (arm.name, arm.palm_link, arm.gripper_links) == ("arm", "palm", ("left", "right"))
    assert cfg.forces_angle_tolerance == pytest.approx(deg(120))
    assert (cfg.update_rate, cfg.max_grip_count, cfg.grip_count_threshold, cfg.release_tolerance,
            cfg.disable_collisions_on_attach, cfg.notes) == (5, 10, 5, 0.005, False, ())
    assert cfg.update_period == pytest.approx(0.2)


def test_kinova_values():
    cfg = grasp_fix_config(plugin(
        "<arm><arm_name>my_gen3</arm_name><palm_link> bracelet_link </palm_link>"
        "<gripper_link>left_inner_finger</gripper_link><gripper_link>right_inner_finger</gripper_link></arm>"
        "<forces_angle_tolerance>100</forces_angle_tolerance><update_rate>10</update_rate>"
        "<grip_count_threshold>3</grip_count_threshold><max_grip_count>10</max_grip_count>"
        "<release_tolerance>0.001</release_tolerance><disable_collisions_on_attach>1</disable_collisions_on_attach>"
        "<contact_topic>__default_topic__</contact_topic>"), PATH)
    assert cfg.arms[0].palm_link == "bracelet_link"
    assert cfg.forces_angle_tolerance == pytest.approx(deg(100))
    assert (cfg.update_rate, cfg.grip_count_threshold, cfg.max_grip_count, cfg.release_tolerance,
            cfg.disable_collisions_on_attach) == (10, 3, 10, 0.001, True)


def test_threshold_default_is_half_of_max_rounded_down_and_int_tags_read_like_stoi():
    cfg = grasp_fix_config(plugin(ARM + "<max_grip_count>7</max_grip_count><update_rate>4.9</update_rate>"), PATH)
    assert (cfg.max_grip_count, cfg.grip_count_threshold, cfg.update_rate) == (7, 3, 4)
    assert any("<update_rate> of " + PATH in note for note in cfg.notes)


@pytest.mark.parametrize("text, value, noted", [("true", True, False), ("1", True, False), ("false", False, False),
                                                ("True", False, True), ("yes", False, True)])
def test_disable_collisions_only_true_or_1(text, value, noted):
    cfg = grasp_fix_config(plugin(ARM + f"<disable_collisions_on_attach>{text}</disable_collisions_on_attach>"), PATH)
    assert cfg.disable_collisions_on_attach is value
    assert any("disable_collisions_on_attach" in note for note in cfg.notes) is noted


def test_odd_values_are_noted():
    cfg = grasp_fix_config(plugin(ARM + "<forces_angle_tolerance>60</forces_angle_tolerance>"
                                  "<grip_count_threshold>10</grip_count_threshold>"), PATH)
    assert any("nothing is ever gripped" in note for note in cfg.notes)
    assert any("nothing is ever attached" in note for note in cfg.notes)


@pytest.mark.parametrize("body, tag", [(ARM + "<update_rate>fast</update_rate>", "update_rate"),
                                       (ARM + "<update_rate>0</update_rate>", "update_rate"),
                                       (ARM + "<release_tolerance>x</release_tolerance>", "release_tolerance")])
def test_bad_numbers_name_tag_and_plugin(body, tag):
    with pytest.raises(ConfigError) as err:
        grasp_fix_config(plugin(body), PATH)
    assert err.value.name == f"<{tag}> of {PATH}"


def test_incomplete_arm_skipped_with_note():
    cfg = grasp_fix_config(plugin("<arm><arm_name>a</arm_name><palm_link>p</palm_link></arm>" + ARM), PATH)
    assert [arm.name for arm in cfg.arms] == ["arm"]
    assert cfg.notes == (f"{PATH}/arm[1]: not all of <arm_name>, <palm_link> and <gripper_link> given: "
                         "arm skipped",)


def test_no_arm_or_no_valid_arm_is_an_error_naming_the_plugin():
    with pytest.raises(PluginNotLoaded, match="without any <arm>") as err:
        grasp_fix_config(plugin("<update_rate>5</update_rate>"), PATH)
    assert PATH in str(err.value)
    with pytest.raises(PluginNotLoaded, match="no arms were configured") as err:
        grasp_fix_config(plugin("<arm><arm_name>a</arm_name><gripper_link>l</gripper_link></arm>"), PATH)
    assert f"{PATH}/arm[1]: not all of" in str(err.value) and "\n" not in str(err.value)


def test_links_checked_against_the_model():
    links = {"palm": 1, "left": 1, "right": 0}
    body = (ARM + "<arm><arm_name>b</arm_name><palm_link>wrist</palm_link><gripper_link>left</gripper_link></arm>"
            "<arm><arm_name>c</arm_name><palm_link>palm</palm_link><gripper_link>ghost</gripper_link></arm>")
    cfg = grasp_fix_config(plugin(body), PATH, link_collisions=links)
    assert [(arm.name, arm.gripper_links) for arm in cfg.arms] == [("arm", ("left",))]
    assert any("'right' has no collision" in note for note in cfg.notes)
    assert any("palm link 'wrist' not found" in note for note in cfg.notes)
    assert any("'ghost' not found" in note for note in cfg.notes)
    with pytest.raises(PluginNotLoaded):
        grasp_fix_config(plugin(ARM), PATH, link_collisions={"palm": 1})


def test_repeated_arm_name_merges_and_shared_link_is_noted():
    body = (ARM + "<arm><arm_name>arm</arm_name><palm_link>hand</palm_link><gripper_link>right</gripper_link>"
            "<gripper_link>thumb</gripper_link></arm>"
            "<arm><arm_name>other</arm_name><palm_link>p2</palm_link><gripper_link>thumb</gripper_link></arm>")
    cfg = grasp_fix_config(plugin(body), PATH)
    assert [(a.name, a.palm_link, a.gripper_links) for a in cfg.arms] == [
        ("arm", "hand", ("left", "right", "thumb")), ("other", "p2", ("thumb",))]
    assert any("already added" in note for note in cfg.notes)
    assert any("'thumb' is already in arm 'arm'" in note for note in cfg.notes)


def test_mapping_input():
    cfg = grasp_fix_config({"arm": [{"arm_name": "a", "palm_link": "p", "gripper_link": ["l", "r"]}],
                            "update_rate": "10"}, PATH)
    assert cfg.arms[0].gripper_links == ("l", "r") and cfg.update_rate == 10


# ------------------------------------------------------------------------------------------------ CheckGrip

def test_check_grip_opposing_forces():
    assert check_grip([(1.0, 0.0, 0.0), (-1.0, 0.0, 0.0)], deg(120))


def test_forces_at_60_degrees_do_not_grip():
    assert not check_grip([(1.0, 0.0, 0.0), (0.5, math.sqrt(3) / 2, 0.0)], deg(120))


@pytest.mark.parametrize("angle, gripped", [(121, True), (119, False)])
def test_check_grip_angle_threshold(angle, gripped):
    other = (math.cos(deg(angle)), math.sin(deg(angle)), 0.0)
    assert check_grip([(2.0, 0.0, 0.0), tuple(2.0 * c for c in other)], deg(120)) is gripped


def test_check_grip_length_ratio_and_tiny_forces():
    assert check_grip([(1.0, 0.0, 0.0), (-0.3, 0.0, 0.0)], deg(120))
    assert not check_grip([(1.0, 0.0, 0.0), (-0.29, 0.0, 0.0)], deg(120))
    assert not check_grip([(1.0, 0.0, 0.0), (-5e-5, 0.0, 0.0)], deg(90))
    assert check_grip([(1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (-0.9, 0.1, 0.0)], deg(120))  # any pair


def test_tolerance_below_90_degrees_never_grips():
    assert not check_grip([(1.0, 0.0, 0.0), (-1.0, 0.0, 0.0)], deg(89))
    assert check_grip([(1.0, 0.0, 0.0), (-0.1, 1.0, 0.0)], deg(90))


# ------------------------------------------------------------------------------------------------ core

LEFT_POSE = ((0.0, 0.05, 0.0), IDENTITY)
RIGHT_POSE = ((0.0, -0.05, 0.0), IDENTITY)


def squeeze(obj="box", left=("left", LEFT_POSE), right=("right", RIGHT_POSE), force=1.0):
    """Two fingers pressing a box at the origin from +y and -y."""
    (left_link, left_pose), (right_link, right_pose) = left, right
    return [GraspContact(left_link, obj, (0.0, 0.02, 0.0), (0.0, -force, 0.0), (0.0, 0.0, 0.0), left_pose),
            GraspContact(right_link, obj, (0.0, -0.02, 0.0), (0.0, force, 0.0), (0.0, 0.0, 0.0), right_pose)]


def make_core(body=ARM):
    return GraspFixCore(grasp_fix_config(plugin(body), PATH))


def grip_until_attached(core, updates=6):
    results = [core.update(squeeze()) for _ in range(updates)]
    assert results[:-1] == [[]] * (updates - 1)
    return results[-1]


def test_two_opposing_forces_attach_after_threshold_plus_one_updates():
    core = make_core()
    assert grip_until_attached(core) == [("attach", "arm", "box", "palm")]
    assert core.attached == {"arm": "box"} and core.grip_counts == {"box": 6}
    assert core.update(squeeze()) == []  # already attached
    for _ in range(6):
        core.update(squeeze())
    assert core.grip_counts["box"] == 10  # capped at max_grip_count


def test_one_finger_never_grips():
    core = make_core()
    for _ in range(8):
        assert core.update(squeeze()[:1]) == []
    assert core.grip_counts == {}


def test_contacts_of_other_links_are_ignored():
    core = make_core()
    for _ in range(8):
        assert core.update(squeeze(right=("table_leg", RIGHT_POSE))) == []


def test_forces_are_averaged_per_link_over_the_interval_not_summed():
    core = GraspFixCore(grasp_fix_config(plugin(ARM + "<grip_count_threshold>0</grip_count_threshold>"), PATH))
    left = [GraspContact("left", "box", (0.0, 0.02, 0.0), (0.0, -f, 0.0), (0.0, 0.0, 0.0), LEFT_POSE)
            for f in (1.0, 3.0)]  # mean 2.0, sum 4.0
    right = GraspContact("right", "box", (0.0, -0.02, 0.0), (0.0, 0.7, 0.0), (0.0, 0.0, 0.0), RIGHT_POSE)
    assert core.update(left + [right]) == [("attach", "arm", "box", "palm")]  # 0.7/2 = 0.35 >= 0.3


def test_grip_count_goes_down_when_not_gripped():
    core = make_core()
    for _ in range(3):
        core.update(squeeze())
    core.update([])
    assert core.grip_counts == {"box": 2}
    for _ in range(3):
        core.update([])
    assert core.grip_counts == {"box": 0}


def test_attaches_to_the_arm_with_most_links_in_contact():
    body = ("<arm><arm_name>a</arm_name><palm_link>pa</palm_link><gripper_link>a1</gripper_link></arm>"
            "<arm><arm_name>b</arm_name><palm_link>pb</palm_link><gripper_link>b1</gripper_link>"
            "<gripper_link>b2</gripper_link></arm><grip_count_threshold>0</grip_count_threshold>")
    core = make_core(body)
    contacts = squeeze(left=("a1", LEFT_POSE), right=("b1", RIGHT_POSE)) + [
        GraspContact("b2", "box", (0.02, 0.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 0.0, 0.0), ((0.05, 0.0, 0.0), IDENTITY))]
    assert core.update(contacts) == [("attach", "b", "box", "pb")]


def test_one_object_per_arm():
    core = make_core(ARM + "<grip_count_threshold>0</grip_count_threshold>")
    assert core.update(squeeze("box")) == [("attach", "arm", "box", "palm")]
    assert core.update(squeeze("box") + squeeze("can")) == []
    assert core.attached == {"arm": "box"}


def test_release_after_contact_points_move():
    core = make_core()
    grip_until_attached(core)
    poses = {"left": LEFT_POSE, "right": RIGHT_POSE}
    origin = {"box": (0.0, 0.0, 0.0)}
    assert core.update([], poses, origin) == []  # count 5 <= threshold, nothing moved
    poses["left"] = ((0.0, 0.054, 0.0), IDENTITY)  # 4 mm: within the 5 mm tolerance
    assert core.update([], poses, origin) == []
    poses["left"] = ((0.0, 0.056, 0.0), IDENTITY)  # finger opened 6 mm
    assert core.update([], poses, origin) == [("detach", "arm", "box")]
    assert core.attached == {} and core.grip_counts == {"box": 0}
    assert core.update([], poses, origin) == []


def test_no_release_while_count_above_threshold():
    core = make_core()
    for _ in range(8):
        core.update(squeeze())  # count 8
    far = {"left": ((0.0, 1.0, 0.0), IDENTITY), "right": RIGHT_POSE}
    assert core.update([], far, {"box": (0.0, 0.0, 0.0)}) == []  # count 7 > 5: not even checked
    assert core.update([], {}, {}) == []  # count 6: poses not needed
    with pytest.raises(KeyError):
        core.update([], {}, {})  # count 5: the release check needs the poses


def test_release_check_uses_the_link_frame():
    core = make_core()
    grip_until_attached(core)
    turned_about_y = ((0.0, 0.05, 0.0), (0.0, math.sin(math.pi / 4), 0.0, math.cos(math.pi / 4)))
    poses = {"left": turned_about_y, "right": RIGHT_POSE}
    assert core.update([], poses, {"box": (0.0, 0.0, 0.0)}) == []  # contact point lies on the turn axis
    turned_about_z = ((0.0, 0.05, 0.0), (0.0, 0.0, 1.0, 0.0))  # the contact point swings to y = 0.08
    poses["left"] = turned_about_z
    assert core.update([], poses, {"box": (0.0, 0.0, 0.0)}) == [("detach", "arm", "box")]


def test_object_moving_with_the_fingers_is_kept():
    core = make_core()
    grip_until_attached(core)
    lifted = {"left": ((0.0, 0.05, 0.3), IDENTITY), "right": ((0.0, -0.05, 0.3), IDENTITY)}
    for _ in range(3):
        assert core.update([], lifted, {"box": (0.0, 0.0, 0.3)}) == []


def test_grasp_contact_averages_points_and_forces():
    contact = grasp_contact("left", "box", [(0.0, 0.0, 0.0), (0.0, 0.02, 0.04)], [(1.0, 0.0, 0.0), (3.0, 2.0, 0.0)],
                            (0.0, 0.0, 0.0), LEFT_POSE)
    assert contact.point == pytest.approx((0.0, 0.01, 0.02)) and contact.force == pytest.approx((2.0, 1.0, 0.0))
    with pytest.raises(ValueError):
        grasp_contact("left", "box", [(0.0, 0.0, 0.0)], [], (0.0, 0.0, 0.0), LEFT_POSE)


def test_two_tiny_forces_are_skipped_however_opposed():
    assert not check_grip([(5e-5, 0.0, 0.0), (-5e-5, 0.0, 0.0)], deg(120))
    assert check_grip([(2e-4, 0.0, 0.0), (-2e-4, 0.0, 0.0)], deg(120))


def test_release_uses_the_configured_tolerance():
    core = make_core(ARM + "<release_tolerance>0.01</release_tolerance>")
    grip_until_attached(core)
    poses = {"left": ((0.0, 0.058, 0.0), IDENTITY), "right": RIGHT_POSE}
    assert core.update([], poses, {"box": (0.0, 0.0, 0.0)}) == []  # 8 mm < 10 mm
    poses["left"] = ((0.0, 0.062, 0.0), IDENTITY)
    assert core.update([], poses, {"box": (0.0, 0.0, 0.0)}) == [("detach", "arm", "box")]


def test_tie_goes_to_the_arm_of_the_first_link_name():
    body = ("<arm><arm_name>b</arm_name><palm_link>pb</palm_link><gripper_link>b1</gripper_link></arm>"
            "<arm><arm_name>a</arm_name><palm_link>pa</palm_link><gripper_link>a1</gripper_link></arm>"
            "<grip_count_threshold>0</grip_count_threshold>")
    core = make_core(body)
    assert core.update(squeeze(left=("b1", LEFT_POSE), right=("a1", RIGHT_POSE))) == [("attach", "a", "box", "pa")]


def test_contact_points_are_kept_in_the_link_frame():
    core = make_core()
    quarter_turn = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))
    turned = ((0.0, 0.05, 0.0), quarter_turn)
    for _ in range(6):
        actions = core.update(squeeze(left=("left", turned)))
    assert actions == [("attach", "arm", "box", "palm")]
    poses = {"left": turned, "right": RIGHT_POSE}
    assert core.update([], poses, {"box": (0.0, 0.0, 0.0)}) == []  # nothing moved


def test_repeated_arm_that_fails_removes_the_arm():
    body = ARM + "<arm><arm_name>arm</arm_name><palm_link>ghost</palm_link><gripper_link>left</gripper_link></arm>"
    with pytest.raises(PluginNotLoaded, match="palm link 'ghost' not found"):
        grasp_fix_config(plugin(body), PATH, link_collisions={"palm": 1, "left": 1, "right": 1})
