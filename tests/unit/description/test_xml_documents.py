"""description/xml_documents: XML as TinyXML takes it (whitespace or a byte-order mark before ``<?xml``,
text after the root), and the model files that go through it: a URDF file read directly, a robot_description
text, a COLLADA mesh."""
import xml.etree.ElementTree as ET

import pytest

from diffbot_sim.description import mesh_formats, xml_documents
from diffbot_sim.description.model_files import load_file
from diffbot_sim.description.prepared_model import prepare_model

DECLARED = '<?xml version="1.0" encoding="utf-8"?>\n<robot name="r"><link name="base_link"/></robot>\n'


@pytest.mark.parametrize("data", [DECLARED, DECLARED.encode("utf-8")], ids=["str", "bytes"])
@pytest.mark.parametrize("lead", ["", "\n", " \t\r\n\n", "\ufeff", "\ufeff \n"])
def test_parse_skips_what_tinyxml_skips(data, lead):
    prefix = lead.encode("utf-8") if isinstance(data, bytes) else lead
    assert xml_documents.parse(prefix + data).get("name") == "r"
    assert xml_documents.document_start(prefix + data) == data


def test_expat_alone_refuses_a_blank_line_before_the_declaration():
    """What the module is for: without it, this is the error users saw."""
    with pytest.raises(ET.ParseError, match="not at start of entity"):
        ET.fromstring("\n" + DECLARED)


@pytest.mark.parametrize("lead, position", [("", (1, 15)), ("  ", (1, 17)), ("\n\n", (3, 15)), ("\n  ", (2, 17)),
                                            ("\ufeff\n", (2, 15))])
def test_errors_name_the_place_in_the_text_as_given(lead, position):
    text = lead + "<robot><link></robot>"  # expat: mismatched tag at column 15 of the document's line
    with pytest.raises(ET.ParseError) as err:
        xml_documents.parse(text)
    assert err.value.position == position
    assert str(err.value) == f"mismatched tag: line {position[0]}, column {position[1]}"


def test_text_after_the_root_is_refused_unless_asked():
    text = "\n<robot name='r'/>\n\nleft over </robot>\n</robot>"
    with pytest.raises(ET.ParseError, match="junk after document element") as err:
        xml_documents.parse(text)
    assert err.value.position[0] == 4
    seen = []
    assert xml_documents.parse(text, seen.append).get("name") == "r"
    assert seen == [4]
    assert xml_documents.parse(text.encode("utf-8"), seen.append).get("name") == "r"


def test_text_after_the_root_with_multibyte_characters_before_it():
    text = "<robot name='é→r'><link name='ü'/></robot>\nrest"
    assert xml_documents.parse(text, lambda line: None).get("name") == "é→r"
    assert xml_documents.parse(text.encode("utf-8"), lambda line: None).get("name") == "é→r"


def test_a_urdf_file_with_a_blank_line_before_the_declaration_loads(tmp_path):
    path = tmp_path / "lead.urdf"
    path.write_text("\n\n" + DECLARED)
    text = load_file(str(path))
    assert text == DECLARED
    assert ET.fromstring(text).get("name") == "r"


def test_a_robot_description_with_a_blank_line_before_the_declaration_is_prepared(tmp_path):
    prepared = prepare_model("\n  \n" + DECLARED, "robot_description", cache_dir=str(tmp_path))
    assert prepared.model.name == "r" and ET.fromstring(prepared.text).get("name") == "r"


def test_a_collada_mesh_with_a_blank_line_before_the_declaration_loads(tmp_path):
    dae = tmp_path / "tri.dae"
    dae.write_text("""
<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <library_geometries><geometry id="g"><mesh>
    <source id="p"><float_array id="pa" count="9">0 0 0 1 0 0 0 1 0</float_array>
      <technique_common><accessor source="#pa" count="3" stride="3"><param name="X" type="float"/>
        <param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
""")
    vertices, faces = mesh_formats.read_dae(str(dae))
    assert len(faces) == 1 and len(vertices) == 3
