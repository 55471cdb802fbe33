"""The package as users meet it: rosrun/roslaunch/rostest find each name exactly once, in this checkout's
catkin_ws and in a user's own workspace; the model passes check_urdf. Needs the ROS environment
(tools/run_tests.py provides it)."""
import os
import shutil
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
VENV_PY = os.path.join(ROOT, ".venv", "bin", "python")

# Run in a fresh bash that sources a workspace, so what we check is what a new terminal gets.
PROBE = r"""
import json, roslib.packages, rospkg
rp = rospkg.RosPack()
out = {"pkg": rp.get_path("diffbot_sim")}
for name in ("sim.launch", "teleop.launch", "drive.test", "diffbot.urdf.xacro"):
    out[name] = roslib.packages.find_resource("diffbot_sim", name, rospack=rp)
print(json.dumps(out))
"""
# rosrun itself, non-interactively: one line and status 0 means it resolved the name to one executable
# (a devel-space relay plus its source script counts as one, as rosrun treats it).
ROSRUN = ("for n in bullet_sim teleop_key test_drive.py; do "
          "rosrun --prefix 'echo RESOLVED' diffbot_sim $n </dev/null || echo FAILED $n; done")


def probe(setup_bash):
    script = f"source {setup_bash} && python3 -c '{PROBE}' && {ROSRUN}"
    proc = subprocess.run(["bash", "-c", script], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    import json
    lines = proc.stdout.strip().splitlines()
    resolved = [line for line in lines if line.startswith(("RESOLVED", "FAILED"))]
    assert len(resolved) == 3 and all(line.startswith("RESOLVED") for line in resolved), proc.stdout
    return json.loads(next(line for line in lines if line.startswith("{")))


def assert_each_once(found, package_dir):
    assert os.path.realpath(found.pop("pkg")) == os.path.realpath(package_dir)
    for name, paths in found.items():
        assert len(paths) == 1, f"{name} resolves to {len(paths)} files: {paths}"


def test_no_link_points_at_an_ancestor():
    for dirpath, dirnames, filenames in os.walk(ROOT):
        dirnames[:] = [d for d in dirnames if d not in (".git", ".venv", "build", "devel")]
        for name in dirnames + filenames:
            path = os.path.join(dirpath, name)
            if os.path.islink(path):
                target = os.path.realpath(path)
                assert not (ROOT.startswith(target + os.sep) or target == ROOT or
                            os.path.realpath(dirpath).startswith(target + os.sep)), f"{path} -> {target} loops"


def test_names_resolve_once_in_catkin_ws():
    assert_each_once(probe(os.path.join(ROOT, "catkin_ws", "devel", "setup.bash")),
                     os.path.join(ROOT, "catkin_ws", "src", "diffbot_sim"))


def test_names_resolve_once_in_a_users_workspace(tmp_path):
    """A user clones the repository into an existing workspace's src/ and builds it there."""
    src = tmp_path / "ws" / "src"
    src.mkdir(parents=True)
    # What a clone holds: the tracked files, none of this checkout's build products, install spaces or venv.
    tracked = subprocess.run(["git", "-C", ROOT, "ls-files", "-z"], capture_output=True, check=True).stdout
    for name in filter(None, tracked.decode().split("\0")):
        origin, copy = os.path.join(ROOT, name), src / "diffbot_sim" / name
        copy.parent.mkdir(parents=True, exist_ok=True)
        if os.path.islink(origin):
            os.symlink(os.readlink(origin), copy)
        elif os.path.exists(origin):  # tracked but deleted in this checkout: a clone would have it; skip
            shutil.copy2(origin, copy)
    shutil.rmtree(src / "diffbot_sim" / "catkin_ws" / "src", ignore_errors=True)
    build = subprocess.run(["catkin_make", "-C", str(tmp_path / "ws"), f"-DPYTHON_EXECUTABLE={VENV_PY}"],
                           capture_output=True, text=True, timeout=300)
    assert build.returncode == 0, build.stdout[-2000:] + build.stderr[-2000:]
    assert_each_once(probe(str(tmp_path / "ws" / "devel" / "setup.bash")), src / "diffbot_sim")


def test_model_passes_check_urdf(tmp_path):
    if shutil.which("check_urdf") is None:
        pytest.fail("check_urdf (Debian liburdfdom-tools) is not installed: make setup installs it")
    sys.path.insert(0, os.path.join(ROOT, "src"))
    from diffbot_sim.description.model_files import load_file

    urdf = tmp_path / "diffbot.urdf"
    urdf.write_text(load_file(os.path.join(ROOT, "urdf", "diffbot.urdf.xacro")))
    proc = subprocess.run(["check_urdf", str(urdf)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "root Link: base_footprint" in proc.stdout


def test_test_nodes_are_executable_in_git():
    """A clean clone gets the modes git recorded, not this checkout's: rostest answers 'does not exist or is
    not executable' for a test node committed without its executable bit."""
    import re
    if not os.path.isdir(os.path.join(ROOT, ".git")):
        pytest.skip("not a git checkout")
    staged = subprocess.run(["git", "-C", ROOT, "ls-files", "-s", "tests/integration", "tests/rostest"],
                            capture_output=True, text=True, check=True).stdout
    modes = {line.split("\t")[1].rsplit("/", 1)[-1]: line.split()[0] for line in staged.splitlines()}
    named = set()
    for folder in ("tests/integration", "tests/rostest"):
        for test_file in os.listdir(os.path.join(ROOT, folder)):
            if test_file.endswith((".test", ".launch")):
                with open(os.path.join(ROOT, folder, test_file)) as handle:
                    named.update(re.findall(r'<test\b[^>]*\btype="([^"$]+\.py)"', handle.read()))
    assert named, "no test nodes found"
    not_executable = sorted(n for n in named if n in modes and modes[n] != "100755")
    assert not not_executable, f"test nodes committed without the executable bit: {not_executable}"


def test_every_launch_and_test_file_is_well_formed_xml():
    """roslaunch parses with xml.dom.minidom and refuses a file that is not well-formed (a '--' inside a comment
    is enough): the suites make test leaves out (nav_*, moveit_*) and the MoveIt config's launch files too."""
    import glob
    from xml.dom import minidom
    from xml.parsers.expat import ExpatError
    patterns = ("launch/*.launch", "tests/integration/*.test", "tests/rostest/*.test", "moveit_config/launch/*.launch*",
                "tests/data/**/*.launch")
    files = sorted({f for p in patterns for f in glob.glob(os.path.join(ROOT, p), recursive=True)})
    assert len(files) > 50, files
    bad = []
    for path in files:
        try:
            minidom.parse(path)
        except ExpatError as err:
            bad.append(f"{os.path.relpath(path, ROOT)}: {err}")
    assert not bad, bad
