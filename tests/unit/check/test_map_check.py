"""map_check: a SLAM map judged against the world's true geometry (a made-up world, made-up maps)."""
import numpy as np
import pytest

from diffbot_sim.check import map_check
from diffbot_sim.world.bodies import Body, Shape, WorldDescription

RES = 0.05


def world():
    """A 1 m x 0.4 m box centred at (1.0, 0.0) and a cylinder of radius 0.3 at (-1.0, 0.5), both 1 m high."""
    box = Body("box::link", "box", ((1.0, 0.0, 0.5), (0, 0, 0, 1)), True, [Shape("box", (1.0, 0.4, 1.0))])
    cyl = Body("cyl::link", "cyl", ((-1.0, 0.5, 0.5), (0, 0, 0, 1)), True, [Shape("cylinder", (0.3, 1.0))])
    plane = Body("ground::link", "ground", ((0, 0, 0), (0, 0, 0, 1)), True, [Shape("plane", (0, 0, 1))])
    return WorldDescription("w", "w.world", [plane, box, cyl])


def true_map(shift=(0.0, 0.0), hole=False, drop_cylinder=False):
    """A 4 m x 3 m map as a perfect SLAM run would make it: occupied on the solids' outlines, free around,
    unknown inside; ``shift`` moves the outlines, ``hole`` frees the box's middle, ``drop_cylinder`` leaves it
    out."""
    grid = map_check.Grid(-2.0, -1.5, RES, 80, 60, np.zeros((60, 80), dtype=np.int16))
    rows, cols = np.indices(grid.data.shape)
    xy = grid.centres(rows.ravel(), cols.ravel()) - np.array(shift)
    x, y = xy[:, 0].reshape(60, 80), xy[:, 1].reshape(60, 80)
    in_box = (np.abs(x - 1.0) < 0.5) & (np.abs(y) < 0.2)
    in_cyl = np.hypot(x + 1.0, y - 0.5) < 0.3
    solids = in_box | (in_cyl if not drop_cylinder else False)
    edge = solids & ~map_check._erode(solids)
    grid.data[solids] = -1
    grid.data[edge] = 100
    if hole:
        grid.data[(np.abs(x - 1.0) < 0.3) & (np.abs(y) < 0.1)] = 0
    return grid


@pytest.fixture(scope="module")
def sections():
    return map_check.world_section(world(), 0.15)


def test_the_section_has_the_solids_that_cross_the_laser_plane(sections):
    assert [name for name, _ in sections] == ["box::link", "cyl::link"]
    box = sections[0][1]
    assert box[:, [0, 2]].min() == pytest.approx(0.5) and box[:, [0, 2]].max() == pytest.approx(1.5)
    points = np.array([[1.0, 0.0], [1.6, 0.0], [-1.0, 0.5], [-1.0, 0.9]])
    assert list(map_check.inside(points, box)) == [True, False, False, False]
    assert list(map_check.inside(points, sections[1][1])) == [False, False, True, False]
    assert map_check.distances(np.array([[2.0, 0.0]]), box)[0] == pytest.approx(0.5)


def test_a_faithful_map_passes(sections):
    report = map_check.judge(true_map(), sections)
    assert report.passed, report.failures
    assert report.near_fraction == 1.0 and report.median_error < 0.05 and report.free_inside == 0
    assert len(report.obstacles) == 2 and all(o.mapped >= 0.9 * o.seen > 0 for o in report.obstacles)


def test_a_shifted_map_fails_on_its_surfaces(sections):
    report = map_check.judge(true_map(shift=(0.3, 0.0)), sections)
    assert any("occupied cells lie within" in f for f in report.failures), report.failures


def test_a_missing_obstacle_is_named(sections):
    report = map_check.judge(true_map(drop_cylinder=True), sections)
    assert any(f.startswith("the obstacle at (-1.00, 0.50)") for f in report.failures), report.failures


def test_free_cells_inside_a_wall_are_a_hole(sections):
    report = map_check.judge(true_map(hole=True), sections)
    assert report.free_inside > 0 and any("inside a solid" in f for f in report.failures)
