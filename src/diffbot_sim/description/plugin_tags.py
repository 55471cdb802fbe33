"""Read a model's ``<gazebo><plugin>`` blocks the way gazebo_ros would, in both tag dialects.

Pure. The ROS 1 plugin (gazebo_plugins noetic) uses camelCase tags (``leftJoint``, ``wheelTorque``, ...); the
ROS 2 port uses snake_case (``left_joint``, ``max_wheel_torque``, ...) plus ``<ros><namespace>`` and topic
remapping. Both are turned into one dict of canonical snake_case keys holding only what the model *says*;
defaults and validation live in :mod:`diffbot_sim.config`, so a tag, a ROS parameter and a default are
merged in one place.
"""
import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import ConfigError, ModelError

DIFF_DRIVE = "libgazebo_ros_diff_drive.so"
JOINT_STATE = "libgazebo_ros_joint_state_publisher.so"
#: Plugins whose job this simulator does natively, so they are not reported as unsupported.
NATIVE = ("libgazebo_ros_control.so",)

# tag -> canonical key. Joint tags are lists (ROS 2 repeats left_joint/right_joint per wheel pair).
_ROS1_TAGS = {
    "leftJoint": "left_joints", "rightJoint": "right_joints", "wheelSeparation": "wheel_separation",
    "wheelDiameter": "wheel_diameter", "wheelTorque": "max_wheel_torque",
    "wheelAcceleration": "max_wheel_acceleration", "commandTopic": "command_topic",
    "odometryTopic": "odometry_topic", "odometryFrame": "odometry_frame", "robotBaseFrame": "robot_base_frame",
    "odometrySource": "odometry_source", "publishOdomTF": "publish_odom_tf", "publishTf": "publish_odom",
    "publishWheelJointState": "publish_wheel_joint_state", "updateRate": "update_rate",
    "robotNamespace": "namespace",
}
_ROS2_TAGS = {
    "left_joint": "left_joints", "right_joint": "right_joints", "wheel_separation": "wheel_separation",
    "wheel_diameter": "wheel_diameter", "max_wheel_torque": "max_wheel_torque",
    "max_wheel_acceleration": "max_wheel_acceleration", "update_rate": "update_rate",
    "odometry_frame": "odometry_frame", "robot_base_frame": "robot_base_frame",
    "odometry_source": "odometry_source", "publish_odom": "publish_odom", "publish_odom_tf": "publish_odom_tf",
    "covariance_x": "covariance_x", "covariance_y": "covariance_y", "covariance_yaw": "covariance_yaw",
    # Named in the ROS 2 plugin's header comment but never read by its code; users paste them, we honour them.
    "command_topic": "command_topic", "odometry_topic": "odometry_topic",
}
_LIST_KEYS = ("left_joints", "right_joints")
# Tags that are valid for the real plugin but change nothing here (TF of wheels comes from
# robot_state_publisher; legacyMode was removed in noetic).
_IGNORED = {"legacyMode", "rosDebugLevel", "publishWheelTF", "publish_wheel_tf", "num_wheel_pairs", "ros",
            "alwaysOn", "always_on"}


@dataclass
class PluginBlock:
    """What one plugin element says: canonical key -> raw text (or list of texts), and where it stands."""

    path: str
    dialect: str  # "ros1" or "ros2"
    values: dict[str, object] = field(default_factory=dict)
    unknown_tags: list[str] = field(default_factory=list)
    tags: dict[str, str] = field(default_factory=dict)  # canonical key -> the tag as written

    def tag(self, key):
        """The tag the model used for a canonical key (for error messages that point at the file)."""
        return self.tags.get(key, key)


@dataclass
class PluginElement:
    """A ``<plugin>`` of the model other than the diff drive and joint-state publisher (read here)."""

    filename: str  # normalised: libNAME.so
    name: str
    element: ET.Element
    path: str


@dataclass
class SensorElement:
    """A ``<sensor>`` of a ``<gazebo reference=link>`` block: its type, the link it is mounted on, and the
    ``<plugin>``s inside it (normalised filenames), which decide who simulates it."""

    type: str
    name: str
    link: str | None
    element: ET.Element
    path: str
    plugins: list[str] = field(default_factory=list)


@dataclass
class Plugins:
    diff_drive: PluginBlock | None = None
    joint_state: PluginBlock | None = None
    others: list[PluginElement] = field(default_factory=list)  # every other plugin, in model order
    sensors: list[SensorElement] = field(default_factory=list)  # every <sensor>, in model order
    unsupported: list[str] = field(default_factory=list)  # plugins and sensors we do not simulate
    warnings: list[str] = field(default_factory=list)


def plugin_filename(text):
    """A ``<plugin filename=...>`` as Gazebo finds it: the base name, as ``libNAME.so`` ("" for none)."""
    base = (text or "").strip().rsplit("/", 1)[-1]
    if base and not base.endswith(".so"):
        base = f"lib{base}.so" if not base.startswith("lib") else f"{base}.so"
    return base


def read_plugins(model, known=NATIVE, known_sensors=()):
    """Collect the plugin blocks of ``model`` (a RobotModel): the diff drive and joint-state publisher read
    into PluginBlocks, every other plugin as a PluginElement; those whose filename is not in ``known``
    (nor one of the two) are also named in ``unsupported``. Every ``<sensor>`` is collected in ``sensors``;
    one with no plugin whose filename is in ``known_sensors`` is named in ``unsupported`` too.

    Raises:
        ModelError: a plugin without a filename.
    """
    found = Plugins()
    for block in model.gazebo:
        for index, el in enumerate(block.element.findall("plugin"), start=1):
            filename = (el.get("filename") or "").strip()
            name = el.get("name") or filename
            path = f"{block.path}/plugin[@name='{name}']" if el.get("name") else f"{block.path}/plugin[{index}]"
            if not filename:
                raise ModelError("plugin has no filename", model.source, path)
            base = plugin_filename(filename)
            if base == DIFF_DRIVE:
                if found.diff_drive is not None:
                    found.warnings.append(f"{path}: a second diff-drive plugin is ignored")
                    continue
                found.diff_drive = _read_diff_drive(el, path)
            elif base == JOINT_STATE:
                if found.joint_state is not None:
                    found.warnings.append(f"{path}: a second joint-state plugin is ignored")
                    continue
                found.joint_state = _read_joint_state(el, path)
            else:
                found.others.append(PluginElement(base, name, el, path))
                if base not in known:
                    found.unsupported.append(f"plugin {name} ({filename})")
        for index, el in enumerate(block.element.iter("sensor"), start=1):
            sname, stype = el.get("name") or "", el.get("type") or ""
            path = f"{block.path}/sensor[@name='{sname}']" if sname else f"{block.path}/sensor[{index}]"
            plugins = []
            for plugin in el.findall("plugin"):
                base = plugin_filename(plugin.get("filename"))
                if base:
                    plugins.append(base)
            found.sensors.append(SensorElement(stype, sname, block.reference, el, path, plugins))
            if not any(p in known_sensors for p in plugins):
                found.unsupported.append(f"sensor {sname or '?'} (type {stype or '?'})")
    return found


def _dialect(el):
    tags = {child.tag for child in el}
    return "ros2" if tags & (set(_ROS2_TAGS) | {"ros"}) - {"command_topic", "odometry_topic"} else "ros1"


def _read_diff_drive(el, path):
    block = PluginBlock(path, _dialect(el))
    table = dict(_ROS1_TAGS)
    table.update(_ROS2_TAGS)
    for child in el:
        key = table.get(child.tag)
        text = (child.text or "").strip()
        if key is None:
            if child.tag not in _IGNORED:
                block.unknown_tags.append(child.tag)
            continue
        block.tags[key] = child.tag
        if key in _LIST_KEYS:
            block.values.setdefault(key, []).extend(_split_names(text))
        else:
            block.values[key] = text
    _read_ros_block(el, block, {"cmd_vel": "command_topic", "odom": "odometry_topic"})
    return block


def _read_joint_state(el, path):
    block = PluginBlock(path, _dialect(el))
    for child in el:
        text = (child.text or "").strip()
        if child.tag in ("jointName", "joint_name"):
            block.values.setdefault("joints", []).extend(_split_names(text))
        elif child.tag in ("updateRate", "update_rate"):
            block.values["update_rate"] = text
        elif child.tag == "robotNamespace":
            block.values["namespace"] = text
        elif child.tag not in _IGNORED:
            block.unknown_tags.append(child.tag)
    _read_ros_block(el, block, {"joint_states": "topic"})
    return block


def _read_ros_block(el, block, topics):
    """ROS 2 ``<ros>``: ``<namespace>``, ``<remapping>from:=to</remapping>``, ``<argument>--ros-args -r a:=b``."""
    ros = el.find("ros")
    if ros is None:
        return
    ns = ros.find("namespace")
    if ns is not None and (ns.text or "").strip():
        block.values["namespace"] = ns.text.strip()
    rules = []
    for child in ros:
        text = (child.text or "").strip()
        if child.tag == "remapping":
            rules.append(text)
        elif child.tag == "argument":
            rules.extend(tok for tok in re.split(r"\s+", text) if ":=" in tok)
    for rule in rules:
        src, _, dst = rule.partition(":=")
        src = src.strip().lstrip("~/")
        if src in topics and dst.strip():
            block.values[topics[src]] = dst.strip()


def _split_names(text):
    return [name for name in re.split(r"[\s,]+", text) if name]


def read_tags(element):
    """{tag: text} of a plugin element's direct children (both ``<a>v</a>`` and ``<a value="v"/>``)."""
    return {child.tag: tag_value(child) for child in element} if element is not None else {}


def vector(text, where, tag, count=3):
    """``count`` finite numbers from a tag's text."""
    try:
        values = tuple(float(v) for v in str(text).split())
    except ValueError:
        values = ()
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise ConfigError(f"<{tag}> of {where}", text, f"{count} finite numbers")
    return values
