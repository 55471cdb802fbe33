"""world.actor_sdf, actor_splines, actor_script and actor_walk: Gazebo-classic 11 <actor> reading, script
playback, ActorPlugin.

Fixtures are written inline after gazebo-classic's worlds/actor.world, animated_box.world (the actor
tutorial's square), animation_tension.world and cafe.world. Expected positions are hand-computed from the
cubic Hermite basis h00 = 2u^3 - 3u^2 + 1, h10 = u^3 - 2u^2 + u, h01 = -2u^3 + 3u^2, h11 = u^3 - u^2 with
Catmull-Rom tangents m_i = 0.5 (1 - tension) (p[i+1] - p[i-1]).
"""
import math
import random
import xml.etree.ElementTree as ET

import pytest

from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.transforms import slerp
from diffbot_sim.world.actor_script import ActorScript
from diffbot_sim.world.actor_sdf import pose6_to_pose, read_actor
from diffbot_sim.world.actor_walk import (
    FLOOR_X,
    FLOOR_Y,
    PERSON_SIZE,
    WALK_ROOT_HEIGHT,
    ActorWalker,
    person_box,
    read_walker_config,
    upright_pose,
)

PATH = "test.world: /sdf/world/actor"


def actor(xml, notes=None):
    return read_actor(ET.fromstring(xml), PATH, [] if notes is None else notes)


def waypoints(*points):
    """(time, "x y z r p y") pairs as <waypoint> elements."""
    return "".join(f"<waypoint><time>{t}</time><pose>{p}</pose></waypoint>" for t, p in points)


def script_actor(trajectories, loop="true", delay="0", auto="true", pose="0 0 0 0 0 0", extra=""):
    return actor(f'<actor name="a"><pose>{pose}</pose><script><loop>{loop}</loop><delay_start>{delay}</delay_start>'
                 f'<auto_start>{auto}</auto_start>{trajectories}</script>{extra}</actor>')


def trajectory(points, ident=0, tension=None, kind="walking"):
    attr = "" if tension is None else f" tension='{tension}'"
    return f"<trajectory id='{ident}' type='{kind}'{attr}>{waypoints(*points)}</trajectory>"


def yaw(q):
    x, y, z, w = q
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


# animation_tension.world: waypoints at 0, 5 and 8 s, the last one only turning
TENSION_POINTS = ((0.0, "0 0 0 0 0 0"), (5.0, "2 0 0 0 0 0"), (8.0, "2 0 0 -0.009635 0.191045 0.490471"))
# the actor tutorial's animated box: a closed square, 1 s per side
SQUARE = ((0, "-1 -1 1 0 0 0"), (1, "-1 1 1 0 0 0"), (2, "1 1 1 0 0 0"), (3, "1 -1 1 0 0 0"), (4, "-1 -1 1 0 0 0"))
# actor.world's first quarter circle (the file's first 5 waypoints), its skin and walking animation
ACTOR_WORLD = """<actor name="actor"><skin><filename>moonwalk.dae</filename><scale>1.0</scale></skin>
  <pose>0 0 0 0 0 0</pose>
  <animation name="walking"><filename>walk.dae</filename><scale>1.000000</scale>
    <interpolate_x>true</interpolate_x></animation>
  <script><loop>true</loop><delay_start>0.000000</delay_start><auto_start>true</auto_start>
    <trajectory id="0" type="walking">""" + waypoints(
    (0.5, "0.195090 0.980785 0 0 0 -0.196350"), (0.0, "0 1 0 0 0 0"), (2.0, "0.707107 0.707107 0 0 0 -0.785398"),
    (1.0, "0.382683 0.923880 0 0 0 -0.392699"), (1.5, "0.555570 0.831470 0 0 0 -0.589049")) + """</trajectory>
  </script></actor>"""
CAFE_ACTOR = """<actor name="actor1"><pose>0 1 1.25 0 0 0</pose>
  <skin><filename>file://media/models/walk.dae</filename><scale>1.0</scale></skin>
  <animation name="walking"><filename>file://media/models/walk.dae</filename><scale>1.000000</scale>
    <interpolate_x>true</interpolate_x></animation>
  <plugin name="actor1_plugin" filename="libActorPlugin.so">
    <target>0 -5 1.2138</target><target_weight>1.15</target_weight><obstacle_weight>1.8</obstacle_weight>
    <animation_factor>5.1</animation_factor>
    <ignore_obstacles><model>cafe</model><model>ground_plane</model></ignore_obstacles>
  </plugin></actor>"""


# ------------------------------------------------------------------------------------------ reading

def test_reads_actor_world_skin_animation_script_and_sorts_waypoints_by_time():
    notes = []
    desc = actor(ACTOR_WORLD, notes)
    assert desc.name == "actor" and desc.pose == (0, 0, 0, 0, 0, 0)
    assert desc.skin.filename == "moonwalk.dae" and desc.skin.scale == 1.0
    (walk,) = desc.animations
    assert (walk.name, walk.filename, walk.scale, walk.interpolate_x) == ("walking", "walk.dae", 1.0, True)
    script = desc.script
    assert (script.loop, script.delay_start, script.auto_start) == (True, 0.0, True)
    (traj,) = script.trajectories
    assert (traj.id, traj.type, traj.tension, traj.duration) == (0, "walking", 0.0, 2.0)
    assert [w.time for w in traj.waypoints] == [0.0, 0.5, 1.0, 1.5, 2.0]
    assert traj.waypoints[1].pose == (0.195090, 0.980785, 0, 0, 0, -0.196350)
    assert notes == []


def test_defaults_of_an_actor_with_only_a_name_and_a_link():
    notes = []
    desc = actor('<actor name="box"><link name="l"/><script/></actor>', notes)
    assert desc.pose == (0, 0, 0, 0, 0, 0) and desc.skin is None and desc.animations == ()
    assert (desc.script.loop, desc.script.delay_start, desc.script.auto_start) == (True, 0.0, True)
    assert desc.script.trajectories == () and desc.plugins == ()


def test_actor_without_name_is_an_error_naming_the_element():
    with pytest.raises(ModelError, match=r"actor.*name") as err:
        actor("<actor><script/></actor>")
    assert PATH in str(err.value) and "\n" not in str(err.value)


def test_actor_without_script_gets_sdformats_default_script_and_a_note():
    notes = []
    desc = actor('<actor name="a"><pose>1 2 0 0 0 0</pose></actor>', notes)
    assert desc.script.loop and desc.script.auto_start and desc.script.trajectories == ()
    assert len(notes) == 1 and "no <script>" in notes[0] and PATH in notes[0]
    # an ActorPlugin actor (cafe.world) has none by design: no note
    notes = []
    actor(CAFE_ACTOR, notes)
    assert notes == []


def test_actor_poses_are_read_as_every_sdf_pose_is():
    """The one <pose> reader (world.sdf_elements): SDF 1.9's forms too, and its message for a bad pose."""
    s = math.sqrt(0.5)
    desc = actor(f'<actor name="a"><pose rotation_format="quat_xyzw">1 2 0 0 0 {s} {s}</pose><script/></actor>')
    assert desc.pose == pytest.approx((1.0, 2.0, 0.0, 0.0, 0.0, math.pi / 2))
    desc = actor('<actor name="a"><pose degrees="true">1 2 0 0 0 90</pose><script/></actor>')
    assert desc.pose == pytest.approx((1.0, 2.0, 0.0, 0.0, 0.0, math.pi / 2))
    with pytest.raises(ModelError, match=r"/pose: <pose> '1 2 3' is not 6 finite numbers"):
        actor('<actor name="a"><pose>1 2 3</pose><script/></actor>')


def test_trajectories_play_in_id_order_back_to_back():
    first = trajectory(((0, "0 0 0 0 0 0"), (2, "2 0 0 0 0 0")), ident=1)
    second = trajectory(((0, "5 5 0 0 0 0"), (3, "5 8 0 0 0 0")), ident=-4, kind="other")
    desc = script_actor(first + second)
    assert [t.id for t in desc.script.trajectories] == [-4, 1]
    script = ActorScript(desc, frame_period=0)
    assert script.script_length == 5.0
    assert script.trajectory_pose(0.0)[0] == (5.0, 5.0, 0.0)
    assert script.trajectory_pose(3.0)[0] == (5.0, 8.0, 0.0)  # the boundary belongs to the first one
    assert script.trajectory_pose(5.0)[0] == (2.0, 0.0, 0.0)
    assert script.trajectory_pose(4.0)[0][0] == pytest.approx(1.0)
    assert script.pose_at(3.0)[0] == (5.0, 8.0, 0.0) and script.pose_at(3.5) == script.trajectory_pose(3.5)


def test_unordered_waypoints_play_like_ordered_ones():
    ordered = ActorScript(script_actor(trajectory(SQUARE)), frame_period=0)
    shuffled = ActorScript(script_actor(trajectory(SQUARE[::-1][1:] + SQUARE[-1:])), frame_period=0)
    for t in (0.0, 0.3, 1.7, 2.5, 3.9, 4.0):
        assert shuffled.trajectory_pose(t) == ordered.trajectory_pose(t)


def test_duplicate_waypoint_times_keep_the_last_pose_with_a_note():
    notes = []
    desc = actor('<actor name="a"><script>' + trajectory(
        ((0, "0 0 0 0 0 0"), (1, "9 9 9 0 0 0"), (2, "2 0 0 0 0 0"), (1.0, "1 0 0 0 0 0"))) + "</script></actor>",
        notes)
    (traj,) = desc.script.trajectories
    assert [w.time for w in traj.waypoints] == [0.0, 1.0, 2.0]
    assert traj.waypoints[1].pose[:3] == (1.0, 0.0, 0.0)
    assert len(notes) == 1 and "waypoint[4]" in notes[0]


def test_first_waypoint_moves_to_time_zero_as_gazebo_11():
    notes = []
    desc = actor('<actor name="a"><script>' + trajectory(((2, "1 0 0 0 0 0"), (4, "3 0 0 0 0 0")))
                 + "</script></actor>", notes)
    (traj,) = desc.script.trajectories
    assert [w.time for w in traj.waypoints] == [0.0, 4.0] and traj.duration == 4.0
    assert len(notes) == 1 and "played at 0 s" in notes[0]
    script = ActorScript(desc, frame_period=0)
    assert script.trajectory_pose(2.0)[0] == (2.0, 0.0, 0.0)  # halfway in time, not the first waypoint


def test_duplicate_trajectory_ids_play_the_last_ones_waypoints():
    desc = script_actor(trajectory(((0, "0 0 0 0 0 0"), (2, "2 0 0 0 0 0")), ident=3)
                        + trajectory(((0, "0 5 0 0 0 0"), (1, "0 6 0 0 0 0")), ident=3))
    durations = [t.duration for t in desc.script.trajectories]
    assert durations == [2.0, 1.0]
    assert all(t.waypoints[-1].pose[:2] == (0.0, 6.0) for t in desc.script.trajectories)


def test_bad_numbers_are_one_note_each_and_no_number_is_an_error():
    notes = []
    desc = actor('<actor name="a"><skin><filename>s.dae</filename><scale>1.5x</scale></skin><script>'
                 '<delay_start>2.0s</delay_start>' + trajectory(((0, "0 0 0 0 0 0"), ("3.0 sec", "1 0 0 0 0 0")))
                 + "</script></actor>", notes)
    assert desc.skin.scale == 1.5 and desc.script.delay_start == 2.0
    assert desc.script.trajectories[0].duration == 3.0
    assert len(notes) == 3
    assert any("delay_start" in n and "2.0s" in n for n in notes)
    with pytest.raises(ModelError, match="waypoint.*time") as err:
        actor('<actor name="a"><script>' + trajectory(((0, "0 0 0 0 0 0"), ("soon", "1 0 0 0 0 0")))
              + "</script></actor>")
    assert "'soon' is not a number" in str(err.value)
    with pytest.raises(ModelError, match="pose"):
        actor('<actor name="a"><script>' + trajectory(((0, "0 0 0 0 0"),)) + "</script></actor>")
    with pytest.raises(ModelError, match="loop"):
        actor('<actor name="a"><script><loop>yes</loop></script></actor>')
    with pytest.raises(ModelError, match="id and a type"):
        actor('<actor name="a"><script><trajectory id="0"/></script></actor>')


def test_tension_outside_0_1_is_used_with_a_note():
    notes = []
    desc = script_actor(trajectory(TENSION_POINTS, tension="1.5"))
    assert desc.script.trajectories[0].tension == 1.5
    actor('<actor name="a"><script>' + trajectory(TENSION_POINTS, tension="-1") + "</script></actor>", notes)
    assert len(notes) == 1 and "tension" in notes[0]


def test_plugins_are_kept_for_the_lead_to_find():
    desc = actor(CAFE_ACTOR)
    plugin = desc.plugin("libActorPlugin.so")
    assert plugin.name == "actor1_plugin" and plugin.element.findtext("target") == "0 -5 1.2138"
    assert desc.plugin("ActorPlugin") is plugin and desc.plugin("libOther.so") is None


# ------------------------------------------------------------------------------------------ splines

def test_waypoints_are_hit_exactly_at_their_times():
    for tension in ("0.0", "1.0", "0.4"):
        script = ActorScript(script_actor(trajectory(TENSION_POINTS, tension=tension)), frame_period=0)
        for time, pose in TENSION_POINTS:
            position, rotation = script.trajectory_pose(time)
            expected = pose6_to_pose(tuple(float(v) for v in pose.split()))
            assert position == pytest.approx(expected[0], abs=1e-9)
            assert rotation == pytest.approx(expected[1], abs=1e-9)


def test_hermite_values_between_waypoints_with_tension_0_and_1():
    # tension 0: m0 = (1,0,0), m1 = 0.5 (p2 - p0) = (1,0,0), m2 = 0.5 (p2 - p1) = 0
    low = ActorScript(script_actor(trajectory(TENSION_POINTS, tension="0.0")), frame_period=0)
    high = ActorScript(script_actor(trajectory(TENSION_POINTS, tension="1.0")), frame_period=0)
    # u = 0.25 in the first segment (1.25 s of 5): 0.140625 m0 + 0.15625 p1 - 0.046875 m1
    assert low.trajectory_pose(1.25)[0] == pytest.approx((0.40625, 0, 0), abs=1e-12)
    assert high.trajectory_pose(1.25)[0] == pytest.approx((0.3125, 0, 0), abs=1e-12)
    # u = 0.5 in the second segment (6.5 s): 0.5 p1 + 0.125 m1 + 0.5 p2 - 0.125 m2: overshoots past 2 m
    assert low.trajectory_pose(6.5)[0] == pytest.approx((2.125, 0, 0), abs=1e-12)
    assert high.trajectory_pose(6.5)[0] == pytest.approx((2.0, 0, 0), abs=1e-12)


def test_closed_spline_wraps_its_end_tangents():
    square = ActorScript(script_actor(trajectory(SQUARE)), frame_period=0)
    # closed: m0 = m4 = 0.5 (p1 - p3) = (-1, 1); m1 = (1, 1); m3 = (-1, -1)
    assert square.trajectory_pose(0.5)[0] == pytest.approx((-1.25, 0.0, 1.0), abs=1e-12)
    assert square.trajectory_pose(3.5)[0] == pytest.approx((0.0, -1.25, 1.0), abs=1e-12)
    # the same square not quite closed (2 mm off) uses one-sided end tangents: m0 = (0, 1), m4 = (-1, 0)
    opened = ActorScript(script_actor(trajectory(SQUARE[:-1] + ((4, "-1.002 -1 1 0 0 0"),))), frame_period=0)
    assert opened.trajectory_pose(0.5)[0][0] == pytest.approx(-1.125, abs=1e-12)
    assert opened.trajectory_pose(3.5)[0][1] == pytest.approx(-1.125, abs=1e-12)


def test_slerp_halfway_yaw_and_shortest_path():
    script = ActorScript(script_actor(trajectory(((0, "0 0 0 0 0 0"), (2, "0 0 0 0 0 1.0")))), frame_period=0)
    assert yaw(script.trajectory_pose(1.0)[1]) == pytest.approx(0.5, abs=1e-12)
    q3, q_minus3 = pose6_to_pose((0, 0, 0, 0, 0, 3.0))[1], pose6_to_pose((0, 0, 0, 0, 0, -3.0))[1]
    assert abs(yaw(slerp(0.5, q3, q_minus3, shortest_path=True))) == pytest.approx(math.pi, abs=1e-12)
    assert yaw(slerp(0.5, q3, q_minus3)) == pytest.approx(0.0, abs=1e-12)


def test_rotation_uses_gazebo_11s_squad_between_three_yaw_keyframes():
    # coaxial squad: tangent yaws a0 = -0.25, a1 = 1.25; at u = 0.25, s = 2u(1-u) = 0.375:
    # (1 - s) * 0.25 + s * (-0.25 + 0.25 * 1.5) = 0.203125 (plain SLERP would give 0.25)
    script = ActorScript(script_actor(trajectory(((0, "0 0 0 0 0 0"), (1, "0 0 0 0 0 1"), (2, "0 0 0 0 0 1")))),
                         frame_period=0)
    assert yaw(script.trajectory_pose(0.25)[1]) == pytest.approx(0.203125, abs=1e-12)


def test_closed_rotation_spline_wraps_its_end_tangents():
    # yaws 0, 1, 0: closed, so the last tangent sees yaw 1 on both sides: a2 = -0.5 (open: -0.25), a1 = 1.5;
    # at u = 0.25 of the second segment: 0.625 * 0.75 + 0.375 * (1.5 + 0.25 * (a2 - a1)) = 0.84375
    script = ActorScript(script_actor(trajectory(((0, "0 0 0 0 0 0"), (1, "0 0 0 0 0 1"), (2, "0 0 0 0 0 0")))),
                         frame_period=0)
    assert yaw(script.trajectory_pose(1.25)[1]) == pytest.approx(0.84375, abs=1e-12)
    assert yaw(script.trajectory_pose(0.75)[1]) == pytest.approx(0.84375, abs=1e-12)  # and the first, mirrored


def test_yaw_across_pi_swings_round_as_gazebos_squad_does():
    # keyframes 3 -> -3 rad: the tangents' logs take the long way (a0 = 4.5, a1 = -4.5 rad), so halfway
    # squad blends yaw pi (shortest slerp) with a full turn: yaw -pi/2, not pi
    script = ActorScript(script_actor(trajectory(((0, "0 0 0 0 0 3"), (2, "0 0 0 0 0 -3")))), frame_period=0)
    assert yaw(script.trajectory_pose(1.0)[1]) == pytest.approx(-math.pi / 2, abs=1e-9)


# ------------------------------------------------------------------------------------------ playback

def square_positions(script, times):
    return [tuple(round(c, 9) for c in script.pose_at(t)[0]) for t in times]


def test_loop_waits_delay_start_again_every_cycle():
    desc = script_actor(trajectory(SQUARE), delay="1", pose="7 7 7 0 0 0")
    script = ActorScript(desc, frame_period=0)
    times = [k * 0.25 for k in range(0, 45)]  # 0 .. 11 s
    got = dict(zip(times, square_positions(script, times)))
    start, corner2 = (-1.0, -1.0, 1.0), (1.0, 1.0, 1.0)
    assert got[0.0] == got[0.75] == (7.0, 7.0, 7.0)  # waiting for the first start: the <pose>
    assert got[1.0] == start and got[3.0] == corner2 and got[4.0] == (1.0, -1.0, 1.0)
    assert got[5.0] == start  # wrapped: script time 0 drawn, play start moved to 5 s
    assert got[5.25] == got[5.75] == start  # the delay again, holding the first frame
    assert got[6.0] == start and got[8.0] == corner2  # second cycle, 5 s (length + delay) later
    assert got[11.0] == start and got[7.5] == got[2.5] != start  # same script time, one period apart


def test_auto_start_false_waits_for_play():
    script = ActorScript(script_actor(trajectory(SQUARE), auto="false", pose="7 7 7 0 0 0"), frame_period=0)
    assert script.pose_at(2.0)[0] == (7.0, 7.0, 7.0) and not script.active
    script.play(3.0)
    assert script.pose_at(3.0)[0] == (-1.0, -1.0, 1.0)
    assert script.pose_at(5.0)[0] == pytest.approx((1.0, 1.0, 1.0))
    script.stop()
    assert script.pose_at(5.5)[0] == pytest.approx((1.0, 1.0, 1.0))


def test_no_loop_freezes_at_the_last_frame_drawn():
    desc = script_actor(trajectory(TENSION_POINTS, tension="1.0"), loop="false", delay="2")
    script = ActorScript(desc, frame_period=0)
    for k in range(0, 40):
        script.pose_at(k * 0.25)  # last frame inside the script: 9.75 s = script time 7.75
    last = script.trajectory_pose(7.75)
    assert script.pose_at(10.0) == last and script.pose_at(30.0) == last and not script.active
    assert last[1] != pytest.approx(script.trajectory_pose(8.0)[1], abs=1e-6)


def test_frames_are_held_for_a_thirtieth_of_a_second():
    script = ActorScript(script_actor(trajectory(((0, "0 0 0 0 0 0"), (10, "10 0 0 0 0 0")))))
    xs = {k: script.pose_at(k * 0.01)[0][0] for k in range(0, 14)}
    at = {k: script.trajectory_pose(k * 0.01)[0][0] for k in (4, 5, 8, 12)}
    assert xs[0] == xs[3] == 0.0  # no frame before 1/30 s
    assert xs[4] == at[4] > 0.0  # first frame at the first step >= 1/30 s
    assert xs[5] == xs[6] == xs[7] == xs[4]  # held
    assert xs[8] == at[8] and xs[11] == xs[8] and xs[12] == at[12]
    smooth = ActorScript(script.description, frame_period=0)
    assert smooth.pose_at(0.05)[0][0] == at[5] > at[4]


def test_time_going_back_restarts_the_script():
    script = ActorScript(script_actor(trajectory(SQUARE), delay="1", pose="7 7 7 0 0 0"), frame_period=0)
    assert script.pose_at(3.0)[0] == (1.0, 1.0, 1.0)
    assert script.pose_at(0.5)[0] == (7.0, 7.0, 7.0)  # world reset: back at the <pose>
    # loaded at 1 s instead (delay 1 s): 1 s, then 2 s into the script
    assert script.pose_at(3.0, play_start_time=1.0)[0] == pytest.approx((-1.0, 1.0, 1.0))
    assert script.pose_at(4.0)[0] == pytest.approx((1.0, 1.0, 1.0))


def test_script_without_waypoints_stays_at_its_pose():
    notes = []
    desc = actor('<actor name="a"><pose>1 2 3 0 0 0</pose><script><trajectory id="0" type="walking"/></script>'
                 '</actor>', notes)
    assert len(notes) == 1 and "no waypoints" in notes[0]
    assert ActorScript(desc, frame_period=0).pose_at(5.0)[0] == (1.0, 2.0, 3.0)


# ------------------------------------------------------------------------------------------ ActorPlugin

def walker(xml=CAFE_ACTOR, seed=1, notes=None):
    desc = actor(xml)
    config = read_walker_config(desc, desc.plugin("libActorPlugin.so"), PATH + "/plugin",
                                [] if notes is None else notes)
    return ActorWalker(config, desc.world_pose, random.Random(seed)), config


def walker_with(plugin_tags, pose="0 0 1.2138 0 0 0"):
    return walker(f'<actor name="w"><pose>{pose}</pose><skin><filename>walk.dae</filename></skin>'
                  '<animation name="walking"><filename>walk.dae</filename></animation>'
                  f'<plugin name="p" filename="libActorPlugin.so">{plugin_tags}</plugin></actor>')[0]


def test_walker_config_from_cafe_world_and_defaults():
    _, config = walker()
    assert config.actor_name == "actor1" and config.target == (0.0, -5.0, 1.2138)
    assert (config.target_weight, config.obstacle_weight, config.animation_factor) == (1.15, 1.8, 5.1)
    assert config.ignore_models == ("cafe", "ground_plane")
    notes = []
    bare = walker('<actor name="b"><skin><filename>x.dae</filename></skin>'
                  '<plugin name="p" filename="libActorPlugin.so"/></actor>', notes=notes)[1]
    assert bare.target == (0.0, -5.0, 1.2138) and bare.target_weight == 1.15
    assert (bare.obstacle_weight, bare.animation_factor, bare.ignore_models) == (1.5, 4.5, ())
    assert len(notes) == 1 and "walking" in notes[0]
    notes = []
    odd = walker(CAFE_ACTOR.replace("<target_weight>1.15", "<target_weight>2.5 please"), notes=notes)[1]
    assert odd.target_weight == 2.5 and len(notes) == 1
    with pytest.raises(ModelError, match="target"):
        walker(CAFE_ACTOR.replace("0 -5 1.2138", "0 -5"))


def test_walker_turns_in_place_first_then_walks_to_its_target():
    w = walker_with("<target>3 0 1.2138</target>")  # facing yaw 0: the heading wants yaw 0 + 1.5707
    pose = w.update(0.001, {})
    assert pose[0] == (0.0, 0.0, 1.2138)  # turned, did not move
    roll = math.atan2(2 * (pose[1][3] * pose[1][0] + pose[1][1] * pose[1][2]),
                      1 - 2 * (pose[1][0] ** 2 + pose[1][1] ** 2))
    assert roll == pytest.approx(1.5707, abs=1e-9)
    assert w.body_pose()[1] == pytest.approx(0.0015707 - 1.5707, abs=1e-9)
    t = 0.001
    while w.body_pose()[1] < -math.radians(10) - 1e-9 and t < 5:
        t += 0.001
        w.update(t, {})
        assert w.position[:2] == (0.0, 0.0)
    assert 2.0 < t < 2.4  # 0.1 % of the error per update: about ln(9) s at 1 kHz
    w.update(t + 0.01, {})
    assert w.body_pose()[1] == pytest.approx(0.0, abs=1e-9)  # snapped to the heading, walking
    assert w.position[0] == pytest.approx(0.8 * 1.15 * 0.01)
    for k in range(2, 400):
        w.update(t + 0.01 * k, {})
        if w.target != (3.0, 0.0, 1.2138):
            break
    assert w.position[0] == pytest.approx(2.7, abs=0.01)  # within 0.3 m: a new target
    assert w.body_pose()[0][2] == pytest.approx(0.0)  # feet on the floor


def test_obstacles_push_the_heading_away():
    w = walker_with("<target>0 5 1.2138</target><obstacle_weight>1.5</obstacle_weight>"
                    "<ignore_obstacles><model>ground_plane</model></ignore_obstacles>")
    free = w.steering({})
    assert free == pytest.approx((0.0, 1.15, 0.0))
    pushed = w.steering({"box": (1.0, 1.0, 1.2138), "far": (5.0, 0.0, 1.2138), "ground_plane": (0.0, 0.0, 0.0),
                         "w": (0.0, 0.1, 1.2138)})
    d = math.sqrt(2.0)
    assert pushed == pytest.approx((-1.5 / d / d, 1.15 - 1.5 / d / d, 0.0))  # only "box": 1.5 / d along -unit


def test_new_targets_stay_on_the_floor_clear_of_models_and_repeat_with_the_seed():
    models = {"table1": (0.5, -1.6, 0.2), "table2": (2.4, -5.5, 0.2), "cafe": (0.0, 0.0, 0.0)}

    def draws(seed):
        w = walker_with("<target>0 0.1 1.2138</target>", pose="0 0 1.2138 0 0 0")
        w.rng = random.Random(seed)
        targets = []
        for k in range(20):
            w.position = w.target[:2] + (WALK_ROOT_HEIGHT,)  # arrived
            old = w.target
            w.update(k * 0.001, models)
            assert w.target != old
            x, y, z = w.target
            assert FLOOR_X[0] <= x <= FLOOR_X[1] and FLOOR_Y[0] <= y <= FLOOR_Y[1] and z == old[2]
            assert math.dist(w.target, old) >= 2.0
            assert all(math.dist(w.target, m) >= 2.0 for m in models.values())
            targets.append(w.target)
        return targets

    assert draws(7) == draws(7) and draws(7) != draws(8)


class ScriptedDraws:
    """A stand-in for random.Random that hands out given values and checks each draw's bounds."""

    def __init__(self, values):
        self.values = list(values)
        self.calls = []

    def uniform(self, low, high):
        self.calls.append((low, high))
        value = self.values.pop(0)
        assert low <= value <= high
        return value


def test_new_target_rejects_draws_near_the_old_target_and_near_ignored_models():
    w = walker_with("<target>0 0 1.2138</target><ignore_obstacles><model>ground_plane</model></ignore_obstacles>",
                    pose="0.29 0 1.2138 0 0 1.5707")
    w.rng = ScriptedDraws([-1.9, 0.0,  # 1.9 m from the old target (2.19 m from the actor): rejected
                           3.0, -3.0,  # 1.1 m from the ignored ground_plane model: rejected all the same
                           -2.9, -5.0])
    w.update(0.001, {"ground_plane": (3.0, -2.0, 1.2138)})
    assert w.target == (-2.9, -5.0, 1.2138)
    assert w.rng.calls == [(-3.0, 3.5), (-10.0, 2.0)] * 3  # x, then y, per draw


def test_walker_clamps_to_the_floor_and_resets():
    w = walker_with("<target>20 0 1.2138</target>", pose="3.4 0 1.25 0 0 1.5707")
    w.update(1.0, {})  # one 1 s step towards +x: clamped at 3.5
    assert w.position == (3.5, 0.0, 1.2138)
    w.reset()
    assert w.position == (3.4, 0.0, 1.25) and w.target == (20.0, 0.0, 1.2138) and w.last_update == 0.0


# ------------------------------------------------------------------------------------------ the body

def test_person_box_default_and_from_y_up_mesh_bounds():
    plain = actor('<actor name="a"><script/></actor>')
    assert person_box(plain) == PERSON_SIZE + ((0.0, 0.0, 0.9),)
    scaled = actor('<actor name="a"><skin><filename>w.dae</filename><scale>2</scale></skin></actor>')
    assert person_box(scaled)[:3] == pytest.approx((0.7, 1.0, 3.6))
    # skin frame: x across the shoulders, y up, z forward
    sx, sy, sz, centre = person_box(scaled, ((-0.25, 0.0, -0.1), (0.25, 1.8, 0.2)))
    assert (sx, sy, sz) == pytest.approx((0.6, 1.0, 3.6))
    assert centre == pytest.approx((0.1, 0.0, 1.8))
    with pytest.raises(ConfigError):
        person_box(plain, ((0, 1, 0), (1, 0, 1)))


def test_upright_pose_of_a_scripted_actor_and_of_a_walker():
    assert upright_pose(pose6_to_pose((1, 2, 0, 0, 0, 0.3))) == ((1, 2, 0), pytest.approx(0.3))
    walking = pose6_to_pose((1, 2, 1.2138, 1.5707, 0, 0.5 + 1.5707))
    (x, y, z), heading = upright_pose(walking, yaw_offset=1.5707, root_height=1.2138)
    assert (x, y, z) == (1, 2, pytest.approx(0.0)) and heading == pytest.approx(0.5)
