"""How ~world / empty_world.launch's world_name is found: as given, else in GAZEBO_RESOURCE_PATH, else in
this package (which ships Gazebo's default worlds/empty.world); and how world_markers and view_rviz find a
running simulator's world and robots from its parameters."""
import os

import pytest

from diffbot_sim.errors import ModelError
from diffbot_sim.world.loading import resolve_world_path, robot_namespaces, simulator_world
from diffbot_sim.world.map_image import synthetic_map
from diffbot_sim.world.sdf_reader import read_world

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


def test_gazebo_default_world_is_ours(monkeypatch, tmp_path):
    monkeypatch.delenv("GAZEBO_RESOURCE_PATH", raising=False)
    monkeypatch.chdir(tmp_path)
    path = resolve_world_path("worlds/empty.world", ROOT)
    assert path == os.path.join(ROOT, "worlds", "empty.world")
    world = read_world(path, model_paths=[])
    assert [b.top_model for b in world.bodies] == ["ground_plane"] and world.has_ground


def test_gazebo_resource_path_comes_first(monkeypatch, tmp_path):
    (tmp_path / "worlds").mkdir()
    (tmp_path / "worlds" / "empty.world").write_text("<sdf version='1.6'><world name='x'/></sdf>")
    monkeypatch.setenv("GAZEBO_RESOURCE_PATH", f"/nonexistent:{tmp_path}")
    monkeypatch.chdir("/")
    assert resolve_world_path("worlds/empty.world", ROOT) == str(tmp_path / "worlds" / "empty.world")


def test_a_missing_world_names_itself_and_where_it_looked(monkeypatch, tmp_path):
    monkeypatch.setenv("GAZEBO_RESOURCE_PATH", str(tmp_path))
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ModelError) as err:
        resolve_world_path("worlds/willowgarage.world", ROOT)
    assert "worlds/willowgarage.world" in str(err.value) and "GAZEBO_RESOURCE_PATH" in str(err.value)
    absent = str(tmp_path / "absent.world")  # an absolute path is taken as given; the reader names it
    assert resolve_world_path(absent, ROOT) == absent
    with pytest.raises(ModelError, match="absent.world"):
        read_world(absent)


def test_simulator_world_reads_the_simulators_world_parameter(tmp_path):
    path = synthetic_map(str(tmp_path / "rooms.yaml"), size=60, room=30, wall=2, door=6, noise=0.0)
    params = {"/bullet_sim/world_name": path, "/bullet_sim/map_wall_height": 0.5}
    asked = []

    def get_param(name, default):
        asked.append(name)
        return params.get(name, default)

    world = simulator_world("/bullet_sim", get_param)
    assert world.source == path and world.bodies  # ~world unset: empty_world.launch's world_name is read
    assert asked == ["/bullet_sim/world", "/bullet_sim/world_name", "/bullet_sim/map_wall_height"]
    assert {float(b.shapes[0].vertices[:, 2].max()) for b in world.bodies} == {0.5}  # map_wall_height, not 1 m
    assert simulator_world("/other_sim", get_param) is None


def test_robot_namespaces_from_the_robots_parameter():
    assert robot_namespaces(None) == [""]  # the one robot of x, y, yaw
    assert robot_namespaces(["a", {"name": "b", "x": 1.0}]) == ["a", "b"]
