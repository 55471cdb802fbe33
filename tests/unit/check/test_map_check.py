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


def test_true_map_marks_the_solids_and_their_outlines_occupied_and_the_rest_free(sections):
    grid = map_check.true_map(sections, -2.0, -1.5, RES, 80, 60)
    occupied = grid.centres(*np.nonzero(grid.data == 100))
    assert set(np.unique(grid.data)) == {0, 100}
    # Every occupied cell is inside a solid or within half a cell's diagonal of a surface; every solid's centre
    # and a point on the box's face are occupied; the open floor between them is free.
    all_segments = np.vstack([s for _, s in sections])
    rows, cols = np.nonzero(grid.data == 100)
    on_surface = map_check.distances(occupied, all_segments) <= RES * np.sqrt(0.5) + 1e-9
    assert (on_surface | map_check.solids_on(grid, sections)[rows, cols]).all()

    def at(x, y):
        return grid.data[int((y + 1.5) / RES), int((x + 2.0) / RES)]
    assert at(1.0, 0.0) == 100 and at(-1.0, 0.5) == 100 and at(0.52, 0.0) == 100
    assert at(0.0, 0.0) == 0 and at(1.0, 0.3) == 0 and at(-1.0, 0.9) == 0


def test_a_fleet_robot_s_partial_map_passes_without_the_obstacles_it_never_saw(sections):
    grid = true_map(drop_cylinder=True)
    assert not map_check.judge(grid, sections, every_obstacle=True).passed
    # Unseen: the cylinder's cells left unknown (no free cell next to them).
    rows, cols = np.indices(grid.data.shape)
    xy = grid.centres(rows.ravel(), cols.ravel())
    grid.data[(np.hypot(xy[:, 0] + 1.0, xy[:, 1] - 0.5) < 0.5).reshape(grid.data.shape)] = -1
    assert not map_check.judge(grid, sections).passed
    assert map_check.judge(grid, sections, every_obstacle=False).passed


def test_enough_mapped_cells_pass_an_obstacle_seen_mostly_at_grazing_angles(sections):
    # The box mapped on its east end only (the rest of its outline free): under half its seen outline.
    grid = true_map()
    rows, cols = np.indices(grid.data.shape)
    x = grid.centres(rows.ravel(), cols.ravel())[:, 0].reshape(grid.data.shape)
    box_west = (x < 1.3) & (x > 0.4) & (grid.data == 100)
    grid.data[box_west] = 0
    strict = map_check.judge(grid, sections)
    assert any(f.startswith("the obstacle at (1.00, 0.00)") for f in strict.failures), strict.failures
    assert not map_check.judge(grid, sections, enough_mapped=1000).passed
    assert map_check.judge(grid, sections, enough_mapped=10).passed
