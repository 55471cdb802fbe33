"""A world's static geometry as rviz markers (pure: plain data, no rospy, no message classes).

Gazebo draws the world in its own window; a headless simulator has none, so rviz must draw it. Each static
collision shape of a :class:`diffbot_sim.world.bodies.WorldDescription` becomes one :class:`MarkerSpec` posed in
the world frame, which :func:`diffbot_sim.messages.markers.marker_array` turns into a
``visualization_msgs/MarkerArray``. Collision shapes, not visuals: the reader keeps no visuals, and the
collision geometry is what the robot and its sensors meet, so it is what a user checks against a scan.

Left out, each for a reason: planes (infinite; rviz's grid already shows the ground), dynamic bodies (they
move when pushed, and a marker drawn at their start pose would show a box where there is none).
"""
from dataclasses import dataclass, field

import numpy as np

from diffbot_sim.transforms import compose

#: Colour of shapes whose world gives none (rviz rgba, 0..1): light grey, visible on rviz's dark background.
DEFAULT_COLOR = (0.7, 0.7, 0.72, 1.0)
#: Marker kinds, named as visualization_msgs/Marker's type constants.
CUBE, SPHERE, CYLINDER, MESH_RESOURCE, TRIANGLE_LIST = "CUBE", "SPHERE", "CYLINDER", "MESH_RESOURCE", "TRIANGLE_LIST"
#: Triangles of map walls (``trimesh`` shapes) per marker: rviz builds each marker as one vertex buffer, and
#: 100 000 triangles keep each marker's points under 4 MB.
TRIANGLES_PER_MARKER = 100_000
#: Triangles drawn per world at most. Building and sending geometry_msgs/Point objects costs ~1 us each in
#: Python: 500 000 triangles (a large clean floor plan has ~15 000) take about 2 s. A speckled SLAM map can
#: have millions; the rest is left out, with one warning (:func:`marker_specs`'s ``warnings``).
MAX_TRIANGLES = 500_000


@dataclass
class MarkerSpec:
    """One marker: ``kind`` (see the constants), ``pose`` ((x, y, z), (qx, qy, qz, qw)) in the world frame,
    ``scale`` (m; for a mesh, the mesh's own scale factors), ``color`` rgba 0..1, ``ns`` (the body's name,
    so rviz lists one namespace per body), ``mesh`` (a ``file://`` URI for MESH_RESOURCE), ``points``
    (TRIANGLE_LIST: (N, 3) m, three rows per triangle, in the marker's pose frame)."""

    kind: str
    pose: tuple[tuple[float, float, float], tuple[float, float, float, float]]
    scale: tuple[float, float, float]
    color: tuple[float, float, float, float]
    ns: str
    mesh: str | None = None
    points: object = field(default_factory=list)  # (N, 3) array or [(x, y, z)]


def marker_specs(world, warnings=None, max_triangles=MAX_TRIANGLES):
    """Every static shape of ``world`` as :class:`MarkerSpec` (world frame).

    Args:
        world: a :class:`diffbot_sim.world.bodies.WorldDescription`.
        warnings: a list that gets one line per thing left out (triangles past ``max_triangles``).
        max_triangles: map-wall triangles drawn at most (see MAX_TRIANGLES).

    Returns:
        list of MarkerSpec, in body order then shape order.
    """
    out = []
    budget = [max_triangles]
    for body in world.bodies:
        if not body.static:
            continue
        color = tuple(body.color) if body.color is not None else DEFAULT_COLOR
        for shape in body.shapes:
            pose = compose(body.pose, shape.pose)
            out.extend(_shape_specs(shape, pose, color, body.name, budget, warnings))
    return out


def _shape_specs(shape, pose, color, ns, budget, warnings):
    kind = shape.kind
    if kind == "box":
        return [MarkerSpec(CUBE, pose, tuple(float(s) for s in shape.size[:3]), color, ns)]
    if kind == "cylinder":
        radius, length = float(shape.size[0]), float(shape.size[1])
        return [MarkerSpec(CYLINDER, pose, (2 * radius, 2 * radius, length), color, ns)]
    if kind == "sphere":
        d = 2 * float(shape.size[0])
        return [MarkerSpec(SPHERE, pose, (d, d, d), color, ns)]
    if kind == "mesh" and shape.mesh:
        return [MarkerSpec(MESH_RESOURCE, pose, tuple(float(s) for s in shape.scale), color, ns,
                           mesh="file://" + shape.mesh)]
    if kind == "trimesh" and shape.vertices is not None and shape.indices is not None:
        return _trimesh_specs(shape, pose, color, ns, budget, warnings)
    return []  # plane: infinite (the grid shows the ground); anything else has no marker form


def _trimesh_specs(shape, pose, color, ns, budget, warnings):
    """A map's walls (vertices + triangle indices) as TRIANGLE_LIST markers of at most
    TRIANGLES_PER_MARKER triangles each; ``points`` is then an (N, 3) float array."""
    vertices = np.asarray(shape.vertices, dtype=float).reshape(-1, 3)
    triangles = np.asarray(shape.indices, dtype=int).reshape(-1, 3)
    if len(triangles) > budget[0]:
        if warnings is not None:
            warnings.append(f"{ns}: {len(triangles)} wall triangles, {budget[0]} drawn (the markers' limit, "
                            f"MAX_TRIANGLES); the simulation has them all")
        triangles = triangles[:budget[0]]
    budget[0] -= len(triangles)
    out = []
    for start in range(0, len(triangles), TRIANGLES_PER_MARKER):
        points = vertices[triangles[start:start + TRIANGLES_PER_MARKER].reshape(-1)]
        out.append(MarkerSpec(TRIANGLE_LIST, pose, (1.0, 1.0, 1.0), color, ns, points=points))
    return out


def bounds_xy(specs):
    """The x, y extent of ``specs`` in the world frame, ``(xmin, ymin, xmax, ymax)`` m, or None when there
    are none: what the rviz view is fitted to. A shape counts by the corners of its bounding box as posed
    (a cylinder's or sphere's box holds it); a triangle list by the corners of its points' box; a mesh, whose
    size is unknown here, by its origin."""
    xs, ys = [], []
    for spec in specs:
        if spec.kind == TRIANGLE_LIST:
            if not len(spec.points):
                continue
            lo, hi = np.min(spec.points, axis=0), np.max(spec.points, axis=0)
        elif spec.kind == MESH_RESOURCE:
            lo = hi = np.zeros(3)
        else:
            hi = 0.5 * np.asarray(spec.scale, dtype=float)
            lo = -hi
        for cx in (lo[0], hi[0]):
            for cy in (lo[1], hi[1]):
                for cz in (lo[2], hi[2]):
                    (px, py, _), _ = compose(spec.pose, ((float(cx), float(cy), float(cz)), (0.0, 0.0, 0.0, 1.0)))
                    xs.append(px)
                    ys.append(py)
    if not xs:
        return None
    return (min(xs), min(ys), max(xs), max(ys))
