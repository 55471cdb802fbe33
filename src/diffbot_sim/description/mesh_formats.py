"""Mesh files read the way Gazebo classic reads them (pure; numpy): binary and ASCII STL, Wavefront OBJ and
COLLADA (units, node transforms, ``<up_axis>`` ignored as Gazebo does unless asked), and written back as
.obj in metres. :mod:`diffbot_sim.description.meshes` caches the results and rewrites model files to them;
why and what Gazebo does is told there.
"""
import math
import os
import re
import xml.etree.ElementTree as ET

import numpy as np

from diffbot_sim.description import xml_documents
from diffbot_sim.errors import ModelError

#: Binary STL: an 80-byte header, a little-endian uint32 triangle count, then 50-byte records.
_STL_RECORD = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])
_STL_HEADER = 84

#: Deepest COLLADA node nesting followed; deeper means an ``<instance_node>`` cycle.
_MAX_NODE_DEPTH = 64

_UP_AXIS_ROTATIONS = {
    "Z_UP": np.eye(3),
    "Y_UP": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),  # y -> z
    "X_UP": np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]),  # x -> z
}


# ------------------------------------------------------------------------------------------------ readers

def read_mesh(path, honour_up_axis=False):
    """Read an .stl, .obj or .dae file (chosen by extension, case-insensitive) -> (vertices, faces).

    Raises:
        ModelError: unknown extension, unreadable or malformed file, or a mesh without triangles.
    """
    ext = os.path.splitext(path)[1].lower()
    if ext == ".stl":
        return read_stl(path)
    if ext == ".obj":
        return read_obj(path)
    if ext == ".dae":
        return read_dae(path, honour_up_axis=honour_up_axis)
    raise ModelError(f"mesh format '{ext or '(no extension)'}' is not supported (.stl, .obj and .dae are)", path)


def _read_bytes(path):
    try:
        with open(path, "rb") as handle:
            return handle.read()
    except OSError as err:
        raise ModelError(f"cannot read ({err.strerror or err})", path) from None


def _checked(vertices, faces, path):
    """Common exit of every reader: float64 Nx3, int64 Mx3, finite, indices in range, not empty."""
    vertices = np.ascontiguousarray(vertices, dtype=np.float64).reshape(-1, 3)
    faces = np.ascontiguousarray(faces, dtype=np.int64).reshape(-1, 3)
    if len(faces) == 0:
        raise ModelError("has no triangles", path)
    if not np.isfinite(vertices).all():
        raise ModelError("has vertex coordinates that are not finite numbers", path)
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise ModelError(f"a face refers to a vertex that does not exist ({len(vertices)} vertices)", path)
    return vertices, faces


def _weld(corners):
    """(3M)x3 triangle corners -> (unique vertices, Mx3 faces). STL stores every corner again; sharing
    them makes the .obj about 4x smaller and PyBullet's hull build faster, for ~20 ms per 2 MB."""
    order = np.lexsort((corners[:, 2], corners[:, 1], corners[:, 0]))
    ordered = corners[order]
    new = np.ones(len(ordered), dtype=bool)
    new[1:] = np.any(ordered[1:] != ordered[:-1], axis=1)
    index = np.empty(len(ordered), dtype=np.int64)
    index[order] = np.cumsum(new) - 1
    return ordered[new], index.reshape(-1, 3)


def read_stl(path):
    """Read a binary or ASCII STL -> (vertices [m] float64 Nx3, faces int64 Mx3).

    Binary is recognised by size (84 + 50 * count bytes), not by the "solid" prefix, because SolidWorks
    and others write binary files whose header starts with "solid". STL has no unit: numbers are metres.

    Raises:
        ModelError: unreadable, truncated, or not STL (message names the file).
    """
    data = _read_bytes(path)
    count = int(np.frombuffer(data, "<u4", count=1, offset=80)[0]) if len(data) >= _STL_HEADER else -1
    ascii_like = data.lstrip()[:5].lower() == b"solid" and b"facet" in data[:4096]
    if count >= 0 and len(data) == _STL_HEADER + 50 * count and not (count == 0 and ascii_like):
        records = np.frombuffer(data, _STL_RECORD, count=count, offset=_STL_HEADER)
        corners = records["vertices"].reshape(-1, 3).astype(np.float64)
    elif ascii_like:
        corners = _read_ascii_stl(data, path)
    elif count >= 0 and len(data) > _STL_HEADER + 50 * count:
        # Some exporters pad binary files; the records the count announces are all there.
        records = np.frombuffer(data, _STL_RECORD, count=count, offset=_STL_HEADER)
        corners = records["vertices"].reshape(-1, 3).astype(np.float64)
    elif count >= 0 and not data.lstrip().lower().startswith(b"solid"):
        raise ModelError(f"binary STL is truncated: header announces {count} triangles "
                         f"({_STL_HEADER + 50 * count} bytes), the file has {len(data)} bytes", path)
    else:
        raise ModelError("is not an STL file (neither binary nor ASCII 'solid ... facet')", path)
    if len(corners) == 0:
        raise ModelError("has no triangles", path)
    vertices, faces = _weld(corners)
    return _checked(vertices, faces, path)


_ASCII_VERTEX = re.compile(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)", re.IGNORECASE)


def _read_ascii_stl(data, path):
    found = _ASCII_VERTEX.findall(data)
    if len(found) % 3:
        raise ModelError(f"ASCII STL has {len(found)} vertex lines, not a multiple of 3", path)
    try:
        return np.array(found, dtype=np.bytes_).astype(np.float64)
    except ValueError as err:
        raise ModelError(f"ASCII STL has a vertex that is not three numbers ({err})", path) from None


def read_obj(path):
    """Read a Wavefront .obj -> (vertices [m] float64 Nx3, faces int64 Mx3).

    Only ``v`` and ``f`` lines matter for a shape: ``f`` entries may be ``i``, ``i/t``, ``i//n`` or
    ``i/t/n``, negative (relative) indices are resolved, and polygons are split into triangle fans.
    Materials, groups, normals and texture coordinates are dropped. OBJ has no unit: numbers are metres.

    Raises:
        ModelError: unreadable file, or a malformed ``v``/``f`` line (message names the line number).
    """
    text = _read_bytes(path).decode("utf-8", errors="replace")
    coordinates = []
    faces = []
    for number, line in enumerate(text.splitlines(), start=1):
        if line.startswith("v "):
            parts = line.split()
            try:
                coordinates.append((float(parts[1]), float(parts[2]), float(parts[3])))
            except (ValueError, IndexError):
                raise ModelError("vertex is not three numbers", path, f"line {number}") from None
        elif line.startswith("f "):
            try:
                corners = [int(item.split("/", 1)[0]) for item in line.split()[1:]]
            except ValueError:
                raise ModelError("face has an index that is not an integer", path, f"line {number}") from None
            if len(corners) < 3:
                raise ModelError("face has fewer than 3 vertices", path, f"line {number}")
            known = len(coordinates)
            corners = [c - 1 if c > 0 else known + c for c in corners]  # -1 is the latest vertex
            faces.extend((corners[0], corners[i], corners[i + 1]) for i in range(1, len(corners) - 1))
    vertices = np.array(coordinates, dtype=np.float64).reshape(-1, 3)
    return _checked(vertices, np.array(faces, dtype=np.int64).reshape(-1, 3), path)


# ------------------------------------------------------------------------------------------------ COLLADA

def _local(tag):
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else tag


def _numbers(element, dtype, path, where):
    text = element.text or ""
    try:
        return np.array(text.split(), dtype=dtype)
    except ValueError:
        raise ModelError(f"<{_local(element.tag)}> holds something that is not a number", path, where) from None


def _axis_angle(axis, degrees):
    """Rotation matrix for ``degrees`` about ``axis`` (COLLADA <rotate> is in degrees)."""
    norm = np.linalg.norm(axis)
    if norm == 0.0:
        return np.eye(3)
    x, y, z = axis / norm
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    t = 1.0 - c
    return np.array([[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
                     [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
                     [t * x * z - s * y, t * y * z + s * x, t * z * z + c]])


class _Collada:
    """One parsed COLLADA document: ids, unit, up axis, and the triangles its visual scene instantiates."""

    def __init__(self, path):
        self.path = path
        try:
            root = xml_documents.parse(_read_bytes(path))  # a blank line before <?xml is fine, as in Gazebo
        except ET.ParseError as err:
            raise ModelError(f"malformed XML ({err})", path) from None
        for element in root.iter():
            element.tag = _local(element.tag)  # COLLADA 1.4 and 1.5 differ only in namespace here
        if root.tag != "COLLADA":
            raise ModelError(f"root element is <{root.tag}>, expected <COLLADA>", path, f"/{root.tag}")
        self.root = root
        self.ids = {element.get("id"): element for element in root.iter() if element.get("id")}
        self.meter = 1.0
        self.up_axis = "Y_UP"  # the COLLADA default when <up_axis> is absent
        asset = root.find("asset")
        if asset is not None:
            unit = asset.find("unit")
            if unit is not None and unit.get("meter") is not None:
                try:
                    self.meter = float(unit.get("meter"))
                except ValueError:
                    raise ModelError(f"meter='{unit.get('meter')}' is not a number", path,
                                     "/COLLADA/asset/unit[@meter]") from None
                if not (math.isfinite(self.meter) and self.meter > 0.0):
                    raise ModelError(f"meter='{unit.get('meter')}' must be > 0", path, "/COLLADA/asset/unit[@meter]")
            up = asset.find("up_axis")
            if up is not None and (up.text or "").strip():
                self.up_axis = up.text.strip().upper()
        self.vertex_blocks = []
        self.face_blocks = []
        self.count = 0

    def ref(self, url, tag, where):
        """The element a ``#id`` URL names; must be a ``<tag>``."""
        target = self.ids.get((url or "").lstrip("#"))
        if target is None or target.tag != tag:
            raise ModelError(f"refers to <{tag}> '{url}', which the file does not have", self.path, where)
        return target

    def load(self):
        scene = self.root.find("scene/instance_visual_scene")
        if scene is not None:
            visual_scene = self.ref(scene.get("url"), "visual_scene", "/COLLADA/scene/instance_visual_scene")
        else:
            visual_scene = self.root.find("library_visual_scenes/visual_scene")
        if visual_scene is not None:
            for node in visual_scene.findall("node"):
                self.node(node, np.eye(4), "/COLLADA/library_visual_scenes/visual_scene/node", 0)
        else:
            # No scene at all (Gazebo would crash on this): take every geometry as it stands.
            for geometry in self.root.iterfind("library_geometries/geometry"):
                self.geometry(geometry, np.eye(4))
        if not self.face_blocks:
            raise ModelError("has no triangles in its visual scene (lines, skins and splines are not read)",
                             self.path)
        vertices = np.concatenate(self.vertex_blocks) * self.meter
        return vertices, np.concatenate(self.face_blocks)

    def transform(self, node, where):
        """The node's local 4x4 transform: its transform elements composed in document order."""
        matrix = np.eye(4)
        for child in node:
            tag = child.tag
            if tag not in ("matrix", "translate", "rotate", "scale"):
                continue
            values = _numbers(child, np.float64, self.path, f"{where}/{tag}")
            size = {"matrix": 16, "translate": 3, "rotate": 4, "scale": 3}[tag]
            if len(values) != size:
                raise ModelError(f"<{tag}> has {len(values)} numbers, expected {size}", self.path, f"{where}/{tag}")
            local = np.eye(4)
            if tag == "matrix":
                local = values.reshape(4, 4)  # row-major, translation in the last column
            elif tag == "translate":
                local[:3, 3] = values
            elif tag == "rotate":
                local[:3, :3] = _axis_angle(values[:3], values[3])
            else:
                local[:3, :3] = np.diag(values)
            matrix = matrix @ local
        return matrix

    def node(self, node, parent, where, depth):
        if depth > _MAX_NODE_DEPTH:
            raise ModelError(f"nodes nest deeper than {_MAX_NODE_DEPTH} (an <instance_node> cycle?)", self.path, where)
        if node.get("id"):
            where = f"{where}[@id='{node.get('id')}']"
        matrix = parent @ self.transform(node, where)
        for child in node:
            if child.tag == "node":
                self.node(child, matrix, f"{where}/node", depth + 1)
            elif child.tag == "instance_node":
                target = self.ref(child.get("url"), "node", f"{where}/instance_node")
                self.node(target, matrix, "/COLLADA/library_nodes/node", depth + 1)
            elif child.tag == "instance_geometry":
                self.geometry(self.ref(child.get("url"), "geometry", f"{where}/instance_geometry"), matrix)

    def geometry(self, geometry, matrix):
        where = f"/COLLADA/library_geometries/geometry[@id='{geometry.get('id')}']"
        mesh = geometry.find("mesh")
        if mesh is None:
            return  # <convex_mesh>, <spline>, <brep>: no triangles Gazebo would read either
        for index, primitive in enumerate(mesh):
            if primitive.tag in ("triangles", "polylist", "polygons", "trifans", "tristrips"):
                self.primitive(primitive, mesh, matrix, f"{where}/mesh/{primitive.tag}[{index + 1}]")

    def positions(self, mesh, source_url, where):
        """Positions [file units] an ``<input semantic="VERTEX">`` refers to, via ``<vertices>``."""
        vertices = self.ref(source_url, "vertices", where)
        position = next((i for i in vertices.findall("input") if i.get("semantic") == "POSITION"), None)
        if position is None:
            raise ModelError("<vertices> has no POSITION input", self.path, where)
        source = self.ref(position.get("source"), "source", where)
        array = source.find("float_array")
        if array is None:
            raise ModelError(f"<source id='{source.get('id')}'> has no <float_array>", self.path, where)
        values = _numbers(array, np.float64, self.path, f"{where}/float_array")
        accessor = source.find("technique_common/accessor")
        stride = int(accessor.get("stride", 3)) if accessor is not None else 3
        offset = int(accessor.get("offset", 0)) if accessor is not None else 0
        if stride < 3 or len(values) < offset + 3:
            return np.zeros((0, 3))
        count = (len(values) - offset) // stride
        return values[offset:offset + count * stride].reshape(count, stride)[:, :3]

    def primitive(self, primitive, mesh, matrix, where):
        inputs = primitive.findall("input")
        vertex_input = next((i for i in inputs if i.get("semantic") == "VERTEX"), None)
        if vertex_input is None:
            raise ModelError("has no VERTEX input", self.path, where)
        stride = max(int(i.get("offset", 0)) for i in inputs) + 1
        column = int(vertex_input.get("offset", 0))
        positions = self.positions(mesh, vertex_input.get("source"), where)
        kind = primitive.tag
        blocks = primitive.findall("p")
        if kind in ("triangles", "polylist"):
            if not blocks:
                return
            index = _numbers(blocks[0], np.int64, self.path, f"{where}/p")
            index = index[:len(index) // stride * stride].reshape(-1, stride)[:, column]
            if kind == "triangles":
                triangles = index[:len(index) // 3 * 3].reshape(-1, 3)
            else:
                vcount_el = primitive.find("vcount")
                if vcount_el is None:
                    raise ModelError("has no <vcount>", self.path, where)
                counts = _numbers(vcount_el, np.int64, self.path, f"{where}/vcount")
                if counts.sum() != len(index) or (counts < 0).any():
                    raise ModelError(f"<vcount> adds up to {counts.sum()} vertices, <p> has {len(index)}",
                                     self.path, where)
                triangles = _fans(index, counts)
        else:  # polygons, trifans, tristrips: one <p> per polygon, fan or strip
            parts = []
            for block in blocks:
                index = _numbers(block, np.int64, self.path, f"{where}/p")
                index = index[:len(index) // stride * stride].reshape(-1, stride)[:, column]
                if len(index) < 3:
                    continue
                if kind == "tristrips":
                    strip = np.stack([index[:-2], index[1:-1], index[2:]], axis=1)
                    strip[1::2] = strip[1::2][:, [1, 0, 2]]  # every other strip triangle is wound backwards
                    parts.append(strip)
                else:
                    parts.append(_fans(index, np.array([len(index)])))
            triangles = np.concatenate(parts) if parts else np.zeros((0, 3), dtype=np.int64)
        if len(triangles) == 0:
            return
        if triangles.min() < 0 or triangles.max() >= len(positions):
            raise ModelError(f"<p> refers to vertex {triangles.max()}, the source has {len(positions)}",
                             self.path, where)
        used, local = np.unique(triangles, return_inverse=True)
        points = positions[used] @ matrix[:3, :3].T + matrix[:3, 3]
        faces = local.reshape(-1, 3)
        if np.linalg.det(matrix[:3, :3]) < 0:
            faces = faces[:, [0, 2, 1]]  # a mirroring transform turns faces inside out; keep them outward
        self.face_blocks.append(faces + self.count)
        self.vertex_blocks.append(points)
        self.count += len(points)


def _fans(index, counts):
    """Split polygons (``counts`` corners each, listed one after another in ``index``) into triangle fans;
    a polygon with fewer than 3 corners gives none but still uses its place in ``index``."""
    starts = np.concatenate(([0], np.cumsum(counts)[:-1])).astype(np.int64)
    per_polygon = np.maximum(counts - 2, 0)
    first = np.repeat(starts, per_polygon)
    # the i-th triangle of a polygon uses its corners 0, i + 1 and i + 2
    step = np.arange(per_polygon.sum()) - np.repeat(np.cumsum(per_polygon) - per_polygon, per_polygon)
    return np.stack([index[first], index[first + step + 1], index[first + step + 2]], axis=1)


def read_dae(path, honour_up_axis=False):
    """Read a COLLADA .dae -> (vertices [m] float64 Nx3, faces int64 Mx3), as Gazebo classic does.

    Walks the visual scene: nodes (nested, and ``<instance_node>``), their ``<matrix>``/``<translate>``/
    ``<rotate>``/``<scale>`` in document order, and every ``<instance_geometry>``; reads ``<triangles>``,
    ``<polylist>``, ``<polygons>`` (fans; ``<ph>`` holes ignored), ``<trifans>`` and ``<tristrips>``
    through their ``<input offset>``s. Vertices are then multiplied by ``<unit meter>``.

    Args:
        honour_up_axis: rotate a Y_UP or X_UP file so its up axis becomes z. Off by default because
            Gazebo classic (and RViz) ignore ``<up_axis>``, and ROS robot meshes are drawn for them.

    Raises:
        ModelError: unreadable or malformed file, a dangling ``#id`` reference, or no triangles at all.
    """
    document = _Collada(path)
    vertices, faces = document.load()
    if honour_up_axis:
        rotation = _UP_AXIS_ROTATIONS.get(document.up_axis)
        if rotation is None:
            raise ModelError(f"up_axis '{document.up_axis}' is not X_UP, Y_UP or Z_UP", path, "/COLLADA/asset/up_axis")
        vertices = vertices @ rotation.T
    return _checked(vertices, faces, path)


def dae_up_axis(path):
    """The ``<up_axis>`` a .dae declares (None when absent or unreadable); cheap: reads only the head."""
    try:
        with open(path, "rb") as handle:
            head = handle.read(8192)
    except OSError:
        return None
    found = re.search(rb"<up_axis>\s*(\w+)\s*</up_axis>", head)
    return found.group(1).decode("ascii", "replace").upper() if found else None


# ------------------------------------------------------------------------------------------------ writing

def write_obj(path, vertices, faces, comment=""):
    """Write an .obj: ``v`` lines with 9 significant digits (float32 sources lose nothing), 1-based ``f``.

    One %-format over the whole array runs in C: ~3x faster than ``numpy.savetxt`` (measured 64 ms against
    157 ms for 120 000 vertices).
    """
    head = "".join(f"# {line}\n" for line in comment.splitlines())
    body = ("v %.9g %.9g %.9g\n" * len(vertices)) % tuple(vertices.ravel().tolist())
    body += ("f %d %d %d\n" * len(faces)) % tuple((faces + 1).ravel().tolist())
    with open(path, "w", encoding="ascii") as out:
        out.write(head)
        out.write(body)
