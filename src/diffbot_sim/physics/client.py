"""PyBullet itself: imported here once, quietly, and its EGL renderer probed in a child process."""
import contextlib
import os


@contextlib.contextmanager
def quiet(fd):
    """Silence a file descriptor: PyBullet's C code prints a build banner on import (stderr) and
    link-merging chatter while loading (stdout), which would break the one-line error contract."""
    try:
        saved = os.dup(fd)
    except OSError:
        yield
        return
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), fd)
        yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)


try:
    with quiet(1), quiet(2):
        # The package's one import of them; the other physics modules take them from here (`as`: re-exported).
        import pybullet as pybullet
        import pybullet_data as pybullet_data
except ImportError as _missing:
    # One line and status 1, not a traceback: the usual cause is a node started by a Python other than the
    # venv's (the checkout's .venv, or an install space's PREFIX/.venv: docs/install.md).
    import sys

    raise SystemExit(f"diffbot_sim: the Python package {_missing.name or 'pybullet'} is missing from "
                     f"{sys.executable}: install it with `{sys.executable} -m pip install pybullet` "
                     "(requirements.txt pins the version), or run the node with the venv's Python "
                     "(docs/install.md)") from None


#: Probe program: load PyBullet's EGL plugin in a throw-away process. On a machine without an EGL library
#: the plugin ends the whole process (status 1, no exception), so it must never be tried in ours first.
_EGL_PROBE = ("import sys, pybullet as p\n"
              "c = p.connect(p.DIRECT)\n"
              "sys.exit(0 if p.loadPlugin(sys.argv[1], '_eglRendererPlugin', physicsClientId=c) >= 0 else 3)\n")


def egl_probe(plugin_path, timeout=30.0):
    """None when PyBullet's EGL plugin loads in a child process, else why not (one line)."""
    import subprocess
    import sys

    try:
        proc = subprocess.run([sys.executable, "-c", _EGL_PROBE, plugin_path], stdin=subprocess.DEVNULL,
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=timeout)
    except (OSError, subprocess.TimeoutExpired) as err:
        return f"the EGL probe did not finish ({err})"
    if proc.returncode == 3:
        return "PyBullet's EGL plugin did not load"
    if proc.returncode != 0:
        return (f"PyBullet's EGL plugin ended its process (status {proc.returncode}): no usable EGL/OpenGL "
                "library on this machine")
    return None
