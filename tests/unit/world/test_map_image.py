"""diffbot_sim.world.map_image: map_server YAML + image -> one static trimesh of walls (pure; no master)."""
import math
import os
import time

import numpy as np
import pytest

from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.world.map_image import (
    MAX_BOXES_PER_BODY,
    REQUIRED_KEYS,
    MapImage,
    merge_rectangles,
    occupancy,
    read_map,
    read_pgm,
    synthetic_map,
    walls_mesh,
)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
MAZE = os.path.join(ROOT, "worlds", "maze.yaml")


def write_pgm(path, pixels, maxval=255, binary=True, comment=True):
    """A PGM of ``pixels`` (rows top first): P5 (16-bit big-endian above 255) or P2."""
    pixels = np.asarray(pixels)
    height, width = pixels.shape
    head = b"P5" if binary else b"P2"
    head += b"\n# written by test_world_map\n" if comment else b"\n"
    head += b"%d %d\n%d\n" % (width, height, maxval)
    with open(path, "wb") as stream:
        stream.write(head)
        if binary:
            stream.write(pixels.astype(np.uint8 if maxval < 256 else ">u2").tobytes())
        else:
            for row in pixels:
                stream.write(b" ".join(b"%d" % v for v in row) + b"\n")
    return str(path)


def write_yaml(path, image="map.pgm", resolution=0.1, origin=(0.0, 0.0, 0.0), negate=0, occ=0.65, free=0.196,
               extra="", drop=()):
    """A map YAML; ``drop`` leaves keys out, ``extra`` is appended verbatim."""
    values = {"image": image, "resolution": resolution, "origin": "[{!r}, {!r}, {!r}]".format(*tuple(origin)),
              "negate": negate, "occupied_thresh": occ, "free_thresh": free}
    with open(path, "w") as stream:
        for key, value in values.items():
            if key not in drop:
                stream.write(f"{key}: {value}\n")
        stream.write(extra)
    return str(path)


def make_map(tmp_path, pixels, name="map", **yaml_args):
    write_pgm(tmp_path / f"{name}.pgm", pixels)
    return write_yaml(tmp_path / f"{name}.yaml", image=f"{name}.pgm", **yaml_args)


def mesh_of(world):
    assert len(world.bodies) == 1
    shape = world.bodies[0].shapes[0]
    return shape.vertices, shape.indices


def box_bounds(vertices):
    """Per box (8 vertices each): (xmin, xmax, ymin, ymax, zmin, zmax)."""
    boxes = vertices.reshape(-1, 8, 3)
    return np.stack([boxes[:, :, 0].min(1), boxes[:, :, 0].max(1), boxes[:, :, 1].min(1), boxes[:, :, 1].max(1),
                     boxes[:, :, 2].min(1), boxes[:, :, 2].max(1)], axis=1)


def rasterise(rects, shape):
    cover = np.zeros(shape, dtype=np.int64)
    for c0, r0, c1, r1 in rects:
        cover[r0:r1, c0:c1] += 1
    return cover


# ------------------------------------------------------------------------------------------ thresholds


def test_trinary_threshold_is_strict_at_occupied_thresh():
    v = 89
    thresh = (255 - v) / 255.0  # the pixel's p, computed as map_server does
    grid = occupancy(np.array([[v, v - 1, v + 1]], dtype=np.uint8), False, thresh)
    assert grid.tolist() == [[False, True, False]]


def test_default_thresholds_on_grey_levels():
    pixels = np.array([[0, 89, 90, 205, 254, 255]], dtype=np.uint8)  # p = 1, .651, .647, .196, .004, 0
    assert occupancy(pixels, False, 0.65).tolist() == [[True, True, False, False, False, False]]


def test_negate_makes_white_occupied():
    pixels = np.array([[0, 166, 165, 255]], dtype=np.uint8)  # negated: 255, 89, 90, 0
    assert occupancy(pixels, True, 0.65).tolist() == [[False, True, False, True]]


def test_scale_mode_gives_the_same_walls_as_trinary():
    pixels = np.arange(256, dtype=np.uint8).reshape(16, 16)
    for negate in (False, True):
        assert np.array_equal(occupancy(pixels, negate, 0.65, "scale"), occupancy(pixels, negate, 0.65, "trinary"))


def test_raw_mode_pixel_is_occupancy_percent():
    pixels = np.array([[0, 65, 66, 100, 101, 255]], dtype=np.uint8)
    assert occupancy(pixels, False, 0.65, "raw").tolist() == [[False, False, True, True, False, False]]
    # negate first: 155 -> 100 (a wall), 255 -> 0
    assert occupancy(np.array([[155, 255, 189]], dtype=np.uint8), True, 0.65, "raw").tolist() == \
        [[True, False, True]]


def test_channel_mean_and_alpha_rule():
    # RGB (200, 0, 0): mean 66.67, p = 0.739
    rgb = MapImage(np.array([[200]]), 3, 255)
    assert occupancy(rgb, False, 0.70).tolist() == [[True]]
    assert occupancy(rgb, False, 0.74).tolist() == [[False]]


def test_grid_is_the_image_flipped_vertically():
    pixels = np.full((3, 2), 254, dtype=np.uint8)
    pixels[0, 1] = 0  # top-right pixel of the image
    grid = occupancy(pixels, False, 0.65)
    assert grid[2, 1] and grid.sum() == 1  # the last grid row is the map's far (top) edge


# ------------------------------------------------------------------------------ placement in the world


def test_single_pixel_lands_on_its_world_square(tmp_path):
    pixels = np.full((4, 5), 254, dtype=np.uint8)
    pixels[1, 3] = 0  # image row 1 of 4 -> grid row 2
    world = read_map(make_map(tmp_path, pixels, resolution=0.1, origin=(1.0, 2.0, 0.0)), wall_height=0.5)
    vertices, indices = mesh_of(world)
    np.testing.assert_allclose(box_bounds(vertices), [[1.3, 1.4, 2.2, 2.3, 0.0, 0.5]], atol=1e-12)
    assert indices.shape == (10, 3) and indices.dtype == np.int32


def test_origin_yaw_rotates_the_map_about_the_origin(tmp_path):
    pixels = np.full((4, 5), 254, dtype=np.uint8)
    pixels[1, 3] = 0  # grid cell (col 3, row 2): local [0.3, 0.4] x [0.2, 0.3]
    world = read_map(make_map(tmp_path, pixels, resolution=0.1, origin=(1.0, 2.0, math.pi / 2)))
    vertices, _ = mesh_of(world)
    # +90 deg: local (x, y) -> (-y, x)
    np.testing.assert_allclose(box_bounds(vertices), [[0.7, 0.8, 2.3, 2.4, 0.0, 1.0]], atol=1e-12)


def test_relative_and_absolute_image_paths(tmp_path):
    pixels = np.zeros((2, 2), dtype=np.uint8)
    sub = tmp_path / "maps"
    sub.mkdir()
    image = write_pgm(sub / "walls.pgm", pixels)
    relative = read_map(write_yaml(sub / "rel.yaml", image="walls.pgm"))
    absolute = read_map(write_yaml(tmp_path / "abs.yaml", image=image))
    assert np.array_equal(mesh_of(relative)[0], mesh_of(absolute)[0])


# ---------------------------------------------------------------------------------------- rectangles


@pytest.mark.parametrize("seed,density", [(0, 0.05), (1, 0.3), (2, 0.5), (3, 0.8), (4, 0.97)])
def test_rectangles_cover_the_grid_exactly_once(seed, density):
    rng = np.random.default_rng(seed)
    grid = rng.random((37, 53)) < density
    rects = merge_rectangles(grid)
    assert np.array_equal(rasterise(rects, grid.shape), grid.astype(np.int64))
    runs = int((np.diff(np.pad(grid.astype(np.int8), ((0, 0), (1, 0))), axis=1) == 1).sum())
    assert len(rects) <= runs


def test_rectangle_counts_on_known_shapes():
    assert len(merge_rectangles(np.ones((50, 40), bool))) == 1
    assert len(merge_rectangles(np.zeros((5, 5), bool))) == 0
    ell = np.zeros((6, 6), bool)
    ell[0:6, 0:2] = True
    ell[0:2, 2:6] = True  # an L: a 2-row bar (rows 0-1) and a column above it (rows 2-5)
    assert sorted(merge_rectangles(ell).tolist()) == [[0, 0, 6, 2], [0, 2, 2, 6]]
    checker = (np.add.outer(np.arange(8), np.arange(8)) % 2).astype(bool)
    assert len(merge_rectangles(checker)) == 32
    rooms = np.zeros((30, 30), bool)
    rooms[:, :3] = rooms[:, -3:] = rooms[:3, :] = rooms[-3:, :] = True
    assert len(merge_rectangles(rooms)) == 4  # two bars, two side walls between them


# ---------------------------------------------------------------------------------------------- mesh


def test_mesh_boxes_are_the_wall_rectangles():
    rng = np.random.default_rng(7)
    grid = rng.random((20, 30)) < 0.4
    rects = merge_rectangles(grid)
    vertices, indices = walls_mesh(rects, 0.05, (-1.0, 2.0, 0.0), 0.8)
    assert vertices.shape == (8 * len(rects), 3) and vertices.dtype == np.float64
    assert indices.shape == (10 * len(rects), 3) and indices.dtype == np.int32
    assert indices.min() == 0 and indices.max() == len(vertices) - 1
    expected = np.stack([-1.0 + 0.05 * rects[:, 0], -1.0 + 0.05 * rects[:, 2], 2.0 + 0.05 * rects[:, 1],
                         2.0 + 0.05 * rects[:, 3], np.zeros(len(rects)), np.full(len(rects), 0.8)], axis=1)
    np.testing.assert_allclose(box_bounds(vertices), expected, atol=1e-12)


def test_many_boxes_are_split_into_bodies_pybullet_accepts(tmp_path):
    checker = (np.add.outer(np.arange(10), np.arange(9)) % 2 * 254).astype(np.uint8)  # 45 isolated cells
    world = read_map(make_map(tmp_path, checker, resolution=1.0), max_boxes=20)
    assert [b.name for b in world.bodies] == ["map::walls", "map::walls_1", "map::walls_2"]
    boxes = []
    for body in world.bodies:
        (shape,) = body.shapes
        assert body.static and body.model == "map" and len(shape.vertices) <= 8 * 20
        assert shape.indices.min() == 0 and shape.indices.max() == len(shape.vertices) - 1
        boxes.append(box_bounds(shape.vertices))
    cells = np.rint(np.concatenate(boxes)[:, :4]).astype(int)
    assert np.array_equal(rasterise(cells[:, [0, 2, 1, 3]], (10, 9)), occupancy(checker, False, 0.65))
    assert 8 * MAX_BOXES_PER_BODY <= 131072  # PyBullet 3.2.7's vertices per collision mesh


def test_mesh_triangles_face_outwards_and_cover_top_and_sides():
    vertices, indices = walls_mesh(np.array([[0, 0, 2, 1]]), 1.0, (0.0, 0.0, 0.3), 1.0)
    tri = vertices[indices]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    centre = vertices.mean(axis=0)
    assert np.all(np.einsum("ij,ij->i", normals, tri.mean(axis=1) - centre) > 0)
    area = np.linalg.norm(normals, axis=1).sum() / 2.0
    assert area == pytest.approx(2.0 + 2 * (2.0 + 1.0))  # top 2 x 1, sides 2 x (2 + 1) high 1, no bottom


# --------------------------------------------------------------------------------------------- images


def test_pgm_p5_and_p2_read_the_same(tmp_path):
    pixels = np.random.default_rng(3).integers(0, 256, (7, 11)).astype(np.uint8)
    values5, max5 = read_pgm(write_pgm(tmp_path / "a.pgm", pixels))
    values2, max2 = read_pgm(write_pgm(tmp_path / "b.pgm", pixels, binary=False))
    assert max5 == max2 == 255
    assert np.array_equal(values5, pixels) and np.array_equal(values2, pixels)


def test_pgm_16_bit_is_scaled_to_255(tmp_path):
    # 65535 * 0.35 = 22937.25: p just above 0.65 for 22937, below for 22938 ... as 8-bit 89.2 vs 89.3
    pixels = np.array([[0, 22937, 23131, 65535]], dtype=np.uint16)
    for binary in (True, False):
        path = write_pgm(tmp_path / f"w{binary}.pgm", pixels, maxval=65535, binary=binary)
        values, maxval = read_pgm(path)
        assert maxval == 65535 and values.tolist() == pixels.tolist()
        world = read_map(write_yaml(tmp_path / f"w{binary}.yaml", image=os.path.basename(path), resolution=1.0))
        np.testing.assert_allclose(box_bounds(mesh_of(world)[0])[:, :4], [[0.0, 2.0, 0.0, 1.0]])


def test_pgm_small_maxval_is_scaled(tmp_path):
    pixels = np.array([[0, 1, 2, 3]], dtype=np.uint8)  # maxval 3: 0, 85, 170, 255
    write_pgm(tmp_path / "m.pgm", pixels, maxval=3)
    world = read_map(write_yaml(tmp_path / "m.yaml", image="m.pgm", resolution=1.0))
    np.testing.assert_allclose(box_bounds(mesh_of(world)[0])[:, :4], [[0.0, 2.0, 0.0, 1.0]])


@pytest.mark.parametrize("mode", ["L", "RGB"])
def test_png_through_pillow(tmp_path, mode):
    Image = pytest.importorskip("PIL.Image")
    pixels = np.full((3, 4), 254, dtype=np.uint8)
    pixels[0, 0] = 0  # top-left
    data = pixels if mode == "L" else np.repeat(pixels[:, :, None], 3, axis=2)
    Image.fromarray(data, mode).save(tmp_path / "map.png")
    world = read_map(write_yaml(tmp_path / "map.yaml", image="map.png", resolution=0.5))
    np.testing.assert_allclose(box_bounds(mesh_of(world)[0])[:, :4], [[0.0, 0.5, 1.0, 1.5]])


def test_png_alpha_counts_in_trinary_only(tmp_path):
    Image = pytest.importorskip("PIL.Image")
    # opaque black: trinary mean (0+0+0+255)/4 = 63.75 -> p = 0.75; scale mean 0 -> p = 1
    Image.fromarray(np.array([[[0, 0, 0, 255]]], dtype=np.uint8), "RGBA").save(tmp_path / "a.png")
    trinary = read_map(write_yaml(tmp_path / "t.yaml", image="a.png", occ=0.8))
    scale = read_map(write_yaml(tmp_path / "s.yaml", image="a.png", occ=0.8, extra="mode: scale\n"))
    assert trinary.bodies == [] and len(scale.bodies) == 1
    assert len(read_map(write_yaml(tmp_path / "t2.yaml", image="a.png", occ=0.7)).bodies) == 1


def test_raw_mode_from_yaml(tmp_path):
    path = make_map(tmp_path, np.array([[100, 50, 255]], dtype=np.uint8), resolution=1.0, extra="mode: raw\n")
    np.testing.assert_allclose(box_bounds(mesh_of(read_map(path))[0])[:, :4], [[0.0, 1.0, 0.0, 1.0]])


# -------------------------------------------------------------------------------- world and warnings


def test_world_description_fields(tmp_path):
    path = make_map(tmp_path, np.zeros((2, 3), dtype=np.uint8), name="office")
    world = read_map(path, wall_height=2.5)
    assert world.name == "office" and world.source == os.path.abspath(path)
    assert world.has_ground is False and world.gravity == (0.0, 0.0, -9.8) and world.warnings == []
    (body,) = world.bodies
    assert (body.name, body.model, body.static) == ("map::walls", "map", True)
    assert body.pose == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    (shape,) = body.shapes
    assert shape.kind == "trimesh" and len(shape.indices) == 10  # all 6 cells: one rectangle


def test_warnings_for_empty_map_unknown_mode_and_keys(tmp_path):
    path = make_map(tmp_path, np.full((3, 3), 254, dtype=np.uint8), extra="mode: fancy\ncolour: red\n")
    world = read_map(path)
    assert world.bodies == []
    text = "\n".join(world.warnings)
    assert len(world.warnings) == 3
    assert "no occupied cell" in text and "'fancy'" in text and "'colour'" in text


# ---------------------------------------------------------------------------------------------- errors


@pytest.mark.parametrize("key", REQUIRED_KEYS)
def test_missing_key_is_a_model_error_naming_key_and_file(tmp_path, key):
    write_pgm(tmp_path / "map.pgm", np.zeros((2, 2)))
    path = write_yaml(tmp_path / "map.yaml", drop=(key,))
    with pytest.raises(ModelError) as info:
        read_map(path)
    message = str(info.value)
    assert key in message and path in message and "\n" not in message


@pytest.mark.parametrize("content", [None, b"this is not an image\n", b"P5\n10 10\n255\n\x00\x00"])
def test_unreadable_image_is_a_model_error_naming_image_and_yaml(tmp_path, content):
    if content is not None:
        (tmp_path / "map.pgm").write_bytes(content)
    path = write_yaml(tmp_path / "map.yaml")
    with pytest.raises(ModelError) as info:
        read_map(path)
    message = str(info.value)
    assert str(tmp_path / "map.pgm") in message and path in message and "\n" not in message


@pytest.mark.parametrize("args,key", [({"resolution": 0}, "resolution"), ({"resolution": "'a'"}, "resolution"),
                                      ({"negate": 2}, "negate"), ({"occ": "[1]"}, "occupied_thresh")])
def test_bad_values_are_model_errors(tmp_path, args, key):
    write_pgm(tmp_path / "map.pgm", np.zeros((2, 2)))
    path = write_yaml(tmp_path / "map.yaml", **args)
    with pytest.raises(ModelError, match=key):
        read_map(path)


def test_bad_origin_and_not_a_mapping(tmp_path):
    write_pgm(tmp_path / "map.pgm", np.zeros((2, 2)))
    path = write_yaml(tmp_path / "map.yaml")
    with open(path, "a") as stream:
        stream.write("origin: [1, 2]\n")  # the later key wins in PyYAML
    with pytest.raises(ModelError, match="origin"):
        read_map(path)
    (tmp_path / "list.yaml").write_text("- 1\n- 2\n")
    with pytest.raises(ModelError, match="mapping"):
        read_map(str(tmp_path / "list.yaml"))


@pytest.mark.parametrize("height", [0, -1, float("nan"), "x"])
def test_bad_wall_height_is_a_config_error(tmp_path, height):
    path = make_map(tmp_path, np.zeros((2, 2), dtype=np.uint8))
    with pytest.raises(ConfigError, match="wall_height"):
        read_map(path, wall_height=height)


# ------------------------------------------------------------------------------------- the maze example


MAZE_WALLS = [  # as documented in worlds/maze.yaml
    (-5.0, 5.0, -4.0, -3.8), (-5.0, 5.0, 3.8, 4.0), (-5.0, -4.8, -3.8, 3.8), (4.8, 5.0, -3.8, 3.8),
    (2.0, 2.2, -3.8, 1.0), (2.0, 2.2, 2.0, 3.8), (-4.8, -0.5, 1.5, 1.7), (0.5, 2.0, 1.5, 1.7),
    (-4.8, -1.0, -2.2, -2.0), (-3.0, -2.6, -0.4, 0.4), (3.5, 4.0, -0.5, 0.5),
]


def test_maze_walls_are_where_its_yaml_says():
    world = read_map(MAZE)
    bounds = box_bounds(mesh_of(world)[0])
    expected = np.zeros((160, 200), bool)
    for x0, x1, y0, y1 in MAZE_WALLS:
        expected[round((y0 + 4) / 0.05):round((y1 + 4) / 0.05), round((x0 + 5) / 0.05):round((x1 + 5) / 0.05)] = True
    cells = np.rint((bounds[:, :4] - [-5, -5, -4, -4]) / 0.05).astype(int)
    got = rasterise(cells[:, [0, 2, 1, 3]], expected.shape)
    assert np.array_equal(got, expected.astype(np.int64))

    def first_face(direction):
        """The nearest wall face met from (0, 0) along +x, -x, +y or -y (a zero-width ray)."""
        hits = []
        for xmin, xmax, ymin, ymax in bounds[:, :4]:
            if direction in "+x-x" and ymin < 0 < ymax:
                hits += [xmin] if direction == "+x" and xmin > 0 else [xmax] if direction == "-x" and xmax < 0 else []
            if direction in "+y-y" and xmin < 0 < xmax:
                hits += [ymin] if direction == "+y" and ymin > 0 else [ymax] if direction == "-y" and ymax < 0 else []
        return min(hits, key=abs)

    assert [first_face(d) for d in ("+x", "-x", "+y", "-y")] == pytest.approx([2.0, -2.6, 3.8, -3.8])


# ---------------------------------------------------------------------------------------------- speed


def _timed_synthetic(tmp_path, size):
    path = synthetic_map(str(tmp_path / "synthetic.yaml"), size=size)
    start = time.perf_counter()
    world = read_map(path)
    elapsed = time.perf_counter() - start
    assert all(len(b.shapes[0].vertices) <= 8 * MAX_BOXES_PER_BODY for b in world.bodies)
    return elapsed, sum(len(b.shapes[0].indices) for b in world.bodies)


def test_2000_cell_map_loads_fast(tmp_path):
    """The walls are merged boxes, not a box per cell: few triangles, and read in about 0.07 s here (2 cores).
    The time bound is 40x that, so a busy machine never misses it; it catches only a per-cell regression.
    The start-up figure that matters (first /odom in a 4000 x 4000 map, <= 3 s) is make bench's
    ``worlds`` item (tools/bench_items/startup.py)."""
    elapsed, triangles = _timed_synthetic(tmp_path, 2000)
    assert elapsed < 3.0, f"read_map took {elapsed:.2f} s"
    assert triangles < 2_000_000


@pytest.mark.slow
def test_4000_cell_map_stays_small(tmp_path):
    """A 4000 x 4000 map (read in about 0.45 s here): bounded geometry; its load time is make bench's
    ``worlds`` figure (first /odom, <= 3 s), not a unit-test assertion."""
    _, triangles = _timed_synthetic(tmp_path, 4000)
    assert triangles < 4_000_000
