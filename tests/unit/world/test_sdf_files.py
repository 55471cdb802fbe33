"""World files read as Gazebo's sdformat (TinyXML) reads them: blank lines or a byte-order mark before
``<?xml ...?>``, and text after the root element (``world/sdf_files.parse_xml`` through
``description/xml_documents``). expat alone refuses all three ("XML or text declaration not at start of
entity", "junk after document element")."""
import os

import pytest

from diffbot_sim.errors import ModelError
from diffbot_sim.world.sdf_reader import read_world

BOX = ('<model name="{name}"><static>true</static><link name="link"><collision name="c"><geometry><box>'
       '<size>1 1 1</size></box></geometry></collision></link></model>')
DECLARATION = '<?xml version="1.0"?>\n'


def write(path, data):
    os.makedirs(os.path.dirname(str(path)), exist_ok=True)
    with open(str(path), "wb") as out:
        out.write(data.encode("utf-8") if isinstance(data, str) else data)
    return str(path)


def world_text(body, lead=""):
    return f'{lead}{DECLARATION}<sdf version="1.6">\n<world name="w">\n{body}\n</world>\n</sdf>\n'


def names(world):
    return sorted(body.name for body in world.bodies)


@pytest.mark.parametrize("lead", ["\n", "\n\n  \t", "   ", "\ufeff", "\ufeff\n"],
                         ids=["blank line", "blank lines and spaces", "spaces", "BOM", "BOM and blank line"])
def test_whitespace_or_bom_before_the_declaration_of_world_model_and_config(tmp_path, lead):
    models = tmp_path / "models"
    write(models / "crate" / "model.config",
          f'{lead}{DECLARATION}<model><name>crate</name><sdf version="1.6">model.sdf</sdf></model>')
    write(models / "crate" / "model.sdf", f'{lead}{DECLARATION}<sdf version="1.6">{BOX.format(name="crate")}</sdf>')
    path = write(tmp_path / "lead.world",
                 world_text(BOX.format(name="wall") + "<include><uri>model://crate</uri></include>", lead))
    world = read_world(path, model_paths=[str(models)])
    assert names(world) == ["crate::link", "wall::link"]
    assert world.warnings == []


def test_an_error_after_blank_lines_names_the_line_in_the_file(tmp_path):
    path = write(tmp_path / "broken.world", "\n\n" + DECLARATION + '<sdf version="1.6">\n<world name="w">\n'
                                            '<model name="m">\n</world>\n</sdf>\n')
    with pytest.raises(ModelError) as err:
        read_world(path, model_paths=[])
    assert str(err.value).startswith(f"{path}: malformed XML at line 7, column 3"), str(err.value)


def test_an_error_on_the_first_line_after_spaces_names_its_column(tmp_path):
    path = write(tmp_path / "broken.world", '   <sdf version="1.6"><world name="w"></model></world></sdf>')
    with pytest.raises(ModelError) as err:
        read_world(path, model_paths=[])
    assert str(err.value).startswith(f"{path}: malformed XML at line 1, column 41"), str(err.value)


@pytest.mark.parametrize("tail", ["\ngarbage left by an editor\n", "\n</sdf>\n", "<sdf version='1.6'/>"],
                         ids=["text", "a second end tag", "a second root"])
def test_text_after_the_root_is_ignored_with_one_warning(tmp_path, tail):
    path = write(tmp_path / "tail.world", world_text(BOX.format(name="wall")) + tail)
    world = read_world(path, model_paths=[])
    assert names(world) == ["wall::link"]
    line = 8 if tail.startswith("\n") else 7  # the root ends on line 6
    assert world.warnings == [f"{path}: line {line}: text after the root element ignored, "
                              "as Gazebo's parser ignores it"]


def test_a_world_that_is_not_xml_at_all_is_still_refused(tmp_path):
    path = write(tmp_path / "text.world", "\n\nnot xml\n")
    with pytest.raises(ModelError, match=r"malformed XML at line 3, column 1"):
        read_world(path, model_paths=[])
