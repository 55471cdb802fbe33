"""The rviz configuration ``view.launch`` opens, made from ``rviz/diffbot.rviz`` and what is running (pure).

A fixed rviz file cannot know which robot the simulator loaded: a LaserScan display without a laser stays
yellow ("no messages received"), a robot in ``robot1/`` needs prefixed frames, and the world decides where
the camera should look. So ``rosrun diffbot_sim view_rviz`` asks the master what the simulator publishes and
this module turns ``rviz/diffbot.rviz`` (a complete config for the seed robot, usable alone with
``rviz -d``) into the config for that run:

- per robot: a RobotModel (its ``robot_description``, its TF prefix) and an Odometry display (its odometry
  topic, arrows every 5 cm or 0.1 rad, the last 60 kept), one LaserScan display per LaserScan topic and one
  Image display per image topic (depth images left out) that the simulator publishes in its namespace;
- the fixed frame: the first robot's odometry frame (``odom``, or ``robot1/odom``);
- the view: top-down orthographic (``top``) or orbiting (``3d``), fitted to the world's static geometry and
  the robots' spawn points.

Display and property names are rviz 1.14's (``src/rviz/default_plugin/*.cpp``).
"""
import copy
from dataclasses import dataclass, field

import yaml

#: Size of rviz's 3-D view in ``rviz/diffbot.rviz``'s 1280 x 800 window with the Displays dock, in pixels
#: (measured under Xvfb: 900 x 709); the top view's scale is fitted to it.
PANEL = (900, 700)
#: Space kept around the fitted area [m].
MARGIN = 0.4
#: Half-width of the area shown when there is no world [m]: the robot and a few metres around it.
DEFAULT_HALF_EXTENT = 2.0
VIEWS = ("top", "3d")
#: Colour of laser points (rviz "r; g; b"): green, apart from the robot, the grey walls and the red arrows.
SCAN_COLOR = "0; 255; 0"


@dataclass
class RobotView:
    """What rviz shows of one robot.

    ``name``: '' for the one robot of a simulator without ``~robots``; ``prefix``: its TF prefix ('' or
    ``robot1``); ``description``: the parameter holding its URDF; ``odom_topic`` and ``odom_frame`` as the
    simulator publishes them; ``scans``/``images``: its LaserScan and Image topics; ``spawn`` (x, y) m in the
    world.
    """

    name: str
    prefix: str
    description: str
    odom_topic: str
    odom_frame: str
    scans: list[str] = field(default_factory=list)
    images: list[str] = field(default_factory=list)
    spawn: tuple[float, float] = (0.0, 0.0)


def load_template(path):
    """The rviz config at ``path`` as a dict (rviz configs are YAML)."""
    with open(path) as f:
        return yaml.safe_load(f)


def dump(config):
    """``config`` as rviz config text (YAML, keys in the order given: rviz reads any order, people don't)."""
    return yaml.safe_dump(config, sort_keys=False, default_flow_style=False, width=120)


def sensor_topics(published, namespace=""):
    """The LaserScan and image topics of one robot, from the simulator's published topics.

    Args:
        published: ``[(topic, type)]``: what the simulator node publishes.
        namespace: the robot's namespace (``/robot1``); '' takes every topic.

    Returns:
        ``(scans, images)``: sorted topic lists. Images are ``sensor_msgs/Image`` topics that are not depth
        images (a topic with a ``depth`` segment): a depth image shows as grey noise in an Image display.
    """
    prefix = namespace.rstrip("/") + "/" if namespace else "/"
    scans, images = [], []
    for topic, kind in published:
        if not topic.startswith(prefix):
            continue
        if kind == "sensor_msgs/LaserScan":
            scans.append(topic)
        elif kind == "sensor_msgs/Image" and "depth" not in topic.split("/"):
            images.append(topic)
    return sorted(scans), sorted(images)


def fit_top_view(bounds, panel=PANEL, margin=MARGIN):
    """Centre and scale of a top-down orthographic view showing ``bounds``.

    Args:
        bounds: ``(xmin, ymin, xmax, ymax)`` m in the fixed frame.
        panel: the 3-D view's (width, height) in pixels.
        margin: space kept on each side [m].

    Returns:
        ``(x, y, scale)``: the view's centre [m] and rviz's TopDownOrtho ``Scale`` [pixels per metre].
    """
    xmin, ymin, xmax, ymax = bounds
    width, height = (xmax - xmin) + 2 * margin, (ymax - ymin) + 2 * margin
    scale = min(panel[0] / max(width, 1e-3), panel[1] / max(height, 1e-3))
    return 0.5 * (xmin + xmax), 0.5 * (ymin + ymax), float(scale)


def view_bounds(world_bounds, robots):
    """What the view must show: the world's static geometry (``(xmin, ymin, xmax, ymax)`` or None) and
    every robot's spawn point with DEFAULT_HALF_EXTENT around it."""
    xs, ys = [], []
    if world_bounds is not None:
        xs += [world_bounds[0], world_bounds[2]]
        ys += [world_bounds[1], world_bounds[3]]
    for robot in robots:
        x, y = robot.spawn
        d = 0.0 if world_bounds is not None else DEFAULT_HALF_EXTENT
        xs += [x - d, x + d]
        ys += [y - d, y + d]
    if not xs:
        xs, ys = [-DEFAULT_HALF_EXTENT, DEFAULT_HALF_EXTENT], [-DEFAULT_HALF_EXTENT, DEFAULT_HALF_EXTENT]
    return min(xs), min(ys), max(xs), max(ys)


def build(template, robots, world_bounds=None, view="top", markers_topic="/world_markers"):
    """The rviz config for ``robots`` from ``template`` (``rviz/diffbot.rviz`` loaded).

    The template's Grid, World (MarkerArray) and TF displays are kept; its RobotModel and Odometry displays
    are the pattern copied once per robot; LaserScan and Image displays are added per topic.

    Args:
        template: the template config (dict).
        robots: list of RobotView, at least one.
        world_bounds: the world's static geometry extent in the fixed frame, or None.
        view: ``top`` (orthographic, from above: what the headless checks measure) or ``3d`` (orbit).
        markers_topic: the world's MarkerArray topic.

    Returns:
        the config dict.

    Raises:
        ValueError: no robot, an unknown view, or a template without RobotModel or Odometry display.
    """
    if not robots:
        raise ValueError("no robot to show")
    if view not in VIEWS:
        raise ValueError(f"view {view!r}: expected one of {', '.join(VIEWS)}")
    config = copy.deepcopy(template)
    manager = config["Visualization Manager"]
    patterns = {d.get("Class"): d for d in manager["Displays"]}
    for needed in ("rviz/RobotModel", "rviz/Odometry"):
        if needed not in patterns:
            raise ValueError(f"the rviz template has no {needed} display")
    displays = []
    for display in manager["Displays"]:
        if display.get("Class") == "rviz/MarkerArray":
            display["Marker Topic"] = markers_topic
        if display.get("Class") not in ("rviz/RobotModel", "rviz/Odometry"):
            displays.append(display)
    many = len(robots) > 1
    for robot in robots:
        label = (robot.name + " ") if many else ""
        model = copy.deepcopy(patterns["rviz/RobotModel"])
        model.update({"Name": label + "RobotModel", "Robot Description": robot.description,
                      "TF Prefix": robot.prefix})
        odom = copy.deepcopy(patterns["rviz/Odometry"])
        odom.update({"Name": label + "Odometry", "Topic": robot.odom_topic})
        displays += [model, odom]
        for topic in robot.scans:
            displays.append(_scan_display(label + "LaserScan " + topic, topic))
        for topic in robot.images:
            displays.append(_image_display(label + "Image " + topic, topic))
    manager["Displays"] = displays
    manager["Global Options"]["Fixed Frame"] = robots[0].odom_frame
    x, y, scale = fit_top_view(view_bounds(world_bounds, robots))
    manager["Views"]["Current"] = _top_view(x, y, scale) if view == "top" else _orbit_view(x, y, scale)
    return config


def _scan_display(name, topic):
    return {
        "Alpha": 1, "Autocompute Intensity Bounds": True, "Autocompute Value Bounds": {"Max Value": 10,
                                                                                        "Min Value": -10,
                                                                                        "Value": True},
        "Axis": "Z", "Channel Name": "intensity", "Class": "rviz/LaserScan", "Color": SCAN_COLOR,
        "Color Transformer": "FlatColor", "Decay Time": 0, "Enabled": True, "Invert Rainbow": False,
        "Max Color": "255; 255; 255", "Min Color": "0; 0; 0", "Name": name, "Position Transformer": "XYZ",
        "Queue Size": 10, "Selectable": True, "Size (Pixels)": 3, "Size (m)": 0.06, "Style": "Flat Squares",
        "Topic": topic, "Unreliable": False, "Use Fixed Frame": True, "Use rainbow": True, "Value": True,
    }


def _image_display(name, topic):
    return {
        "Class": "rviz/Image", "Enabled": True, "Image Topic": topic, "Max Value": 1, "Median window": 5,
        "Min Value": 0, "Name": name, "Normalize Range": True, "Queue Size": 2, "Transport Hint": "raw",
        "Unreliable": False, "Value": True,
    }


def _top_view(x, y, scale):
    return {"Angle": 0, "Class": "rviz/TopDownOrtho", "Enable Stereo Rendering": _NO_STEREO,
            "Invert Z Axis": False, "Name": "Current View", "Near Clip Distance": 0.01,
            "Scale": round(scale, 3), "Target Frame": "<Fixed Frame>", "X": round(x, 4), "Y": round(y, 4)}


def _orbit_view(x, y, scale):
    # The top view's width in metres, seen from far enough that a 45-degree field of view holds it.
    distance = max(2.0, 1.3 * PANEL[0] / scale)
    return {"Class": "rviz/Orbit", "Distance": round(distance, 3), "Enable Stereo Rendering": _NO_STEREO,
            "Focal Point": {"X": round(x, 4), "Y": round(y, 4), "Z": 0}, "Focal Shape Fixed Size": True,
            "Focal Shape Size": 0.05, "Invert Z Axis": False, "Name": "Current View",
            "Near Clip Distance": 0.01, "Pitch": 0.9, "Target Frame": "<Fixed Frame>", "Yaw": 3.9}


_NO_STEREO = {"Stereo Eye Separation": 0.06, "Stereo Focal Distance": 1, "Swap Stereo Eyes": False,
              "Value": False}


def spawn_of(robot_param):
    """(x, y) of a ``~robots`` entry (a name alone spawns at the origin)."""
    if isinstance(robot_param, dict):
        return float(robot_param.get("x", 0.0)), float(robot_param.get("y", 0.0))
    return 0.0, 0.0


def prefix_of(frame):
    """The TF prefix of a prefixed frame (``robot1/odom`` -> ``robot1``; ``odom`` -> '')."""
    frame = frame.lstrip("/")
    return frame.rsplit("/", 1)[0] if "/" in frame else ""


def description_param(namespace, has_param):
    """The robot_description parameter rviz should read: ``<namespace>/robot_description`` when it is
    set (``spawn_model`` style), else the shared ``robot_description`` (``multi.launch``)."""
    if namespace:
        own = namespace.rstrip("/") + "/robot_description"
        if has_param(own):
            return own
    return "robot_description"


__all__ = ["RobotView", "build", "dump", "fit_top_view", "load_template", "sensor_topics", "view_bounds",
           "spawn_of", "prefix_of", "description_param", "PANEL", "VIEWS"]
