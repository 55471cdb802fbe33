"""world.sdf_reader.read_world: Gazebo-classic .world files (SDF 1.4-1.9) into WorldDescription, without PyBullet.

Every fixture is written here into tmp_path (TurtleBot3-style world and model directories included), except
the repository's own worlds/room.world. Poses are checked as (xyz, quaternion xyzw) in the world frame for
bodies and in the link frame for shapes, as world.bodies defines them.
"""
import math
import os

import pytest

from diffbot_sim.description import mesh_formats
from diffbot_sim.errors import ModelError
from diffbot_sim.transforms import yaw_from_quaternion
from diffbot_sim.world.model_paths import env_model_paths, ros_package_model_paths
from diffbot_sim.world.sdf_reader import read_world

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
ROOM = os.path.join(ROOT, "worlds", "room.world")
ROOM_MODELS = os.path.join(ROOT, "worlds", "models")


# ------------------------------------------------------------------------------------------ helpers

def write(path, text):
    os.makedirs(os.path.dirname(str(path)), exist_ok=True)
    with open(str(path), "w", encoding="utf-8") as out:
        out.write(text)
    return str(path)


def world_file(tmp_path, body, version="1.6", name="test.world", world="default"):
    return write(tmp_path / name, f'<?xml version="1.0"?>\n<sdf version="{version}">\n<world name="{world}">\n'
                                  f'{body}\n</world>\n</sdf>\n')


def model_dir(root, name, sdf_text, entries=(("1.6", "model.sdf"),), files=None):
    """A Gazebo model directory: model.config listing ``entries`` (version, file) and the given files."""
    directory = os.path.join(str(root), name)
    config = "".join(f'<sdf version="{v}">{f}</sdf>' if v else f"<sdf>{f}</sdf>" for v, f in entries)
    write(os.path.join(directory, "model.config"), f"<?xml version='1.0'?><model><name>{name}</name>{config}</model>")
    for _, filename in entries:
        write(os.path.join(directory, filename), sdf_text)
    for rel, text in (files or {}).items():
        write(os.path.join(directory, rel), text)
    return directory


def box_model(name, pose="0 0 0 0 0 0", static="true", size="1 1 1", link="link", extra=""):
    return (f'<model name="{name}"><static>{static}</static><pose>{pose}</pose>{extra}'
            f'<link name="{link}"><collision name="c"><geometry><box><size>{size}</size></box></geometry>'
            f'</collision><visual name="v"><geometry><box><size>{size}</size></box></geometry></visual>'
            f'</link></model>')


def model_sdf(model, version="1.6"):
    return f'<?xml version="1.0"?><sdf version="{version}">{model}</sdf>'


def bodies(world):
    return {b.name: b for b in world.bodies}


def near(a, b, tol=1e-9):
    return all(abs(x - y) <= tol for x, y in zip(a, b)) and len(a) == len(b)


def same_rotation(q, r, tol=1e-9):
    return near(q, r, tol) or near(q, tuple(-c for c in r), tol)


def yaw(q):
    return yaw_from_quaternion(*q)


def read(path, dirs=(), **kwargs):
    return read_world(path, model_paths=list(dirs), **kwargs)


TINY_DAE = """<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="inch" meter="0.0254"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries>
    <geometry id="hex" name="hex">
      <mesh>
        <source id="hex-pos">
          <float_array id="hex-pos-array" count="12">0 0 0 10 0 0 0 10 0 0 0 10</float_array>
          <technique_common><accessor source="#hex-pos-array" count="4" stride="3">
            <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
          </accessor></technique_common>
        </source>
        <vertices id="hex-vtx"><input semantic="POSITION" source="#hex-pos"/></vertices>
        <triangles count="4"><input semantic="VERTEX" source="#hex-vtx" offset="0"/>
          <p>0 2 1 0 1 3 0 3 2 1 2 3</p></triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="Scene"><node id="n"><instance_geometry url="#hex"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
"""


# ------------------------------------------------------------------------------------------ room.world

def test_room_world_layout_state_and_model_uri():
    world = read(ROOM, [ROOM_MODELS])
    b = bodies(world)
    assert world.name == "room" and world.has_ground and world.warnings == []
    assert set(b) == {"ground_plane::link", "walls::south", "walls::east", "walls::west", "walls::north",
                      "pillar::link", "ring::link", "pushable_box::link"}
    assert b["ground_plane::link"].shapes[0].kind == "plane"
    assert b["ground_plane::link"].shapes[0].surface == {"mu": 100.0, "mu2": 50.0}
    assert near(b["walls::east"].pose[0], (3.05, 0, 0.5)) and b["walls::east"].shapes[0].size == (0.1, 4.2, 1.0)
    north = b["walls::north"]
    assert [s.pose[0][0] for s in north.shapes] == [-1.8, 1.8]  # the doorway is x in [-0.5, 0.5]
    assert all(s.size == (2.6, 0.1, 1.0) for s in north.shapes)
    assert b["pillar::link"].shapes[0].kind == "cylinder" and b["pillar::link"].shapes[0].size == (0.2, 1.0)
    assert near(b["pillar::link"].pose[0], (1.5, -1.0, 0.5))
    ring = b["ring::link"]
    assert ring.static and ring.shapes[0].kind == "mesh"
    assert ring.shapes[0].mesh == os.path.join(ROOM_MODELS, "ring", "meshes", "ring.obj")
    assert near(ring.pose[0], (-1.5, -1.0, 0.0))
    box = b["pushable_box::link"]
    assert not box.static and box.mass == 0.5 and box.inertia[:3] == (0.0075, 0.0075, 0.0075)
    assert near(box.pose[0], (2.0, 0.0, 0.15))  # moved by <state> from the model's (1.0, 1.2, 0.15)
    assert box.shapes[0].size == (0.3, 0.3, 0.3)
    assert all(body.static for name, body in b.items() if name != "pushable_box::link")
    assert world.max_step_size == 0.001 and world.real_time_factor == 1.0 and world.gravity == (0, 0, -9.8)
    assert "light sun (directional)" in world.not_simulated
    assert world.real_time_update_rate == 1000.0  # with the 1 ms step: real time (simulator.robots)


def test_room_ring_mesh_is_a_hollow_hexagon():
    vertices, faces = mesh_formats.read_obj(os.path.join(ROOM_MODELS, "ring", "meshes", "ring.obj"))
    radii = sorted({round(math.hypot(x, y), 6) for x, y, _ in vertices})
    assert radii == [0.4, 0.5] and len(faces) == 48 and vertices[:, 2].max() == 0.5


def test_room_world_resolves_ring_through_package_export_path():
    world = read_world(ROOM, model_paths=[], package_model_paths=[ROOM_MODELS])
    assert bodies(world)["ring::link"].shapes[0].mesh.endswith("ring.obj")


# ------------------------------------------------------------------------------------------ TurtleBot3-style

def tb3_style(tmp_path):
    """A 1.4 world like turtlebot3_world.world / turtlebot3_stage_4.world, built from our own files."""
    models = tmp_path / "models"
    hexagons = ('<model name="ros_symbol"><static>1</static><link name="symbol">'
                '<collision name="one_one"><pose>-1.1 -1.1 0.25 0 0 0</pose>'
                '<geometry><cylinder><radius>0.15</radius><length>0.5</length></cylinder></geometry></collision>'
                '<collision name="head"><pose>3.5 0 -0.5 0 0 -1.5708</pose><geometry><mesh>'
                '<uri>model://tb3_world/meshes/hexagon.dae</uri><scale>0.55 0.55 0.55</scale></mesh></geometry>'
                '</collision><visual name="v"><geometry><mesh><uri>model://tb3_world/meshes/hexagon.dae</uri>'
                '</mesh></geometry></visual></link></model>')
    model_dir(models, "tb3_world", model_sdf(hexagons, "1.5"),
              entries=(("1.4", "model-1_4.sdf"), ("1.5", "model.sdf")),
              files={"meshes/hexagon.dae": TINY_DAE})
    # model-1_4.sdf deliberately differs: Gazebo picks model.sdf (the highest version), so must we
    write(models / "tb3_world" / "model-1_4.sdf", model_sdf(box_model("wrong_file"), "1.4"))
    body = """
    <include><uri>model://sun</uri></include>
    <include><uri>model://ground_plane</uri></include>
    <scene><ambient>0.4 0.4 0.4 1</ambient><shadows>true</shadows></scene>
    <gui fullscreen='0'><camera name='user_camera'><pose>0.8 0 12 0 1.5 0</pose></camera></gui>
    <physics type="ode">
      <real_time_update_rate>1000.0</real_time_update_rate>
      <max_step_size>0.001</max_step_size>
      <real_time_factor>1</real_time_factor>
      <gravity>0 0 -9.81</gravity>
      <ode><solver><type>quick</type><iters>150</iters></solver><constraints><cfm>0.00001</cfm></constraints></ode>
    </physics>
    <include><uri>model://tb3_world</uri><pose>0 0 0 0 0 0</pose></include>
    <model name='obstacle_2'>
      <pose frame=''>-1 1 0.125 0 0 0</pose>
      <plugin name='obstacle_2' filename='libobstacle_2.so'/>
      <link name='obstacle'>
        <collision name='obstacle'><geometry><cylinder><radius>0.12</radius><length>0.25</length></cylinder>
        </geometry><max_contacts>10</max_contacts></collision>
      </link>
    </model>
    """
    return world_file(tmp_path, body, version="1.4"), str(models)


def test_turtlebot3_style_world(tmp_path):
    path, models = tb3_style(tmp_path)
    world = read(path, [str(tmp_path / "empty"), models])
    b = bodies(world)
    assert set(b) == {"ground_plane::link", "ros_symbol::symbol", "obstacle_2::obstacle"}
    symbol = b["ros_symbol::symbol"]
    assert symbol.model == "ros_symbol" and symbol.static and near(symbol.pose[0], (0, 0, 0))
    mesh = [s for s in symbol.shapes if s.kind == "mesh"][0]
    assert mesh.mesh == os.path.join(models, "tb3_world", "meshes", "hexagon.dae")
    assert mesh.scale == (0.55, 0.55, 0.55) and mesh.name == "head"
    assert near(mesh.pose[0], (3.5, 0, -0.5)) and abs(yaw(mesh.pose[1]) + 1.5708) < 1e-9
    cylinder = [s for s in symbol.shapes if s.kind == "cylinder"][0]
    assert cylinder.size == (0.15, 0.5) and near(cylinder.pose[0], (-1.1, -1.1, 0.25))
    obstacle = b["obstacle_2::obstacle"]
    assert not obstacle.static and obstacle.mass == 1.0 and obstacle.inertia == (1, 1, 1, 0, 0, 0)
    assert near(obstacle.pose[0], (-1, 1, 0.125))
    assert world.gravity == (0, 0, -9.81)  # 1.4: gravity lives in <physics>
    assert world.has_ground and world.max_step_size == 0.001 and world.real_time_factor == 1.0
    assert world.real_time_update_rate == 1000.0
    assert world.sdf and world.solver_iterations == 150  # <ode><solver><iters>: Bullet's solver iterations
    for item in ("light sun (directional)", "plugin libobstacle_2.so in model obstacle_2", "scene", "gui"):
        assert item in world.not_simulated
    ode = [item for item in world.not_simulated if item.startswith("physics ode ")]
    assert len(ode) == 1 and "solver/type quick" in ode[0] and "constraints/cfm 0.00001" in ode[0]
    assert "only <solver><iters> is taken" in ode[0]
    assert len(world.not_simulated) == len(set(world.not_simulated))
    assert world.warnings == []
    # the tiny .dae is a real COLLADA file our mesh reader takes (inch units honoured)
    vertices, faces = mesh_formats.read_dae(mesh.mesh)
    assert len(faces) == 4 and abs(vertices.max() - 0.254) < 1e-9


# ------------------------------------------------------------------------------------------ includes

def test_include_name_pose_static_override_and_empty_pose(tmp_path):
    models = tmp_path / "models"
    model_dir(models, "crate", model_sdf(box_model("crate", pose="5 5 5 0 0 0", static="false")))
    path = world_file(tmp_path, """
      <include><uri>model://crate</uri><name>a</name><pose>1 2 0 0 0 1.5707963267948966</pose></include>
      <include><uri>model://crate</uri><name>b</name><static>true</static></include>
      <include><uri>model://crate</uri><name>c</name><pose/></include>
      <include><uri>model://crate</uri></include>""")
    b = bodies(read(path, [models]))
    assert near(b["a::link"].pose[0], (1, 2, 0)) and abs(yaw(b["a::link"].pose[1]) - math.pi / 2) < 1e-9
    assert not b["a::link"].static and b["b::link"].static
    assert near(b["b::link"].pose[0], (5, 5, 5))  # no <pose> in the include: the model's own
    assert near(b["c::link"].pose[0], (0, 0, 0))  # an empty <pose/> resets it to zero
    assert near(b["crate::link"].pose[0], (5, 5, 5)) and b["crate::link"].model == "crate"


def test_include_inside_model_and_its_plugins(tmp_path):
    models = tmp_path / "models"
    model_dir(models, "wheel", model_sdf(box_model("wheel", pose="0 0 1 0 0 0")))
    path = world_file(tmp_path, """
      <model name="cart"><static>true</static><pose>10 0 0 0 0 0</pose>
        <include><uri>model://wheel</uri><name>front</name><pose>1 0 0 0 0 0</pose>
          <plugin name="spin" filename="libspin.so"/></include>
        <include><uri>model://wheel</uri></include>
      </model>""")
    world = read(path, [models])
    b = bodies(world)
    assert near(b["cart::front::link"].pose[0], (11, 0, 0)) and b["cart::front::link"].model == "cart::front"
    assert near(b["cart::wheel::link"].pose[0], (10, 0, 1))
    assert "plugin libspin.so in model cart::front" in world.not_simulated


def test_include_file_uri_absolute_and_relative_paths(tmp_path):
    crate = model_dir(tmp_path / "elsewhere", "crate", model_sdf(box_model("crate")))
    single = write(tmp_path / "single.sdf", model_sdf(box_model("single", pose="0 3 0 0 0 0")))
    path = world_file(tmp_path, f"""
      <include><uri>file://{crate}</uri><name>abs</name></include>
      <include><uri>elsewhere/crate</uri><name>rel</name></include>
      <include><uri>{single}</uri></include>""")
    b = bodies(read(path, []))
    assert {"abs::link", "rel::link", "single::link"} == set(b)


def test_builtin_ground_plane_and_sun_without_any_model_directory(tmp_path):
    path = world_file(tmp_path, "<include><uri>model://ground_plane</uri></include>"
                                "<include><uri>model://sun</uri></include>")
    world = read(path, [str(tmp_path / "nothing_here")])
    (ground,) = world.bodies
    assert ground.name == "ground_plane::link" and ground.static and world.has_ground
    assert ground.shapes[0].name == "collision" and ground.shapes[0].size == (0, 0, 1)
    assert world.not_simulated == ["light sun (directional)"]


def test_directory_ground_plane_wins_over_builtin(tmp_path):
    models = tmp_path / "models"
    model_dir(models, "ground_plane", model_sdf(box_model("ground_plane", size="9 9 0.1")))
    path = world_file(tmp_path, "<include><uri>model://ground_plane</uri></include>")
    world = read(path, [models])
    assert world.bodies[0].shapes[0].kind == "box" and not world.has_ground


def test_unresolved_uri_names_uri_including_file_and_every_directory(tmp_path):
    path = world_file(tmp_path, "<include><uri>model://nowhere</uri></include>")
    dirs = [str(tmp_path / "a"), str(tmp_path / "b")]
    with pytest.raises(ModelError) as err:
        read(path, dirs[:1], package_model_paths=dirs[1:])
    text = str(err.value)
    assert "model://nowhere" in text and path in text and dirs[0] in text and dirs[1] in text
    assert "\n" not in text and "never downloaded" in text


def test_network_uri_is_never_fetched(tmp_path):
    path = world_file(tmp_path, "<include><uri>https://fuel.gazebosim.org/1.0/OpenRobotics/models/X</uri>"
                                "</include>")
    with pytest.raises(ModelError, match="network address"):
        read(path, [])


def test_include_cycle_is_an_error(tmp_path):
    models = tmp_path / "models"
    model_dir(models, "loop", model_sdf('<model name="loop"><include><uri>model://loop</uri></include></model>'))
    path = world_file(tmp_path, "<include><uri>model://loop</uri></include>")
    with pytest.raises(ModelError, match="includes itself"):
        read(path, [models])


def test_include_without_uri_is_an_error(tmp_path):
    path = world_file(tmp_path, "<include><name>x</name></include>")
    with pytest.raises(ModelError, match="no <uri>"):
        read(path, [])


# ------------------------------------------------------------------------------------------ model.config

def test_model_config_picks_highest_version_up_to_1_9(tmp_path):
    models = tmp_path / "models"
    directory = model_dir(models, "m", model_sdf(box_model("m")),
                          entries=(("1.5", "a.sdf"), ("1.9", "b.sdf"), ("2.0", "c.sdf"), ("1.7", "d.sdf")))
    write(os.path.join(directory, "b.sdf"), model_sdf(box_model("chosen"), "1.9"))
    world = read(world_file(tmp_path, "<include><uri>model://m</uri></include>"), [models])
    assert world.bodies[0].model == "chosen"
    assert any("c.sdf" in w and "ignored" in w for w in world.warnings)


def test_model_config_without_versions_takes_the_first(tmp_path):
    models = tmp_path / "models"
    directory = model_dir(models, "m", model_sdf(box_model("second")), entries=((None, "a.sdf"), (None, "b.sdf")))
    write(os.path.join(directory, "a.sdf"), model_sdf(box_model("first")))
    world = read(world_file(tmp_path, "<include><uri>model://m</uri></include>"), [models])
    assert world.bodies[0].model == "first"


def test_manifest_xml_fallback_warns(tmp_path):
    directory = tmp_path / "models" / "old"
    write(directory / "manifest.xml", '<model><sdf version="1.4">model.sdf</sdf></model>')
    write(directory / "model.sdf", model_sdf(box_model("old"), "1.4"))
    world = read(world_file(tmp_path, "<include><uri>model://old</uri></include>"), [tmp_path / "models"])
    assert world.bodies[0].model == "old"
    assert any("manifest.xml is deprecated" in w for w in world.warnings)


def test_model_directory_without_config_is_an_error(tmp_path):
    write(tmp_path / "models" / "bare" / "model.sdf", model_sdf(box_model("bare")))
    with pytest.raises(ModelError, match="has no model.config"):
        read(world_file(tmp_path, "<include><uri>model://bare</uri></include>"), [tmp_path / "models"])


def test_model_config_naming_a_missing_file_is_an_error(tmp_path):
    directory = model_dir(tmp_path / "models", "m", model_sdf(box_model("m")))
    os.remove(os.path.join(directory, "model.sdf"))
    with pytest.raises(ModelError, match="model.sdf, which does not exist"):
        read(world_file(tmp_path, "<include><uri>model://m</uri></include>"), [tmp_path / "models"])


# ------------------------------------------------------------------------------------------ search order

def test_search_order_home_then_gazebo_model_path_then_packages(tmp_path, monkeypatch):
    home, first, second, package = (tmp_path / n for n in ("home", "first", "second", "package"))
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.setenv("GAZEBO_MODEL_PATH", f"{first}::{second}")
    assert env_model_paths() == [str(home / ".gazebo" / "models"), str(first), str(second)]
    for directory, tag in ((second, "second"), (package, "package"), (first, "first")):
        model_dir(directory, "thing", model_sdf(box_model(tag)))
    path = world_file(tmp_path, "<include><uri>model://thing</uri></include>")
    assert read_world(path, package_model_paths=[str(package)]).bodies[0].model == "first"
    model_dir(home / ".gazebo" / "models", "thing", model_sdf(box_model("home")))
    assert read_world(path, package_model_paths=[str(package)]).bodies[0].model == "home"
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(tmp_path / "nothing"))
    os.rename(str(home / ".gazebo" / "models" / "thing"), str(home / "moved"))
    assert read_world(path, package_model_paths=[str(package)]).bodies[0].model == "package"


def test_model_paths_argument_replaces_the_environment(tmp_path, monkeypatch):
    env_dir, arg_dir = tmp_path / "env", tmp_path / "arg"
    model_dir(env_dir, "thing", model_sdf(box_model("from_env")))
    model_dir(arg_dir, "thing", model_sdf(box_model("from_arg")))
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(env_dir))
    path = world_file(tmp_path, "<include><uri>model://thing</uri></include>")
    assert read_world(path, model_paths=[str(arg_dir)]).bodies[0].model == "from_arg"


def test_mesh_model_uri_uses_the_same_search(tmp_path):
    models = tmp_path / "models"
    model_dir(models, "meshes_only", "", entries=(), files={"meshes/part.stl": "solid x\nendsolid x\n"})
    path = world_file(tmp_path, """<model name="m"><static>1</static><link name="l"><collision name="c">
      <geometry><mesh><uri>model://meshes_only/meshes/part.stl</uri></mesh></geometry></collision></link></model>""")
    (body,) = read(path, [models]).bodies
    assert body.shapes[0].mesh == str(models / "meshes_only" / "meshes" / "part.stl")
    assert body.shapes[0].scale == (1.0, 1.0, 1.0)


def _package(root, name, depends=(), export=None):
    deps = "".join(f"<depend>{d}</depend>" for d in depends)
    exp = f'<export><gazebo_ros gazebo_model_path="{export}"/></export>' if export else ""
    write(os.path.join(str(root), name, "package.xml"),
          f'<?xml version="1.0"?><package format="2"><name>{name}</name><version>1.0.0</version>'
          f'<description>d</description><maintainer email="dev@example.com">m</maintainer><license>BSD</license>'
          f'<buildtool_depend>catkin</buildtool_depend>{deps}{exp}</package>')
    os.makedirs(os.path.join(str(root), name, "models"), exist_ok=True)


def test_ros_package_model_paths_dependents_first_then_other_exporters(tmp_path):
    rospkg = pytest.importorskip("rospkg")
    _package(tmp_path, "zeta_gazebo", depends=["gazebo_ros"], export="${prefix}/models")
    _package(tmp_path, "alpha_sim", export="${prefix}/models")
    _package(tmp_path, "no_export", depends=["gazebo_ros"])
    paths = ros_package_model_paths(rospkg.RosPack(ros_paths=[str(tmp_path)]))
    assert paths == [str(tmp_path / "zeta_gazebo" / "models"), str(tmp_path / "alpha_sim" / "models")]


def test_ros_package_model_paths_follow_a_linked_manifest(tmp_path):
    rospkg = pytest.importorskip("rospkg")
    _package(tmp_path / "source", "linked", export="${prefix}/worlds/models")
    os.makedirs(str(tmp_path / "source" / "linked" / "worlds" / "models"))
    os.makedirs(str(tmp_path / "ws" / "linked"))
    os.symlink(str(tmp_path / "source" / "linked" / "package.xml"), str(tmp_path / "ws" / "linked" / "package.xml"))
    paths = ros_package_model_paths(rospkg.RosPack(ros_paths=[str(tmp_path / "ws")]))
    assert paths == [str(tmp_path / "source" / "linked" / "worlds" / "models")]


def test_ros_package_model_paths_of_the_package_path_are_read_once(tmp_path, monkeypatch):
    rospkg = pytest.importorskip("rospkg")
    _package(tmp_path, "alpha_sim", export="${prefix}/models")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    made = []

    class CountingRosPack(rospkg.RosPack):
        def __init__(self, *args, **kwargs):
            made.append(1)
            super().__init__(*args, **kwargs)
    monkeypatch.setattr(rospkg, "RosPack", CountingRosPack)
    first = ros_package_model_paths()
    first.append("changed by the caller")
    assert ros_package_model_paths() == [str(tmp_path / "alpha_sim" / "models")] and len(made) == 1


# ------------------------------------------------------------------------------------------ models, links

def test_nested_models_names_poses_and_inherited_static(tmp_path):
    path = world_file(tmp_path, """
      <model name="outer"><static>true</static><pose>1 0 0 0 0 1.5707963267948966</pose>
        <link name="base"><pose>0 0 0.5 0 0 0</pose></link>
        <model name="inner"><pose>2 0 0 0 0 0</pose>
          <link name="part"><pose>0 1 0 0 0 0</pose>
            <collision name="c"><pose>0 0 0.1 0 0 0</pose><geometry><sphere><radius>0.3</radius></sphere>
            </geometry></collision></link>
        </model>
      </model>""")
    b = bodies(read(path, []))
    part = b["outer::inner::part"]
    assert part.model == "outer::inner" and part.static  # a static parent makes its nested models static
    assert near(part.pose[0], (0, 2, 0))  # (1,0,0) + Rz(90) * ((2,0,0) + (0,1,0)) = (1,0,0) + (-1,2,0)
    assert abs(yaw(part.pose[1]) - math.pi / 2) < 1e-9
    assert near(part.shapes[0].pose[0], (0, 0, 0.1)) and part.shapes[0].size == (0.3,)
    assert near(b["outer::base"].pose[0], (1, 0, 0.5))


def test_several_links_are_separate_bodies_and_joints_warn_once(tmp_path):
    path = world_file(tmp_path, """
      <model name="door"><pose>0 0 0 0 0 0</pose>
        <link name="frame"><inertial><mass>5</mass><pose>0 0 1 0 0 0</pose>
          <inertia><ixx>2</ixx><iyy>3</iyy><izz>4</izz><ixy>0.1</ixy></inertia></inertial>
          <collision name="c"><geometry><box><size>0.1 0.1 2</size></box></geometry></collision></link>
        <link name="leaf"><pose>0.5 0 1 0 0 0</pose>
          <collision name="c"><geometry><box><size>1 0.05 2</size></box></geometry></collision></link>
        <joint name="hinge" type="revolute"><parent>frame</parent><child>leaf</child></joint>
        <joint name="lock" type="fixed"><parent>world</parent><child>frame</child></joint>
      </model>""")
    world = read(path, [])
    b = bodies(world)
    assert [n for n in b] == ["door::frame", "door::leaf"] and not any(x.static for x in b.values())
    frame = b["door::frame"]
    assert frame.mass == 5 and frame.inertia == (2, 3, 4, 0.1, 0, 0) and near(frame.inertial_pose[0], (0, 0, 1))
    assert b["door::leaf"].mass == 1.0 and b["door::leaf"].inertia == (1, 1, 1, 0, 0, 0)
    joint_warnings = [w for w in world.warnings if "joint" in w]
    assert len(joint_warnings) == 1 and "hinge" in joint_warnings[0] and "lock" in joint_warnings[0]


def test_visuals_are_ignored_and_a_link_without_collisions_has_no_shapes(tmp_path):
    path = world_file(tmp_path, """<model name="m"><static>1</static><link name="l">
      <visual name="v"><geometry><box><size>1 1 1</size></box></geometry></visual></link></model>""")
    (body,) = read(path, []).bodies
    assert body.shapes == []


def test_static_values(tmp_path):
    path = world_file(tmp_path, box_model("a", static="true") + box_model("b", static="1")
                      + box_model("c", static="false") + box_model("d", static="0")
                      + '<model name="e"><link name="link"/></model>')
    b = bodies(read(path, []))
    assert [b[f"{n}::link"].static for n in "abcde"] == [True, True, False, False, False]


def test_zero_mass_is_tolerated_in_static_models_and_defaulted_in_dynamic_ones(tmp_path):
    link = '<link name="link"><inertial><mass>0</mass></inertial></link>'
    path = world_file(tmp_path, f'<model name="s"><static>true</static>{link}</model>'
                                f'<model name="d">{link}</model>')
    world = read(path, [])
    b = bodies(world)
    assert b["s::link"].mass == 0 and b["d::link"].mass == 1.0
    assert [w for w in world.warnings if "mass" in w] == [
        f"{path}: /sdf/world[@name='default']/model[@name='d']/link[@name='link']/inertial/mass: 0.0 is not > 0 "
        f"in a non-static model; SDF's default 1 kg used"]


def test_duplicate_model_name_is_skipped_with_a_warning(tmp_path):
    world = read(world_file(tmp_path, box_model("x") + box_model("x", pose="1 0 0 0 0 0")), [])
    assert len(world.bodies) == 1 and any("second model named 'x'" in w for w in world.warnings)


# ------------------------------------------------------------------------------------------ geometry

def test_geometries_and_surfaces(tmp_path):
    write(tmp_path / "meshes" / "rel.stl", "solid x\nendsolid x\n")
    absolute = write(tmp_path / "abs" / "part.obj", "v 0 0 0\n")
    path = world_file(tmp_path, f"""
      <model name="m"><static>true</static><link name="l">
        <collision name="box"><geometry><box><size>1 2 3</size></box></geometry>
          <laser_retro>100</laser_retro>
          <surface><friction><ode><mu>0.3</mu><mu2>0.4</mu2></ode><bullet><friction>9</friction></bullet>
          </friction><contact><ode><kp>1e6</kp><kd>10</kd></ode></contact></surface></collision>
        <collision name="cyl"><geometry><cylinder><radius>0.5</radius><length>2</length></cylinder></geometry>
          <surface><friction><bullet><friction>0.7</friction><friction2>0.8</friction2></bullet></friction>
          </surface></collision>
        <collision name="ball"><geometry><sphere><radius>0.25</radius></sphere></geometry></collision>
        <collision name="floor"><geometry><plane><normal>0 0 2</normal><size>5 5</size></plane></geometry>
        </collision>
        <collision name="rel"><geometry><mesh><uri>meshes/rel.stl</uri><scale>2 2 2</scale></mesh></geometry>
        </collision>
        <collision name="file"><geometry><mesh><uri>file://{absolute}</uri></mesh></geometry></collision>
        <collision name="abs"><geometry><mesh><uri>{absolute}</uri>
          <submesh><name>part</name><center>true</center></submesh></mesh></geometry></collision>
        <collision name="hm"><geometry><heightmap><uri>x.png</uri></heightmap></geometry></collision>
        <collision name="pl"><geometry><polyline><point>0 0</point><height>1</height></polyline></geometry>
        </collision>
        <collision name="img"><geometry><image><uri>x.png</uri></image></geometry></collision>
        <collision name="none"><geometry><empty/></geometry></collision>
        <collision name="missing"><geometry><mesh><uri>model://ghost/meshes/x.dae</uri></mesh></geometry>
        </collision>
        <collision name="fbx"><geometry><mesh><uri>meshes/x.fbx</uri></mesh></geometry></collision>
      </link></model>""")
    world = read(path, [])
    shapes = {s.name: s for s in world.bodies[0].shapes}
    assert list(shapes) == ["box", "cyl", "ball", "floor", "rel", "file", "abs"]
    assert shapes["box"].size == (1, 2, 3)
    assert shapes["box"].surface == {"mu": 0.3, "mu2": 0.4, "kp": 1e6, "kd": 10, "laser_retro": 100}
    assert shapes["cyl"].size == (0.5, 2) and shapes["cyl"].surface == {"mu": 0.7, "mu2": 0.8}
    assert shapes["ball"].size == (0.25,) and shapes["ball"].surface == {}
    assert shapes["floor"].kind == "plane" and shapes["floor"].size == (0, 0, 1)  # unit normal; size ignored
    assert shapes["rel"].mesh == str(tmp_path / "meshes" / "rel.stl") and shapes["rel"].scale == (2, 2, 2)
    assert shapes["file"].mesh == absolute and shapes["abs"].mesh == absolute
    text = "\n".join(world.warnings)
    for needle in ("submesh is not supported", "<heightmap> geometry is not supported",
                   "<polyline> geometry is not supported", "<image> geometry is not supported",
                   "<empty> geometry is not supported", "mesh 'model://ghost/meshes/x.dae' not found",
                   "is not .dae, .stl or .obj"):
        assert needle in text
    assert all("\n" not in w for w in world.warnings)
    assert world.has_ground


def test_geometry_defaults_follow_sdf(tmp_path):
    path = world_file(tmp_path, """<model name="m"><static>1</static><link name="l">
      <collision name="b"><geometry><box/></geometry></collision>
      <collision name="c"><geometry><cylinder/></geometry></collision>
      <collision name="s"><geometry><sphere/></geometry></collision>
      <collision name="p"><geometry><plane/></geometry></collision></link></model>""")
    shapes = read(path, []).bodies[0].shapes
    assert [s.size for s in shapes] == [(1, 1, 1), (1, 1), (1,), (0, 0, 1)]


def test_plane_in_dynamic_model_warns_and_is_not_ground(tmp_path):
    path = world_file(tmp_path, """<model name="m"><link name="l">
      <collision name="p"><geometry><plane/></geometry></collision></link></model>""")
    world = read(path, [])
    assert not world.has_ground and any("non-static" in w for w in world.warnings)


def test_a_number_with_a_tail_is_read_as_sdformat_reads_it(tmp_path):
    path = world_file(tmp_path, '<model name="m"><static>true</static><link name="l"><collision name="c"><geometry>'
                                '<sphere><radius>0.25m</radius></sphere></geometry></collision></link></model>')
    world = read(path, [])
    (body,) = [b for b in world.bodies if b.shapes[0].kind == "sphere"]
    assert body.shapes[0].size == (0.25,)
    assert len([w for w in world.warnings if "<radius>" not in w and "/radius: took 0.25 from '0.25m'" in w]) == 1


def test_bad_numbers_name_the_element(tmp_path):
    path = world_file(tmp_path, box_model("m", size="1 two 3"))
    with pytest.raises(ModelError) as err:
        read(path, [])
    assert "model[@name='m']" in str(err.value) and "<size> '1 two 3' is not 3 finite numbers" in str(err.value)
    path = world_file(tmp_path, box_model("m", pose="1 2 3"))
    with pytest.raises(ModelError, match=r"<pose> '1 2 3' is not 6 finite numbers"):
        read(path, [])
    path = world_file(tmp_path, '<model name="m"><link name="l"><collision name="c"><geometry><sphere>'
                                '<radius>-1</radius></sphere></geometry></collision></link></model>')
    with pytest.raises(ModelError, match=r"<radius> -1 must be > 0"):
        read(path, [])


# ------------------------------------------------------------------------------------------ poses

def test_sdf_1_7_relative_to_models_links_and_frames(tmp_path):
    path = world_file(tmp_path, """
      <frame name="corner"><pose>10 0 0 0 0 0</pose></frame>
      <frame name="beside_table" attached_to="table"><pose>0 1 0 0 0 0</pose></frame>
      <model name="table"><static>true</static><pose relative_to="corner">1 0 0 0 0 1.5707963267948966</pose>
        <frame name="top" attached_to="legs"><pose>0 0 0.7 0 0 0</pose></frame>
        <link name="legs"><pose>0.5 0 0 0 0 0</pose></link>
        <link name="plate"><pose relative_to="top">0 0 0.05 0 0 0</pose></link>
        <link name="rel_model"><pose relative_to="__model__">0 0 1 0 0 0</pose></link>
      </model>
      <model name="cup"><static>true</static><pose relative_to="table::plate">0 0 0.1 0 0 0</pose>
        <link name="link"/></model>
      <model name="chair"><static>true</static><pose relative_to="beside_table"/><link name="link"/></model>
      <model name="lamp"><static>true</static><pose relative_to="">3 0 0 0 0 0</pose><link name="link"/></model>
      """, version="1.7")
    b = bodies(read(path, []))
    # table frame: (11, 0, 0) yawed 90 degrees; its x axis is the world's y
    assert near(b["table::legs"].pose[0], (11, 0.5, 0))
    assert near(b["table::plate"].pose[0], (11, 0.5, 0.75)) and abs(yaw(b["table::plate"].pose[1]) - math.pi / 2) < 1e-9
    assert near(b["table::rel_model"].pose[0], (11, 0, 1))
    assert near(b["cup::link"].pose[0], (11, 0.5, 0.85))
    assert near(b["chair::link"].pose[0], (10, 0, 0))  # table frame + its local y (-x in the world)
    assert near(b["lamp::link"].pose[0], (3, 0, 0))


def test_sdf_1_6_frame_attribute_empty_is_tolerated(tmp_path):
    path = world_file(tmp_path, box_model("m").replace("<pose>", "<pose frame=''>"))
    assert near(read(path, []).bodies[0].pose[0], (0, 0, 0))


def test_unknown_relative_to_warns_and_uses_the_parent_frame(tmp_path):
    path = world_file(tmp_path, '<model name="m"><static>1</static><pose>1 0 0 0 0 0</pose>'
                                '<link name="l"><pose relative_to="nothing">0 2 0 0 0 0</pose></link></model>',
                      version="1.7")
    world = read(path, [])
    assert near(world.bodies[0].pose[0], (1, 2, 0))
    assert any("relative_to 'nothing' names no frame of model m" in w for w in world.warnings)


def test_cycle_of_frames_is_an_error(tmp_path):
    path = world_file(tmp_path, '<frame name="a"><pose relative_to="b"/></frame>'
                                '<frame name="b"><pose relative_to="a"/></frame>'
                                '<model name="m"><pose relative_to="a"/><link name="l"/></model>', version="1.7")
    with pytest.raises(ModelError, match="cycle"):
        read(path, [])


def test_sdf_1_9_degrees_and_quaternions(tmp_path):
    path = world_file(tmp_path, """
      <model name="deg"><static>1</static><pose degrees="true">1 0 0 0 0 90</pose><link name="l"/></model>
      <model name="quat"><static>1</static>
        <pose rotation_format="quat_xyzw">0 2 0 0 0 0.7071067811865476 0.7071067811865476</pose>
        <link name="l"><pose degrees="true">1 0 0 180 0 0</pose></link></model>""", version="1.9")
    b = bodies(read(path, []))
    assert abs(yaw(b["deg::l"].pose[1]) - math.pi / 2) < 1e-9
    quat = b["quat::l"]
    assert near(quat.pose[0], (0, 3, 0))  # the link's local x is the world's y
    assert same_rotation(quat.pose[1], (0.7071067811865476, 0.7071067811865476, 0, 0))
    bad = world_file(tmp_path, '<model name="m"><pose rotation_format="quat_xyzw">0 0 0 0 0 0 0</pose>'
                               '<link name="l"/></model>', version="1.9", name="bad.world")
    with pytest.raises(ModelError, match="quaternion is zero"):
        read(bad, [])


def test_placement_frame_places_the_named_frame(tmp_path):
    models = tmp_path / "models"
    model_dir(models, "shelf", model_sdf('<model name="shelf"><static>1</static>'
                                         '<frame name="foot"><pose>0 0 -0.5 0 0 0</pose></frame>'
                                         '<link name="link"/></model>', "1.8"))
    path = world_file(tmp_path, "<include><uri>model://shelf</uri><pose>2 0 0 0 0 0</pose>"
                                "<placement_frame>foot</placement_frame></include>", version="1.8")
    assert near(read(path, [models]).bodies[0].pose[0], (2, 0, 0.5))


# ------------------------------------------------------------------------------------------ state

def test_first_state_overrides_model_link_and_nested_poses(tmp_path):
    path = world_file(tmp_path, """
      <model name="car"><pose>1 0 0 0 0 0</pose>
        <link name="body"><pose>0 0 0.2 0 0 0</pose></link>
        <link name="wheel"><pose>0.5 0 0 0 0 0</pose></link>
        <model name="roof"><pose>0 0 1 0 0 0</pose><link name="rack"/></model>
      </model>
      <model name="stay"><pose>7 7 0 0 0 0</pose><link name="l"/></model>
      <model name="origin"><pose>4 4 0 0 0 0</pose><link name="l"/></model>
      <state world_name="default">
        <sim_time>12 0</sim_time>
        <model name="car"><pose>5 5 0 0 0 1.5707963267948966</pose>
          <link name="car::wheel"><pose>9 9 9 0 0 0</pose></link>
          <model name="roof"><pose>0 0 3 0 0 0</pose></model>
        </model>
        <model name="origin"/>
        <model name="unit_box"><pose>1 1 1 0 0 0</pose></model>
      </state>
      <state world_name="default"><model name="stay"><pose>0 0 0 0 0 0</pose></model></state>
      """)
    world = read(path, [])
    b = bodies(world)
    assert near(b["car::body"].pose[0], (5, 5, 0.2)) and abs(yaw(b["car::body"].pose[1]) - math.pi / 2) < 1e-9
    assert near(b["car::wheel"].pose[0], (9, 9, 9))  # a link state sets that link's world pose
    assert near(b["car::roof::rack"].pose[0], (0, 0, 3))  # nested model state: its world pose
    assert near(b["stay::l"].pose[0], (7, 7, 0))  # only the first <state> applies
    assert near(b["origin::l"].pose[0], (0, 0, 0))  # a state entry without <pose>: zero, as Gazebo
    assert any("no model named 'unit_box'" in w for w in world.warnings)
    assert any("only the first applies" in w for w in world.warnings)


def test_state_moves_nested_models_rigidly_with_their_parent(tmp_path):
    path = world_file(tmp_path, """
      <model name="p"><pose>1 0 0 0 0 0</pose><link name="a"/>
        <model name="q"><pose>0 1 0 0 0 0</pose><link name="b"/></model></model>
      <state world_name="default"><model name="p"><pose>2 0 0 0 0 0</pose></model></state>""")
    b = bodies(read(path, []))
    assert near(b["p::a"].pose[0], (2, 0, 0)) and near(b["p::q::b"].pose[0], (2, 1, 0))


def test_state_insertions_and_deletions(tmp_path):
    path = world_file(tmp_path, box_model("old") + """
      <state world_name="default">
        <insertions>""" + box_model("added", pose="3 0 0 0 0 0") + """</insertions>
        <deletions><name>old</name></deletions>
        <model name="added"><pose>4 0 0 0 0 0</pose></model>
      </state>""")
    b = bodies(read(path, []))
    assert list(b) == ["added::link"] and near(b["added::link"].pose[0], (4, 0, 0))


# ------------------------------------------------------------------------------------------ physics, rest

def test_physics_gravity_and_not_simulated_once(tmp_path):
    path = world_file(tmp_path, """
      <gravity>0 0 -3.7</gravity>
      <physics name="fast" type="bullet"><max_step_size>0.004</max_step_size>
        <real_time_factor>2</real_time_factor><max_contacts>20</max_contacts><gravity>0 0 -1</gravity>
        <bullet><solver><iters>50</iters></solver></bullet></physics>
      <physics name="slow"><max_step_size>0.01</max_step_size></physics>
      <light name="lamp" type="point"/><light name="spot1" type="spot"/><light name="lamp" type="point"/>
      <scene/><gui/><atmosphere type="adiabatic"/><magnetic_field>0 0 1</magnetic_field>
      <spherical_coordinates/><wind/><audio/><actor name="walker"/><road name="street"/>
      <population name="cans"/><plugin name="p" filename="libworld_thing.so"/>
      <model name="robot"><plugin name="drive" filename="libdrive.so"/><link name="l">
        <sensor name="lidar" type="ray"/></link></model>""")
    world = read(path, [])
    assert world.gravity == (0, 0, -3.7) and world.max_step_size == 0.004 and world.real_time_factor == 2
    assert [a.name for a in world.actors] == ["walker"]  # an actor is simulated (simulator.actors)
    assert world.not_simulated == [
        "light lamp (point)", "light spot1 (spot)", "scene", "gui", "atmosphere", "magnetic_field",
        "spherical_coordinates", "wind", "audio", "road street", "population cans",
        "plugin libworld_thing.so in world", "plugin libdrive.so in model robot",
        "sensor lidar (ray) in link robot::l", "physics profile slow",
        "physics type bullet (Bullet is used whatever the file says)", "physics max_contacts",
        "physics bullet/solver"]
    assert any("SDF 1.6 moved gravity to <world>" in w for w in world.warnings)


def test_default_physics_profile_is_chosen(tmp_path):
    path = world_file(tmp_path, '<physics name="a"><max_step_size>0.002</max_step_size></physics>'
                                '<physics name="b" default="true"><max_step_size>0.005</max_step_size></physics>')
    world = read(path, [])
    assert world.max_step_size == 0.005 and "physics profile a" in world.not_simulated


def test_no_physics_leaves_defaults(tmp_path):
    world = read(world_file(tmp_path, box_model("m")), [])
    assert world.max_step_size is None and world.real_time_factor is None and world.gravity == (0, 0, -9.8)
    assert not world.has_ground


def test_unknown_versions_are_read_as_the_nearest(tmp_path):
    world = read(world_file(tmp_path, box_model("m"), version="1.3"), [])
    assert any("SDF 1.3 is not one of 1.4-1.9; read as SDF 1.4" in w for w in world.warnings)
    world = read(world_file(tmp_path, box_model("m"), version="1.11"), [])
    assert any("read as SDF 1.9" in w for w in world.warnings)
    world = read(world_file(tmp_path, box_model("m"), version="abc"), [])
    assert any("is not a version" in w for w in world.warnings)


def test_malformed_xml_names_file_and_line(tmp_path):
    path = write(tmp_path / "broken.world", '<?xml version="1.0"?>\n<sdf version="1.6">\n<world name="w">\n'
                                            '<model name="m">\n</world>\n</sdf>\n')
    with pytest.raises(ModelError) as err:
        read(path, [])
    assert str(err.value).startswith(f"{path}: malformed XML at line 5") and "\n" not in str(err.value)


def test_malformed_included_model_names_that_file(tmp_path):
    directory = model_dir(tmp_path / "models", "m", "<sdf version='1.6'><model name='m'>")
    path = world_file(tmp_path, "<include><uri>model://m</uri></include>")
    with pytest.raises(ModelError) as err:
        read(path, [tmp_path / "models"])
    assert str(err.value).startswith(os.path.join(directory, "model.sdf") + ": malformed XML at line 1")


def test_missing_file_and_missing_world(tmp_path):
    with pytest.raises(ModelError, match="no such file"):
        read(str(tmp_path / "nope.world"), [])
    path = write(tmp_path / "model.sdf", model_sdf(box_model("m")))
    with pytest.raises(ModelError, match="no <world> element"):
        read(path, [])
    path = write(tmp_path / "robot.world", "<robot name='r'/>")
    with pytest.raises(ModelError, match="root element is <robot>"):
        read(path, [])


def test_actors_of_the_world_and_of_includes(tmp_path):
    """<actor> at world level and through <include> (its <name> and <pose> replace the file's): read as
    world.actor_script reads them; a second model or actor of one name is one warning."""
    models = tmp_path / "models"
    model_dir(models, "person", '<sdf version="1.6"><actor name="someone"><pose>9 9 0 0 0 0</pose><script>'
              '<trajectory id="0" type="walking"><waypoint><time>0</time><pose>0 0 0 0 0 0</pose></waypoint>'
              '<waypoint><time>2</time><pose>1 0 0 0 0 0</pose></waypoint></trajectory></script></actor></sdf>')
    path = world_file(tmp_path, """
      <actor name="a1"><script><trajectory id="0" type="walk"><waypoint><time>0</time><pose>1 2 0 0 0 0</pose>
        </waypoint></trajectory></script></actor>
      <include><uri>model://person</uri><name>visitor</name><pose>3 4 0 0 0 1</pose></include>
      <actor name="a1"/>""")
    world = read(path, [str(models)])
    assert [a.name for a in world.actors] == ["a1", "visitor"]
    assert world.actors[1].pose == (3.0, 4.0, 0.0, 0.0, 0.0, 1.0)
    assert world.actors[1].script.trajectories[0].duration == 2.0
    assert any("a second model or actor named 'a1'" in w for w in world.warnings)
