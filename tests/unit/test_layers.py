"""The package layout stays true: every module of src/diffbot_sim imports only from its own subpackage or from
lower layers along the data path (description -> world -> physics -> plugins -> simulator -> nodes), no
modules import each other in a circle, the pure subpackages import no rospy, and only physics/ imports
PyBullet. Imports inside functions count too: a lazy import is still a dependency.

docs/architecture.md explains the layers; this test is their definition.
"""
import ast
import os

import pytest

PACKAGE = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "src",
                       "diffbot_sim")

#: Each top-level module or subpackage ("unit") and its layer. A unit imports its own modules and units of
#: lower layers, never one of its own layer or above.
LAYERS = {
    # the exception hierarchy every layer raises
    "errors": 0,
    # what everything shares: checked values, rotations and poses, the process's output streams, waiting with
    # a deadline
    "values": 1, "transforms": 1, "streams": 1, "waiting": 1,
    # descriptions read into data, the controllers' and the teleop's mathematics, the validated config
    "config": 2, "description": 2, "control": 2, "teleop": 2,
    # worlds (they name packages through description) and sensor models (they read description's tags)
    "world": 3, "sensors": 3,
    # the one PyBullet user; gazebo_ros's decisions; pictures
    "physics": 4, "gazebo": 4, "view": 4,
    # judging a robot (it loads it into physics); ROS messages from plain numbers, control/'s trajectory
    # points and world/'s marker specs (message modules only)
    "check": 5, "messages": 5,
    # running scenario files as processes, here or on Ray (no rospy: a run's ROS processes are children)
    "batch": 5,
    # Gymnasium environments: a robot in a world in-process, through physics/ and the pure models (no rospy)
    "gym": 5,
    # one module per Gazebo plugin (rospy)
    "plugins": 6,
    # bullet_sim at run time (rospy)
    "simulator": 7,
    # one thin rospy module per executable
    "nodes": 8,
}
#: Units that must not import rospy (unit-tested without a master).
PURE = {unit for unit, layer in LAYERS.items() if layer <= 5}
#: The only unit that may import PyBullet.
PYBULLET_OWNER = "physics"


def module_name(path, package_dir=PACKAGE):
    rel = os.path.relpath(path, package_dir)[:-3].replace(os.sep, ".")
    return "diffbot_sim" + ("" if rel == "__init__" else "." + rel.removesuffix(".__init__"))


def unit_of(module):
    """``diffbot_sim.world.sdf_reader`` -> ``world``; ``diffbot_sim`` -> None (the package itself)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None


def imports_of(path, module):
    """Absolute names of every module ``path`` imports (relative imports resolved), at any depth."""
    tree = ast.parse(open(path).read(), path)
    package = module if path.endswith("__init__.py") else module.rpartition(".")[0]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([node.module] if node.module else []))
            found.add(base)
            found.update(f"{base}.{alias.name}" for alias in node.names)  # `from pkg import module`
    return found


def scan(package_dir=PACKAGE):
    """{module: set of imported module names} for every module under ``package_dir``."""
    graph = {}
    for dirpath, _, files in os.walk(package_dir):
        for name in files:
            if name.endswith(".py"):
                path = os.path.join(dirpath, name)
                module = module_name(path, package_dir)
                graph[module] = imports_of(path, module)
    return graph


def problems(graph, layers=LAYERS, pure=PURE, pybullet_owner=PYBULLET_OWNER):
    """Every broken rule of ``graph`` as one line each."""
    found = []
    modules = set(graph)
    for module, imported in sorted(graph.items()):
        unit = unit_of(module)
        if unit is not None and unit not in layers:
            found.append(f"{module}: its unit '{unit}' has no layer in LAYERS (a new subpackage? give it one)")
            continue
        for name in sorted(imported):
            if name == "rospy" or name.startswith("rospy."):
                if unit in pure:
                    found.append(f"{module} imports rospy, but {unit}/ is pure")
            elif name.split(".")[0] in ("pybullet", "pybullet_data") and unit != pybullet_owner:
                found.append(f"{module} imports {name}: only {pybullet_owner}/ talks to PyBullet")
            elif name in modules and name != module:
                other = unit_of(name)
                if unit is None or other is None or other == unit:
                    continue
                if layers.get(other, -1) >= layers[unit]:
                    found.append(f"{module} (layer {layers[unit]}) imports {name} (layer {layers.get(other)}): "
                                 f"an upward or sideways import")
    found.extend(f"import circle: {' -> '.join(cycle)}" for cycle in cycles(graph))
    return found


def cycles(graph):
    """One representative circle per strongly connected group of modules (Tarjan), as lists of names."""
    edges = {m: sorted(i for i in imported if i in graph and i != m) for m, imported in graph.items()}
    index, low, stack, on_stack, out = {}, {}, [], set(), []
    counter = [0]

    def visit(node):
        index[node] = low[node] = counter[0]
        counter[0] += 1
        stack.append(node)
        on_stack.add(node)
        for nxt in edges[node]:
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            group = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                group.append(member)
                if member == node:
                    break
            if len(group) > 1:
                out.append(sorted(group) + [sorted(group)[0]])

    for node in sorted(edges):
        if node not in index:
            visit(node)
    return out


def test_the_package_keeps_its_layers():
    graph = scan()
    assert len(graph) > 50  # the walk found the package
    assert problems(graph) == []


#: The most lines a module may have: past this it has more than one job (docs/architecture.md, "Module size").
MAX_MODULE_LINES = 500


def test_no_module_is_over_500_lines():
    sizes = {}
    for dirpath, _, files in os.walk(PACKAGE):
        for name in files:
            if name.endswith(".py"):
                path = os.path.join(dirpath, name)
                with open(path) as module:
                    sizes[os.path.relpath(path, PACKAGE)] = sum(1 for _ in module)
    assert len(sizes) > 50  # the walk found the package
    assert {path: lines for path, lines in sizes.items() if lines > MAX_MODULE_LINES} == {}


def test_every_subpackage_has_a_layer():
    units = {name for name in os.listdir(PACKAGE) if not name.startswith("__")}
    units = {u[:-3] if u.endswith(".py") else u for u in units}
    assert units == set(LAYERS), f"units without a layer: {units - set(LAYERS)}; gone: {set(LAYERS) - units}"


# -- the checker itself: each rule reports what breaks it ---------------------------------------------------

@pytest.mark.parametrize("graph, culprit", [
    ({"diffbot_sim.world.a": {"diffbot_sim.plugins.p"}, "diffbot_sim.plugins.p": set()},
     "diffbot_sim.world.a (layer 3) imports diffbot_sim.plugins.p (layer 6): an upward or sideways import"),
    ({"diffbot_sim.world.a": {"diffbot_sim.sensors.s"}, "diffbot_sim.sensors.s": set()},
     "an upward or sideways import"),
    ({"diffbot_sim.description.a": {"rospy"}}, "diffbot_sim.description.a imports rospy, but description/ is pure"),
    ({"diffbot_sim.sensors.a": {"pybullet"}}, "only physics/ talks to PyBullet"),
    ({"diffbot_sim.world.a": {"diffbot_sim.world.b"}, "diffbot_sim.world.b": {"diffbot_sim.world.a"}},
     "import circle: diffbot_sim.world.a -> diffbot_sim.world.b -> diffbot_sim.world.a"),
    ({"diffbot_sim.newthing.a": set()}, "has no layer in LAYERS"),
])
def test_the_checker_reports_a_broken_rule(graph, culprit):
    assert any(culprit in line for line in problems(graph)), problems(graph)


def test_the_checker_accepts_downward_and_local_imports():
    graph = {"diffbot_sim.plugins.p": {"diffbot_sim.world.a", "diffbot_sim.plugins.q", "rospy"},
             "diffbot_sim.plugins.q": set(), "diffbot_sim.world.a": {"diffbot_sim.errors"}, "diffbot_sim.errors": set()}
    assert problems(graph) == []


def test_an_upward_import_added_to_a_real_module_is_caught(tmp_path):
    import shutil

    copy = tmp_path / "diffbot_sim"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    with open(copy / "world" / "bodies.py", "a") as module:
        module.write("\nfrom diffbot_sim.plugins import registry\n")
    found = problems(scan(str(copy)))
    culprit = "diffbot_sim.world.bodies (layer 3) imports diffbot_sim.plugins.registry"
    assert any(line.startswith(culprit) for line in found)
