"""meshes.py: STL/OBJ/COLLADA read as Gazebo classic reads them, the .obj cache, URDF rewriting and the
published mistakes it survives; then the result loaded into PyBullet DIRECT with the right size.

Every mesh file here is generated in tmp_path; expected coordinates are worked out by hand in comments.
"""
import os
import time
import xml.etree.ElementTree as ET

import numpy as np
import pybullet
import pytest

from diffbot_sim.description import mesh_formats, meshes
from diffbot_sim.errors import ModelError

# A box 1000 x 1000 x 500 (mm), centred on the origin: 8 corners, 12 outward-wound triangles.
BOX_HALF = (500.0, 500.0, 250.0)
BOX_FACES = [(0, 3, 2), (0, 1, 3), (4, 7, 5), (4, 6, 7), (0, 5, 1), (0, 4, 5),
             (2, 7, 6), (2, 3, 7), (0, 6, 4), (0, 2, 6), (1, 7, 3), (1, 5, 7)]


def box_corners(half=BOX_HALF):
    """Corner i has x = +half if bit 2 of i, y if bit 1, z if bit 0 (else -half)."""
    hx, hy, hz = half
    return np.array([[sx * hx, sy * hy, sz * hz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])


def write_binary_stl(path, triangles, header=b"binary box"):
    record = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])
    data = np.zeros(len(triangles), record)
    data["vertices"] = triangles
    with open(path, "wb") as out:
        out.write(header.ljust(80, b" ") + np.uint32(len(triangles)).tobytes() + data.tobytes())
    return str(path)


def write_ascii_stl(path, triangles):
    lines = ["solid box"]
    for triangle in triangles:
        lines += ["  facet normal 0 0 0", "    outer loop"]
        lines += [f"      vertex {x:e} {y:e} {z:e}" for x, y, z in triangle]
        lines += ["    endloop", "  endfacet"]
    path.write_text("\n".join(lines + ["endsolid box", ""]))
    return str(path)


def box_triangles(half=BOX_HALF):
    return box_corners(half)[np.array(BOX_FACES)]


def triangles_of(vertices, faces):
    """Sorted set of triangles as tuples of rounded points: compares meshes regardless of vertex order."""
    return sorted(tuple(sorted(tuple(np.round(p, 9)) for p in vertices[f])) for f in faces)


# -------------------------------------------------------------------------------------------------- COLLADA

def dae_text(unit="0.001", up="Y_UP", matrix="0 -1 0 10  1 0 0 20  0 0 1 30  0 0 0 1", namespace=True):
    """Two geometries, both in mm:

    * ``block``: the box 0..200 x 0..100 x 0..50 as 6 quads in a <polylist> (VERTEX offset 0, NORMAL
      offset 1, so <p> holds pairs), instanced by node ``parent`` with the 4x4 ``matrix`` (row-major;
      default: rotate +90 deg about z, then translate (10, 20, 30)).
    * ``tri``: one <triangles> triangle (0,0,0) (10,0,0) (0,10,0), instanced by node ``child`` inside
      ``parent`` with <translate>0 0 100</translate><rotate>1 0 0 180</rotate><scale>2 2 2</scale>.
    """
    xmlns = ' xmlns="http://www.collada.org/2005/11/COLLADASchema"' if namespace else ""
    block = " ".join(f"{x} {y} {z}" for x in (0, 200) for y in (0, 100) for z in (0, 50))
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    p_block = " ".join(f"{v} {q}" for q, quad in enumerate(quads) for v in quad)
    asset = ""
    if unit is not None or up is not None:
        asset = "<asset>" + (f'<unit meter="{unit}" name="millimetre"/>' if unit else "") \
                + (f"<up_axis>{up}</up_axis>" if up else "") + "</asset>"
    return f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA{xmlns} version="1.4.1">
  {asset}
  <library_geometries>
    <geometry id="block" name="block"><mesh>
      <source id="block-pos"><float_array id="block-pos-array" count="24">{block}</float_array>
        <technique_common><accessor source="#block-pos-array" count="8" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common></source>
      <source id="block-nrm">
        <float_array id="block-nrm-array" count="18">-1 0 0 1 0 0 0 -1 0 0 1 0 0 0 -1 0 0 1</float_array>
        <technique_common><accessor source="#block-nrm-array" count="6" stride="3"/></technique_common></source>
      <vertices id="block-vtx"><input semantic="POSITION" source="#block-pos"/></vertices>
      <polylist count="6">
        <input semantic="VERTEX" source="#block-vtx" offset="0"/>
        <input semantic="NORMAL" source="#block-nrm" offset="1"/>
        <vcount>4 4 4 4 4 4</vcount>
        <p>{p_block}</p>
      </polylist>
    </mesh></geometry>
    <geometry id="tri" name="tri"><mesh>
      <source id="tri-pos"><float_array id="tri-pos-array" count="9">0 0 0 10 0 0 0 10 0</float_array>
        <technique_common><accessor source="#tri-pos-array" count="3" stride="3"/></technique_common></source>
      <vertices id="tri-vtx"><input semantic="POSITION" source="#tri-pos"/></vertices>
      <triangles count="1"><input semantic="VERTEX" source="#tri-vtx" offset="0"/><p>0 1 2</p></triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="Scene">
      <node id="parent" name="parent">
        <matrix>{matrix}</matrix>
        <instance_geometry url="#block"/>
        <node id="child" name="child">
          <translate>0 0 100</translate><rotate>1 0 0 180</rotate><scale>2 2 2</scale>
          <instance_geometry url="#tri"/>
        </node>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
"""


def write_dae(path, **kwargs):
    path.write_text(dae_text(**kwargs))
    return str(path)


def block_expected_mm():
    """The block's corners after the parent matrix: (x, y, z) -> (-y + 10, x + 20, z + 30)."""
    return [(-y + 10, x + 20, z + 30) for x in (0, 200) for y in (0, 100) for z in (0, 50)]


def tri_expected_mm():
    """child (translate 0 0 100, rotate 180 about x, scale 2): (x, y, z) -> (2x, -2y, 100 - 2z); then the
    parent matrix: (0,0,0) -> (0,0,100) -> (10, 20, 130); (10,0,0) -> (20,0,100) -> (10, 40, 130);
    (0,10,0) -> (0,-20,100) -> (30, 20, 130)."""
    return [(10, 20, 130), (10, 40, 130), (30, 20, 130)]


def test_read_dae_applies_unit_and_node_transforms_and_ignores_up_axis(tmp_path):
    vertices, faces = mesh_formats.read_dae(write_dae(tmp_path / "m.dae"))
    expected = np.array(block_expected_mm() + tri_expected_mm()) * 0.001
    assert sorted(map(tuple, np.round(vertices, 9))) == sorted(map(tuple, np.round(expected, 9)))
    assert len(faces) == 6 * 2 + 1  # 6 quads fanned into 2 triangles each, plus the triangle
    # Corner (200, 100, 50) mm -> (-90, 220, 80) mm -> metres.
    assert np.isclose(vertices, [-0.09, 0.22, 0.08]).all(axis=1).any()
    assert np.allclose(vertices.min(axis=0), [-0.09, 0.02, 0.03])
    assert np.allclose(vertices.max(axis=0), [0.03, 0.22, 0.13])


def test_read_dae_can_honour_y_up_and_x_up(tmp_path):
    base, _ = mesh_formats.read_dae(write_dae(tmp_path / "m.dae"))
    y_up, _ = mesh_formats.read_dae(str(tmp_path / "m.dae"), honour_up_axis=True)
    # Y_UP: (x, y, z) -> (x, -z, y): (-0.09, 0.22, 0.08) -> (-0.09, -0.08, 0.22)
    assert np.allclose(y_up, base[:, [0, 2, 1]] * [1, -1, 1])
    assert np.isclose(y_up, [-0.09, -0.08, 0.22]).all(axis=1).any()
    x_up, _ = mesh_formats.read_dae(write_dae(tmp_path / "x.dae", up="X_UP"), honour_up_axis=True)
    # X_UP: (x, y, z) -> (-z, y, x)
    assert np.allclose(x_up, np.stack([-base[:, 2], base[:, 1], base[:, 0]], axis=1))
    z_up, _ = mesh_formats.read_dae(write_dae(tmp_path / "z.dae", up="Z_UP"), honour_up_axis=True)
    assert np.allclose(z_up, base)


def test_read_dae_without_asset_or_namespace_is_metres(tmp_path):
    vertices, _ = mesh_formats.read_dae(write_dae(tmp_path / "m.dae", unit=None, up=None, namespace=False))
    assert np.isclose(vertices, [-90, 220, 80]).all(axis=1).any()


def test_read_dae_mirroring_matrix_keeps_faces_outward(tmp_path):
    mirrored = "-1 0 0 0  0 1 0 0  0 0 1 0  0 0 0 1"
    plain_v, plain_f = mesh_formats.read_dae(write_dae(tmp_path / "a.dae", matrix="1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1"))
    mirror_v, mirror_f = mesh_formats.read_dae(write_dae(tmp_path / "b.dae", matrix=mirrored))

    def volume(v, f):  # signed volume of the closed block: > 0 when faces wind outward
        a, b, c = v[f[:12, 0]], v[f[:12, 1]], v[f[:12, 2]]
        return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0

    assert volume(plain_v, plain_f) == pytest.approx(0.2 * 0.1 * 0.05)
    assert volume(mirror_v, mirror_f) == pytest.approx(0.2 * 0.1 * 0.05)


def test_read_dae_polygons_and_instance_node(tmp_path):
    text = """<COLLADA version="1.4.1"><asset><unit meter="0.01"/></asset>
      <library_geometries><geometry id="g"><mesh>
        <source id="s"><float_array count="15">0 0 0 1 0 0 1 1 0 0 1 0 0 0 1</float_array></source>
        <vertices id="v"><input semantic="POSITION" source="#s"/></vertices>
        <polygons count="2"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2 3</p><p>0 1 4</p></polygons>
      </mesh></geometry></library_geometries>
      <library_nodes><node id="lib"><translate>0 0 5</translate><instance_geometry url="#g"/></node></library_nodes>
      <library_visual_scenes><visual_scene id="vs"><node><translate>100 0 0</translate>
        <instance_node url="#lib"/></node></visual_scene></library_visual_scenes>
      <scene><instance_visual_scene url="#vs"/></scene></COLLADA>"""
    (tmp_path / "p.dae").write_text(text)
    vertices, faces = mesh_formats.read_dae(str(tmp_path / "p.dae"))
    assert len(faces) == 3  # quad -> 2 (fan) + triangle
    # (x, y, z) cm -> (x + 100, y, z + 5) cm -> m
    assert np.allclose(vertices.min(axis=0), [1.0, 0.0, 0.05])
    assert np.allclose(vertices.max(axis=0), [1.01, 0.01, 0.06])


@pytest.mark.parametrize("body, message", [
    ("<nope/>", "expected <COLLADA>"),
    ("<COLLADA><library_visual_scenes><visual_scene id='s'><node><instance_geometry url='#missing'/></node>"
     "</visual_scene></library_visual_scenes></COLLADA>", "'#missing'"),
    ("<COLLADA><asset><unit meter='mm'/></asset></COLLADA>", "not a number"),
    ("<COLLADA></COLLADA>", "no triangles"),
    ("<COLLADA><library_visual_scenes><visual_scene><node id='a'><instance_node url='#a'/></node>"
     "</visual_scene></library_visual_scenes></COLLADA>", "cycle"),
    ("<COLLADA", "malformed XML"),
])
def test_read_dae_errors_name_the_file(tmp_path, body, message):
    path = tmp_path / "bad.dae"
    path.write_text(body)
    with pytest.raises(ModelError, match=message) as info:
        mesh_formats.read_dae(str(path))
    assert str(path) in str(info.value)


# -------------------------------------------------------------------------------------------------- STL/OBJ

@pytest.mark.parametrize("writer", [write_binary_stl, write_ascii_stl])
def test_read_stl_binary_and_ascii(tmp_path, writer):
    path = writer(tmp_path / "box.stl", box_triangles())
    vertices, faces = mesh_formats.read_stl(path)
    assert vertices.dtype == np.float64 and faces.shape == (12, 3)
    assert len(vertices) == 8  # corners shared between triangles are welded
    assert triangles_of(vertices, faces) == triangles_of(box_corners(), np.array(BOX_FACES))


def test_read_stl_binary_whose_header_says_solid(tmp_path):
    """SolidWorks writes binary STL starting with "solid"; the size tells them apart."""
    path = write_binary_stl(tmp_path / "sw.stl", box_triangles(), header=b"solid part exported")
    vertices, faces = mesh_formats.read_stl(path)
    assert len(faces) == 12 and np.allclose(vertices.max(axis=0), BOX_HALF)


def test_read_stl_truncated_and_garbage(tmp_path):
    path = write_binary_stl(tmp_path / "cut.stl", box_triangles())
    with open(path, "r+b") as handle:
        handle.truncate(84 + 50 * 5)
    with pytest.raises(ModelError, match=r"truncated.*12 triangles") as info:
        mesh_formats.read_stl(path)
    assert path in str(info.value)
    (tmp_path / "tiny.stl").write_bytes(b"hello")
    with pytest.raises(ModelError, match="not an STL"):
        mesh_formats.read_stl(str(tmp_path / "tiny.stl"))


def test_read_obj_polygons_slashes_negative_indices(tmp_path):
    path = tmp_path / "m.obj"
    path.write_text("# a quad and a triangle\nmtllib x.mtl\no thing\n"
                    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
                    "f 1/1/1 2/1/1 3/1/1 4/1/1\n"
                    "v 0 0 2\nf -5//1 -4//1 -1//1\n")
    vertices, faces = mesh_formats.read_obj(str(path))
    assert vertices.shape == (5, 3) and vertices[4].tolist() == [0, 0, 2]
    assert faces.tolist() == [[0, 1, 2], [0, 2, 3], [0, 1, 4]]


def test_read_obj_errors_name_file_and_line(tmp_path):
    path = tmp_path / "bad.obj"
    path.write_text("v 0 0 0\nv 1 0\n")
    with pytest.raises(ModelError, match=r"bad.obj: line 2: vertex is not three numbers"):
        mesh_formats.read_obj(str(path))
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    with pytest.raises(ModelError, match="does not exist"):
        mesh_formats.read_obj(str(path))


def test_write_obj_round_trip(tmp_path):
    vertices, faces = box_corners() * 0.001, np.array(BOX_FACES)
    mesh_formats.write_obj(str(tmp_path / "o.obj"), vertices, faces, comment="test")
    back_v, back_f = mesh_formats.read_obj(str(tmp_path / "o.obj"))
    assert np.allclose(back_v, vertices) and (back_f == faces).all()


# -------------------------------------------------------------------------------------------------- URDF

def urdf(*links, declaration=True):
    head = '<?xml version="1.0"?>\n' if declaration else ""
    return head + '<robot name="r">\n  <!-- keep me -->\n' + "\n".join(links) + "\n</robot>\n"


def link(name, body):
    return f'  <link name="{name}">{body}</link>'


def mesh_element(kind, filename, scale="0.001 0.001 0.001", extra=""):
    scale_attr = f' scale="{scale}"' if scale is not None else ""
    return f'<{kind}><geometry><mesh filename="{filename}"{scale_attr}/>{extra}</geometry></{kind}>'


def no_packages(package):
    raise LookupError(package)


@pytest.fixture
def model(tmp_path):
    """A model directory: model/robot.urdf's meshes under model/meshes; a cache dir beside it."""
    (tmp_path / "model" / "meshes").mkdir(parents=True)
    write_binary_stl(tmp_path / "model" / "meshes" / "box.stl", box_triangles())
    return tmp_path


def prepare(text, tmp, **kwargs):
    kwargs.setdefault("resolve_package", lambda pkg: str(tmp / "model") if pkg == "my_robot" else no_packages(pkg))
    return meshes.prepare_meshes(text, "robot.urdf", str(tmp / "model"), str(tmp / "cache"), **kwargs)


def meshes_of(text):
    return [m.attrib for m in ET.fromstring(text).iter("mesh")]


@pytest.mark.parametrize("uri", ["meshes/box.stl", "package://my_robot/meshes/box.stl",
                                 "package://my_robot/urdf/../meshes/box.stl", "{abs}", "file://{abs}",
                                 "./meshes/../meshes/box.stl"])
def test_uris_resolve_to_one_cached_obj(model, uri):
    uri = uri.format(abs=model / "model" / "meshes" / "box.stl")
    text, warnings = prepare(urdf(link("base_link", mesh_element("collision", uri))), model)
    assert warnings == []
    (attrib,) = meshes_of(text)
    assert attrib["scale"] == "0.001 0.001 0.001"  # kept: PyBullet applies it
    assert os.path.dirname(attrib["filename"]) == str(model / "cache") and attrib["filename"].endswith(".obj")
    vertices, _ = mesh_formats.read_obj(attrib["filename"])
    assert np.allclose(vertices.max(axis=0), BOX_HALF)  # STL numbers as written; the URDF scale does the mm


def test_rest_of_urdf_unchanged(model):
    original = urdf(link("base_link", '<inertial><mass value="2"/></inertial>'
                         + mesh_element("visual", "meshes/box.stl")
                         + '<collision><geometry><box size="1 2 3"/></geometry></collision>'),
                    '  <gazebo reference="base_link"><mu1>0.5</mu1></gazebo>')
    text, warnings = prepare(original, model)
    assert warnings == [] and text.startswith("<?xml") and "<!-- keep me -->" in text
    before, after = ET.fromstring(original), ET.fromstring(text)
    for element in before.iter("mesh"):
        element.set("filename", "X")
    for element in after.iter("mesh"):
        element.set("filename", "X")
    assert ET.tostring(before) == ET.tostring(after)


def test_text_without_meshes_is_returned_as_is(model):
    text = urdf(link("a", "<collision><geometry><box size='1 1 1'/></geometry></collision>"))
    assert prepare(text, model) == (text, [])


def test_missing_mesh_warns_and_removes_only_that_element(model):
    text, warnings = prepare(urdf(link("base_link",
                                       mesh_element("collision", "package://my_robot/meshes/base.stl")
                                       + mesh_element("visual", "meshes/box.stl"))), model)
    looked = model / "model" / "meshes" / "base.stl"
    assert warnings == [f"link 'base_link': collision mesh 'package://my_robot/meshes/base.stl' not found "
                        f"(looked at {looked}); the link loads without that shape"]
    base = ET.fromstring(text).find("link")
    assert base.find("collision") is None and base.find("visual/geometry/mesh") is not None


@pytest.mark.parametrize("uri, words", [
    ("package://nope/meshes/base.stl", "package 'nope', which is not found"),
    ("http://example.com/base.stl", "scheme 'http://' that is not supported"),
    ("meshes/box.ply", "not supported"),
])
def test_unusable_mesh_warns_and_removes(model, uri, words):
    (model / "model" / "meshes" / "box.ply").write_text("ply\n")
    text, warnings = prepare(urdf(link("wheel", mesh_element("visual", uri))), model)
    assert len(warnings) == 1 and f"link 'wheel': visual mesh '{uri}'" in warnings[0] and words in warnings[0]
    assert ET.fromstring(text).find("link/visual") is None


def test_unreadable_mesh_warns_with_the_reason(model):
    (model / "model" / "meshes" / "broken.stl").write_bytes(b"\0" * 84 + b"\1")
    text, warnings = prepare(urdf(link("arm", mesh_element("collision", "meshes/broken.stl"))), model)
    assert len(warnings) == 1 and "is unreadable" in warnings[0] and "broken.stl" in warnings[0]
    assert ET.fromstring(text).find("link/collision") is None


def test_relative_path_without_model_dir_warns(model):
    text, warnings = meshes.prepare_meshes(urdf(link("a", mesh_element("visual", "meshes/box.stl"))),
                                           "robot_description", None, str(model / "cache"), no_packages)
    assert "relative path" in warnings[0] and ET.fromstring(text).find("link/visual") is None


def test_two_meshes_in_one_geometry_keeps_the_first(model):
    second = '<mesh filename="meshes/other.stl" scale=""/>'
    text, warnings = prepare(urdf(link("base_link", mesh_element("collision", "meshes/box.stl", extra=second))),
                             model)
    assert len(warnings) == 1 and "more than one shape" in warnings[0] and "meshes/other.stl" in warnings[0]
    (attrib,) = meshes_of(text)
    assert attrib["filename"].endswith(".obj") and attrib["scale"] == "0.001 0.001 0.001"


@pytest.mark.parametrize("scale, written, words", [
    ("", "1.0 1.0 1.0", "scale='' is empty"),
    ("0.001", "0.001 0.001 0.001", "one number"),
    ("a b c", "1.0 1.0 1.0", "not three numbers"),
])
def test_bad_scale_tolerated(model, scale, written, words):
    text, warnings = prepare(urdf(link("base_link", mesh_element("visual", "meshes/box.stl", scale=scale))), model)
    assert len(warnings) == 1 and words in warnings[0] and "link 'base_link'" in warnings[0]
    assert meshes_of(text)[0]["scale"] == written


def test_second_start_parses_nothing(model, monkeypatch):
    both = mesh_element("collision", "meshes/box.stl") + mesh_element("visual", "meshes/box.stl")
    text = urdf(link("base_link", both))
    first, _ = prepare(text, model)

    def boom(*args, **kwargs):
        raise AssertionError("parsed a mesh on a cache hit")

    monkeypatch.setattr(meshes, "read_mesh", boom)  # the converter's one entry to the readers
    for name in ("read_mesh", "read_stl", "read_obj", "read_dae"):
        monkeypatch.setattr(mesh_formats, name, boom)
    second, warnings = prepare(text, model)
    assert second == first and warnings == []


def test_changed_mesh_is_converted_again_and_old_entry_pruned(model):
    text = urdf(link("base_link", mesh_element("collision", "meshes/box.stl")))
    first, _ = prepare(text, model)
    old_obj = meshes_of(first)[0]["filename"]
    path = model / "model" / "meshes" / "box.stl"
    write_binary_stl(path, box_triangles((1.0, 1.0, 1.0)))
    stat = os.stat(path)
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1_000_000))
    second, _ = prepare(text, model)
    new_obj = meshes_of(second)[0]["filename"]
    assert new_obj != old_obj and not os.path.exists(old_obj)
    assert np.allclose(mesh_formats.read_obj(new_obj)[0].max(axis=0), 1.0)
    assert [n for n in os.listdir(model / "cache")] == [os.path.basename(new_obj)]  # no temporaries left


def test_dae_up_axis_is_noted_not_applied(model):
    write_dae(model / "model" / "meshes" / "wheel.dae")
    text, warnings = prepare(urdf(link("wheel", mesh_element("visual", "meshes/wheel.dae", scale=None))), model)
    assert len(warnings) == 1 and "up_axis Y_UP; ignored" in warnings[0]
    turned, warnings = prepare(urdf(link("wheel", mesh_element("visual", "meshes/wheel.dae", scale=None))), model,
                               honour_up_axis=True)
    assert warnings == [] and meshes_of(turned)[0]["filename"] != meshes_of(text)[0]["filename"]


def test_malformed_urdf_is_a_model_error(model):
    with pytest.raises(ModelError, match="robot.urdf: malformed XML"):
        prepare("<robot><link><mesh filename='x'/></robot>", model)


def test_default_cache_dir_follows_ros_home(monkeypatch, tmp_path):
    monkeypatch.setenv("ROS_HOME", str(tmp_path))
    assert meshes.default_cache_dir() == str(tmp_path / "diffbot_sim" / "mesh_cache")
    monkeypatch.delenv("ROS_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert meshes.default_cache_dir() == str(tmp_path / "home" / ".ros" / "diffbot_sim" / "mesh_cache")


# -------------------------------------------------------------------------------------------------- PyBullet

INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'


def mesh_robot(base_mesh, wheel_mesh, wheel_scale="0.001 0.001 0.001"):
    """base_link: ``base_mesh`` collision; wheel_link 2 m above it (continuous joint): ``wheel_mesh``."""
    return urdf(
        link("base_link", INERTIAL + mesh_element("collision", base_mesh) + mesh_element("visual", base_mesh)),
        link("wheel_link", INERTIAL + mesh_element("collision", wheel_mesh, scale=wheel_scale)),
        '  <joint name="wheel_joint" type="continuous"><parent link="base_link"/><child link="wheel_link"/>'
        '<origin xyz="0 0 2"/><axis xyz="0 1 0"/></joint>')


@pytest.fixture
def world():
    from diffbot_sim.physics import World

    made = World(1.0 / 240.0)
    # No ground: these tests measure shapes where they are loaded, and a robot placed into the ground is
    # lifted out of it.
    pybullet.removeBody(made.plane, physicsClientId=made.client)
    made.plane = None
    yield made
    made.close()


def extent(body, index, client):
    low, high = pybullet.getAABB(body, index, physicsClientId=client)
    return np.array(high) - np.array(low), np.array(low), np.array(high)


# PyBullet pads a convex hull's AABB by its collision margin (a few mm at most here).
MARGIN = 0.01


@pytest.mark.parametrize("writer", [write_binary_stl, write_ascii_stl])
def test_pybullet_box_mesh_has_metre_size(model, world, writer):
    from diffbot_sim.description.urdf_model import parse_urdf

    writer(model / "model" / "meshes" / "box.stl", box_triangles())
    write_dae(model / "model" / "meshes" / "wheel.dae")
    text, warnings = prepare(mesh_robot("package://my_robot/meshes/box.stl", "meshes/wheel.dae", wheel_scale=None),
                             model)
    robot = world.load_robot(text, parse_urdf(text, "robot.urdf"))
    size, low, high = extent(robot.body, -1, world.client)
    assert np.allclose(size, [1.0, 1.0, 0.5], atol=MARGIN)  # 1000 x 1000 x 500 mm with scale 0.001
    assert np.allclose((low + high) / 2, 0.0, atol=MARGIN)
    # The wheel: the .dae block with unit 0.001 and its node matrix, up_axis ignored as in Gazebo:
    # x -0.09..0.03, y 0.02..0.22, z 0.03..0.13 (the child triangle reaches z 0.13), 2 m up.
    size, low, high = extent(robot.body, 0, world.client)
    assert np.allclose(low, [-0.09, 0.02, 2.03], atol=MARGIN) and np.allclose(high, [0.03, 0.22, 2.13], atol=MARGIN)


def test_pybullet_y_up_dae_honoured_is_turned(model, world):
    from diffbot_sim.description.urdf_model import parse_urdf

    write_dae(model / "model" / "meshes" / "wheel.dae")
    text, _ = prepare(mesh_robot("meshes/box.stl", "meshes/wheel.dae", wheel_scale="2 2 2"), model,
                      honour_up_axis=True)
    robot = world.load_robot(text, parse_urdf(text, "robot.urdf"))
    # Y_UP turned: (x, y, z) -> (x, -z, y), then the URDF scale 2: y -0.26..-0.06, z 0.04..0.44.
    _, low, high = extent(robot.body, 0, world.client)
    assert np.allclose(low, [-0.18, -0.26, 2.04], atol=MARGIN) and np.allclose(high, [0.06, -0.06, 2.44], atol=MARGIN)


def test_pybullet_cannot_read_ascii_stl_itself(model, world):
    """Why ASCII STL is converted: PyBullet 3.2.7 loads it as a 2 mm placeholder, without an error."""
    path = write_ascii_stl(model / "a.stl", box_triangles((0.5, 0.5, 0.25)))
    urdf_path = model / "a.urdf"
    urdf_path.write_text(urdf(link("base_link", INERTIAL + mesh_element("collision", path, scale=None))))
    body = pybullet.loadURDF(str(urdf_path), physicsClientId=world.client)
    size, _, _ = extent(body, -1, world.client)
    assert (size < 0.01).all()


# -------------------------------------------------------------------------------------------------- speed

def test_two_megabyte_stl_cold_and_cached(tmp_path):
    """~2 MB binary STL (40 000 triangles): converted well within the 2 s start-up budget; cached ~free.

    Measured here (2 cores): about 0.09 s cold and 0.3 ms cached. The bounds are 20x and over 100x that,
    so a busy machine never misses them; they catch a conversion gone quadratic or a cache not used. The
    start-up figures (first /odom with this much STL, cache empty and filled) are make bench's
    ``meshes`` item (tools/bench_items/startup.py)."""
    rng = np.random.default_rng(1)
    points = rng.random((20000, 3)) * 1000.0
    triangles = points[rng.integers(0, len(points), (40000, 3))]
    (tmp_path / "model").mkdir()
    write_binary_stl(tmp_path / "model" / "big.stl", triangles)
    assert os.path.getsize(tmp_path / "model" / "big.stl") == 84 + 50 * 40000
    text = urdf(link("base_link", mesh_element("collision", "big.stl") + mesh_element("visual", "big.stl")))
    start = time.perf_counter()
    prepare(text, tmp_path)
    cold = time.perf_counter() - start
    start = time.perf_counter()
    prepare(text, tmp_path)
    cached = time.perf_counter() - start
    assert cold < 2.0, cold
    assert cached < 0.05, cached
