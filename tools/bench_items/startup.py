"""Items ``startup``, ``meshes``, ``worlds``: ``roslaunch`` -> the first ``/odom``, and what a world costs.

- ``startup``: ``roslaunch diffbot_sim sim.launch`` -> first /odom, median of 5.
- ``meshes``: the same for a robot with 2 MB of binary STL meshes (collision and visual), with an empty mesh
  cache and with the cache filled; median of 3 each.
- ``worlds``: the same in a world of 30 models with COLLADA collision meshes (empty mesh cache), in the
  furnished house of meshes of tests/data/multi_way (cache warm) against no world, and with a 4000 x 4000 map
  image (a floor plan, and the same with 2 % speckle); fast-mode RTF of the seed robot in worlds/room.world
  against the empty world (medians of 3).
"""
import math
import os
import shutil
import statistics

from benchkit.common import RESULTS, ROBOTS, ROOT, TOPICS
from benchkit.launching import Launch, sim_args, startup_times, subscriber
from benchkit.report import Item

DAE = """<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit meter="0.001"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries><geometry id="g"><mesh>
    <source id="p"><float_array id="pa" count="{count}">{points}</float_array>
      <technique_common><accessor source="#pa" count="{vcount}" stride="3"><param name="X" type="float"/>
      <param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="{tcount}"><input semantic="VERTEX" source="#v" offset="0"/><p>{indices}</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node><instance_geometry url="#g"/></node></visual_scene>
  </library_visual_scenes><scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""


def mesh_robot():
    """A two-wheel robot whose base is a 2 MB binary STL (collision and visual), written once into RESULTS."""
    from mesh_speed import sphere_stl  # tools/mesh_speed.py
    folder = os.path.join(RESULTS, "mesh_robot")
    os.makedirs(folder, exist_ok=True)
    stl = os.path.join(folder, "base.stl")
    if not os.path.exists(stl):
        sphere_stl(stl)
    with open(os.path.join(ROBOTS, "fixed_caster.urdf")) as f:
        text = f.read()
    mesh = '<geometry><mesh filename="base.stl" scale="0.001 0.001 0.001"/></geometry>'
    text = text.replace('<visual><geometry><box size="0.2 0.15 0.04"/></geometry></visual>',
                        f'<visual><origin xyz="0 0 0.2"/>{mesh}</visual>')
    text = text.replace('<collision><geometry><box size="0.2 0.15 0.04"/></geometry></collision>',
                        f'<collision><origin xyz="0 0 0.2"/>{mesh}</collision>', 1)
    path = os.path.join(folder, "mesh_robot.urdf")
    with open(path, "w") as f:
        f.write(text)
    return path, os.path.getsize(stl)


def meshes(runs):
    """Start-up to first /odom with 2 MB of STL: every run with an empty mesh cache, then with it filled."""
    path, size = mesh_robot()
    home = os.path.join(RESULTS, "ros_home_meshes")
    cache = os.path.join(home, "diffbot_sim", "mesh_cache")
    cold = startup_times(runs, (f"model:={path}", "robot_state_publisher:=false"), home,
                         lambda: shutil.rmtree(cache, ignore_errors=True))
    warm = startup_times(runs, (f"model:={path}", "robot_state_publisher:=false"), home)
    return {"stl_bytes": size, "cold": cold, "cached": warm}


def mesh_world(models=30, segments=64):
    """A world of ``models`` static models, each a cylinder-ish COLLADA mesh (mm units) of its own file."""
    folder = os.path.join(RESULTS, "mesh_world")
    os.makedirs(folder, exist_ok=True)
    lines = ['<?xml version="1.0"?>', '<sdf version="1.6"><world name="mesh_world">',
             "<include><uri>model://ground_plane</uri></include><include><uri>model://sun</uri></include>"]
    for k in range(models):
        r = 150.0 + 5 * k
        points, tris = [], []
        for i in range(segments):
            a = 2 * math.pi * i / segments
            points += [(r * math.cos(a), r * math.sin(a), 0.0), (r * math.cos(a), r * math.sin(a), 800.0)]
        for i in range(segments):
            j = (i + 1) % segments
            tris += [(2 * i, 2 * j, 2 * j + 1), (2 * i, 2 * j + 1, 2 * i + 1)]
        name = os.path.join(folder, f"obstacle{k}.dae")
        with open(name, "w") as f:
            f.write(DAE.format(count=3 * len(points), vcount=len(points), tcount=len(tris),
                               points=" ".join(f"{c:g}" for pt in points for c in pt),
                               indices=" ".join(str(i) for t in tris for i in t)))
        x, y = 2.0 + 1.5 * (k % 6), -4.0 + 1.5 * (k // 6)
        lines.append(f'<model name="obstacle{k}"><static>true</static><pose>{x} {y} 0 0 0 0</pose><link name="l">'
                     f'<collision name="c"><geometry><mesh><uri>obstacle{k}.dae</uri></mesh></geometry></collision>'
                     f"</link></model>")
    lines.append("</world></sdf>")
    path = os.path.join(folder, "mesh_world.world")
    with open(path, "w") as f:
        f.write("\n".join(lines))
    return path


def worlds(runs, seconds):
    """Load times of a mesh world and of 4000 x 4000 maps; RTF in the example world against none."""
    from run_tests import MULTI_FIXTURES, add_package_path  # tools/run_tests.py: the test suites' fixture packages

    from diffbot_sim.world import map_image as world_map
    out = {}
    home = os.path.join(RESULTS, "ros_home_worlds")
    cache = os.path.join(home, "diffbot_sim", "mesh_cache")
    world = mesh_world()
    out["mesh_world"] = startup_times(runs, (f"world:={world}", "robot_state_publisher:=false"), home,
                                      lambda: shutil.rmtree(cache, ignore_errors=True))
    # The furnished house of meshes (tests/data/multi_way: 30 000 triangles in COLLADA, STL and OBJ, found as
    # model://house through tb3like_gazebo's gazebo_model_path export), with the mesh cache warm: one run fills it.
    add_package_path(MULTI_FIXTURES)
    house = (f"world:={os.path.join(MULTI_FIXTURES, 'tb3like_gazebo', 'worlds', 'house.world')}",
             "robot_state_publisher:=false")
    startup_times(1, house, home)
    out["house_world"] = startup_times(runs, house, home)
    out["empty_world"] = startup_times(runs, ("robot_state_publisher:=false",), home)
    for key, noise in (("map_floor_plan", 0.0), ("map_speckled", 0.02)):
        path = world_map.synthetic_map(os.path.join(RESULTS, f"{key}.yaml"), size=4000, noise=noise)
        out[key] = startup_times(runs, (f"world:={path}", "robot_state_publisher:=false"), home)
    rtf = {"room": [], "empty": []}
    for _ in range(runs):
        for key, extra in (("room", (f"world:={os.path.join(ROOT, 'worlds', 'room.world')}",)), ("empty", ())):
            with Launch(sim_args("real_time:=false", "robot_state_publisher:=false", *extra), f"world_{key}") as launch:
                for topic in TOPICS[1:]:
                    subscriber(launch, [topic])
                rtf[key].append(launch.probe("rtf", seconds=seconds, warmup=3.0, leave=True)["rtf"])
    out["rtf_room"], out["rtf_empty"] = statistics.median(rtf["room"]), statistics.median(rtf["empty"])
    out["rtf_runs"] = rtf
    return out


def startup_rows(r):
    if not r.get("startup"):
        return []
    return [("roslaunch -> first /odom (median of 5)", f"{r['startup']['median_s']:.2f} s", "<= 3 s")]


def meshes_rows(r):
    if not r.get("meshes"):
        return []
    m = r["meshes"]
    return [(f"first /odom, {m['stl_bytes'] / 1e6:.1f} MB STL, empty mesh cache", f"{m['cold']['median_s']:.2f} s",
             "<= 2 s"),
            ("  same, mesh cache filled", f"{m['cached']['median_s']:.2f} s", "")]


def worlds_rows(r):
    if not r.get("worlds"):
        return []
    w = r["worlds"]
    return [("first /odom, world of 30 COLLADA mesh models (empty cache)", f"{w['mesh_world']['median_s']:.2f} s",
             "<= 3 s"),
            ("first /odom, the furnished house of meshes (cache warm) / no world",
             f"{w['house_world']['median_s']:.2f} s / {w['empty_world']['median_s']:.2f} s", "<= 2 s"),
            ("first /odom, 4000 x 4000 map, floor plan", f"{w['map_floor_plan']['median_s']:.2f} s", "<= 3 s"),
            ("first /odom, 4000 x 4000 map, 2 % speckle", f"{w['map_speckled']['median_s']:.2f} s", "<= 3 s"),
            ("fast-mode RTF in worlds/room.world / empty world",
             f"{w['rtf_room']:.1f} / {w['rtf_empty']:.1f} = {w['rtf_room'] / w['rtf_empty']:.2f}", ">= 0.8")]


ITEMS = [Item("startup", lambda q: startup_times(2 if q else 5), startup_rows),
         Item("meshes", lambda q: meshes(1 if q else 3), meshes_rows),
         Item("worlds", lambda q: worlds(1 if q else 3, 4 if q else 10), worlds_rows)]
PROBES = {}
