"""The scenario file of ``batch``: read, checked and expanded into runs (pure: no rospy, no processes).

    scenarios:
      - name: drive-{world}-{seed}      # {arg} filled from args and matrix; unique per run
        test: diffbot_sim/tests/rostest/drive.test   # `package/relative/path.test`, or a path
        args: {gui: "false"}            # roslaunch args of the test file
        matrix: {world: [empty.world, room.world], seed: [1, 2, 3]}   # cartesian product: one run each
        repeat: 1                       # each expanded run this many times (name gets -r<k>)
        timeout: 300                    # wall seconds per run (default 600)
        cpus: 1                         # Ray CPUs per run (default 1)

A matrix's keys are roslaunch args too. Every mistake is a :class:`ScenarioError`: one line naming the file and
the element, raised before anything runs.
"""
import itertools
import os
import string
from collections.abc import Callable
from dataclasses import dataclass, field

import yaml

from diffbot_sim.errors import DiffbotSimError

DEFAULT_TIMEOUT = 600.0  # wall s per run
DEFAULT_CPUS = 1.0
KEYS = ("name", "test", "args", "matrix", "repeat", "timeout", "cpus")


class ScenarioError(DiffbotSimError):
    """A scenario file that cannot run: ``<file>: <element>: <what is wrong>``."""


@dataclass(frozen=True)
class Run:
    """One rostest run: the test file with these roslaunch args, under a name unique in the batch."""

    name: str
    test: str  # as written in the file
    test_path: str  # absolute path of the .test file
    args: dict[str, str] = field(default_factory=dict)
    timeout: float = DEFAULT_TIMEOUT
    cpus: float = DEFAULT_CPUS


def _scalar(value):
    """A roslaunch arg value as text (YAML's true/false become "true"/"false", as roslaunch writes them)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def resolve_test(test, base_dir, find_package):
    """The absolute path of ``test``: a path (absolute, or relative to the scenario file's folder) when such a
    file exists, else ``package/relative/path.test`` with the package found by ``find_package(name)`` (which
    returns its folder or raises KeyError). Returns (path, None) or (None, why)."""
    candidate = test if os.path.isabs(test) else os.path.join(base_dir, test)
    if os.path.isfile(candidate):
        return os.path.abspath(candidate), None
    if os.path.isabs(test):
        return None, f"no such file {test}"
    package, _, rest = test.partition("/")
    if not rest:
        return None, f"no such file {candidate} (nor a `package/path.test`)"
    try:
        folder = find_package(package)
    except KeyError:
        return None, f"no file {candidate} and no package '{package}'"
    path = os.path.join(folder, rest)
    if not os.path.isfile(path):
        return None, f"package '{package}' ({folder}) has no {rest}"
    return path, None


def _fields(template):
    """The ``{name}`` fields of a name template (format specs are not allowed: names stay literal)."""
    names = []
    for _, name, spec, conversion in string.Formatter().parse(template):
        if name is None:
            continue
        if name == "" or spec or conversion or not name.replace("_", "").isalnum():
            raise ValueError(f"'{{{name}{'!' + conversion if conversion else ''}{':' + spec if spec else ''}}}'")
        names.append(name)
    return names


def expand(data, source, find_package: Callable[[str], str], base_dir: str | None = None) -> list[Run]:
    """Every run of a parsed scenario file (``data``, from YAML; ``source`` names it in errors)."""
    base_dir = base_dir if base_dir is not None else os.path.dirname(os.path.abspath(source))

    def bad(where, what):
        return ScenarioError(f"{source}: {where}: {what}")

    if not isinstance(data, dict) or not isinstance(data.get("scenarios"), list) or not data["scenarios"]:
        raise ScenarioError(f"{source}: expected a mapping with a non-empty list 'scenarios:'")
    extra = sorted(set(data) - {"scenarios"})
    if extra:
        raise bad(extra[0], "unknown top-level key (only 'scenarios')")
    runs: list[Run] = []
    seen: dict[str, str] = {}
    for index, sc in enumerate(data["scenarios"]):
        where = f"scenarios[{index}]"
        if not isinstance(sc, dict):
            raise bad(where, "a scenario is a mapping (name, test, args, matrix, repeat, timeout, cpus)")
        unknown = sorted(set(sc) - set(KEYS))
        if unknown:
            raise bad(f"{where}.{unknown[0]}", f"unknown key (known: {', '.join(KEYS)})")
        name = sc.get("name")
        if not isinstance(name, str) or not name.strip():
            raise bad(f"{where}.name", "missing or not a string")
        where = f"scenarios[{index}] ({name})"
        test = sc.get("test")
        if not isinstance(test, str) or not test.strip():
            raise bad(f"{where}.test", "missing or not a string (a rostest file: package/path.test or a path)")
        path, why = resolve_test(test, base_dir, find_package)
        if path is None:
            raise bad(f"{where}.test", why)
        args = sc.get("args") or {}
        if not isinstance(args, dict):
            raise bad(f"{where}.args", f"expected a mapping of roslaunch args, got {type(args).__name__}")
        for key, value in args.items():
            if isinstance(value, (dict, list)) or value is None:
                raise bad(f"{where}.args.{key}", "a roslaunch arg takes one value (text or number)")
        matrix = sc.get("matrix") or {}
        if not isinstance(matrix, dict):
            raise bad(f"{where}.matrix", f"expected a mapping of arg: [values], got {type(matrix).__name__}")
        for key, values in matrix.items():
            if not isinstance(values, list) or not values:
                raise bad(f"{where}.matrix.{key}", f"expected a non-empty list of values, got {values!r}")
            if any(isinstance(v, (dict, list)) or v is None for v in values):
                raise bad(f"{where}.matrix.{key}", "each value is one roslaunch arg value (text or number)")
            if key in args:
                raise bad(f"{where}.matrix.{key}", "also given in args: give it in one place")
        repeat = sc.get("repeat", 1)
        if isinstance(repeat, bool) or not isinstance(repeat, int) or repeat < 1:
            raise bad(f"{where}.repeat", f"expected a whole number >= 1, got {repeat!r}")
        timeout = sc.get("timeout", DEFAULT_TIMEOUT)
        if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not timeout > 0:
            raise bad(f"{where}.timeout", f"expected wall seconds > 0, got {timeout!r}")
        cpus = sc.get("cpus", DEFAULT_CPUS)
        if isinstance(cpus, bool) or not isinstance(cpus, (int, float)) or not cpus > 0:
            raise bad(f"{where}.cpus", f"expected a number of CPUs > 0, got {cpus!r}")
        try:
            fields = _fields(name)
        except ValueError as err:
            raise bad(f"{where}.name", f"field {err} is not a plain {{arg}}") from None
        known = set(args) | set(matrix)
        for f in fields:
            if f not in known:
                raise bad(f"{where}.name", f"'{{{f}}}' is neither in args nor in matrix "
                                           f"({', '.join(sorted(known)) or 'none given'})")
        keys = list(matrix)
        for combo in itertools.product(*(matrix[k] for k in keys)):
            values = {k: _scalar(v) for k, v in args.items()}
            values.update({k: _scalar(v) for k, v in zip(keys, combo)})
            base = name.format(**values)
            for k in range(1, repeat + 1):
                run_name = base if repeat == 1 else f"{base}-r{k}"
                if run_name in seen:
                    raise bad(f"{where}.name", f"run name '{run_name}' is not unique (also from {seen[run_name]}); "
                                               f"put every matrix arg in the name")
                if "/" in run_name or run_name in (".", "..") or not run_name.strip():
                    raise bad(f"{where}.name", f"run name '{run_name}' cannot name a folder (no '/')")
                seen[run_name] = where
                runs.append(Run(run_name, test, path, dict(values), float(timeout), float(cpus)))
    return runs


def load(path, find_package) -> list[Run]:
    """Read ``path`` and expand it (:func:`expand`); ScenarioError on any mistake."""
    try:
        with open(path) as f:
            data = yaml.safe_load(f)
    except OSError as err:
        raise ScenarioError(f"{path}: cannot read: {err.strerror}") from None
    except yaml.YAMLError as err:
        raise ScenarioError(f"{path}: not YAML: {' '.join(str(err).split())}") from None
    return expand(data, path, find_package)
