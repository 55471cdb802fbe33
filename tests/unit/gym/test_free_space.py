"""Where starts and goals may be (diffbot_sim.gym.free_space): the arena a world's bodies span, the grid of
cells, only the free cells a robot can drive to from its spawn, and start/goal draws that keep their distance."""
import numpy as np

from diffbot_sim.gym import free_space as fs


def test_arena_ignores_unbounded_bodies_and_defaults_to_a_square():
    plane = ((-1e30, -1e30, -1e30), (1e30, 1e30, 1e30))
    walls = [((-3.1, -2.1, 0.0), (3.1, -2.0, 1.0)), ((-0.5, 1.0, 0.0), (0.5, 2.1, 1.0))]
    assert fs.arena_bounds([plane] + walls, 2.0) == ((-3.1, -2.1), (3.1, 2.1))
    assert fs.arena_bounds([plane], 2.0) == ((-2.0, -2.0), (2.0, 2.0))


def test_grid_cells_are_centred_row_major():
    rows, cols, points = fs.grid(((0.0, 0.0), (0.4, 0.2)), 0.1)
    assert (rows, cols) == (2, 4)
    assert np.allclose(points[:5], [[0.05, 0.05], [0.15, 0.05], [0.25, 0.05], [0.35, 0.05], [0.05, 0.15]])


# A 5 x 7 floor plan: '.' free, '#' a body; the pocket at the right is closed by a ring of '#'.
PLAN = ["..#....",
        "..#.###",
        "....#.#",
        "..#.###",
        "..#...."]


def plan():
    free = np.array([[c == "." for c in row] for row in PLAN])
    rows, cols = free.shape
    cols_x, rows_y = np.meshgrid(np.arange(cols), np.arange(rows))
    return rows, cols, free.ravel(), np.stack([cols_x.ravel(), rows_y.ravel()], axis=1).astype(float)


def test_only_cells_connected_to_the_spawn_count():
    rows, cols, free, points = plan()
    reachable = {tuple(p) for p in fs.reachable_cells(points, free, rows, cols, near=(0.2, 0.1))}
    assert (0.0, 0.0) in reachable and (6.0, 0.0) in reachable  # around the wall through row 2
    assert (5.0, 2.0) not in reachable  # the closed pocket
    assert len(reachable) == int(free.sum()) - 1
    # spawned in the pocket: only the pocket
    assert fs.reachable_cells(points, free, rows, cols, near=(5.0, 2.0)).tolist() == [[5.0, 2.0]]
    assert fs.connected(free, rows, cols, start=2).size == 0  # a body's cell reaches nothing
    assert fs.reachable_cells(points, np.zeros_like(free), rows, cols, near=(0, 0)).shape == (0, 2)


def test_start_and_goal_keep_their_distance_and_follow_the_generator():
    cells = np.array([[x, 0.0] for x in np.arange(0.0, 3.01, 0.5)])
    draws = [fs.draw_start_goal(np.random.default_rng(seed), cells, 1.0) for seed in range(40)]
    assert all(abs(goal[0] - start[0]) >= 1.0 for start, goal in draws)
    assert len({d for d in draws}) > 5  # not one fixed pair
    assert draws[3] == fs.draw_start_goal(np.random.default_rng(3), cells, 1.0)
    start, goal = fs.draw_start_goal(np.random.default_rng(0), cells, 10.0)  # none that far: any other cell
    assert start != goal
    assert fs.draw_start_goal(np.random.default_rng(0), cells[:1], 1.0) == ((0.0, 0.0), (0.0, 0.0))
