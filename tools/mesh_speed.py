#!/usr/bin/env python3
"""How long meshes cost at start-up: a ~2 MB binary STL (a UV sphere, 40 000 triangles) used as a link's
collision and visual, through meshes.prepare_meshes cold (parse + .obj write) and cached (stat only), then
loaded into PyBullet DIRECT by physics.World.load_robot. Prints one line per figure (best of --repeat).

Run: bash tools/rosenv.sh python3 tools/mesh_speed.py
"""
import argparse
import os
import shutil
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "src"))

from diffbot_sim.description import mesh_formats, meshes

RECORD = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])


def sphere_stl(path, rings=100, segments=200, radius_mm=150.0):
    """A UV sphere of radius ``radius_mm`` as binary STL: 2 * rings * segments triangles, corners repeated
    per triangle as STL stores them (100 x 200 -> 40 000 triangles, 2 000 084 bytes)."""
    theta = np.linspace(0.0, np.pi, rings + 1)
    phi = np.linspace(0.0, 2.0 * np.pi, segments + 1)
    grid = radius_mm * np.stack([np.outer(np.sin(theta), np.cos(phi)), np.outer(np.sin(theta), np.sin(phi)),
                                 np.outer(np.cos(theta), np.ones_like(phi))], axis=-1)
    a, b = grid[:-1, :-1], grid[:-1, 1:]
    c, d = grid[1:, :-1], grid[1:, 1:]
    triangles = np.concatenate([np.stack([a, c, d], axis=2).reshape(-1, 3, 3),
                                np.stack([a, d, b], axis=2).reshape(-1, 3, 3)])
    data = np.zeros(len(triangles), RECORD)
    data["vertices"] = triangles
    with open(path, "wb") as out:
        out.write(b"solid sphere (binary)".ljust(80) + np.uint32(len(triangles)).tobytes() + data.tobytes())


URDF = """<?xml version="1.0"?>
<robot name="speed">
  <link name="base_link">
    <inertial><mass value="2"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry>
      <mesh filename="package://speed/meshes/sphere.stl" scale="0.001 0.001 0.001"/></geometry></collision>
    <visual><geometry>
      <mesh filename="package://speed/meshes/sphere.stl" scale="0.001 0.001 0.001"/></geometry></visual>
  </link>
</robot>
"""


def best(function, repeat):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return min(times), result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    root = tempfile.mkdtemp(prefix="mesh_speed_")
    try:
        os.makedirs(os.path.join(root, "speed", "meshes"))
        stl = os.path.join(root, "speed", "meshes", "sphere.stl")
        sphere_stl(stl)
        cache = os.path.join(root, "cache")
        package = {"speed": os.path.join(root, "speed")}.__getitem__

        def cold():
            shutil.rmtree(cache, ignore_errors=True)
            return meshes.prepare_meshes(URDF, "speed.urdf", root, cache, package)

        def cached():
            return meshes.prepare_meshes(URDF, "speed.urdf", root, cache, package)

        print(f"mesh: {os.path.getsize(stl)} bytes binary STL, 40000 triangles")
        t_read, (vertices, faces) = best(lambda: mesh_formats.read_stl(stl), args.repeat)
        print(f"read_stl (frombuffer + weld): {t_read * 1000:.1f} ms -> {len(vertices)} vertices")
        t_cold, (text, _) = best(cold, args.repeat)
        obj = text.split('filename="')[1].split('"')[0]
        print(f"prepare_meshes cold: {t_cold * 1000:.1f} ms (.obj {os.path.getsize(obj)} bytes)")
        t_hit, _ = best(cached, args.repeat)
        print(f"prepare_meshes cached: {t_hit * 1000:.2f} ms")

        from diffbot_sim.description.urdf_model import parse_urdf
        from diffbot_sim.physics import World

        def load(urdf_text):
            world = World(1.0 / 240.0)
            try:
                start = time.perf_counter()
                world.load_robot(urdf_text, parse_urdf(urdf_text, "speed.urdf"))
                return time.perf_counter() - start
            finally:
                world.close()

        t_load = min(load(text) for _ in range(args.repeat))
        print(f"World.load_robot of the prepared URDF (collision hull + visual): {t_load * 1000:.1f} ms")
        raw = URDF.replace("package://speed/meshes/sphere.stl", stl)
        t_raw = min(load(raw) for _ in range(args.repeat))
        print(f"World.load_robot of the raw binary STL (for comparison): {t_raw * 1000:.1f} ms")
        print(f"start-up share, cold: {(t_cold + t_load) * 1000:.0f} ms; cached: {(t_hit + t_load) * 1000:.0f} ms")
    finally:
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
