#!/usr/bin/env python3
"""Writes the mesh files of the multi_way fixture packages (run once; the outputs are committed):

* ``tb3like_gazebo/models/house/meshes/``: a furnished one-storey house, 10 x 8 m inside, as a Gazebo user
  gets it from a modelling tool: walls as COLLADA (quads in a ``<polylist>``, metres), furniture as binary STL
  in millimetres (scaled 0.001 in model.sdf), Wavefront OBJ in metres and COLLADA in centimetres whose
  ``<up_axis>`` says Y_UP over Z-up data (Gazebo ignores the tag, gazebo-classic #1305; so do tools that
  export for it). Surfaces are tessellated as exporters do (walls in ~0.4 m panels, cushions as rounded
  boxes, legs as 24-sided cylinders), so the house has the triangle count of a real one (about 30 000).
* ``tb3like_description/meshes/base_plate.stl``: the robot's visual body, millimetres (URDF scale 0.001).

The geometry the tests compute against (tests/integration/test_multi_way.py) is stated in house.world's
comment: inner wall faces at x = +-5.0 and y = +-4.0, the living room's south wall clear for x in [-3.2, 0.9].

    python3 tests/data/multi_way/make_meshes.py
"""
import math
import os
import struct

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
HOUSE = os.path.join(HERE, "tb3like_gazebo", "models", "house", "meshes")
ROBOT = os.path.join(HERE, "tb3like_description", "meshes")

WALL_HEIGHT = 2.4  # m
DOOR_HEIGHT = 2.05  # m, top of a doorway
PANEL = 0.4  # m, edge of the panels a wall face is tessellated into


# ------------------------------------------------------------------------------------------ building blocks

class Mesh:
    """Vertices (N x 3, m) and faces (lists of vertex indices, counter-clockwise seen from outside)."""

    def __init__(self, vertices=None, faces=None):
        self.vertices = np.zeros((0, 3)) if vertices is None else np.asarray(vertices, dtype=float)
        self.faces = [] if faces is None else list(faces)

    def add(self, other):
        base = len(self.vertices)
        self.vertices = np.vstack([self.vertices, other.vertices])
        self.faces.extend([i + base for i in face] for face in other.faces)
        return self

    def moved(self, offset=(0.0, 0.0, 0.0), yaw=0.0):
        c, s = math.cos(yaw), math.sin(yaw)
        rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        return Mesh(self.vertices @ rotation.T + np.asarray(offset), self.faces)

    def scaled(self, factor):
        return Mesh(self.vertices * factor, self.faces)

    def triangles(self):
        """Every face as a triangle fan: an M x 3 index array."""
        out = [(f[0], f[i], f[i + 1]) for f in self.faces for i in range(1, len(f) - 1)]
        return np.array(out, dtype=np.int64).reshape(-1, 3)


def merged(*meshes):
    out = Mesh()
    for mesh in meshes:
        out.add(mesh)
    return out


def _grid(origin, u, v, nu, nv):
    """A planar patch split into nu x nv quads: origin + i/nu u + j/nv v; normal along u x v."""
    vertices = [np.asarray(origin) + (i / nu) * np.asarray(u) + (j / nv) * np.asarray(v)
                for j in range(nv + 1) for i in range(nu + 1)]
    faces = [[j * (nu + 1) + i, j * (nu + 1) + i + 1, (j + 1) * (nu + 1) + i + 1, (j + 1) * (nu + 1) + i]
             for j in range(nv) for i in range(nu)]
    return Mesh(vertices, faces)


def box(x0, x1, y0, y1, z0, z1, panel=None):
    """An axis-aligned box; each face split into panels about ``panel`` m wide (one quad per face if None)."""
    def count(length):
        return max(1, int(round(length / panel))) if panel else 1
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    nx, ny, nz = count(dx), count(dy), count(dz)
    return merged(
        _grid((x0, y0, z0), (0, dy, 0), (dx, 0, 0), ny, nx),  # bottom (-z)
        _grid((x0, y0, z1), (dx, 0, 0), (0, dy, 0), nx, ny),  # top (+z)
        _grid((x0, y0, z0), (dx, 0, 0), (0, 0, dz), nx, nz),  # south (-y)
        _grid((x1, y1, z0), (-dx, 0, 0), (0, 0, dz), nx, nz),  # north (+y)
        _grid((x0, y1, z0), (0, -dy, 0), (0, 0, dz), ny, nz),  # west (-x)
        _grid((x1, y0, z0), (0, dy, 0), (0, 0, dz), ny, nz),  # east (+x)
    )


def cylinder(cx, cy, z0, z1, radius, sides=24):
    """An upright closed cylinder."""
    ring = [(cx + radius * math.cos(2 * math.pi * k / sides), cy + radius * math.sin(2 * math.pi * k / sides))
            for k in range(sides)]
    vertices = [(x, y, z0) for x, y in ring] + [(x, y, z1) for x, y in ring]
    faces = [[k, (k + 1) % sides, sides + (k + 1) % sides, sides + k] for k in range(sides)]
    faces.append(list(range(sides - 1, -1, -1)))
    faces.append(list(range(sides, 2 * sides)))
    return Mesh(vertices, faces)


def rounded_box(centre, size, roundness=0.15, nu=24, nv=12):
    """A cushion: a superellipsoid filling ``size`` (x, y, z extents), exponent ``roundness`` (0: a box,
    1: an ellipsoid), as a UV-tessellated closed surface (nu * nv quads, poles as triangle fans)."""
    def signed_power(value, exponent):
        return math.copysign(abs(value) ** exponent, value)
    a, b, c = (s / 2.0 for s in size)
    vertices = [(centre[0], centre[1], centre[2] - c)]
    for j in range(1, nv):
        phi = -math.pi / 2 + math.pi * j / nv
        for i in range(nu):
            theta = 2 * math.pi * i / nu
            cp, sp = signed_power(math.cos(phi), roundness), signed_power(math.sin(phi), roundness)
            ct, st = signed_power(math.cos(theta), roundness), signed_power(math.sin(theta), roundness)
            vertices.append((centre[0] + a * cp * ct, centre[1] + b * cp * st, centre[2] + c * sp))
    vertices.append((centre[0], centre[1], centre[2] + c))
    top = len(vertices) - 1

    def ring(j, i):
        return 1 + (j - 1) * nu + i % nu
    faces = [[0, ring(1, i + 1), ring(1, i)] for i in range(nu)]
    for j in range(1, nv - 1):
        faces.extend([ring(j, i), ring(j, i + 1), ring(j + 1, i + 1), ring(j + 1, i)] for i in range(nu))
    faces.extend([ring(nv - 1, i), ring(nv - 1, i + 1), top] for i in range(nu))
    return Mesh(vertices, faces)


def sphere(centre, radius, nu=16, nv=10):
    return rounded_box(centre, (2 * radius,) * 3, roundness=1.0, nu=nu, nv=nv)


# -------------------------------------------------------------------------------------------------- walls

def wall(x0, x1, y0, y1, openings=()):
    """A wall of thickness along the short side of [x0, x1] x [y0, y1], full height, with openings
    ``(a0, a1, z0, z1)`` along its long axis: the wall is cut into the boxes around each opening."""
    along_x = (x1 - x0) >= (y1 - y0)
    start, end = (x0, x1) if along_x else (y0, y1)

    def piece(a0, a1, z0, z1):
        if a1 - a0 < 1e-9 or z1 - z0 < 1e-9:
            return Mesh()
        if along_x:
            return box(a0, a1, y0, y1, z0, z1, PANEL)
        return box(x0, x1, a0, a1, z0, z1, PANEL)
    parts, cursor = [], start
    for a0, a1, z0, z1 in sorted(openings):
        parts.append(piece(cursor, a0, 0.0, WALL_HEIGHT))
        parts.append(piece(a0, a1, 0.0, z0))  # below a window
        parts.append(piece(a0, a1, z1, WALL_HEIGHT))  # lintel
        cursor = a1
    parts.append(piece(cursor, end, 0.0, WALL_HEIGHT))
    return merged(*parts)


def door_casing(centre_line, a0, a1, along_x, half_thickness):
    """Trim around a doorway on both faces: two jambs and a head, 7 cm wide, 1.5 cm proud of the wall."""
    parts = []
    for side in (-1.0, 1.0):
        face = centre_line + side * half_thickness
        outer = face + side * 0.015
        lo, hi = sorted((face, outer))
        for b0, b1, z0, z1 in ((a0 - 0.07, a0, 0.0, DOOR_HEIGHT + 0.07), (a1, a1 + 0.07, 0.0, DOOR_HEIGHT + 0.07),
                               (a0, a1, DOOR_HEIGHT, DOOR_HEIGHT + 0.07)):
            parts.append(box(b0, b1, lo, hi, z0, z1) if along_x else box(lo, hi, b0, b1, z0, z1))
    return merged(*parts)


def baseboards():
    """8 cm skirting along the rooms' inner faces (below the lasers' height of 0.18 m)."""
    strips = [(-5.0, 5.0, -4.0, -3.985), (-5.0, 5.0, 3.985, 4.0), (-5.0, -4.985, -4.0, 4.0), (4.985, 5.0, -4.0, 4.0)]
    return merged(*[box(x0, x1, y0, y1, 0.0, 0.08, 1.0) for x0, x1, y0, y1 in strips])


def walls():
    """Outer walls 0.2 m thick (inner faces x = +-5, y = +-4); inner walls 0.12 m. Rooms: living room
    (x < 1, y < 0.5), kitchen (x > 1, y < 0.5), bedroom (x < -0.5), bathroom, second bedroom (x > 1.5)."""
    door, window = (0.0, DOOR_HEIGHT), (0.9, 2.1)
    parts = [
        wall(-5.2, 5.2, -4.2, -4.0),  # south: solid (the tests' wall)
        wall(-5.2, 5.2, 4.0, 4.2, [(-3.5, -2.3) + window, (2.5, 3.7) + window]),
        wall(-5.2, -5.0, -4.0, 4.0, [(1.6, 2.8) + window]),
        wall(5.0, 5.2, -4.0, 4.0, [(-3.0, -2.0) + door, (1.5, 2.7) + window]),  # front door into the kitchen
        wall(-5.0, 5.0, 0.44, 0.56, [(-3.5, -2.6) + door, (0.0, 0.8) + door, (2.8, 3.7) + door]),
        wall(0.94, 1.06, -4.0, 0.44, [(-2.2, -1.0) + door]),  # living room / kitchen archway
        wall(-0.56, -0.44, 0.56, 4.0),
        wall(1.44, 1.56, 0.56, 4.0),
        door_casing(0.5, -3.5, -2.6, True, 0.06), door_casing(0.5, 0.0, 0.8, True, 0.06),
        door_casing(0.5, 2.8, 3.7, True, 0.06), door_casing(1.0, -2.2, -1.0, False, 0.06),
        baseboards(),
    ]
    return merged(*parts)


# ---------------------------------------------------------------------------------------------- furniture

def sofa():
    """A three-seat sofa 0.9 m deep, 2.1 m wide, its back toward -x, origin at its footprint centre (m)."""
    parts = [box(-0.45, 0.45, -1.05, 1.05, 0.08, 0.40)]  # frame
    parts += [cylinder(x, y, 0.0, 0.08, 0.025, 16) for x in (-0.4, 0.4) for y in (-1.0, 1.0)]  # feet
    parts += [rounded_box((-0.35, 0.0, 0.72), (0.2, 1.9, 0.64), 0.25)]  # back
    parts += [rounded_box((0.0, y, 0.62), (0.9, 0.18, 0.44), 0.2) for y in (-0.96, 0.96)]  # arms
    parts += [rounded_box((0.08, y, 0.47), (0.68, 0.58, 0.16), 0.2) for y in (-0.6, 0.0, 0.6)]  # seats
    parts += [rounded_box((-0.17, y, 0.7), (0.18, 0.5, 0.42), 0.3) for y in (-0.6, 0.0, 0.6)]  # back cushions
    return merged(*parts)


def armchair():
    parts = [box(-0.4, 0.4, -0.42, 0.42, 0.08, 0.38)]
    parts += [cylinder(x, y, 0.0, 0.08, 0.022, 16) for x in (-0.35, 0.35) for y in (-0.37, 0.37)]
    parts += [rounded_box((-0.32, 0.0, 0.7), (0.16, 0.84, 0.64), 0.25)]
    parts += [rounded_box((0.0, y, 0.58), (0.8, 0.16, 0.4), 0.2) for y in (-0.36, 0.36)]
    parts += [rounded_box((0.06, 0.0, 0.45), (0.62, 0.56, 0.15), 0.2)]
    return merged(*parts)


def table(length, width, height, leg_radius=0.025, top=0.03, sides=24):
    """Four round legs and a top with a rounded edge; origin at the footprint centre."""
    parts = [rounded_box((0.0, 0.0, height - top / 2), (length, width, top), 0.1, 48, 8)]
    inset = 0.06
    parts += [cylinder(sx * (length / 2 - inset), sy * (width / 2 - inset), 0.0, height - top, leg_radius, sides)
              for sx in (-1, 1) for sy in (-1, 1)]
    return merged(*parts)


def chair(yaw):
    parts = [box(-0.21, 0.21, -0.21, 0.21, 0.43, 0.47)]
    parts += [cylinder(sx * 0.18, sy * 0.18, 0.0, 0.43, 0.015, 16) for sx in (-1, 1) for sy in (-1, 1)]
    parts += [cylinder(-0.18, sy * 0.18, 0.47, 0.9, 0.015, 16) for sy in (-1, 1)]
    parts += [box(-0.2, -0.17, -0.19, 0.19, 0.7, 0.88)]
    return merged(*parts).moved(yaw=yaw)


def dining_set():
    """A 1.4 x 0.8 m table with four chairs, origin at the table's centre."""
    parts = [table(1.4, 0.8, 0.75)]
    for x, y, yaw in ((-0.35, -0.58, math.pi / 2), (0.35, -0.58, math.pi / 2),
                      (-0.35, 0.58, -math.pi / 2), (0.35, 0.58, -math.pi / 2)):
        parts.append(chair(yaw).moved((x, y, 0.0)))
    return merged(*parts)


def bookshelf():
    """A 1.5 m wide, 0.35 m deep, 1.9 m high shelf (back toward -y) with books on five boards."""
    parts = [box(-0.75, -0.73, -0.175, 0.175, 0.0, 1.9), box(0.73, 0.75, -0.175, 0.175, 0.0, 1.9),
             box(-0.73, 0.73, -0.175, -0.165, 0.0, 1.9)]
    rng = np.random.default_rng(7)
    for k in range(6):
        z = 0.05 + k * 0.37
        parts.append(box(-0.73, 0.73, -0.165, 0.175, z - 0.02, z))
        if k == 5:
            break
        x = -0.72
        while x < 0.68:
            width = float(rng.uniform(0.02, 0.05))
            height = float(rng.uniform(0.2, 0.31))
            depth = float(rng.uniform(0.15, 0.25))
            parts.append(box(x, x + width, -0.16, -0.16 + depth, z, z + height))
            x += width + 0.002
    return merged(*parts)


def counter():
    """Kitchen counter 2.5 x 0.6 m, 0.9 m high, a sink bowl and a tap; back toward -y."""
    parts = [box(-1.25, 1.25, -0.3, 0.25, 0.1, 0.86, 0.3), box(-1.25, 1.25, -0.3, 0.2, 0.0, 0.1),
             box(-1.27, -0.45, -0.3, 0.3, 0.86, 0.9), box(0.15, 1.27, -0.3, 0.3, 0.86, 0.9),
             box(-0.45, 0.15, -0.3, -0.2, 0.86, 0.9), box(-0.45, 0.15, 0.2, 0.3, 0.86, 0.9)]
    bowl = rounded_box((-0.15, 0.0, 0.8), (0.56, 0.38, 0.2), 0.3, 32, 12)
    parts += [bowl, cylinder(-0.15, -0.25, 0.9, 1.15, 0.015, 16)]
    parts += [box(x - 0.2, x + 0.2, 0.25, 0.26, 0.15, 0.8) for x in (-0.9, -0.45, 0.45, 0.9)]  # doors
    return merged(*parts)


def bed():
    """A 1.6 x 2.05 m double bed: frame, mattress, two pillows, a headboard at -y. Metres."""
    parts = [box(-0.82, 0.82, -1.05, 1.05, 0.1, 0.3, 0.25)]
    parts += [cylinder(sx * 0.76, sy * 0.98, 0.0, 0.1, 0.03, 16) for sx in (-1, 1) for sy in (-1, 1)]
    parts += [rounded_box((0.0, 0.02, 0.42), (1.58, 2.0, 0.24), 0.15, 64, 16)]
    parts += [rounded_box((sx * 0.4, -0.8, 0.6), (0.6, 0.32, 0.14), 0.5, 32, 12) for sx in (-1, 1)]
    parts += [box(-0.82, 0.82, -1.1, -1.05, 0.0, 1.0, 0.2)]
    return merged(*parts)


def plant():
    """A potted plant: a tapered pot and a crown of leaf clusters."""
    sides = 32
    ring_lo = [(0.12 * math.cos(2 * math.pi * k / sides), 0.12 * math.sin(2 * math.pi * k / sides), 0.0)
               for k in range(sides)]
    ring_hi = [(0.17 * math.cos(2 * math.pi * k / sides), 0.17 * math.sin(2 * math.pi * k / sides), 0.4)
               for k in range(sides)]
    pot = Mesh(ring_lo + ring_hi, [[k, (k + 1) % sides, sides + (k + 1) % sides, sides + k] for k in range(sides)]
               + [list(range(sides - 1, -1, -1)), list(range(sides, 2 * sides))])
    parts = [pot, cylinder(0.0, 0.0, 0.4, 0.9, 0.02, 12)]
    rng = np.random.default_rng(3)
    for _ in range(10):
        angle, lift = rng.uniform(0, 2 * math.pi), rng.uniform(0.7, 1.2)
        reach = rng.uniform(0.08, 0.25)
        parts.append(sphere((reach * math.cos(angle), reach * math.sin(angle), lift), rng.uniform(0.08, 0.14), 16, 10))
    return merged(*parts)


def wardrobe():
    parts = [box(-0.6, 0.6, -0.3, 0.3, 0.05, 2.1, 0.3), box(-0.58, 0.58, -0.28, 0.28, 0.0, 0.05)]
    parts += [cylinder(x, 0.31, 1.0, 1.3, 0.01, 12) for x in (-0.05, 0.05)]
    return merged(*parts)


def robot_base_plate():
    """The robot's visual body in millimetres: two stacked plates with standoffs, a battery and a board."""
    parts = [rounded_box((-32.0, 0.0, 15.0), (138.0, 138.0, 6.0), 0.12, 48, 6),
             rounded_box((-32.0, 0.0, 75.0), (138.0, 138.0, 6.0), 0.12, 48, 6),
             rounded_box((-32.0, 0.0, 135.0), (138.0, 138.0, 6.0), 0.12, 48, 6),
             box(-80.0, 10.0, -35.0, 35.0, 20.0, 60.0), box(-70.0, 5.0, -40.0, 40.0, 80.0, 95.0)]
    parts += [cylinder(-32.0 + sx * 58.0, sy * 58.0, 18.0, 132.0, 3.0, 12) for sx in (-1, 1) for sy in (-1, 1)]
    return merged(*parts)


# ------------------------------------------------------------------------------------------------ writers

def _normals(vertices, triangles):
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    n = np.cross(b - a, c - a)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(length > 0, length, 1.0)


def write_stl(path, mesh, name):
    """Binary STL (units: whatever the mesh's numbers are)."""
    vertices, triangles = mesh.vertices, mesh.triangles()
    normals = _normals(vertices, triangles)
    records = np.zeros(len(triangles), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    records["n"], records["v"] = normals, vertices[triangles]
    with open(path, "wb") as out:
        out.write(name.encode("ascii")[:80].ljust(80, b" "))
        out.write(struct.pack("<I", len(triangles)))
        out.write(records.tobytes())
    return len(triangles)


def write_obj(path, mesh, name):
    """Wavefront OBJ with per-face normals (``f v//n``), one group."""
    vertices, triangles = mesh.vertices, mesh.triangles()
    normals = _normals(vertices, triangles)
    lines = [f"# {name}: {len(triangles)} triangles, metres", f"o {name}"]
    lines += [f"v {_short(x)} {_short(y)} {_short(z)}" for x, y, z in vertices]
    lines += [f"vn {_short(x)} {_short(y)} {_short(z)}" for x, y, z in normals]
    lines += [f"f {a + 1}//{k + 1} {b + 1}//{k + 1} {c + 1}//{k + 1}" for k, (a, b, c) in enumerate(triangles)]
    with open(path, "w") as out:
        out.write("\n".join(lines) + "\n")
    return len(triangles)


def _short(value):
    """A number with at most 4 decimals and no trailing zeros (what exporters write)."""
    text = f"{value:.4f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def write_dae(path, mesh, name, unit=1.0, up_axis="Z_UP", quads=False):
    """COLLADA 1.4.1: the mesh's numbers are in ``unit`` metres; faces as ``<polylist>`` (quads kept) or
    ``<triangles>``."""
    vertices = mesh.vertices
    if quads:
        faces = mesh.faces
        primitive = (f'<polylist count="{len(faces)}" material="mat">'
                     f'<input semantic="VERTEX" source="#{name}-vertices" offset="0"/>'
                     f'<vcount>{" ".join(str(len(f)) for f in faces)}</vcount>'
                     f'<p>{" ".join(str(i) for f in faces for i in f)}</p></polylist>')
        count = sum(len(f) - 2 for f in faces)
    else:
        triangles = mesh.triangles()
        primitive = (f'<triangles count="{len(triangles)}" material="mat">'
                     f'<input semantic="VERTEX" source="#{name}-vertices" offset="0"/>'
                     f'<p>{" ".join(str(i) for i in triangles.ravel())}</p></triangles>')
        count = len(triangles)
    positions = " ".join(_short(v) for v in vertices.ravel())
    text = f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset>
    <contributor><authoring_tool>diffbot_sim tests/data/multi_way/make_meshes.py</authoring_tool></contributor>
    <unit name="{'meter' if unit == 1.0 else 'centimeter' if unit == 0.01 else 'unit'}" meter="{unit}"/>
    <up_axis>{up_axis}</up_axis>
  </asset>
  <library_effects><effect id="mat-effect"><profile_COMMON><technique sid="common"><lambert>
    <diffuse><color>0.8 0.78 0.72 1</color></diffuse></lambert></technique></profile_COMMON></effect></library_effects>
  <library_materials><material id="mat" name="mat"><instance_effect url="#mat-effect"/></material></library_materials>
  <library_geometries>
    <geometry id="{name}" name="{name}"><mesh>
      <source id="{name}-positions">
        <float_array id="{name}-positions-array" count="{vertices.size}">{positions}</float_array>
        <technique_common><accessor source="#{name}-positions-array" count="{len(vertices)}" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common></source>
      <vertices id="{name}-vertices"><input semantic="POSITION" source="#{name}-positions"/></vertices>
      {primitive}
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="Scene" name="Scene">
    <node id="{name}-node" name="{name}" type="NODE">
      <instance_geometry url="#{name}"><bind_material><technique_common>
        <instance_material symbol="mat" target="#mat"/></technique_common></bind_material></instance_geometry>
    </node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
"""
    with open(path, "w") as out:
        out.write(text)
    return count


def main():
    os.makedirs(HOUSE, exist_ok=True)
    os.makedirs(ROBOT, exist_ok=True)
    counts = {
        "walls.dae": write_dae(os.path.join(HOUSE, "walls.dae"), walls(), "walls", quads=True),
        "sofa.stl": write_stl(os.path.join(HOUSE, "sofa.stl"), sofa().scaled(1000.0), "sofa (mm)"),
        "armchair.stl": write_stl(os.path.join(HOUSE, "armchair.stl"), armchair().scaled(1000.0), "armchair (mm)"),
        "coffee_table.obj": write_obj(os.path.join(HOUSE, "coffee_table.obj"), table(1.0, 0.5, 0.42, 0.02),
                                      "coffee_table"),
        "bookshelf.stl": write_stl(os.path.join(HOUSE, "bookshelf.stl"), bookshelf().scaled(1000.0), "bookshelf (mm)"),
        "dining_set.obj": write_obj(os.path.join(HOUSE, "dining_set.obj"), dining_set(), "dining_set"),
        "counter.dae": write_dae(os.path.join(HOUSE, "counter.dae"), counter(), "counter"),
        # centimetres, and Y_UP over Z-up data: what Gazebo reads as Z-up (it ignores <up_axis>)
        "bed.dae": write_dae(os.path.join(HOUSE, "bed.dae"), bed().scaled(100.0), "bed", unit=0.01, up_axis="Y_UP"),
        "plant.obj": write_obj(os.path.join(HOUSE, "plant.obj"), plant(), "plant"),
        "wardrobe.stl": write_stl(os.path.join(HOUSE, "wardrobe.stl"), wardrobe().scaled(1000.0), "wardrobe (mm)"),
    }
    counts["base_plate.stl (robot)"] = write_stl(os.path.join(ROBOT, "base_plate.stl"), robot_base_plate(),
                                                 "tb3like base plate (mm)")
    for name, count in counts.items():
        print(f"{name:28s} {count:6d} triangles")
    print(f"{'house total':28s} {sum(c for n, c in counts.items() if 'robot' not in n):6d} triangles")


if __name__ == "__main__":
    main()
