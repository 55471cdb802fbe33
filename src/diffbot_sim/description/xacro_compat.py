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
   typed value 1.13.3 stores and roslaunch's ``$(arg)`` then fails on (noetic stores the text);
5. ``grab_property``: the property attributes of xacro 1.13.14 / 1.14.10: ``lazy_eval="false"`` (the value
   evaluated where it is defined, so ``<xacro:property name="p" value="${p}_" lazy_eval="false"/>`` extends
   the old value, where a lazy one refers to itself: "recursive variable definition"), ``remove="true"``,
   and a name computed by an expression (``name="${n}"``);
6. ``process_include``: ``<xacro:include optional="true">`` (1.14.1) skips a file that does not exist;
7. ``Table._eval_literal``: a value with an underscore stays text, as in noetic (Python 3 reads ``1_0`` as
   the number 10; noetic 1.14.4 keeps such values as strings).

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
          "print_location", "grab_property", "process_include", "check_attrs", "is_valid_name",
          "remove_previous_comments", "replace_node", "eval_text", "get_boolean_value", "Table",
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
                    return float(eval(str(text), xacro.global_symbols, {})) * factor
                except Exception as err:  # any bad expression is a YAML content error
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
                data = yaml.load(handle, Loader=_loader_class(xacro))  # a SafeLoader subclass
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


def _flag(xacro, text, table, default):
    """A property or include attribute read as a boolean (``true``, ``1``, ``${expr}``; None: ``default``)."""
    if text is None:
        return default
    return xacro.get_boolean_value(xacro.eval_text(text, table), text)


def _remove_property(table, name):
    """Forget property ``name`` in ``table`` and every enclosing scope, as noetic's ``remove="true"`` does (the
    global symbols, ``pi`` and the like, are not properties and stay)."""
    scope = table
    while scope is not None:
        scope.table.pop(name, None)
        scope.unevaluated.discard(name)
        scope = scope.parent


def _make_grab_property(xacro):
    """``<xacro:property>`` as xacro 1.13.14 / 1.14.10 reads it: 1.13.3's ``value``, ``default``, ``scope``
    and blocks, plus ``lazy_eval``, ``remove`` and a name that is an expression."""

    def grab_property(elt, table):
        xacro.remove_previous_comments(elt)
        name, value, default, remove, scope, lazy = xacro.check_attrs(
            elt, ["name"], ["value", "default", "remove", "scope", "lazy_eval"])
        name = str(xacro.eval_text(name, table))
        if not xacro.is_valid_name(name):
            raise xacro.XacroException("Property names must be valid python identifiers: " + name)
        remove = _flag(xacro, remove, table, False)
        if sum((value is not None, default is not None, remove)) > 1:
            raise xacro.XacroException(f"property '{name}': value, default and remove exclude each other")
        if remove:
            _remove_property(table, name)
            xacro.replace_node(elt, by=None)
            return
        if default is not None:
            if scope is not None:
                xacro.warning(f"{name}: default property value can only be defined on local scope")
            if name in table:
                xacro.replace_node(elt, by=None)
                return
            value = default
        if value is None:  # a block property: the element itself
            name, value = "**" + name, elt
        xacro.replace_node(elt, by=None)
        lazy = _flag(xacro, lazy, table, True)
        if scope == "global":
            target, lazy = table.root(), False
        elif scope == "parent":
            if table.parent is None:
                xacro.warning(f"{name}: no parent scope at global scope ")
                return
            target, lazy = table.parent, False
        else:
            target = table
        if not lazy and isinstance(value, str):
            value = xacro.eval_text(value, table)  # now, in the scope where it is defined
        target._setitem(name, value, unevaluated=lazy)

    return grab_property


def _make_process_include(xacro, original):
    """1.13.3's include, and noetic's ``optional="true"``: a file that does not exist is left out."""

    def process_include(elt, macros, symbols, func):
        if elt.hasAttribute("optional"):
            optional = _flag(xacro, elt.getAttribute("optional"), symbols, False)
            elt.removeAttribute("optional")  # 1.13.3 would warn about an unknown attribute
            if optional:
                spec = xacro.abs_filename_spec(str(xacro.eval_text(elt.getAttribute("filename"), symbols)))
                if not re.search(r"[*[?]", spec) and not os.path.isfile(spec):
                    xacro.remove_previous_comments(elt)
                    xacro.replace_node(elt, by=None)
                    return
        original(elt, macros, symbols, func)

    process_include.wrapped = original
    return process_include


def _make_eval_literal(original):
    """Noetic's literal reading: a value with an underscore is text (``1_0`` is not 10, ``arm_1`` stays)."""

    def eval_literal(value):
        if isinstance(value, str) and "_" in value and not (len(value) >= 2 and value[0] == value[-1] == "'"):
            return value
        return original(value)

    eval_literal.wrapped = original
    return staticmethod(eval_literal)


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
    xacro.grab_property = _make_grab_property(xacro)
    xacro.process_include = _make_process_include(xacro, xacro.process_include)
    xacro.Table._eval_literal = _make_eval_literal(xacro.Table._eval_literal)
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
