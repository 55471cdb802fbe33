"""Teach the PyPI xacro 1.13.3 what real ROS 1 (noetic, xacro 1.14) descriptions rely on.

Why a patch at all: PyPI holds only xacro 1.13.3 (ROS 1) and 2.x (ROS 2, whose ``$(find)`` asks the
ament index, useless to a catkin workspace). Debian bookworm packages neither. Noetic descriptions use
features that came after 1.13.3, and 1.13.3's ``load_yaml`` calls ``yaml.load`` without a Loader, which
PyYAML 6 refuses. So we keep 1.13.3 (its ``$(find)``, ``$(arg)``, macros, includes all work) and extend it
at run time. Nothing here is copied from xacro; it is written against 1.13.3's module globals, and
``apply()`` refuses any other version instead of patching it blindly.

The patches (``apply()`` makes them once per process; a second call changes nothing):

1. expression symbols: the ``xacro.``, ``python.`` and ``math.`` namespaces, plus ``len``, ``sorted`` and
   ``range`` unqualified (noetic has them; 1.13.3 answers ``name 'xacro' is not defined``);
2. ``load_yaml``: safe loading, ``!degrees``/``!radians`` (and noetic's length units), attribute access
   to mappings (``props.key`` as well as ``props['key']``);
3. ``parse_macro_arg``: macro defaults as noetic reads them (``lens_mass:= 0.05``, ``ns:=$(arg ns)``,
   ``k:=${a * 2}``), where 1.13.3 splits at the first space and reports ``Undefined parameters``;
4. ``eval_extension``: ``$(dirname)``, the directory of the file being processed (roslaunch resolves it
   only when told the file, and 1.13.3 never tells it); and ``<xacro:arg default="${2 * r}"/>``, whose
   typed value 1.13.3 stores and roslaunch's ``$(arg)`` then fails on (noetic stores the text).

This module imports no rospy and no xacro at import time; ``apply()`` imports xacro.
"""
import builtins
import importlib.metadata
import math
import os
import re
import sys

from diffbot_sim.errors import ModelError

#: The xacro release line these patches are written against.
SUPPORTED_SERIES = "1.13."

#: Module attributes of xacro 1.13.x that the patches read or replace. Checked before patching.
_HOOKS = ("global_symbols", "load_yaml", "parse_macro_arg", "eval_extension", "abs_filename_spec",
          "push_file", "restore_filestack", "filestack", "all_includes", "substitution_args_context",
          "print_location",
          "XacroException", "message", "warning", "error", "main")

#: Set on the xacro module once patched, so ``apply()`` is idempotent.
_MARK = "_diffbot_sim_compat"

#: Builtins reachable as ``python.NAME`` (noetic's set, plus ``pow`` and ``bool`` that descriptions use).
PYTHON_NAMES = ("list", "dict", "map", "len", "str", "float", "int", "bool", "True", "False", "min", "max",
                "round", "abs", "all", "any", "complex", "divmod", "enumerate", "filter", "frozenset", "hash",
                "isinstance", "issubclass", "ord", "repr", "reversed", "slice", "set", "sum", "tuple", "type",
                "zip", "sorted", "range", "pow")

#: Builtins that noetic also exposes unqualified and 1.13.3 lacks.
UNQUALIFIED_NAMES = ("len", "sorted", "range")

#: YAML tags with a unit, and the factor to the SI base unit (rosparam's !degrees/!radians, noetic's lengths).
YAML_UNITS = {"!radians": 1.0, "!degrees": math.pi / 180.0, "!meters": 1.0, "!millimeters": 0.001,
              "!foot": 0.3048, "!inches": 0.0254}


class AttrDict(dict):
    """A dict whose keys also read as attributes: ``props.wheel.radius`` is ``props['wheel']['radius']``.

    Noetic hands ``load_yaml`` results over this way, and descriptions written for it use the dotted form.
    A missing key raises AttributeError (not KeyError) so that ``hasattr`` works.
    """

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(f"the yaml dictionary has no key '{name}'") from None


def dotify(value):
    """Recursively turn the dicts in ``value`` (also those inside lists) into ``AttrDict``; a copy.

    Eager rather than noetic's lazy wrapping: YAML files are small, and a plain list/dict tree is easier to
    reason about than wrappers that re-wrap on every access.
    """
    if isinstance(value, dict):
        return AttrDict((key, dotify(item)) for key, item in value.items())
    if isinstance(value, list):
        return [dotify(item) for item in value]
    return value


class Namespace:
    """A read-only bag of symbols reached as ``label.name`` inside ``${...}`` (``xacro.``, ``python.``).

    A missing name raises AttributeError naming the namespace, e.g. ``'python' has no symbol 'open'``.
    """

    def __init__(self, label, entries):
        self.__dict__["_label"] = label
        self.__dict__["_entries"] = dict(entries)

    def __getattr__(self, name):
        entries = self.__dict__.get("_entries", {})
        if name in entries:
            return entries[name]
        raise AttributeError(f"'{self.__dict__.get('_label')}' has no symbol '{name}'")

    def __setattr__(self, name, value):
        raise AttributeError(f"'{self._label}' is read-only")

    def __dir__(self):
        return sorted(self._entries)


def tokenize(text, sep=",; ", skip_empty=True):
    """``'a, b;c'`` -> ``['a', 'b', 'c']``: noetic's ``xacro.tokenize`` for list-valued properties."""
    parts = re.split("[" + re.escape(sep) + "]", text)
    return [part for part in parts if part] if skip_empty else parts


_yaml_loader = None


def _loader_class(xacro):
    """A SafeLoader subclass with the unit tags. A subclass, so yaml.SafeLoader itself stays untouched."""
    global _yaml_loader
    if _yaml_loader is None:
        import yaml  # lazy: only descriptions that load YAML need it

        class UnitLoader(yaml.SafeLoader):
            """Safe YAML plus unit tags: ``!degrees 90``, or an expression: ``!radians pi/2``."""

        def construct(factor, tag):
            def constructor(loader, node):
                text = loader.construct_scalar(node)
                try:
                    # an xacro expression, as noetic reads it: `!radians pi/2`
                    return float(eval(str(text), xacro.global_symbols, {})) * factor  # noqa: S307
                except Exception as err:  # noqa: BLE001 - any bad expression is a YAML content error
                    problem = f"{tag} needs a number or an expression like pi/2, got '{text}' ({err})"
                    raise yaml.constructor.ConstructorError(None, None, problem, node.start_mark) from None
            return constructor

        for tag, factor in YAML_UNITS.items():
            UnitLoader.add_constructor(tag, construct(factor, tag))
        _yaml_loader = UnitLoader
    return _yaml_loader


def _make_load_yaml(xacro):
    """Our ``load_yaml``: 1.13.3's path handling (relative to the including file), safe and dotted."""

    def load_yaml(filename):
        """Load a YAML file for ``${xacro.load_yaml('file.yaml')}``; relative names resolve against the
        file being processed, as for includes. Mappings read as attributes (``AttrDict``)."""
        import yaml

        path = xacro.abs_filename_spec(str(filename))
        oldstack = xacro.push_file(path)  # errors inside (a bad !degrees expression) name the YAML file
        try:
            with open(path, encoding="utf-8") as handle:
                data = yaml.load(handle, Loader=_loader_class(xacro))  # noqa: S506 - a SafeLoader subclass
        except yaml.YAMLError as err:
            raise xacro.XacroException(f"invalid YAML in {path}:", exc=err) from None
        finally:
            xacro.restore_filestack(oldstack)
        xacro.all_includes.append(path)  # so `xacro --deps` lists it, as 1.13.3 did
        return dotify(data)

    return load_yaml


def parse_macro_arg(spec):
    """Split the first parameter off a macro's ``params`` string, reading defaults as noetic does.

    Accepts ``name``, ``name:=default``, ``name=default``, ``name := default`` and the forwarding forms
    ``name:=^`` / ``name:=^|default``. A default ends at whitespace outside ``${...}``, ``$(...)`` and
    quotes, so ``ns:=$(arg ns)``, ``k:=${a * 2}`` and ``t:='a b'`` are single defaults.

    Returns:
        The contract of xacro 1.13.3's own function, which grab_macro() calls:
        ``(name, (forwarded_name_or_None, default_or_None), rest)``, or ``(name, None, rest)`` when the
        parameter has no ``=`` at all.
    """
    text = spec.lstrip()
    match = re.match(r"([^\s:=]+)\s*:?=\s*", text)
    if not match:
        head = text.split(None, 1)
        return head[0], None, head[1] if len(head) > 1 else ""
    name, pos = match.group(1), match.end()
    forward = re.match(r"\^\|?", text[pos:])
    if forward:
        pos += forward.end()
    start = pos
    while pos < len(text) and not text[pos].isspace():
        if text.startswith(("${", "$("), pos):
            close = text.find("}" if text[pos + 1] == "{" else ")", pos + 2)
            if close < 0:
                raise ValueError(f"macro parameter '{name}': unterminated '{text[pos:pos + 2]}' in default")
            pos = close + 1
        elif text[pos] in "'\"":
            close = text.find(text[pos], pos + 1)
            if close < 0:
                raise ValueError(f"macro parameter '{name}': unterminated quote in default")
            pos = close + 1
        else:
            pos += 1
    default = text[start:pos] or None
    return name, (name if forward else None, default), text[pos:].lstrip()


def _argument_text(xacro):
    """The ``$(arg)`` table, every value as text as noetic stores it (1.13.3 keeps ``${}`` results typed)."""
    table = xacro.substitution_args_context.setdefault("arg", {})
    for name, value in table.items():
        if not isinstance(value, str):
            table[name] = str(value)
    return table


def _make_eval_extension(xacro, original):
    """Wrap 1.13.3's ``$(...)`` evaluation: roslaunch's resolver gets the current file (``$(dirname)``) and
    text-only argument values (its ``$(arg)`` does ``str.replace`` with them)."""

    def eval_extension(text):
        current = xacro.filestack[-1] if xacro.filestack else None
        if current:
            xacro.substitution_args_context["filename"] = current
        else:
            xacro.substitution_args_context.pop("filename", None)
        _argument_text(xacro)
        return original(text)

    eval_extension.wrapped = original
    return eval_extension


def _xacro_namespace(xacro, load_yaml):
    """The ``xacro.`` namespace: YAML, file names, arguments and messages from inside expressions."""

    def print_location():
        xacro.print_location(xacro.filestack or [], file=sys.stderr)
        return ""

    def reporter(report, locate_by_default):
        def report_message(*args, **kwargs):
            locate = kwargs.pop("print_location", locate_by_default)
            kwargs.pop("file", None)  # always stderr: stdout carries the URDF
            report(*(args or ("",)), **kwargs)
            if locate:
                print_location()
            return ""  # so ${xacro.warning(...)} leaves no text behind
        return report_message

    def arg(name):
        try:
            return _argument_text(xacro)[name]
        except KeyError:
            raise xacro.XacroException(f"undefined argument '{name}' in xacro.arg() "
                                       "(declare it with <xacro:arg> or pass name:=value)") from None

    def fatal(*args):
        raise xacro.XacroException(" ".join(str(arg) for arg in args))

    return Namespace("xacro", {
        "load_yaml": load_yaml, "abs_filename": xacro.abs_filename_spec, "dotify": dotify, "arg": arg,
        "message": reporter(xacro.message, False), "warning": reporter(xacro.warning, True),
        "error": reporter(xacro.error, True), "print_location": print_location, "fatal": fatal,
        "tokenize": tokenize,
    })


def check(xacro):
    """Raise ModelError unless ``xacro`` is the PyPI xacro 1.13.x with every hook the patches use.

    The patches replace module globals by name; on another version they would silently do the wrong thing.
    """
    source = getattr(xacro, "__file__", None) or "xacro"
    try:
        dist = importlib.metadata.distribution("xacro")
    except importlib.metadata.PackageNotFoundError:
        raise ModelError("xacro has no installed distribution; diffbot_sim needs the PyPI xacro 1.13.3 "
                         "(pip install xacro==1.13.3)", source) from None
    if not dist.version.startswith(SUPPORTED_SERIES):
        raise ModelError(f"xacro {dist.version} is installed; diffbot_sim's compatibility layer supports "
                         f"{SUPPORTED_SERIES}x only (pip install xacro==1.13.3)", source)
    expected = os.path.realpath(str(dist.locate_file("xacro/__init__.py")))
    if os.path.realpath(source) != expected:
        raise ModelError(f"imported xacro is not the installed xacro {dist.version} at {expected}", source)
    missing = [name for name in _HOOKS if not hasattr(xacro, name)]
    if missing:
        raise ModelError(f"xacro {dist.version} lacks {', '.join(missing)}; cannot apply the "
                         "compatibility layer", source)


def apply():
    """Patch xacro 1.13.3 in this process (once) and return the module.

    Raises:
        ModelError: the installed xacro is not 1.13.x (the message names xacro's file).
    """
    import xacro

    if getattr(xacro, _MARK, False):
        return xacro
    check(xacro)
    load_yaml = _make_load_yaml(xacro)
    symbols = xacro.global_symbols
    allowed = symbols["__builtins__"]  # 1.13.3 evaluates with this dict as the only builtins
    for name in UNQUALIFIED_NAMES:
        allowed.setdefault(name, getattr(builtins, name))
    symbols["python"] = Namespace("python", {name: getattr(builtins, name) for name in PYTHON_NAMES})
    symbols["math"] = math
    symbols["xacro"] = _xacro_namespace(xacro, load_yaml)
    symbols["load_yaml"] = load_yaml  # the old unqualified spelling
    xacro.load_yaml = load_yaml
    xacro.parse_macro_arg = parse_macro_arg
    xacro.eval_extension = _make_eval_extension(xacro, xacro.eval_extension)
    setattr(xacro, _MARK, True)
    return xacro


def main():
    """The ``xacro`` command (installed into the venv by tools/setup.sh): xacro 1.13.3's CLI, patched."""
    try:
        xacro = apply()
    except ModelError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    xacro.main()
    return 0
