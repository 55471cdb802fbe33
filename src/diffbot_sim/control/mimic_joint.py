"""Mimic joints (pure): roboticsgroup's MimicJointPlugin and URDF ``<mimic>``.

Gazebo classic ignores URDF ``<mimic>`` in its physics (sdformat 9 has no mimic code), so Gazebo models that
need a coupled joint (a gripper's second finger) load ``libroboticsgroup_gazebo_mimic_joint_plugin.so``
(roboticsgroup/roboticsgroup_gazebo_plugins master 509a32e, deprecated) or
``libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so`` (roboticsgroup/roboticsgroup_upatras_gazebo_plugins
master 15187ab). Both ``src/mimic_joint_plugin.cpp`` have the same logic, reproduced here:

* Tags (:func:`mimic_config`): ``joint`` (the master) and ``mimicJoint`` are required (without them upstream
  logs ``No joint element present. MimicJointPlugin could not be loaded.`` and stays inactive), as are the
  joints themselves in the model; ``multiplier`` 1.0, ``offset`` 0.0, ``sensitiveness`` 0.0; ``maxEffort``
  defaults to the mimic joint's effort limit (Gazebo's ``GetEffortLimit(0)``, -1 when the model has none);
  ``robotNamespace`` "" (spawn_model injects one). ``<hasPID>``: its *presence* switches to a PID; its text
  is the PID's parameter namespace, relative to robotNamespace unless absolute; empty means
  ``gazebo_ros_control/pid_gains/<mimicJoint>``.
* Every physics step (:meth:`MimicCore.update`): ``target = master * multiplier + offset``; nothing happens
  while ``|target - mimic| < sensitiveness`` (so also when a position is NaN); otherwise, without PID, the mimic
  joint is set to ``target`` (Gazebo's kinematic ``SetPosition(0, target, true)``, which clamps to the joint
  limits), and with PID the effort ``clamp(pid(target - mimic, dt), -maxEffort, maxEffort)`` is applied.
  The coupling is one-way. Without PID upstream also caps the joint motor once with ``fmax = maxEffort``.
* ``<hasPID>`` whose namespace has no ``p``: upstream logs "No p gain specified for pid" and runs an all-zero
  PID: the mimic joint gets effort 0 every step (it goes limp). Reproduced (``gains=None``).
* The clamp is ignition::math's ``max(min(v, hi), lo)``: with a negative maxEffort (Gazebo's -1 "no limit")
  it returns ``-maxEffort`` whatever the PID says, a constant push. Reproduced, with a note in ``notes``.

The PID's ``dt`` is the physics max step size (upstream caches it in a function-static on the first call,
shared by every instance); the caller passes it. :func:`urdf_mimic_target` is for mimic joints no plugin
drives: ``robot_state_publisher`` computes their TF the same way when they are absent from /joint_states.
"""
import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import NamedTuple

from diffbot_sim.control.pid import Pid, PidGains
from diffbot_sim.errors import ConfigError, PluginNotLoaded
from diffbot_sim.values import tag_number

PLUGIN_FILENAMES = ("libroboticsgroup_gazebo_mimic_joint_plugin.so",
                    "libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so")
DEFAULT_PID_NAMESPACE = "gazebo_ros_control/pid_gains/"


@dataclass(frozen=True)
class MimicConfig:
    """One MimicJointPlugin, validated. Positions are rad or m; ``max_effort`` N·m or N.

    ``pid_namespace`` is the resolved parameter namespace of the PID (e.g.
    ``/my_gen3/gazebo_ros_control/pid_gains/right_finger_joint``), None without ``<hasPID>``; the caller
    reads it and passes :func:`diffbot_sim.control.pid.pid_gains` of it to :class:`MimicCore`.
    """

    path: str
    joint: str
    mimic_joint: str
    multiplier: float = 1.0
    offset: float = 0.0
    sensitiveness: float = 0.0
    max_effort: float = -1.0
    has_pid: bool = False
    pid_namespace: str | None = None
    robot_namespace: str = ""
    notes: tuple[str, ...] = ()


class MimicAction(NamedTuple):
    """What to do to the mimic joint this step: ``kind`` "position" (set it kinematically to ``value``, rad or
    m) or "effort" (apply ``value``, N·m or N)."""

    kind: str
    value: float


def _tag_texts(tags):
    """{tag: stripped text} from a dict of tags or the ``<plugin>`` element itself (first of each tag, as
    sdformat's GetElement finds it)."""
    if isinstance(tags, ET.Element):
        texts = {}
        for child in tags:
            texts.setdefault(child.tag, (child.text or "").strip())
        return texts
    return {key: ("" if value is None else str(value).strip()) for key, value in tags.items()}


def _resolve_namespace(robot_namespace, name):
    """roscpp's resolution of ``NodeHandle(NodeHandle(robot_namespace), name)``: absolute names stay; others
    go under the robot namespace (itself under the root). Repeated and trailing slashes are dropped."""
    if not name.startswith("/"):
        name = f"/{robot_namespace}/{name}"
    parts = [part for part in name.split("/") if part]
    return "/" + "/".join(parts)


def mimic_config(tags: Mapping[str, str] | ET.Element, path: str,
                 effort_limit_of: Callable[[str], float]) -> MimicConfig:
    """Read one MimicJointPlugin's tags.

    Args:
        tags: {tag: text} of the ``<plugin>`` element's children (``<hasPID/>`` as ``"hasPID": ""``), or the
            element itself.
        path: the plugin element's location, for messages (``/robot/gazebo[3]/plugin[@name='mimic']``).
        effort_limit_of: joint name -> that joint's effort limit (N·m or N; -1 for none, as Gazebo); raises
            KeyError for a joint the model does not have.

    Raises:
        PluginNotLoaded: ``joint`` / ``mimicJoint`` missing, or naming a joint the model lacks (upstream:
            ROS_ERROR and the plugin stays inactive; the caller warns and goes on without it).
        ConfigError: a number tag without a leading number, or a ``~`` PID namespace (roscpp throws).
    """
    texts = _tag_texts(tags)
    notes: list[str] = []
    robot_namespace = texts.get("robotNamespace", "")
    if "joint" not in texts:
        raise PluginNotLoaded("No joint element present. MimicJointPlugin could not be loaded.", element=path)
    if "mimicJoint" not in texts:
        raise PluginNotLoaded("No mimicJoint element present. MimicJointPlugin could not be loaded.",
                              element=path)
    joint, mimic_joint = texts["joint"], texts["mimicJoint"]
    has_pid = "hasPID" in texts
    pid_namespace = None
    if has_pid:
        name = texts["hasPID"] or DEFAULT_PID_NAMESPACE + mimic_joint
        if name.startswith("~"):
            raise ConfigError(f"<hasPID> of {path}", name, "a PID namespace without '~' (roscpp refuses it)")
        pid_namespace = _resolve_namespace(robot_namespace, name)

    def number(tag, default):
        return tag_number(f"<{tag}> of {path}", texts.get(tag, default), notes)

    multiplier, offset = number("multiplier", 1.0), number("offset", 0.0)
    sensitiveness = number("sensitiveness", 0.0)
    limits = {}
    for role, name in (("joint", joint), ("(mimic) joint", mimic_joint)):
        try:
            limits[name] = effort_limit_of(name)
        except KeyError:
            raise PluginNotLoaded(f'No {role} named "{name}". MimicJointPlugin could not be loaded.',
                                  element=path) from None
    max_effort = number("maxEffort", 0.0) if "maxEffort" in texts else float(limits[mimic_joint])
    if has_pid and max_effort < 0:
        notes.append(f"{path}: maxEffort {max_effort:g} < 0: upstream's clamp then always applies "
                     f"{-max_effort:g} to {mimic_joint}, whatever the PID says (reproduced)")
    return MimicConfig(path=path, joint=joint, mimic_joint=mimic_joint, multiplier=multiplier, offset=offset,
                       sensitiveness=sensitiveness, max_effort=max_effort, has_pid=has_pid,
                       pid_namespace=pid_namespace, robot_namespace=robot_namespace, notes=tuple(notes))


def ignition_clamp(value, low, high):
    """ignition::math::clamp: ``max(min(value, high), low)`` (``low`` wins when ``low > high``)."""
    return max(min(value, high), low)


class MimicCore:
    """One mimic coupling, stepped with the physics.

    Args:
        config: the :class:`MimicConfig`.
        gains: the PID gains read from ``config.pid_namespace``; None there (no ``p``) means upstream's all-zero
            PID. Ignored without ``<hasPID>``.
    """

    def __init__(self, config: MimicConfig, gains: PidGains | None = None):
        self.config = config
        self._pid = Pid(gains or PidGains(p=0.0)) if config.has_pid else None

    def target(self, master_position):
        """Where the mimic joint should be: ``master * multiplier + offset`` (rad or m)."""
        return master_position * self.config.multiplier + self.config.offset

    def update(self, master_position, mimic_position, dt) -> MimicAction | None:
        """This step's action on the mimic joint, or None while within ``sensitiveness`` (or a position is NaN).

        Args:
            master_position, mimic_position: joint positions now (rad or m). dt: the physics max step size (s).
        """
        if self._pid is not None:
            effort = self.effort(master_position, mimic_position, dt)
            return None if effort is None else MimicAction("effort", effort)
        target = self.target(master_position)
        if not abs(target - mimic_position) >= self.config.sensitiveness:
            return None
        return MimicAction("position", target)

    def effort(self, master_position, mimic_position, dt) -> float | None:
        """With ``<hasPID>``: :meth:`update`'s effort (N·m or N) as a number, or None when it does nothing (the
        plugin's every step, without building an action). Without it: None (the joint is positioned instead)."""
        config, pid = self.config, self._pid
        if pid is None:  # no <hasPID>: the joint is positioned (update), never pushed
            return None
        target = master_position * config.multiplier + config.offset
        if not abs(target - mimic_position) >= config.sensitiveness:
            return None
        limit = config.max_effort
        return max(min(pid.compute(target - mimic_position, dt), limit), -limit)  # ignition_clamp


def urdf_mimic_target(master_position, mimic):
    """A URDF ``<mimic>``'s position: ``multiplier * master + offset`` (``mimic`` has ``multiplier`` and
    ``offset``, e.g. :class:`diffbot_sim.description.urdf_model.Mimic`), as robot_state_publisher computes it."""
    return mimic.multiplier * master_position + mimic.offset
