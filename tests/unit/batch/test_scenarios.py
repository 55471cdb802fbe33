"""Scenario files: matrix expansion, names, args, and every mistake one line before anything runs."""
import os

import pytest

from diffbot_sim.batch import scenarios
from diffbot_sim.batch.scenarios import ScenarioError, expand


@pytest.fixture
def pkg(tmp_path):
    root = tmp_path / "my_pkg"
    (root / "tests").mkdir(parents=True)
    (root / "tests" / "drive.test").write_text("<launch/>")
    (tmp_path / "local.test").write_text("<launch/>")

    def find(name):
        if name == "my_pkg":
            return str(root)
        raise KeyError(name)
    return tmp_path, find


def runs_of(pkg, *scs):
    tmp, find = pkg
    return expand({"scenarios": list(scs)}, str(tmp / "s.yaml"), find)


def test_matrix_is_a_cartesian_product_named_from_args(pkg):
    runs = runs_of(pkg, {"name": "drive-{world}-{seed}", "test": "my_pkg/tests/drive.test", "args": {"gui": False},
                         "matrix": {"world": ["empty.world", "room.world"], "seed": [1, 2, 3]}, "timeout": 300})
    assert [r.name for r in runs] == ["drive-empty.world-1", "drive-empty.world-2", "drive-empty.world-3",
                                      "drive-room.world-1", "drive-room.world-2", "drive-room.world-3"]
    assert runs[0].args == {"gui": "false", "world": "empty.world", "seed": "1"}
    assert runs[0].timeout == 300.0 and runs[0].cpus == 1.0
    assert runs[0].test_path == os.path.join(str(pkg[0]), "my_pkg", "tests", "drive.test")


def test_repeat_suffixes_and_defaults(pkg):
    runs = runs_of(pkg, {"name": "x", "test": "local.test", "repeat": 3, "cpus": 2})
    assert [r.name for r in runs] == ["x-r1", "x-r2", "x-r3"]
    assert runs[0].timeout == scenarios.DEFAULT_TIMEOUT and runs[0].cpus == 2.0
    assert runs[0].test_path == str(pkg[0] / "local.test")  # a path relative to the scenario file


@pytest.mark.parametrize("sc, message", [
    ({"name": "a", "test": "nope_pkg/tests/drive.test"}, "scenarios[0] (a).test: no file"),
    ({"name": "a", "test": "my_pkg/tests/missing.test"}, "package 'my_pkg'"),
    ({"name": "a", "test": "/no/such/file.test"}, "no such file /no/such/file.test"),
    ({"name": "a-{seed}", "test": "local.test", "matrix": {"world": ["w"]}},
     "'{seed}' is neither in args nor in matrix"),
    ({"name": "a", "test": "local.test", "matrix": {"seed": [1, 2]}}, "run name 'a' is not unique"),
    ({"name": "a", "test": "local.test", "matrix": {"seed": 3}}, "matrix.seed: expected a non-empty list"),
    ({"name": "a", "test": "local.test", "matrix": [1, 2]}, "matrix: expected a mapping"),
    ({"name": "a", "test": "local.test", "repeat": 0}, "repeat: expected a whole number"),
    ({"name": "a", "test": "local.test", "timeout": "soon"}, "timeout: expected wall seconds"),
    ({"name": "a", "test": "local.test", "args": {"x": [1]}}, "args.x: a roslaunch arg takes one value"),
    ({"name": "a", "test": "local.test", "tmeout": 3}, "scenarios[0].tmeout: unknown key"),
    ({"test": "local.test"}, "scenarios[0].name: missing"),
    ({"name": "a"}, "scenarios[0] (a).test: missing"),
    ({"name": "a-{x:>3}", "test": "local.test", "args": {"x": 1}}, "is not a plain {arg}"),
])
def test_each_mistake_is_one_line_naming_file_and_element(pkg, sc, message):
    with pytest.raises(ScenarioError) as err:
        runs_of(pkg, sc)
    text = str(err.value)
    assert "\n" not in text and text.startswith(str(pkg[0] / "s.yaml") + ": ")
    assert message in text


def test_duplicate_names_across_scenarios(pkg):
    with pytest.raises(ScenarioError, match="run name 'same' is not unique"):
        runs_of(pkg, {"name": "same", "test": "local.test"}, {"name": "same", "test": "local.test"})


def test_the_file_itself(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("scenarios: [\n")
    with pytest.raises(ScenarioError, match="bad.yaml: not YAML"):
        scenarios.load(str(bad), lambda n: (_ for _ in ()).throw(KeyError(n)))
    with pytest.raises(ScenarioError, match="cannot read"):
        scenarios.load(str(tmp_path / "missing.yaml"), lambda n: "")
    empty = tmp_path / "empty.yaml"
    empty.write_text("runs: []\n")
    with pytest.raises(ScenarioError, match="non-empty list 'scenarios:'"):
        scenarios.load(str(empty), lambda n: "")
