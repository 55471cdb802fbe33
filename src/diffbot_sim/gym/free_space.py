"""Where a robot may start and where a goal may be: the free floor of a loaded world, as a grid of cells.

A cell is free when an upright cylinder as wide as the robot plus a clearance, standing there, touches no
world body (``physics.World.free_of_bodies``; the ground is not an obstacle). Of the free cells only those
connected to the robot's spawn cell count (4-neighbour flood fill), so a start or goal is never inside a
closed ring, a wall's interior or a room the robot cannot drive to. The cells are computed once, from the
world at its start state; starts and goals are drawn from them by the environment's own random generator.
This replaces TurtleBot3's hand-made goal tables (random ``x, y`` on a 0.1 m grid, rejected near its four
obstacles: turtlebot3_machine_learning ``respawnGoal.py``) for any world.
"""
from collections import deque

import numpy as np

#: Axis-aligned boxes larger than this [m] on a side are unbounded (an infinite ground plane): not an obstacle
#: that limits the arena.
UNBOUNDED = 1e3


def arena_bounds(boxes, default_half_size):
    """The floor area [(x_lo, y_lo), (x_hi, y_hi)] [m] the world's bounded bodies span (``boxes``: their
    ((lo), (hi)) axis-aligned boxes); a square of ``default_half_size`` around the origin when none is
    bounded (an empty world)."""
    bounded = [(lo, hi) for lo, hi in boxes if all(hi[i] - lo[i] < UNBOUNDED for i in range(2))]
    if not bounded:
        return (-default_half_size, -default_half_size), (default_half_size, default_half_size)
    lo = (min(b[0][0] for b in bounded), min(b[0][1] for b in bounded))
    hi = (max(b[1][0] for b in bounded), max(b[1][1] for b in bounded))
    return lo, hi


def grid(bounds, spacing):
    """Cell centres covering ``bounds`` [(x_lo, y_lo), (x_hi, y_hi)] every ``spacing`` m: (rows, cols, (rows*cols,
    2) array of x, y), row-major (y rows, x columns)."""
    (x_lo, y_lo), (x_hi, y_hi) = bounds
    xs = np.arange(x_lo + spacing / 2.0, x_hi, spacing)
    ys = np.arange(y_lo + spacing / 2.0, y_hi, spacing)
    gx, gy = np.meshgrid(xs, ys)
    return len(ys), len(xs), np.stack([gx.ravel(), gy.ravel()], axis=1)


def connected(free, rows, cols, start):
    """Indices (sorted) of the free cells 4-connected to cell ``start`` (row-major index), ``start`` included;
    empty when ``start`` is not free."""
    free = np.asarray(free, bool).reshape(rows, cols)
    r0, c0 = divmod(int(start), cols)
    if not free[r0, c0]:
        return np.zeros(0, dtype=np.int64)
    seen = np.zeros_like(free)
    seen[r0, c0] = True
    todo = deque([(r0, c0)])
    while todo:
        r, c = todo.popleft()
        for nr, nc in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)):
            if 0 <= nr < rows and 0 <= nc < cols and free[nr, nc] and not seen[nr, nc]:
                seen[nr, nc] = True
                todo.append((nr, nc))
    return np.flatnonzero(seen.ravel())


def reachable_cells(points, free, rows, cols, near):
    """Centres ((n, 2) array) of the free cells connected to the free cell nearest to ``near`` (x, y): where
    a robot standing there can drive. Empty when no cell is free."""
    free = np.asarray(free, bool)
    if not free.any():
        return np.zeros((0, 2))
    candidates = np.flatnonzero(free)
    distance = np.hypot(points[candidates, 0] - near[0], points[candidates, 1] - near[1])
    start = candidates[int(np.argmin(distance))]
    return points[connected(free, rows, cols, start)]


def draw_start_goal(rng, cells, min_distance):
    """A start cell and a goal cell from ``cells`` ((n, 2) centres) with ``rng`` (numpy Generator): the start
    uniformly, the goal uniformly among cells at least ``min_distance`` m away (any other cell if none is, the
    start itself when there is only one). Returns ((x, y), (x, y))."""
    start = cells[int(rng.integers(len(cells)))]
    distance = np.hypot(cells[:, 0] - start[0], cells[:, 1] - start[1])
    far = np.flatnonzero(distance >= min_distance)
    if len(far) == 0:
        far = np.flatnonzero(distance > 0.0)
    if len(far) == 0:
        return (float(start[0]), float(start[1])), (float(start[0]), float(start[1]))
    goal = cells[far[int(rng.integers(len(far)))]]
    return (float(start[0]), float(start[1])), (float(goal[0]), float(goal[1]))
