"""Headless pictures: an Xvfb server, its windows, screenshots, and what is in them (no rospy).

The rviz and PyBullet checks look at real windows on a real X server: Xvfb (a virtual screen, Mesa's
llvmpipe renders the OpenGL), ``xwininfo`` (x11-utils) for the window tree, ImageMagick's ``import`` for
the pixels. The picture analysis at the bottom is plain numpy on RGB arrays, unit-tested with made-up ones.

What a window tree says about rviz (measured on rviz 1.14 under Xvfb): each Ogre render panel (the 3-D view,
each Image display) is a window with no name inside the rviz window; every Qt widget is named ``rviz``.
"""
import os
import re
import shutil
import subprocess
import time
from dataclasses import dataclass

import numpy as np

from diffbot_sim.waiting import wait_for

SCREEN = (1280, 800)
#: rviz's text colours in the Displays panel (rviz/properties/status_property.cpp, display.cpp): a display
#: whose status is Ok is written in blue, Warn in orange, Error in red.
STATUS_OK, STATUS_WARN, STATUS_ERROR = (40, 120, 197), (192, 128, 0), (192, 32, 32)


class XvfbUnavailable(Exception):
    """Xvfb is not installed or did not start: the headless picture checks cannot run here."""


class Xvfb:
    """An Xvfb server on a display number it picks itself (``-displayfd``: no race with another one).

    Use as a context manager; ``display`` is ``":N"``. Stopped (SIGTERM, then SIGKILL) on exit.
    """

    def __init__(self, size=SCREEN, timeout=15.0):
        self.size, self.timeout = size, timeout
        self.proc, self.display = None, None

    def __enter__(self):
        if shutil.which("Xvfb") is None:
            raise XvfbUnavailable("Xvfb is not installed (Debian package xvfb; make setup installs it)")
        read_fd, write_fd = os.pipe()
        try:
            self.proc = subprocess.Popen(
                ["Xvfb", "-displayfd", str(write_fd), "-screen", "0", f"{self.size[0]}x{self.size[1]}x24",
                 "-nolisten", "tcp", "-noreset"],
                pass_fds=(write_fd,), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
        finally:
            os.close(write_fd)
        number = b""
        deadline = time.monotonic() + self.timeout
        with os.fdopen(read_fd, "rb") as pipe:
            os.set_blocking(pipe.fileno(), False)
            while not number.endswith(b"\n"):
                if self.proc.poll() is not None:
                    err = self.proc.stderr.read().decode(errors="replace").strip().splitlines()
                    raise XvfbUnavailable(f"Xvfb exited {self.proc.returncode}: {err[-1] if err else ''}")
                if time.monotonic() > deadline:
                    self.stop()
                    raise XvfbUnavailable(f"Xvfb gave no display number within {self.timeout:g} s")
                chunk = pipe.read()
                if chunk:
                    number += chunk
                else:
                    time.sleep(0.02)
        self.display = ":" + number.decode().strip()
        wait_for(lambda: _xdpyinfo_ok(self.display), self.timeout, f"Xvfb {self.display} to answer", 0.1,
                 error=AssertionError)
        return self

    def stop(self):
        if self.proc is not None and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(5)

    def __exit__(self, *exc):
        self.stop()
        return False

    def env(self, base=None):
        """``base`` (default os.environ) with DISPLAY set to this server."""
        env = dict(os.environ if base is None else base)
        env["DISPLAY"] = self.display
        return env


def _xdpyinfo_ok(display):
    try:
        return subprocess.run(["xdpyinfo", "-display", display], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, timeout=5).returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        return False


@dataclass
class Window:
    """One X window: id, name ('' when it has none), size and absolute position (pixels), tree depth."""

    wid: str
    name: str
    width: int
    height: int
    x: int
    y: int
    depth: int
    children: int = 0

    @property
    def area(self):
        return self.width * self.height

    def box(self):
        """``(x0, y0, x1, y1)``: its pixels on the screen, x1/y1 exclusive."""
        return self.x, self.y, self.x + self.width, self.y + self.height


_LINE = re.compile(r'^(?P<indent>\s*)(?P<wid>0x[0-9a-f]+) (?:"(?P<name>.*?)":|\(has no name\)).*?'
                   r'(?P<w>\d+)x(?P<h>\d+)[+-]-?\d+[+-]-?\d+\s+\+(?P<ax>-?\d+)\+(?P<ay>-?\d+)\s*$')


def parse_tree(text):
    """The windows ``xwininfo -root -tree`` lists, in its order, with their depth (by indentation)."""
    windows = []
    for line in text.splitlines():
        m = _LINE.match(line)
        if not m:
            continue
        windows.append(Window(m["wid"], m["name"] or "", int(m["w"]), int(m["h"]), int(m["ax"]), int(m["ay"]),
                              len(m["indent"]) // 3))
    for i, window in enumerate(windows):
        j = i + 1
        while j < len(windows) and windows[j].depth > window.depth:
            j += 1
        window.children = j - i - 1
    return windows


def subtree(windows, top):
    """The windows below ``top`` (a Window of ``windows``), ``top`` excluded."""
    i = windows.index(top)
    return windows[i + 1:i + 1 + top.children]


def list_windows(display):
    """Every window on ``display`` (``xwininfo -root -tree``)."""
    out = subprocess.run(["xwininfo", "-root", "-tree", "-display", display], capture_output=True, text=True,
                         timeout=10)
    return parse_tree(out.stdout) if out.returncode == 0 else []


def find_window(display, pattern):
    """The first top-level-ish window whose name matches ``pattern`` (a regex) and has a real size, or None."""
    rx = re.compile(pattern)
    for window in list_windows(display):
        if rx.search(window.name) and window.width > 100 and window.height > 100:
            return window
    return None


def screenshot(display, window="root"):
    """The screen (or one window, by id) as an (H, W, 3) uint8 RGB array, through ImageMagick's import."""
    import io

    from PIL import Image

    out = subprocess.run(["import", "-display", display, "-window", window, "png:-"], capture_output=True,
                         timeout=30)
    if out.returncode != 0:
        raise AssertionError(f"import -window {window} failed: {out.stderr.decode(errors='replace').strip()}")
    return np.asarray(Image.open(io.BytesIO(out.stdout)).convert("RGB"))


def save_png(image, path, max_width=None, exact=False):
    """Write an RGB array as PNG, scaled down to ``max_width`` pixels when wider; palette-reduced to 128
    colours (screenshots stay small) unless ``exact``."""
    from PIL import Image

    picture = Image.fromarray(np.asarray(image, dtype=np.uint8))
    if max_width and picture.width > max_width:
        picture = picture.resize((max_width, round(picture.height * max_width / picture.width)), Image.LANCZOS)
    if not exact:
        picture = picture.quantize(colors=128, method=Image.MEDIANCUT, dither=Image.NONE)
    picture.save(path, optimize=True)


# ------------------------------------------------------------------------------------------ analysis

def crop(image, box):
    """The pixels of ``box`` (x0, y0, x1, y1) of ``image``, clipped to it."""
    x0, y0, x1, y1 = box
    h, w = image.shape[:2]
    return image[max(0, y0):min(h, y1), max(0, x0):min(w, x1)]


def count_color(image, rgb, mask=None):
    """How many pixels of ``image`` are exactly ``rgb`` (where ``mask`` is true, when given)."""
    hit = np.all(image == np.asarray(rgb, dtype=image.dtype), axis=2)
    if mask is not None:
        hit &= mask
    return int(hit.sum())


def status_colors(image, mask=None):
    """``{"ok": n, "warn": n, "error": n}``: pixels in rviz's status text colours (see STATUS_*)."""
    return {name: count_color(image, rgb, mask)
            for name, rgb in (("ok", STATUS_OK), ("warn", STATUS_WARN), ("error", STATUS_ERROR))}


def rows_of_color(image, rgb):
    """The row numbers (y) that hold ``rgb`` pixels: where a warning or error sits in the Displays list."""
    return sorted(set(np.nonzero(np.all(image == np.asarray(rgb, dtype=image.dtype), axis=2))[0].tolist()))


def changed(a, b, threshold=40):
    """Boolean mask of pixels whose RGB differ by more than ``threshold`` (sum of absolute differences)."""
    return np.abs(a.astype(int) - b.astype(int)).sum(axis=2) > threshold


def blob(mask):
    """``(count, (u, v) centroid, (u0, v0, u1, v1) bounding box)`` of the true pixels of ``mask``, or
    ``(0, None, None)`` when there are none. u is the column (x), v the row (y)."""
    vs, us = np.nonzero(mask)
    if len(us) == 0:
        return 0, None, None
    return len(us), (float(us.mean()), float(vs.mean())), (int(us.min()), int(vs.min()), int(us.max()),
                                                           int(vs.max()))


def patch(mask, radius):
    """The main patch of true pixels of ``mask``, robust to stray ones elsewhere: centred on the median
    pixel, the pixels within ``radius`` of it. Returns ``(count, (u, v) centroid, stray)``, ``stray``
    counting the true pixels outside; ``(0, None, 0)`` when there are none."""
    vs, us = np.nonzero(mask)
    if len(us) == 0:
        return 0, None, 0
    mu, mv = float(np.median(us)), float(np.median(vs))
    near = (us - mu) ** 2 + (vs - mv) ** 2 <= radius ** 2
    return int(near.sum()), (float(us[near].mean()), float(vs[near].mean())), int((~near).sum())


def greenish(image, margin=40):
    """Pixels whose green exceeds both red and blue by ``margin``: laser points, also where they blend into
    what is next to them."""
    img = image.astype(int)
    return (img[:, :, 1] - np.maximum(img[:, :, 0], img[:, :, 2])) > margin


def top_view_pixel(x, y, panel, center, scale):
    """Where rviz's TopDownOrtho view (angle 0) draws the point ``(x, y)`` m of the fixed frame.

    Args:
        panel: the 3-D view's Window (or ``(x0, y0, x1, y1)``) on the screen.
        center: the view's ``(X, Y)`` m (its centre).
        scale: its ``Scale``, pixels per metre.

    Returns:
        (u, v) screen pixel: +x to the right, +y up.
    """
    x0, y0, x1, y1 = panel.box() if isinstance(panel, Window) else panel
    return (x0 + (x1 - x0) / 2.0 + scale * (x - center[0]), y0 + (y1 - y0) / 2.0 - scale * (y - center[1]))


def project(point, view, projection, size):
    """Where an OpenGL camera (column-major 4x4 ``view`` and ``projection``, as PyBullet gives them) draws
    the world ``point`` in a window of ``size`` (width, height): (u, v) pixels, v down; None when the point
    is behind the camera (dividing by a negative w would put it on the screen, mirrored)."""
    v = np.asarray(view, dtype=float).reshape(4, 4).T
    p = np.asarray(projection, dtype=float).reshape(4, 4).T
    clip = p @ v @ np.array([point[0], point[1], point[2], 1.0])
    if clip[3] <= 0.0:
        return None
    ndc = clip[:3] / clip[3]
    return ((ndc[0] + 1.0) / 2.0 * size[0], (1.0 - ndc[1]) / 2.0 * size[1])


#: PyBullet's window as it opens (pybullet 3.2, getDebugVisualizerCamera measured under Xvfb): 1024 x 768,
#: camera aimed at the world origin from 5 m, yaw 50 deg, pitch -35 deg, z up; its 3-D view fills the window
#: (the Explorer/Params/log panels are drawn over it).
PYBULLET_WINDOW = (1024, 768)
PYBULLET_CAMERA = {"target": (0.0, 0.0, 0.0), "distance": 5.0, "yaw": 50.0, "pitch": -35.0}
#: The part of that window's 3-D view no panel covers (x0, y0, x1, y1; measured: the sky of an empty scene
#: spans columns 254-773, rows 22-645).
PYBULLET_SCENE_BOX = (254, 22, 774, 646)


def orbit_camera(target, distance, yaw, pitch, size, near=0.01, far=1000.0):
    """``(view, projection)`` of PyBullet's debug-window camera (column-major 16-tuples, as
    ``getDebugVisualizerCamera`` returns them; for :func:`project`), z up.

    PyBullet's SimpleCamera: at yaw 0 and pitch 0 the eye is ``distance`` m on -y of ``target`` looking
    along +y; yaw turns it about z (degrees, counter-clockwise seen from above), pitch below 0 raises the eye
    (looking down). The frustum spans 90 deg vertically, ``width / height`` wider horizontally.
    Checked against getDebugVisualizerCamera for the defaults (PYBULLET_CAMERA) to 1e-6."""
    yaw_r, pitch_r = np.radians(yaw), np.radians(pitch)
    forward = np.array([-np.sin(yaw_r) * np.cos(pitch_r), np.cos(yaw_r) * np.cos(pitch_r), np.sin(pitch_r)])
    eye = np.asarray(target, dtype=float) - distance * forward
    right = np.cross(forward, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = right, up, -forward
    view[:3, 3] = -view[:3, :3] @ eye
    aspect = size[0] / float(size[1])
    projection = np.zeros((4, 4))
    projection[0, 0], projection[1, 1] = 1.0 / aspect, 1.0
    projection[2, 2], projection[2, 3] = -(far + near) / (far - near), -2.0 * far * near / (far - near)
    projection[3, 2] = -1.0
    return tuple(view.T.ravel()), tuple(projection.T.ravel())


def pybullet_pixel(point, size=PYBULLET_WINDOW, camera=None):
    """Where PyBullet's window (of ``size``, its default camera unless ``camera``, a PYBULLET_CAMERA-like
    dict) draws the world ``point``: (u, v) pixels of the window, or None when behind the camera."""
    cam = dict(PYBULLET_CAMERA, **(camera or {}))
    view, projection = orbit_camera(cam["target"], cam["distance"], cam["yaw"], cam["pitch"], size)
    return project(point, view, projection, size)


#: Hue ranges (degrees, HSV) of :func:`saturated`'s classes. PyBullet's palette, whose colours it gives
#: bodies that have none (examples/OpenGLWindow/GLInstancingRenderer / OpenGLGuiHelper ``sColors``): red
#: (219, 50, 54) hue 359, yellow (244, 194, 13) 47, green (60, 186, 84) 131, blue (72, 133, 237) 218.
HUES = {"red": (-20.0, 20.0), "yellow": (30.0, 70.0), "green": (90.0, 170.0), "blue": (190.0, 250.0)}


def hue(image):
    """HSV hue of every pixel of an RGB array, degrees in [-60, 300) (reds on both sides of 0)."""
    img = image.astype(float)
    r, g, b = img[:, :, 0], img[:, :, 1], img[:, :, 2]
    hi, lo = img.max(axis=2), img.min(axis=2)
    spread = np.where(hi > lo, hi - lo, 1.0)
    return np.where(r == hi, 60.0 * (g - b) / spread,
                    np.where(g == hi, 120.0 + 60.0 * (b - r) / spread, 240.0 + 60.0 * (r - g) / spread))


def saturated(image, min_saturation=0.5, min_value=60):
    """``{"red", "yellow", "green", "blue": mask}``: strongly coloured pixels by hue (HUES). Strong: the
    brightest channel over ``min_value`` and the spread (brightest - darkest) over ``min_saturation`` of it
    (HSV's V and S), so lit and shaded faces of one colour count alike. Grey, white and the pale blue-grey of
    PyBullet's floor and sky (S about 0.3) are in no class."""
    img = image.astype(int)
    hi, lo = img.max(axis=2), img.min(axis=2)
    strong = (hi > min_value) & (hi - lo > min_saturation * hi)
    h = hue(image)
    return {name: strong & (h >= low) & (h < high) for name, (low, high) in HUES.items()}


def color_counts(image, **kw):
    """``{"red": n, "yellow": n, "green": n, "blue": n}``: pixel counts of :func:`saturated`'s classes."""
    return {name: int(mask.sum()) for name, mask in saturated(image, **kw).items()}


__all__: list[str] = ["Xvfb", "XvfbUnavailable", "Window", "parse_tree", "subtree", "list_windows", "find_window",
                      "screenshot", "save_png", "crop", "count_color", "status_colors", "rows_of_color",
                      "changed", "blob", "patch", "greenish", "top_view_pixel", "project", "orbit_camera",
           "pybullet_pixel", "PYBULLET_CAMERA", "PYBULLET_WINDOW", "saturated", "color_counts", "hue", "HUES",
           "PYBULLET_SCENE_BOX"]
