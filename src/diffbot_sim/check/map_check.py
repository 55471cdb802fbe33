"""Judging a SLAM map against the world it maps (pure; numpy).

A user looks at a gmapping map and asks: are the walls where the walls are, is every obstacle there, is there
free space inside a wall? This module answers with numbers. The world's true geometry is its
:class:`~diffbot_sim.world.bodies.WorldDescription` cut by the laser's plane (every collision shape becomes
triangles, the triangles that cross the plane become 2D segments); the map is a ``nav_msgs/OccupancyGrid``'s
numbers (origin, resolution, width, height, data: -1 unknown, 0 free, 100 occupied, as gmapping writes).

- **near surfaces**: each occupied cell's distance to the nearest true surface; most must lie within ``near``.
- **every obstacle mapped**: the true solids, rasterised on the map's grid, split into connected obstacles;
  of each obstacle's boundary cells that the robot has seen (a free cell of the map next to them), at least
  ``coverage`` must have an occupied cell within ``near``; an obstacle never seen at all is named.
- **no free cells deep inside**: a free map cell more than ``deep`` inside a solid is a hole in a wall.
"""
import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from diffbot_sim.description.mesh_formats import read_mesh
from diffbot_sim.transforms import compose, rotate

NEAR = 0.15  # m: an occupied cell this close to a true surface is on it (three cells of 5 cm)
DEEP = 0.10  # m: a free cell further than this inside a solid is a hole
COVERAGE = 0.5  # of an obstacle's seen boundary cells that must be mapped


@dataclass
class Grid:
    """An occupancy grid as numbers: cell (row, col) covers x0 + col*res .. +res, y0 + row*res .. +res."""

    x0: float
    y0: float
    resolution: float
    width: int
    height: int
    data: np.ndarray  # (height, width) int: -1 unknown, 0..100 occupancy

    @classmethod
    def from_message(cls, msg):
        """A Grid from a nav_msgs/OccupancyGrid (its origin must be unrotated, as gmapping's is)."""
        info = msg.info
        data = np.asarray(msg.data, dtype=np.int16).reshape(info.height, info.width)
        return cls(info.origin.position.x, info.origin.position.y, info.resolution, info.width, info.height, data)

    def centres(self, rows, cols):
        """World (x, y) of the centres of cells (rows, cols): an (N, 2) array."""
        return np.column_stack([self.x0 + (np.asarray(cols) + 0.5) * self.resolution,
                                self.y0 + (np.asarray(rows) + 0.5) * self.resolution])

    @property
    def occupied(self):
        return self.data >= 65  # map_server's occupied_thresh (0.65)

    @property
    def free(self):
        return (self.data >= 0) & (self.data <= 19)  # map_server's free_thresh (0.196)


# ------------------------------------------------------------------------------------------ the true world

def _box(size):
    x, y, z = (s / 2.0 for s in size)
    v = np.array([[sx * x, sy * y, sz * z] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return v, np.array(faces)


def _cylinder(radius, length, sides=48):
    angles = np.linspace(0.0, 2 * math.pi, sides, endpoint=False)
    ring = np.column_stack([radius * np.cos(angles), radius * np.sin(angles)])
    v = np.vstack([np.column_stack([ring, np.full(sides, -length / 2)]),
                   np.column_stack([ring, np.full(sides, length / 2)]), [[0, 0, -length / 2], [0, 0, length / 2]]])
    faces = []
    for i in range(sides):
        j = (i + 1) % sides
        faces += [(i, j, sides + j), (i, sides + j, sides + i), (2 * sides, j, i),
                  (2 * sides + 1, sides + i, sides + j)]
    return v, np.array(faces)


def _sphere(radius, stacks=12, sectors=24):
    points, faces = [], []
    for i in range(stacks + 1):
        phi = math.pi * i / stacks
        for j in range(sectors):
            theta = 2 * math.pi * j / sectors
            points.append((radius * math.sin(phi) * math.cos(theta), radius * math.sin(phi) * math.sin(theta),
                           radius * math.cos(phi)))
    for i in range(stacks):
        for j in range(sectors):
            a, b = i * sectors + j, i * sectors + (j + 1) % sectors
            faces += [(a, b, b + sectors), (a, b + sectors, a + sectors)]
    return np.array(points), np.array(faces)


def shape_triangles(shape):
    """A shape's triangles in its own frame: ((N, 3) vertices, (M, 3) indices), or None (a plane, or a kind
    that has no solid)."""
    if shape.kind == "box":
        return _box(shape.size)
    if shape.kind == "cylinder":
        return _cylinder(*shape.size[:2])
    if shape.kind == "sphere":
        return _sphere(shape.size[0])
    if shape.kind == "trimesh":
        return np.asarray(shape.vertices, dtype=float), np.asarray(shape.indices, dtype=int)
    if shape.kind == "mesh":
        vertices, faces = read_mesh(shape.mesh)
        return np.asarray(vertices, dtype=float) * np.asarray(shape.scale, dtype=float), np.asarray(faces)
    return None


def _posed(vertices, pose):
    return np.array([np.add(pose[0], rotate(pose[1], v)) for v in vertices])


def slice_triangles(vertices, faces, height):
    """The segments where triangles cross the plane z = ``height``: an (K, 4) array x1, y1, x2, y2."""
    tri = vertices[faces]  # (M, 3, 3)
    side = tri[:, :, 2] - height
    out = []
    for corners, s in zip(tri, side):
        points = []
        for a, b in ((0, 1), (1, 2), (2, 0)):
            if (s[a] < 0) != (s[b] < 0):
                t = s[a] / (s[a] - s[b])
                points.append(corners[a] + t * (corners[b] - corners[a]))
        if len(points) == 2:
            out.append((points[0][0], points[0][1], points[1][0], points[1][1]))
    return np.array(out, dtype=float).reshape(-1, 4)


def world_section(world, height):
    """The world cut at z = ``height``: a list of (body name, (K, 4) segments), one per solid shape that the
    plane crosses (each a closed outline: a point is inside when a ray from it crosses it an odd number of
    times)."""
    sections = []
    for body in world.bodies:
        for shape in body.shapes:
            triangles = shape_triangles(shape)
            if triangles is None:
                continue
            vertices = _posed(triangles[0], compose(body.pose, shape.pose))
            segments = slice_triangles(vertices, triangles[1], height)
            if len(segments):
                sections.append((body.name, segments))
    return sections


def distances(points, segments):
    """Distance [m] from each point (N, 2) to the nearest segment (K, 4) (inf when there are none)."""
    if len(segments) == 0:
        return np.full(len(points), np.inf)
    best = np.full(len(points), np.inf)
    a, b = segments[:, 0:2], segments[:, 2:4]
    ab = b - a
    length2 = np.maximum((ab ** 2).sum(axis=1), 1e-18)
    for start in range(0, len(points), 2048):
        p = points[start:start + 2048, None, :]
        t = np.clip(((p - a) * ab).sum(axis=2) / length2, 0.0, 1.0)
        nearest = a + t[:, :, None] * ab
        best[start:start + 2048] = np.sqrt(((p - nearest) ** 2).sum(axis=2)).min(axis=1)
    return best


def inside(points, segments):
    """True for each point (N, 2) inside the closed outline ``segments`` (even-odd rule, a ray along +x)."""
    result = np.zeros(len(points), dtype=bool)
    if len(segments) == 0:
        return result
    x1, y1, x2, y2 = (segments[:, i] for i in range(4))
    for start in range(0, len(points), 2048):
        px = points[start:start + 2048, 0:1]
        py = points[start:start + 2048, 1:2]
        crosses = (y1 > py) != (y2 > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            x_at = x1 + (py - y1) * (x2 - x1) / (y2 - y1)
        result[start:start + 2048] = ((crosses & (px < x_at)).sum(axis=1) % 2) == 1
    return result


def _all_centres(grid):
    """Every cell's centre of ``grid``, row by row: (height * width, 2)."""
    rows, cols = np.indices((grid.height, grid.width))
    return grid.centres(rows.ravel(), cols.ravel())


def _inside_any(points, sections):
    """Whether each of ``points`` ((N, 2)) lies inside any shape's outline of ``sections``."""
    solid = np.zeros(len(points), dtype=bool)
    for _, segments in sections:
        lo, hi = segments[:, [0, 2]].min(), segments[:, [0, 2]].max()
        ylo, yhi = segments[:, [1, 3]].min(), segments[:, [1, 3]].max()
        box = (points[:, 0] >= lo) & (points[:, 0] <= hi) & (points[:, 1] >= ylo) & (points[:, 1] <= yhi)
        solid[box] |= inside(points[box], segments)
    return solid


def solids_on(grid, sections):
    """The true solids on ``grid``'s cells: a (height, width) bool array, True where a cell's centre lies inside
    any shape's outline of ``sections`` (:func:`world_section`)."""
    return _inside_any(_all_centres(grid), sections).reshape(grid.height, grid.width)


def true_map(sections, x0, y0, resolution, width, height):
    """The map a perfect SLAM would make of ``sections``: a :class:`Grid` whose cells are 100 (occupied) where a
    solid is or a true surface passes within half a cell's diagonal of the centre, 0 (free) elsewhere. Makes a
    fixture's map_server map from a world's geometry."""
    grid = Grid(x0, y0, resolution, width, height, np.zeros((height, width), dtype=np.int16))
    centres = _all_centres(grid)
    all_segments = np.vstack([s for _, s in sections]) if sections else np.zeros((0, 4))
    occupied = _inside_any(centres, sections) | (distances(centres, all_segments) <= resolution * math.sqrt(0.5))
    grid.data[occupied.reshape(height, width)] = 100
    return grid


# ----------------------------------------------------------------------------------------------- judging

@dataclass
class Obstacle:
    """One connected true solid on the map's grid, and how much of what the robot saw of it is mapped."""

    cells: int  # grid cells inside it
    centre: tuple[float, float]  # m, the mean of its cells
    seen: int  # boundary cells with a free map cell next to them
    mapped: int  # of those, with an occupied map cell within NEAR


@dataclass
class MapReport:
    occupied: int  # occupied map cells
    near_fraction: float  # of them, within NEAR of a true surface
    median_error: float  # m, their median distance to the nearest true surface
    obstacles: list[Obstacle] = field(default_factory=list)
    free_inside: int = 0  # free map cells deeper than DEEP inside a true solid
    failures: list[str] = field(default_factory=list)

    @property
    def passed(self):
        return not self.failures


def judge(grid, sections, near=NEAR, deep=DEEP, coverage=COVERAGE, min_near_fraction=0.9, every_obstacle=True,
          enough_mapped=None):
    """Compare ``grid`` (a :class:`Grid`) with the true ``sections`` (:func:`world_section`).

    For a robot of a fleet, which maps only its part of the world: with ``every_obstacle`` false an obstacle
    it never saw is no failure, and with ``enough_mapped`` (cells) an obstacle with that many boundary cells
    mapped passes even below ``coverage`` (a face it saw only at a grazing angle from afar counts as seen: a free
    cell next to it, yet no beam ended on it)."""
    all_segments = np.vstack([s for _, s in sections]) if sections else np.zeros((0, 4))
    rows, cols = np.nonzero(grid.occupied)
    occupied_xy = grid.centres(rows, cols)
    d = distances(occupied_xy, all_segments)
    report = MapReport(len(rows), float((d <= near).mean()) if len(d) else 0.0,
                       float(np.median(d)) if len(d) else math.inf)
    if report.occupied == 0:
        report.failures.append("the map has no occupied cell")
    elif report.near_fraction < min_near_fraction:
        report.failures.append(f"only {report.near_fraction:.0%} of the {report.occupied} occupied cells lie within "
                               f"{near} m of a true surface (at least {min_near_fraction:.0%})")

    solid = solids_on(grid, sections)

    free_in = grid.free & solid
    if free_in.any():
        r, c = np.nonzero(free_in)
        depth = distances(grid.centres(r, c), all_segments)
        deep_xy = grid.centres(r, c)[depth > deep]
        report.free_inside = len(deep_xy)
        if report.free_inside:
            where = ", ".join(f"({x:.2f}, {y:.2f})" for x, y in deep_xy[:5])
            report.failures.append(f"{report.free_inside} free map cells lie more than {deep} m inside a solid: "
                                   f"{where}{' ...' if report.free_inside > 5 else ''}")

    near_cells = max(1, int(round(near / grid.resolution)))
    occupied_near = _dilate(grid.occupied, near_cells)
    free_next = _dilate(grid.free, 1)
    boundary = solid & ~_erode(solid)
    for cells in _components(solid):
        r = np.array([p[0] for p in cells])
        c = np.array([p[1] for p in cells])
        edge = boundary[r, c]
        seen = edge & free_next[r, c]
        mapped = seen & occupied_near[r, c]
        centre = tuple(float(v) for v in grid.centres(r, c).mean(axis=0))
        obstacle = Obstacle(len(cells), centre, int(seen.sum()), int(mapped.sum()))
        report.obstacles.append(obstacle)
        where = f"the obstacle at ({centre[0]:.2f}, {centre[1]:.2f}) ({len(cells)} cells)"
        if obstacle.seen == 0:
            if every_obstacle:
                report.failures.append(f"{where} was never seen (no free map cell next to it)")
        elif obstacle.mapped < coverage * obstacle.seen and (enough_mapped is None
                                                              or obstacle.mapped < enough_mapped):
            report.failures.append(f"{where}: {obstacle.mapped} of its {obstacle.seen} seen boundary cells mapped "
                                   f"(at least {coverage:.0%})")
    return report


def _dilate(mask, steps):
    out = mask.copy()
    for _ in range(steps):
        grown = out.copy()
        grown[1:, :] |= out[:-1, :]
        grown[:-1, :] |= out[1:, :]
        grown[:, 1:] |= out[:, :-1]
        grown[:, :-1] |= out[:, 1:]
        out = grown
    return out


def _erode(mask):
    return ~_dilate(~mask, 1)


def _components(mask):
    """4-connected groups of True cells, as lists of (row, col)."""
    seen = np.zeros_like(mask, dtype=bool)
    groups = []
    height, width = mask.shape
    for start in zip(*np.nonzero(mask)):
        if seen[start]:
            continue
        seen[start] = True
        queue, group = deque([start]), []
        while queue:
            r, c = queue.popleft()
            group.append((r, c))
            for nr, nc in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)):
                if 0 <= nr < height and 0 <= nc < width and mask[nr, nc] and not seen[nr, nc]:
                    seen[nr, nc] = True
                    queue.append((nr, nc))
        groups.append(group)
    return groups
