"""xacro_compat.py: noetic (xacro 1.14) descriptions through the PyPI xacro 1.13.3 plus our patches.

Every feature runs twice: in-process through ``description.load_file`` and as the ``xacro`` command on
PATH (what launch files run), which tools/setup.sh points at ``diffbot_sim.description.xacro_compat:main``. Marked
"1.13.3 lacks" are the features that fail without the compatibility layer; the others are checked so a
xacro upgrade or a patch cannot lose them.
"""
import math
import os
import shutil
import subprocess
import textwrap
import xml.etree.ElementTree as ET
from types import SimpleNamespace

import pytest

from diffbot_sim.description import xacro_compat
from diffbot_sim.description.model_files import load_file
from diffbot_sim.errors import ModelError

DATA = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data", "xacro")
XACRO_NS = "http://www.ros.org/wiki/xacro"


def write(directory, name, body, namespace=XACRO_NS):
    """Write ``body`` wrapped in a ``<robot>`` declaring the xacro namespace; returns the path as str."""
    path = directory / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f'<?xml version="1.0"?>\n<robot name="t" xmlns:xacro="{namespace}">\n'
                    f"{textwrap.dedent(body)}\n</robot>\n")
    return str(path)


def write_text(directory, name, text):
    path = directory / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text))
    return str(path)


def values(urdf, tag="v"):
    """``{name: value}`` of every ``<v n=... x=.../>`` in the output (the tests' probe element)."""
    return {el.get("n"): el.get("x") for el in ET.fromstring(urdf).iter(tag)}


@pytest.fixture
def fake_package(tmp_path):
    """A catkin package ``xc_fake_description`` (with config/fake.yaml and urdf/part.xacro); its parent dir
    is what ROS_PACKAGE_PATH must list."""
    root = tmp_path / "pkgs"
    pkg = root / "xc_fake_description"
    write_text(pkg, "package.xml", """\
        <?xml version="1.0"?>
        <package format="2"><name>xc_fake_description</name><version>0.0.1</version>
          <description>test</description><maintainer email="t@example.com">t</maintainer>
          <license>BSD</license>
        </package>
        """)
    write_text(pkg, "config/fake.yaml", "gain: 7\n")
    write(pkg, "urdf/part.xacro", '<v n="part" x="from_package"/>')
    return str(root)


class Runner:
    """Runs a xacro file through load_file or through the ``xacro`` command and returns a Result."""

    def __init__(self, mode, monkeypatch, capsys):
        self.mode = mode
        self.monkeypatch = monkeypatch
        self.capsys = capsys

    def _env(self, env, package_path):
        env = dict(env or {})
        if package_path:
            env["ROS_PACKAGE_PATH"] = package_path + os.pathsep + os.environ.get("ROS_PACKAGE_PATH", "")
        return env

    def __call__(self, path, args=None, env=None, package_path=None):
        """-> SimpleNamespace(ok, urdf, err): the URDF text (or None) and the error text / stderr."""
        env = self._env(env, package_path)
        args = dict(args or {})
        if self.mode == "load_file":
            for name, value in env.items():
                if value is None:
                    self.monkeypatch.delenv(name, raising=False)
                else:
                    self.monkeypatch.setenv(name, value)
            if "ROS_PACKAGE_PATH" in env:
                from roslaunch import substitution_args

                self.monkeypatch.setattr(substitution_args, "_rospack", None)  # it caches the old path
            self.capsys.readouterr()
            try:
                urdf = load_file(path, args)
            except ModelError as err:
                return SimpleNamespace(ok=False, urdf=None, err=str(err))
            return SimpleNamespace(ok=True, urdf=urdf, err=self.capsys.readouterr().err)
        command = shutil.which("xacro")
        assert command, "no xacro on PATH: run `make setup` and the tests through tools/rosenv.sh"
        full_env = dict(os.environ)
        for name, value in env.items():
            if value is None:
                full_env.pop(name, None)
            else:
                full_env[name] = value
        proc = subprocess.run([command, path] + [f"{k}:={v}" for k, v in args.items()], env=full_env,
                              capture_output=True, text=True, timeout=60, check=False)
        ok = proc.returncode == 0
        return SimpleNamespace(ok=ok, urdf=proc.stdout if ok else None, err=proc.stderr)


@pytest.fixture(params=["load_file", "command"])
def run(request, monkeypatch, capsys):
    return Runner(request.param, monkeypatch, capsys)


def ok(result):
    assert result.ok, result.err
    return result.urdf


# --- a whole noetic-style description ------------------------------------------------------------------


def test_noetic_style_description(run):
    urdf = ok(run(os.path.join(DATA, "noetic_robot.urdf.xacro"), {"prefix": "r1_"}))
    robot = ET.fromstring(urdf)
    masses = {link.get("name"): float(link.find("inertial/mass").get("value")) for link in robot.iter("link")}
    assert masses == {"r1_base_link": 2.5, "r1_left_wheel_link": 0.3, "r1_right_wheel_link": 0.3,
                      "r1_front_camera_link": 0.05}
    joints = {joint.get("name"): joint.find("origin") for joint in robot.iter("joint")}
    assert joints["r1_right_wheel_joint"].get("xyz") == "0 -0.15 0"
    assert float(joints["r1_left_wheel_joint"].get("rpy").split()[0]) == pytest.approx(-math.pi / 2)
    assert float(joints["r1_front_camera_joint"].get("rpy").split()[2]) == pytest.approx(math.pi / 2)


# --- xacro.load_yaml (1.13.3 lacks: yaml.load without Loader, no attribute access, no unit tags) --------


def test_load_yaml_relative_to_including_file_with_dotted_access(run, tmp_path):
    write_text(tmp_path, "sub/part.yaml", """\
        base: {mass: 1.5, size: [0.3, 0.2, 0.1]}
        wheels:
          - {name: left, radius: 0.05}
          - {name: right, radius: 0.06}
        """)
    write(tmp_path, "sub/part.xacro", """\
        <xacro:property name="p" value="${xacro.load_yaml('part.yaml')}"/>
        <v n="dotted" x="${p.base.mass}"/>
        <v n="item" x="${p['base']['mass']}"/>
        <v n="list" x="${p.base.size[1]}"/>
        <v n="nested" x="${p.wheels[1].radius}"/>
        <v n="mixed" x="${p['wheels'][0].name}"/>
        <v n="has" x="${python.len(p.wheels)}"/>
        """)
    main = write(tmp_path, "robot.xacro", '<xacro:include filename="sub/part.xacro"/>')
    assert values(ok(run(main))) == {"dotted": "1.5", "item": "1.5", "list": "0.2", "nested": "0.06",
                                     "mixed": "left", "has": "2"}


def test_load_yaml_old_unqualified_name(run, tmp_path):
    write_text(tmp_path, "p.yaml", "k: 3\n")
    path = write(tmp_path, "r.xacro", """\
        <xacro:property name="p" value="${load_yaml('p.yaml')}"/>
        <v n="k" x="${p['k'] * 2}"/><v n="dot" x="${p.k}"/>""")
    assert values(ok(run(path))) == {"k": "6", "dot": "3"}


def test_load_yaml_degrees_radians_and_lengths(run, tmp_path):
    write_text(tmp_path, "limits.yaml", """\
        deg: !degrees 90
        neg: !degrees -180
        rad: !radians pi/2
        plain: 1.25
        mm: !millimeters 25
        """)
    path = write(tmp_path, "r.xacro", """\
        <xacro:property name="l" value="${xacro.load_yaml('limits.yaml')}"/>
        <v n="deg" x="${l.deg}"/><v n="neg" x="${l.neg}"/><v n="rad" x="${l.rad}"/>
        <v n="plain" x="${l.plain}"/><v n="mm" x="${l.mm}"/>""")
    got = {k: float(v) for k, v in values(ok(run(path))).items()}
    assert got == pytest.approx({"deg": math.pi / 2, "neg": -math.pi, "rad": math.pi / 2, "plain": 1.25,
                                 "mm": 0.025})


def test_load_yaml_bad_degrees_value_names_the_yaml_file(run, tmp_path):
    bad = write_text(tmp_path, "bad.yaml", "a: !degrees ninety\n")
    path = write(tmp_path, "r.xacro", '<v n="a" x="${xacro.load_yaml(\'bad.yaml\').a}"/>')
    result = run(path)
    assert not result.ok
    assert bad in result.err and "!degrees" in result.err


def test_load_yaml_is_safe(run, tmp_path):
    write_text(tmp_path, "evil.yaml", "x: !!python/object/apply:os.getcwd []\n")
    path = write(tmp_path, "r.xacro", '<v n="x" x="${xacro.load_yaml(\'evil.yaml\').x}"/>')
    result = run(path)
    assert not result.ok
    assert "evil.yaml" in result.err and "python/object/apply" in result.err  # refused, not run


def test_load_yaml_from_find_package(run, tmp_path, fake_package):
    path = write(tmp_path, "r.xacro", """\
        <xacro:property name="cfg" value="$(find xc_fake_description)/config/fake.yaml"/>
        <v n="via_property" x="${xacro.load_yaml(cfg).gain}"/>
        <v n="inline" x="${xacro.load_yaml('$(find xc_fake_description)/config/fake.yaml')['gain']}"/>""")
    assert values(ok(run(path, package_path=fake_package))) == {"via_property": "7", "inline": "7"}


# --- the rest of the xacro. namespace (1.13.3 lacks) ---------------------------------------------------


def test_xacro_abs_filename_dotify_arg_tokenize(run, tmp_path):
    path = write(tmp_path, "sub/r.xacro", """\
        <xacro:arg name="mode" default="fast"/>
        <v n="abs" x="${xacro.abs_filename('meshes/base.stl')}"/>
        <v n="dotify" x="${xacro.dotify(dict(a=dict(b=4))).a.b}"/>
        <v n="arg" x="${xacro.arg('mode')}"/>
        <v n="given" x="${xacro.arg('speed')}"/>
        <v n="tokens" x="${python.len(xacro.tokenize('a, b;c'))}"/>""")
    got = values(ok(run(path, {"speed": "3"})))
    assert got == {"abs": str(tmp_path / "sub" / "meshes" / "base.stl"), "dotify": "4", "arg": "fast",
                   "given": "3", "tokens": "3"}


def test_xacro_arg_undefined_is_an_error(run, tmp_path):
    result = run(write(tmp_path, "r.xacro", '<v n="a" x="${xacro.arg(\'nope\')}"/>'))
    assert not result.ok and "undefined argument 'nope'" in result.err


def test_xacro_messages_print_and_leave_no_text(run, tmp_path):
    path = write(tmp_path, "r.xacro", """\
        <v n="m" x="a${xacro.message('hello there')}"/>
        <v n="w" x="b${xacro.warning('careful now')}"/>
        <v n="e" x="c${xacro.error('not fatal')}"/>
        <v n="l" x="d${xacro.print_location()}"/>""")
    result = run(path)
    assert values(ok(result)) == {"m": "a", "w": "b", "e": "c", "l": "d"}
    assert "hello there" in result.err and "careful now" in result.err and "not fatal" in result.err
    assert path in result.err  # the location printed by warning/error/print_location


def test_xacro_fatal_fails_with_its_message(run, tmp_path):
    path = write(tmp_path, "r.xacro", """\
        <xacro:property name="wheels" value="3"/>
        <xacro:if value="${wheels != 2}">${xacro.fatal('need two wheels, got', wheels)}</xacro:if>""")
    result = run(path)
    assert not result.ok
    assert "need two wheels, got 3" in result.err


# --- python. and math. namespaces, old names (1.13.3 lacks the namespaces, len, sorted, range) -----------


def test_python_namespace(run, tmp_path):
    path = write(tmp_path, "r.xacro", """\
        <v n="range" x="${python.list(python.range(3))}"/>
        <v n="len" x="${python.len([1, 2])}"/>
        <v n="sum" x="${python.sum([1, 2, 3])}"/>
        <v n="minmax" x="${python.min(4, 2)}${python.max(4, 2)}"/>
        <v n="abs_round" x="${python.abs(python.round(-2.6))}"/>
        <v n="sorted" x="${python.sorted([3, 1, 2])}"/>
        <v n="zip" x="${python.dict(python.zip(['a'], [1]))}"/>
        <v n="enumerate" x="${python.list(python.enumerate('ab'))[1]}"/>
        <v n="pow" x="${python.pow(2, 5)}"/>
        <v n="bool" x="${python.bool(0)}"/>
        <v n="anyall" x="${python.any([0, 1])} ${python.all([0, 1])}"/>
        <v n="convert" x="${python.int('7') + python.float('0.5')}${python.str(1)}"/>
        <v n="map" x="${python.list(python.map(python.abs, [-1]))}"/>""")
    assert values(ok(run(path))) == {
        "range": "[0, 1, 2]", "len": "2", "sum": "6", "minmax": "24", "abs_round": "3", "sorted": "[1, 2, 3]",
        "zip": "{'a': 1}", "enumerate": "(1, 'b')", "pow": "32", "bool": "False", "anyall": "True False",
        "convert": "7.51", "map": "[1]"}


def test_python_namespace_has_no_open(run, tmp_path):
    result = run(write(tmp_path, "r.xacro", '<v n="x" x="${python.open(\'/etc/passwd\')}"/>'))
    assert not result.ok and "'python' has no symbol 'open'" in result.err


def test_math_namespace_and_old_unqualified_names(run, tmp_path):
    path = write(tmp_path, "r.xacro", """\
        <v n="math_pi" x="${math.pi}"/>
        <v n="radians" x="${math.radians(90)}"/>
        <v n="sqrt" x="${math.sqrt(16)}"/>
        <v n="pi" x="${pi}"/>
        <v n="sin" x="${sin(0)}"/>
        <v n="old_radians" x="${radians(180)}"/>
        <v n="len" x="${len([1, 2, 3])}"/>
        <v n="sorted" x="${sorted([2, 1])}"/>
        <v n="range" x="${list(range(2))}"/>""")
    got = values(ok(run(path)))
    assert float(got.pop("math_pi")) == pytest.approx(math.pi)
    assert float(got.pop("radians")) == pytest.approx(math.pi / 2)
    assert float(got.pop("pi")) == pytest.approx(math.pi)
    assert float(got.pop("old_radians")) == pytest.approx(math.pi)
    assert got == {"sqrt": "4.0", "sin": "0.0", "len": "3", "sorted": "[1, 2]", "range": "[0, 1]"}


# --- macro defaults as noetic reads them (1.13.3: "Undefined parameters") ---------------------------------


def test_macro_default_with_space_after_colon_equals(run, tmp_path):
    path = write(tmp_path, "r.xacro", """\
        <xacro:macro name="cam" params="lens_mass:= 0.05 name">
          <v n="${name}" x="${lens_mass}"/>
        </xacro:macro>
        <xacro:cam name="front"/>
        <xacro:cam name="rear" lens_mass="0.1"/>""")
    assert values(ok(run(path))) == {"front": "0.05", "rear": "0.1"}


def test_macro_defaults_with_spaces_inside(run, tmp_path):
    path = write(tmp_path, "r.xacro", """\
        <xacro:arg name="ns" default="robot1"/>
        <xacro:property name="base" value="2"/>
        <xacro:macro name="m" params="a ns:=$(arg ns) k := ${base * 3} t:='x y' plain=p fwd:=^|dflt">
          <v n="${a}" x="${ns}|${k}|${t}|${plain}|${fwd}"/>
        </xacro:macro>
        <xacro:property name="fwd" value="outer"/>
        <xacro:m a="one"/>""")
    assert values(ok(run(path))) == {"one": "robot1|6|x y|p|outer"}


@pytest.mark.parametrize("spec, expected", [
    ("name", ("name", None, "")),
    ("name *origin", ("name", None, "*origin")),
    ("lens_mass:= 0.05 name", ("lens_mass", (None, "0.05"), "name")),
    ("a:=1 b", ("a", (None, "1"), "b")),
    ("a = 1", ("a", (None, "1"), "")),
    ("ns:=$(arg ns) rest", ("ns", (None, "$(arg ns)"), "rest")),
    ("k:=${a * 2}_x  rest", ("k", (None, "${a * 2}_x"), "rest")),
    ("t:='a b' r", ("t", (None, "'a b'"), "r")),
    ("f:=^ r", ("f", ("f", None), "r")),
    ("f:=^|1", ("f", ("f", "1"), "")),
    ("e:= ", ("e", (None, None), "")),
])
def test_parse_macro_arg(spec, expected):
    assert xacro_compat.parse_macro_arg(spec) == expected


# --- property attributes of xacro 1.13.14 / 1.14.10 (1.13.3: "recursive variable definition") --------------


def test_greedy_properties_as_franka_description_uses_them(run):
    result = run(os.path.join(DATA, "greedy_arm.urdf.xacro"), {"arm_id": "fr3"})
    robot = ET.fromstring(ok(result))
    assert "unknown attribute" not in result.err
    assert [link.get("name") for link in robot.iter("link")] == ["world", "fr3_link0", "fr3_link1"]
    masses = {link.get("name"): link.find("inertial/mass").get("value") for link in robot.iter("link")
              if link.find("inertial") is not None}
    assert masses == {"fr3_link0": "0.63", "fr3_link1": "4.97"}
    assert robot.find("link[@name='fr3_link1']/inertial/inertia").get("iyz") == "0.0191"
    assert robot.find("link[@name='fr3_link0']/inertial/origin").get("xyz") == "-0.041 0 0.05"
    limit = robot.find("joint[@name='fr3_joint1']/limit")
    assert (limit.get("lower"), limit.get("effort"), limit.get("velocity")) == ("-2.8973", "87", "2.175")


def test_lazy_properties_stay_lazy(run, tmp_path):
    path = write(tmp_path, "r.xacro", """\
        <xacro:property name="late" value="${later * 2}"/>
        <xacro:property name="eager" value="${1 + 1}" lazy_eval="${not False}"/>
        <xacro:property name="later" value="3"/>
        <v n="late" x="${late}"/><v n="eager" x="${eager}"/>""")
    assert values(ok(run(path))) == {"late": "6", "eager": "2"}
    path = write(tmp_path, "self.xacro", """\
        <xacro:property name="p" value="a"/><xacro:property name="p" value="${p}_b"/><v n="p" x="${p}"/>""")
    result = run(path)
    assert not result.ok and "recursive variable definition: p -> p" in result.err


def test_greedy_property_is_evaluated_where_it_is_defined(run, tmp_path):
    path = write(tmp_path, "r.xacro", """\
        <xacro:property name="n" value="1"/>
        <xacro:property name="snapshot" value="${n * 10}" lazy_eval="false"/>
        <xacro:property name="lazy" value="${n * 10}"/>
        <xacro:property name="n" value="2"/>
        <xacro:property name="name" value="Panda"/>
        <xacro:property name="name" value="${name.lower()}" lazy_eval="false"/>
        <v n="snapshot" x="${snapshot}"/><v n="lazy" x="${lazy}"/><v n="name" x="${name}"/>""")
    assert values(ok(run(path))) == {"snapshot": "10", "lazy": "20", "name": "panda"}
    result = run(write(tmp_path, "undefined.xacro", """\
        <xacro:property name="p" value="${nowhere}" lazy_eval="false"/>"""))
    assert not result.ok and "nowhere" in result.err


def test_property_remove(run, tmp_path):
    path = write(tmp_path, "r.xacro", """\
        <xacro:property name="gone" value="1"/>
        <xacro:property name="kept" value="2"/>
        <xacro:macro name="forget"><xacro:property name="gone" remove="true"/></xacro:macro>
        <xacro:forget/>
        <xacro:property name="gone" default="defined again: it was removed"/>
        <v n="kept" x="${kept}"/><v n="gone" x="${gone}"/>
        <xacro:property name="never_defined" remove="true"/>""")
    assert values(ok(run(path))) == {"kept": "2", "gone": "defined again: it was removed"}
    path = write(tmp_path, "use.xacro", """\
        <xacro:property name="gone" value="1"/><xacro:property name="gone" remove="true"/><v n="g" x="${gone}"/>""")
    result = run(path)
    assert not result.ok and "gone" in result.err
    path = write(tmp_path, "both.xacro", '<xacro:property name="p" value="1" remove="true"/>')
    result = run(path)
    assert not result.ok and "exclude each other" in result.err


def test_property_name_from_an_expression(run, tmp_path):
    # xacro 1.13.14's changelog example: a macro as a function that sets a property of its caller
    path = write(tmp_path, "r.xacro", """\
        <xacro:macro name="square" params="name args">
          <xacro:property name="${name}" value="${[float(x)**2 for x in args]}" scope="parent"/>
        </xacro:macro>
        <xacro:square name="result" args="${python.range(4)}"/>
        <v n="result" x="${result}"/>""")
    assert values(ok(run(path))) == {"result": "[0.0, 1.0, 4.0, 9.0]"}


def test_underscored_values_stay_text_as_in_noetic(run, tmp_path):
    path = write(tmp_path, "r.xacro", """\
        <xacro:property name="serial" value="1_0"/><xacro:property name="ten" value="10"/>
        <v n="serial" x="${serial + 'x'}"/><v n="ten" x="${ten + 1}"/><v n="quoted" x="${'a_1'}"/>""")
    assert values(ok(run(path))) == {"serial": "1_0x", "ten": "11", "quoted": "a_1"}


def test_optional_include(run, tmp_path):
    write(tmp_path, "parts/present.xacro", '<v n="present" x="1"/>')
    path = write(tmp_path, "r.xacro", """\
        <xacro:property name="dir" value="parts"/>
        <xacro:include filename="${dir}/missing.xacro" optional="true"/>
        <xacro:include filename="${dir}/present.xacro" optional="true"/>
        <v n="after" x="1"/>""")
    result = run(path)
    assert values(ok(result)) == {"present": "1", "after": "1"} and "unknown attribute" not in result.err
    for flag in ("", ' optional="false"'):
        result = run(write(tmp_path, "strict.xacro", f'<xacro:include filename="parts/missing.xacro"{flag}/>'))
        assert not result.ok and "missing.xacro" in result.err


# --- features 1.13.3 already has (kept working) -----------------------------------------------------------


def test_optenv_with_default(run, tmp_path):
    path = write(tmp_path, "r.xacro", '<v n="o" x="$(optenv XC_TEST_MODE slow)"/>')
    assert values(ok(run(path, env={"XC_TEST_MODE": None}))) == {"o": "slow"}
    assert values(ok(run(path, env={"XC_TEST_MODE": "fast"}))) == {"o": "fast"}


def test_arg_defaults_and_mappings(run, tmp_path):
    path = write(tmp_path, "r.xacro", """\
        <xacro:arg name="a" default="1"/><xacro:arg name="b" default="x_$(arg a)"/>
        <v n="a" x="$(arg a)"/><v n="b" x="$(arg b)"/>""")
    assert values(ok(run(path))) == {"a": "1", "b": "x_1"}
    assert values(ok(run(path, {"a": "9"}))) == {"a": "9", "b": "x_9"}


def test_arg_default_from_expression(run, tmp_path):
    # 1.13.3 lacks this: it stores the default's typed value (6), and roslaunch's $(arg) needs text.
    path = write(tmp_path, "r.xacro", """\
        <xacro:property name="r" value="3"/>
        <xacro:arg name="b" default="${2 * r}"/>
        <v n="b" x="$(arg b)"/><v n="via_xacro_arg" x="${xacro.arg('b') + '!'}"/>""")
    assert values(ok(run(path))) == {"b": "6", "via_xacro_arg": "6!"}


def test_if_unless_and_not_in(run, tmp_path):
    path = write(tmp_path, "r.xacro", """\
        <xacro:arg name="mode" default="sim"/>
        <xacro:property name="mode" value="$(arg mode)"/>
        <xacro:if value="${mode not in ['real', 'hw']}"><v n="sim_only" x="1"/></xacro:if>
        <xacro:unless value="${mode not in ['real', 'hw']}"><v n="real_only" x="1"/></xacro:unless>
        <xacro:if value="true"><v n="literal" x="1"/></xacro:if>
        <xacro:unless value="0"><v n="zero" x="1"/></xacro:unless>""")
    assert set(values(ok(run(path)))) == {"sim_only", "literal", "zero"}
    assert set(values(ok(run(path, {"mode": "real"})))) == {"real_only", "literal", "zero"}


def test_block_parameters(run, tmp_path):
    path = write(tmp_path, "r.xacro", """\
        <xacro:macro name="box" params="name *origin **extras">
          <link name="${name}"><xacro:insert_block name="origin"/><xacro:insert_block name="extras"/></link>
        </xacro:macro>
        <xacro:box name="b">
          <origin xyz="1 2 3"/>
          <extras><v n="e1" x="1"/><v n="e2" x="2"/></extras>
        </xacro:box>""")
    link = ET.fromstring(ok(run(path))).find("link")
    assert [child.tag for child in link] == ["origin", "v", "v"]  # *: the element, **: its children
    assert link.find("origin").get("xyz") == "1 2 3"


def test_relative_includes_nest(run, tmp_path, monkeypatch):
    write(tmp_path, "a/b/inner.xacro", '<v n="inner" x="1"/>')
    write(tmp_path, "a/outer.xacro", '<xacro:include filename="b/inner.xacro"/><v n="outer" x="1"/>')
    path = write(tmp_path, "r.xacro", '<xacro:include filename="a/outer.xacro"/>')
    monkeypatch.chdir("/")
    assert set(values(ok(run(path)))) == {"inner", "outer"}


@pytest.mark.parametrize("namespace", ["http://www.ros.org/wiki/xacro", "http://ros.org/wiki/xacro",
                                       "http://wiki.ros.org/xacro"])
def test_namespace_spellings(run, tmp_path, namespace):
    path = write(tmp_path, "r.xacro", """\
        <xacro:property name="p" value="5"/>
        <xacro:macro name="m" params="x"><v n="m" x="${x}"/></xacro:macro>
        <xacro:m x="${p}"/>""", namespace=namespace)
    urdf = ok(run(path))
    assert values(urdf) == {"m": "5"} and "xacro:" not in urdf.replace("xmlns:xacro", "")


def test_find_package_include(run, tmp_path, fake_package):
    path = write(tmp_path, "r.xacro",
                 '<xacro:include filename="$(find xc_fake_description)/urdf/part.xacro"/>')
    assert values(ok(run(path, package_path=fake_package))) == {"part": "from_package"}


def test_find_unknown_package_fails(run, tmp_path):
    result = run(write(tmp_path, "r.xacro", '<v n="x" x="$(find xc_no_such_package)"/>'))
    assert not result.ok and "xc_no_such_package" in result.err


def test_dirname(run, tmp_path):
    # 1.13.3 lacks this one too: roslaunch resolves $(dirname) only when told the current file.
    write(tmp_path, "sub/part.xacro", '<v n="part" x="$(dirname)"/>')
    path = write(tmp_path, "r.xacro",
                 '<v n="top" x="$(dirname)"/><xacro:include filename="$(dirname)/sub/part.xacro"/>')
    assert values(ok(run(path))) == {"top": str(tmp_path), "part": str(tmp_path / "sub")}


# --- the layer itself ---------------------------------------------------------------------------------------


def test_apply_is_idempotent():
    first = xacro_compat.apply()
    symbols = dict(first.global_symbols)
    eval_extension, parse_macro_arg = first.eval_extension, first.parse_macro_arg
    second = xacro_compat.apply()
    assert second is first
    assert dict(second.global_symbols) == symbols
    assert second.eval_extension is eval_extension and second.parse_macro_arg is parse_macro_arg
    assert not hasattr(eval_extension.wrapped, "wrapped")  # wrapped once, not twice


def test_check_refuses_other_xacro_versions(monkeypatch):
    import xacro

    class FakeDist:
        version = "2.0.8"

    monkeypatch.setattr(xacro_compat.importlib.metadata, "distribution", lambda name: FakeDist())
    with pytest.raises(ModelError) as info:
        xacro_compat.check(xacro)
    assert xacro.__file__ in str(info.value) and "2.0.8" in str(info.value) and "1.13." in str(info.value)


def test_check_refuses_a_module_without_the_hooks():
    import xacro

    stripped = SimpleNamespace(**{k: v for k, v in vars(xacro).items() if k != "parse_macro_arg"})
    with pytest.raises(ModelError, match="parse_macro_arg"):
        xacro_compat.check(stripped)


def test_check_accepts_the_installed_xacro():
    import xacro

    xacro_compat.check(xacro)


def test_xacro_command_on_path_is_the_compat_launcher():
    command = shutil.which("xacro")
    assert command, "no xacro on PATH"
    with open(command, encoding="utf-8") as handle:
        lines = handle.read().splitlines()
    assert len(lines) == 3 and "diffbot_sim.description.xacro_compat import main" in lines[2], \
        f"{command} is not the launcher tools/setup.sh installs; run `make setup`"
    assert lines[0] == "#!" + os.path.join(os.path.dirname(command), "python")


def test_xacro_command_reports_errors_with_exit_status(tmp_path):
    path = write(tmp_path, "r.xacro", '<v n="x" x="${undefined_name}"/>')
    proc = subprocess.run([shutil.which("xacro") or "xacro", path], capture_output=True, text=True,
                          timeout=60, check=False)
    assert proc.returncode == 2 and "undefined_name" in proc.stderr and path in proc.stderr


def test_main_reports_a_refused_xacro(monkeypatch, capsys):
    def refuse():
        raise ModelError("xacro 2.0.8 is installed", "/x/xacro/__init__.py")

    monkeypatch.setattr(xacro_compat, "apply", refuse)
    assert xacro_compat.main() == 2
    assert "/x/xacro/__init__.py: xacro 2.0.8" in capsys.readouterr().err
