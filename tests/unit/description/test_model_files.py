"""description.model_files: xacro in-process with $(arg) mappings, errors naming the file, parse_args, mesh URIs."""
import os

import pytest

from diffbot_sim.description.model_files import load_file, parse_args
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.errors import ModelError


@pytest.fixture
def args_xacro(data_dir):
    return os.path.join(data_dir, "args.urdf.xacro")


def test_xacro_defaults(args_xacro):
    model = parse_urdf(load_file(args_xacro), args_xacro)
    assert model.name == "argbot"
    assert model.wheel_radius("left_wheel_joint", "x") == pytest.approx(0.05)
    assert model.total_mass() == pytest.approx(1.75)  # the included macro expanded


def test_xacro_arg_mapping(args_xacro):
    text = load_file(args_xacro, parse_args("wheel_radius:=0.09 base_mass:=3"))
    model = parse_urdf(text, args_xacro)
    assert model.links["base_link"].mass == pytest.approx(3.0)
    assert model.wheel_radius("left_wheel_joint", "x") == pytest.approx(0.09)


def test_xacro_args_do_not_leak_between_calls(args_xacro):
    load_file(args_xacro, {"wheel_radius": "0.2", "base_mass": "9"})
    model = parse_urdf(load_file(args_xacro), args_xacro)
    assert model.wheel_radius("left_wheel_joint", "x") == pytest.approx(0.05)
    assert model.links["base_link"].mass == pytest.approx(1.5)


def test_relative_include_independent_of_cwd(args_xacro, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert "left_wheel_link" in load_file(args_xacro)


def test_seed_xacro_loads(seed_urdf):
    assert "<robot" in seed_urdf and "xacro:" not in seed_urdf.replace("xmlns:xacro", "")
    assert "libgazebo_ros_diff_drive.so" in seed_urdf


def test_plain_urdf_read_verbatim(tmp_path):
    path = tmp_path / "plain.urdf"
    text = '<robot name="p"><link name="only"/></robot>'
    path.write_text(text)
    assert load_file(str(path)) == text
    assert load_file(str(path), {"ignored": "1"}) == text


def test_missing_file_names_it(tmp_path):
    missing = str(tmp_path / "nowhere.urdf.xacro")
    with pytest.raises(ModelError) as info:
        load_file(missing)
    assert str(info.value).startswith(missing + ": ")
    assert "no such file" in str(info.value)


@pytest.mark.parametrize("body", [
    '<link name="a"><collision>',  # XML syntax error
    '<link name="${undefined_property}"/>',  # xacro evaluation error
    '<xacro:include filename="does_not_exist.xacro"/>',
    '<xacro:no_such_macro/>',
])
def test_xacro_error_names_file(tmp_path, body):
    path = tmp_path / "broken.urdf.xacro"
    path.write_text('<?xml version="1.0"?>\n<robot name="b" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                    f"  {body}\n</robot>\n")
    with pytest.raises(ModelError) as info:
        load_file(str(path))
    message = str(info.value)
    assert message.startswith(str(path) + ": ")
    assert "xacro failed" in message
    assert "\n" not in message  # one line, loggable


def test_good_file_loads_after_a_xacro_error(tmp_path, args_xacro):
    path = tmp_path / "broken.urdf.xacro"
    path.write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="${nope}"/></robot>')
    with pytest.raises(ModelError):
        load_file(str(path))
    assert parse_urdf(load_file(args_xacro), args_xacro).name == "argbot"


def test_parse_args():
    assert parse_args("a:=1 b:=x  c:=") == {"a": "1", "b": "x", "c": ""}
    assert parse_args("") == {}
    assert parse_args("path:=/a/b:=c") == {"path": "/a/b:=c"}


@pytest.mark.parametrize("text", ["novalue", "a:=1 b=2", ":=3"])
def test_parse_args_bad_token(text):
    with pytest.raises(ModelError) as info:
        parse_args(text)
    assert "~model_args" in str(info.value)
    assert "is not name:=value" in str(info.value)
