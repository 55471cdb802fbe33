"""tools/ has no import circle: its scripts, the bench kit (tools/benchkit/) and the bench's items
(tools/bench_items/) import each other one way only. Imports inside functions count, as in test_layers.py,
whose import reader and circle finder this test uses: a lazy import is still a dependency.
"""
import os

from test_layers import cycles, imports_of

TOOLS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "tools")


def tools_graph(tools_dir=TOOLS):
    """{module: imported module names} for every Python module under ``tools_dir``, named as tools/ on
    sys.path names them (``bench``, ``benchkit.launching``, ``bench_items.fleet``)."""
    graph = {}
    for dirpath, _, files in os.walk(tools_dir):
        for name in files:
            if name.endswith(".py"):
                path = os.path.join(dirpath, name)
                rel = os.path.relpath(path, tools_dir)[:-3].replace(os.sep, ".")
                graph[rel.removesuffix(".__init__")] = imports_of(path, rel.removesuffix(".__init__"))
    return graph


def test_tools_import_each_other_one_way():
    graph = tools_graph()
    assert {"bench", "run_tests"} <= set(graph)  # the walk found the tools
    assert cycles(graph) == []


def test_a_circle_among_tools_is_found(tmp_path):
    (tmp_path / "a.py").write_text("def f():\n    import b\n")
    (tmp_path / "kit").mkdir()
    (tmp_path / "kit" / "__init__.py").write_text("")
    (tmp_path / "kit" / "c.py").write_text("from . import d\n")
    (tmp_path / "kit" / "d.py").write_text("import a\n")
    (tmp_path / "b.py").write_text("from kit import c\n")
    assert cycles(tools_graph(str(tmp_path))) == [["a", "b", "kit.c", "kit.d", "a"]]
