"""A map_server map (YAML + image) as a world of static walls (pure: no rospy, no PyBullet).

Robots that navigate with the ROS 1 navigation stack already have their world as a map_server map. Reading
it here gives the simulator the very walls the planner sees, without a hand-made Gazebo world. The YAML keys
and the per-pixel rules are map_server's (ros-planning/navigation ``map_server/src/main.cpp`` and
``image_loader.cpp``):

* ``image`` (relative to the YAML's directory unless absolute), ``resolution`` (m/pixel), ``origin``
  ``[x, y, yaw]`` (the pose of the lower-left pixel's corner; the map turns by ``yaw`` about it), ``negate``,
  ``occupied_thresh``, ``free_thresh``: all required, as map_server treats a missing one as fatal. ``mode``
  (``trinary``, the default, ``scale`` or ``raw``) is optional.
* A pixel's value is the mean of its channels. An alpha channel takes part in the mean in trinary mode and
  is left out otherwise (map_server's own quirk, kept so both agree). ``negate`` turns the value v into
  255 - v. Then p = (255 - v) / 255, and a cell is occupied (100) where p > occupied_thresh. Trinary and
  scale differ only below that threshold (unknown vs. scaled cost), so both give the same walls.
* Raw mode: map_server copies the value, truncated to an integer, into the grid, so the pixel *is* the
  occupancy in percent. Here a raw cell is a wall where 100 * occupied_thresh < v <= 100. That is the
  same strict ">" as the other modes. Values above 100 are not occupancies (255 is -1, unknown, as int8).
* Image row j is grid row height - 1 - j (the image's top row is the map's far edge). Grid cell (i, r) spans
  ``origin + R(yaw) [i*res, (i+1)*res] x [r*res, (r+1)*res]``.

Images: PGM (P2/P5, any maxval up to 65535) is read by a small numpy reader here, because it is what
map_saver writes and needs no extra package. Wider than 8 bits, values are scaled to 0..255 as floats
(v * 255 / maxval) before the thresholds. Other formats (PNG, BMP...) go through Pillow, Debian's
``python3-pil``, imported only when needed. A palette image is read by colour. Grey+alpha becomes RGBA
(grey in each colour channel), so its mean weighs grey and alpha as an RGBA image would.

Why one mesh: a 4000 x 4000 map has millions of occupied cells. As bodies they would stall PyBullet. So
occupied cells are merged into rectangles: runs along each row, then identical runs on consecutive rows.
The rectangles become axis-aligned boxes (top and four sides; the bottom lies on the ground and is never
touched) in one triangle mesh: one static body, ``map::walls``. One PyBullet collision mesh takes at most
131072 vertices, though (measured on 3.2.7: one vertex more and ``createCollisionShape`` fails; past about
524288 indices it raises SystemError). So a map of more than :data:`MAX_BOXES_PER_BODY` boxes is split into
bodies ``map::walls``, ``map::walls_1``, ..., each a strip of columns (18 for the noisy 4000 x 4000
benchmark of :func:`synthetic_map`).
"""
import math
import os
import re

import numpy as np
import yaml

from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.world.bodies import IDENTITY, Body, Shape, WorldDescription

#: The keys map_server requires (main.cpp exits when one is missing).
REQUIRED_KEYS = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh")
#: Every key map_server reads.
KNOWN_KEYS = REQUIRED_KEYS + ("mode",)
MODES = ("trinary", "scale", "raw")
#: Boxes per wall body: 8 vertices each, so 131072 vertices, PyBullet's limit for one collision mesh.
MAX_BOXES_PER_BODY = 16384

#: Triangles of one box, over its 8 corners (0-3 bottom, 4-7 top, each counter-clockwise from (x0, y0)),
#: wound counter-clockwise seen from outside: top, then the sides facing -y, +x, +y, -x.
_BOX_TRIANGLES = np.array([
    [4, 5, 6], [4, 6, 7],
    [0, 1, 5], [0, 5, 4],
    [1, 2, 6], [1, 6, 5],
    [2, 3, 7], [2, 7, 6],
    [3, 0, 4], [3, 4, 7],
], dtype=np.int32)


def read_map(yaml_path, wall_height=1.0, max_boxes=MAX_BOXES_PER_BODY):
    """Read a map_server YAML and its image as a world whose occupied cells are static walls.

    Args:
        yaml_path: the map's YAML file.
        wall_height: the walls' height [m] (a map has none; 1 m blocks any ground robot and its lidar).
        max_boxes: boxes per body at most (PyBullet's per-mesh vertex limit; see the module docstring).

    Returns:
        WorldDescription with one static body ``map::walls`` (model ``map``, identity pose, one ``trimesh``
        shape in the world frame), plus ``map::walls_1``... when the walls need more than ``max_boxes``
        boxes; no body and a warning when no cell is occupied. ``has_ground`` is False: the simulator adds
        its plane.

    Raises:
        ModelError: unreadable YAML, a missing or malformed key, an unreadable image.
        ConfigError: ``wall_height`` is not a finite number > 0.
    """
    try:
        height_ok = math.isfinite(float(wall_height)) and float(wall_height) > 0
    except (TypeError, ValueError):
        height_ok = False
    if not height_ok:
        raise ConfigError("wall_height", wall_height, "a finite number > 0 (metres)")
    wall_height = float(wall_height)
    yaml_path = os.path.abspath(yaml_path)
    meta, warnings = _read_yaml(yaml_path)
    grid = occupancy(read_image(meta["image"], yaml_path, meta["mode"]), meta["negate"], meta["occupied_thresh"],
                     meta["mode"])
    name = os.path.splitext(os.path.basename(yaml_path))[0]
    world = WorldDescription(name=name, source=yaml_path, has_ground=False, warnings=warnings)
    rects = merge_rectangles(grid)
    if len(rects) == 0:
        world.warnings.append(f"map image {meta['image']} has no occupied cell: the world has no walls")
        return world
    vertices, indices = walls_mesh(rects, meta["resolution"], meta["origin"], wall_height)
    max_boxes = max(1, int(max_boxes))
    for part, first in enumerate(range(0, len(rects), max_boxes)):
        last = min(first + max_boxes, len(rects))
        shape = Shape(kind="trimesh", vertices=vertices[8 * first:8 * last],
                      indices=indices[10 * first:10 * last] - np.int32(8 * first), name="walls")
        world.bodies.append(Body(name=f"map::walls_{part}" if part else "map::walls", model="map", pose=IDENTITY,
                                 static=True, shapes=[shape]))
    return world


def _read_yaml(yaml_path):
    """The map's metadata, checked, with ``image`` made absolute: (dict, warnings)."""
    try:
        with open(yaml_path, encoding="utf-8") as stream:
            doc = yaml.safe_load(stream)
    except OSError as err:
        raise ModelError(f"cannot read the map YAML: {err.strerror or err}", yaml_path) from err
    except yaml.YAMLError as err:
        detail = " ".join(str(err).split())
        raise ModelError(f"not valid YAML: {detail}", yaml_path) from err
    if not isinstance(doc, dict):
        raise ModelError("a map YAML must be a mapping of map_server's keys", yaml_path)
    for key in REQUIRED_KEYS:
        if key not in doc:
            raise ModelError(f"missing required key '{key}' (map_server needs {', '.join(REQUIRED_KEYS)})",
                             yaml_path, key)
    warnings = [f"unknown map YAML key '{key}' ignored (map_server reads {', '.join(KNOWN_KEYS)})"
                for key in doc if key not in KNOWN_KEYS]

    def number(key, low=None, low_open=False):
        value = doc[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ModelError(f"'{key}' must be a finite number, got {value!r}", yaml_path, key)
        if low is not None and (value <= low if low_open else value < low):
            raise ModelError(f"'{key}' must be {'>' if low_open else '>='} {low}, got {value!r}", yaml_path, key)
        return float(value)

    image = doc["image"]
    if not isinstance(image, str) or not image.strip():
        raise ModelError(f"'image' must be a file name, got {image!r}", yaml_path, "image")
    origin = doc["origin"]
    if (not isinstance(origin, (list, tuple)) or len(origin) != 3
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                       for v in origin)):
        raise ModelError(f"'origin' must be [x, y, yaw] (3 finite numbers), got {origin!r}", yaml_path, "origin")
    negate = doc["negate"]
    if negate not in (0, 1):  # also True/False, which map_server's int read would reject; harmless here
        raise ModelError(f"'negate' must be 0 or 1, got {negate!r}", yaml_path, "negate")
    mode = doc.get("mode", "trinary")
    if mode not in MODES:
        warnings.append(f"unknown map mode {mode!r}: using trinary (map_server knows {', '.join(MODES)})")
        mode = "trinary"
    meta = {
        "image": image if os.path.isabs(image) else os.path.join(os.path.dirname(yaml_path), image),
        "resolution": number("resolution", 0.0, low_open=True),
        "origin": tuple(float(v) for v in origin),
        "negate": bool(negate),
        "occupied_thresh": number("occupied_thresh"),
        "free_thresh": number("free_thresh"),
        "mode": mode,
    }
    return meta, warnings


# ---------------------------------------------------------------------------------------------- images


class MapImage:
    """A map image's pixels as map_server sees them.

    Attributes:
        sums: (height, width) integer array: per pixel, the sum of the ``channels`` values averaged (image
            rows top first, as stored).
        channels: how many values each sum adds up (1 grey; 3 RGB; 4 RGBA in trinary mode, else 3).
        maxval: the largest value one channel can have (255, or a PGM's maxval).
    """

    def __init__(self, sums, channels, maxval):
        self.sums = sums
        self.channels = channels
        self.maxval = maxval


def read_image(image_path, yaml_path, mode="trinary"):
    """Read a map image into a :class:`MapImage` (PGM here, other formats through Pillow).

    Args:
        image_path: the image file. yaml_path: the map YAML (named in errors).
        mode: the map's mode, which decides whether an alpha channel counts in the mean.

    Raises:
        ModelError: the file is missing or unreadable (the message names the image; source is the YAML).
    """
    try:
        with open(image_path, "rb") as stream:
            magic = stream.read(2)
    except OSError as err:
        raise ModelError(f"cannot read map image {image_path}: {err.strerror or err}", yaml_path,
                         "image") from err
    try:
        if magic in (b"P2", b"P5"):
            values, maxval = read_pgm(image_path)
            return MapImage(values, 1, maxval)
        return _read_with_pillow(image_path, mode)
    except (ValueError, OSError) as err:
        detail = " ".join(str(err).split())
        raise ModelError(f"cannot read map image {image_path}: {detail}", yaml_path, "image") from err


_PNM_TOKEN = re.compile(rb"(?:\s|#[^\n\r]*[\n\r])*([^\s#]+)")


def read_pgm(path):
    """Read a PGM file (P2 ASCII or P5 binary, maxval 1..65535): (values (height, width), maxval).

    Values keep their integer type: uint8 for maxval < 256, else uint16 (P5 stores those big-endian).

    Raises:
        ValueError: not a PGM, or truncated.
    """
    with open(path, "rb") as stream:
        data = stream.read()
    header, pos = [], 0
    for _ in range(4):  # magic, width, height, maxval (comments may come between them)
        match = _PNM_TOKEN.match(data, pos)
        if not match:
            raise ValueError("truncated PGM header")
        header.append(match.group(1))
        pos = match.end()
    magic = header[0]
    if magic not in (b"P2", b"P5"):
        raise ValueError(f"not a PGM (magic {magic!r})")
    try:
        width, height, maxval = (int(v) for v in header[1:])
    except ValueError as err:
        raise ValueError(f"bad PGM header {b' '.join(header[1:]).decode('ascii', 'replace')}") from err
    if width <= 0 or height <= 0 or not 0 < maxval < 65536:
        raise ValueError(f"bad PGM size {width}x{height} or maxval {maxval}")
    count = width * height
    dtype = np.uint8 if maxval < 256 else np.dtype(">u2")
    if magic == b"P5":
        pos += 1  # exactly one whitespace byte ends the header
        need = count * np.dtype(dtype).itemsize
        if len(data) - pos < need:
            raise ValueError(f"truncated PGM: {len(data) - pos} data bytes for {width}x{height} pixels")
        values = np.frombuffer(data, dtype=dtype, count=count, offset=pos)
    else:
        body = re.sub(rb"#[^\n\r]*", b" ", data[pos:]).split()
        if len(body) < count:
            raise ValueError(f"truncated PGM: {len(body)} values for {width}x{height} pixels")
        values = np.array(body[:count]).astype(np.int64)
        if values.min() < 0 or values.max() > maxval:
            raise ValueError(f"PGM value outside 0..{maxval}")
    values = values.astype(np.uint8 if maxval < 256 else np.uint16, copy=False).reshape(height, width)
    return values, maxval


def _read_with_pillow(path, mode):
    """Any other format through Pillow, channels as SDL_image would give them to map_server."""
    try:
        from PIL import Image
    except ImportError as err:
        raise ValueError("only PGM is read without Pillow; install Debian's python3-pil") from err
    with Image.open(path) as img:
        img.load()
        if img.mode in ("I;16", "I;16B", "I;16L", "I"):
            values = np.asarray(img).astype(np.int64)
            return MapImage(np.clip(values, 0, 65535), 1, 65535)
        if img.mode == "P":
            img = img.convert("RGBA" if "transparency" in img.info else "RGB")
        elif img.mode in ("LA", "PA", "RGBa", "La"):
            img = img.convert("RGBA")
        elif img.mode not in ("L", "RGB", "RGBA"):
            img = img.convert("RGB")  # "1", CMYK, YCbCr, F...: colours as RGB
        pixels = np.asarray(img)
    if pixels.ndim == 2:
        return MapImage(pixels, 1, 255)
    channels = pixels.shape[2]
    if channels == 4 and mode != "trinary":
        channels = 3  # map_server leaves alpha out of the mean except in trinary mode
    return MapImage(pixels[:, :, :channels].sum(axis=2, dtype=np.int32), channels, 255)


# ------------------------------------------------------------------------------------------- occupancy


def occupancy(image, negate, occupied_thresh, mode="trinary"):
    """Which cells are walls: a boolean (rows, cols) grid, row 0 the map's lower edge (image flipped).

    Args:
        image: a :class:`MapImage`, or a plain (height, width) uint8 array of grey values.
        negate: map_server's ``negate`` (value v becomes 255 - v).
        occupied_thresh: walls where p = (255 - v) / 255 > occupied_thresh (raw: 100 * thresh < v <= 100).
        mode: ``trinary``, ``scale`` (same walls) or ``raw``.

    The rule is evaluated once per possible channel sum (a lookup table), with the same float arithmetic as
    map_server, so a pixel exactly at the threshold falls the same way, and a 16-million-pixel map costs
    one table look-up per pixel.
    """
    if not isinstance(image, MapImage):
        image = MapImage(np.asarray(image), 1, 255)
    sums = np.arange(image.channels * image.maxval + 1, dtype=np.float64)
    value = sums / image.channels
    if image.maxval != 255:
        value = value * 255.0 / image.maxval
    if negate:
        value = 255.0 - value
    if mode == "raw":
        raw = np.floor(value)
        table = (raw > 100.0 * occupied_thresh) & (raw <= 100.0)
    else:
        table = (255.0 - value) / 255.0 > occupied_thresh
    return table[image.sums][::-1]


# ------------------------------------------------------------------------------------------ rectangles


def merge_rectangles(grid):
    """Cover a boolean grid's True cells exactly, without overlap, with few rectangles.

    Greedy and vectorised: maximal runs along each row, then a run identical to one on the row below
    extends that rectangle upwards.

    Returns:
        (K, 4) int64 array of ``[col0, row0, col1, row1]`` (half-open: cols col0..col1-1, rows row0..row1-1).
    """
    grid = np.asarray(grid, dtype=bool)
    if grid.ndim != 2 or grid.size == 0:
        return np.zeros((0, 4), dtype=np.int64)
    rows, cols = grid.shape
    padded = np.zeros((rows, cols + 2), dtype=np.int8)
    padded[:, 1:-1] = grid
    edges = np.diff(padded, axis=1)
    start_r, start_c = np.nonzero(edges == 1)  # row-major order: the k-th start pairs with the k-th end
    _, end_c = np.nonzero(edges == -1)
    if len(start_r) == 0:
        return np.zeros((0, 4), dtype=np.int64)
    start_r = start_r.astype(np.int64)
    key = start_c.astype(np.int64) * (cols + 1) + end_c
    order = np.lexsort((start_r, key))  # by run (start, end), then row
    key, row, c0, c1 = key[order], start_r[order], start_c[order], end_c[order]
    new = np.ones(len(key), dtype=bool)
    new[1:] = (key[1:] != key[:-1]) | (row[1:] != row[:-1] + 1)
    first = np.nonzero(new)[0]
    last = np.append(first[1:], len(key)) - 1
    return np.stack([c0[first], row[first], c1[first], row[last] + 1], axis=1).astype(np.int64)


def walls_mesh(rects, resolution, origin, height):
    """One triangle mesh of boxes standing on the rectangles (cell units), in the world frame.

    Args:
        rects: (K, 4) ``[col0, row0, col1, row1]`` as from :func:`merge_rectangles`.
        resolution: metres per cell.
        origin: ``(x, y, yaw)`` of the grid's lower-left corner.
        height: the boxes' height [m] (from z = 0).

    Returns:
        (vertices (8K, 3) float64, indices (10K, 3) int32): per box its top and four sides, outward-facing.
    """
    rects = np.asarray(rects, dtype=np.float64).reshape(-1, 4) * resolution
    count = len(rects)
    x0, y0, x1, y1 = rects[:, 0], rects[:, 1], rects[:, 2], rects[:, 3]
    local = np.empty((count, 8, 2))
    local[:, 0::4, 0], local[:, 0::4, 1] = x0[:, None], y0[:, None]
    local[:, 1::4, 0], local[:, 1::4, 1] = x1[:, None], y0[:, None]
    local[:, 2::4, 0], local[:, 2::4, 1] = x1[:, None], y1[:, None]
    local[:, 3::4, 0], local[:, 3::4, 1] = x0[:, None], y1[:, None]
    ox, oy, yaw = origin
    vertices = np.empty((count, 8, 3))
    if yaw == 0.0:
        vertices[:, :, 0] = local[:, :, 0] + ox
        vertices[:, :, 1] = local[:, :, 1] + oy
    else:
        c, s = math.cos(yaw), math.sin(yaw)
        vertices[:, :, 0] = ox + c * local[:, :, 0] - s * local[:, :, 1]
        vertices[:, :, 1] = oy + s * local[:, :, 0] + c * local[:, :, 1]
    vertices[:, :4, 2] = 0.0
    vertices[:, 4:, 2] = height
    indices = (np.arange(count, dtype=np.int32)[:, None, None] * 8 + _BOX_TRIANGLES[None]).reshape(-1, 3)
    return vertices.reshape(-1, 3), indices.astype(np.int32, copy=False)


# ------------------------------------------------------------------------------------------- benchmark


def synthetic_map(path, size=4000, seed=0, room=200, wall=10, door=40, noise=0.02, resolution=0.05):
    """Write a realistic large test map: a grid of rooms with doors, plus speckle noise (for benchmarks).

    Args:
        path: the YAML file to write; the P5 PGM goes beside it with the same stem.
        size: width and height in cells.
        room: wall spacing in cells; ``wall``: wall thickness; ``door``: door width, one door per wall
            segment between two crossings.
        noise: fraction of pixels set occupied at random (stray obstacles of a SLAM map).

    Returns:
        ``path``.
    """
    rng = np.random.default_rng(seed)
    occupied = np.zeros((size, size), dtype=bool)
    for at in range(0, size, room):
        occupied[at:at + wall, :] = True
        occupied[:, at:at + wall] = True
    occupied[size - wall:, :] = True
    occupied[:, size - wall:] = True
    for at in range(0, size, room):  # a door in the middle of every wall segment
        for mid in range(room // 2, size, room):
            occupied[at:at + wall, mid - door // 2:mid + door // 2] = False
            occupied[mid - door // 2:mid + door // 2, at:at + wall] = False
    occupied |= rng.random((size, size)) < noise
    half = size * resolution / 2.0
    return write_map(path, occupied, resolution, (-half, -half),
                     f"synthetic_map(size={size}, seed={seed}, room={room}, wall={wall}, door={door}, noise={noise})")


def write_map(path, occupied, resolution, origin, comment):
    """Write a map_server map as map_saver does: ``path`` (.yaml) and its trinary .pgm beside it, 0 where
    ``occupied`` (a (rows, cols) bool array, row 0 the image's top), 254 elsewhere; ``origin`` (x, y) [m] of the
    image's bottom-left corner; ``comment`` in both files' headers. Returns ``path``."""
    rows, cols = occupied.shape
    image = os.path.splitext(path)[0] + ".pgm"
    with open(image, "wb") as stream:
        stream.write(b"P5\n# %s\n%d %d\n255\n" % (comment.encode(), cols, rows))
        stream.write(np.where(occupied, 0, 254).astype(np.uint8).tobytes())
    with open(path, "w", encoding="utf-8") as stream:
        stream.write(f"# {comment}\n")
        stream.write(f"image: {os.path.basename(image)}\nresolution: {resolution}\n"
                     f"origin: [{origin[0]}, {origin[1]}, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return path
