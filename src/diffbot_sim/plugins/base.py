"""What every plugin gets (RobotContext) and what the loop asks of it (Plugin).

The loop is single-threaded: subscriber callbacks (rospy's threads) only store data and wake the loop;
``before_step``/``after_step`` run on the loop's thread, the only one that touches the physics.
"""
import math
import re
import warnings
from dataclasses import dataclass

import rospy

from diffbot_sim.config import RobotSpec, SimConfig, prefix_frame
from diffbot_sim.control.schedule import first_due_model, first_due_sensor, next_due
from diffbot_sim.description.urdf_model import RobotModel
from diffbot_sim.plugins.interfaces import PluginRobot, PluginSimulator


def publisher(name, msg_class):
    """A synchronous publisher: publish() writes on the loop's thread. Measured here, rospy's queued
    publishers cost more CPU (a thread hand-off per message and connection) than the write itself; a
    stalled subscriber is handled by the simulator's send timeout instead of by a queue."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SyntaxWarning)  # rospy warns on queue_size=None, which we mean
        return rospy.Publisher(name, msg_class, queue_size=None)


def get_param(name, default):
    """A parameter from the server, or ``default`` when it is absent or the server cannot be asked."""
    try:
        return rospy.get_param(name, default)
    except (KeyError, rospy.ROSException):
        return default


def join(namespace, name):
    """Resolve ``name`` under a plugin namespace (None or "": the node's namespace, a relative name)."""
    if name.startswith("/") or not namespace:
        return name
    return namespace.rstrip("/") + "/" + name.lstrip("/")


def summary_key(kind, name):
    """A start-up summary key, ``<kind>/<name>``, that is a legal ROS parameter name whatever the model called
    the sensor or its topic (rospy warns about, and rosparam cannot address, a name with a space or a
    hyphen): each run of other characters becomes one ``_``, and a part must not start with a digit."""
    parts = [re.sub(r"[^A-Za-z0-9_]+", "_", part) for part in str(name).split("/") if part]
    parts = [part if part[:1].isalpha() else "n" + part for part in parts if part.strip("_")] or ["unnamed"]
    return "/".join([kind] + parts)


def finite_twist(ctx, msg, owner):
    """The six Twist fields of ``msg``, or None (with a throttled warning) when one is not finite: a NaN
    must never reach the physics, and the robot keeps its last valid command, as diff_drive_controller."""
    from diffbot_sim.control.gazebo_diff_drive import non_finite_field
    from diffbot_sim.messages import common as ros_msgs

    values = ros_msgs.twist_values(msg)
    bad = non_finite_field(values)
    if bad is not None:
        ctx.sim.warn(f"nonfinite:{id(owner)}", f"ignored a velocity command with a non-finite {bad} {values}; "
                     "the robot keeps its last valid command")
        return None
    return values


#: Which Twist fields (indices in TWIST_FIELDS order) a drive takes: a wheeled drive linear.x and angular.z, a
#: planar base linear.x, linear.y and angular.z.
DRIVE_TWIST = (0, 5)
PLANAR_TWIST = (0, 1, 5)


def twist_callback(ctx, owner, inbox, fields):
    """The rospy callback of a velocity-command topic: each message's Twist ``fields`` (DRIVE_TWIST,
    PLANAR_TWIST) put into ``inbox`` (a :class:`diffbot_sim.control.command_inbox.CommandInbox` that wakes
    the loop), which the plugin takes on the loop's thread in ``before_step``. A message with a non-finite
    field is dropped with a throttled warning (:func:`finite_twist`): the robot keeps its last valid command."""
    def callback(msg):
        values = finite_twist(ctx, msg, owner)
        if values is not None:
            inbox.put(tuple(values[i] for i in fields))
    return callback


@dataclass
class RobotContext:
    """One robot as its plugins see it.

    Attributes:
        sim: the Simulator, as much of it as plugins may use (:class:`~diffbot_sim.plugins.interfaces.
            PluginSimulator`): sim time, the world, ``warn``, ``post``/``call`` and ``wake`` for callbacks.
        cfg: the SimConfig. spec: the RobotSpec. model: the RobotModel.
        robot: the physics Robot (:class:`~diffbot_sim.plugins.interfaces.PluginRobot`: what plugins use of it).
        params: the node's private parameters (a dict, read once).
        namespace: ``/<name>`` for a named robot of ``~robots`` (it replaces every plugin's own), else None.
        private: prefix of this robot's private topics (``~`` or ``~<name>/``).
    """

    sim: PluginSimulator
    cfg: SimConfig
    spec: RobotSpec
    model: RobotModel
    robot: PluginRobot
    params: dict
    namespace: str | None
    private: str

    @property
    def tf_prefix(self):
        if not self.spec.name:
            return ""
        return self.spec.name if self.spec.tf_prefix is None else self.spec.tf_prefix

    def frame(self, name):
        """A frame id as published: a leading slash stripped (tf2 rejects it), the robot's tf_prefix."""
        return prefix_frame(self.tf_prefix, name)

    def clean_frame(self, name, where):
        """A frame id from a tag, without the leading slash tf2 rejects (with a warning naming ``where``);
        not yet prefixed (``frame`` does that)."""
        if name.startswith("/"):
            self.warnings.append(f"{where}: frame '{name}' has a leading slash, which tf2 rejects; "
                                 f"using '{name.lstrip('/')}'")
            return name.lstrip("/")
        return name

    def plugin_namespace(self, tag_value, default=None):
        """The namespace a plugin's topics live in: the robot's (``~robots``) replaces the plugin's own
        ``robotNamespace``, as gazebo_ros's spawner does; else the tag; else ``default``."""
        if self.namespace:
            return self.namespace
        return tag_value if tag_value is not None else default

    def __post_init__(self):
        self.warnings = []  # start-up warnings of this robot's plugins, logged once in the report
        self.handles = []  # every publisher, subscriber and service this robot's plugins made
        # resolved JointState topic -> the joints a model plugin (joint state publisher, kobuki) publishes there
        self.joint_state_topics: dict[str, set[str]] = {}

    def publishes_joint_states(self, pub, joints):
        """Record that a plugin publishes ``joints`` on ``pub``'s topic: joint_state_controller then leaves them
        out of the passive joints it adds to that topic. A joint on one topic from two publishers (their
        messages stamped at the same step) is a state 'not newer than the previous' to MoveIt's
        CurrentStateMonitor, which then forgets every joint's time and finds the robot's state incomplete."""
        self.joint_state_topics.setdefault(pub.resolved_name, set()).update(joints)

    # -- ROS endpoints: made through the context so that deleting the robot removes every one ---------
    def publisher(self, name, msg_class):
        """A synchronous publisher (:func:`publisher`) owned by this robot."""
        return self._own(publisher(name, msg_class))

    def subscriber(self, name, msg_class, callback, **kwargs):
        """A rospy.Subscriber owned by this robot (unregistered when the robot is deleted)."""
        return self._own(rospy.Subscriber(name, msg_class, callback, **kwargs))

    def service(self, name, srv_class, handler):
        """A rospy.Service owned by this robot (shut down when the robot is deleted)."""
        return self._own(rospy.Service(name, srv_class, handler))

    def _own(self, handle):
        self.handles.append(handle)
        return handle

    def release(self, handle):
        """Remove one endpoint now (a controller unloaded while the robot lives on)."""
        if handle in self.handles:
            self.handles.remove(handle)
        close_handle(handle)

    def close(self):
        """Remove every endpoint of this robot: its topics disappear from the master (delete_model)."""
        handles, self.handles = self.handles, []
        for handle in handles:
            close_handle(handle)


def close_handle(handle):
    """Take a publisher or subscriber off the master (unregister), or shut a service down."""
    if isinstance(handle, rospy.Service):
        handle.shutdown("model deleted")
    else:
        handle.unregister()


class Plugin:
    """What the loop calls. Times are sim seconds; ``stamp`` is the same time as a rospy.Time."""

    #: The robot's context, which each plugin keeps as ``self.ctx`` (declared here so that mypy checks what
    #: plugins do with it against RobotContext's types).
    ctx: RobotContext
    #: The plugin's filename (or a descriptive name for built-in ones), for reports.
    filename = ""
    #: Its publications are sensor data that nodes in the loop answer (``~wait_for_nodes`` waits after them).
    sensor = False
    #: Timed as a Gazebo ``<sensor>`` (its update timer runs on sim time from 0 and reset_world leaves it alone)
    #: rather than as a model plugin (first update one period after its start or reset): see :meth:`first_due`.
    sensor_timer = False

    def joints(self):
        """Joints this plugin commands (a joint has one owner)."""
        return set()

    def publishers(self):
        """Publishers the loop writes to (their connections are tuned and batched by the simulator)."""
        return []

    def next_control(self):
        """Sim time at which ``before_step`` has work (control); inf: only when a command arrives."""
        return math.inf

    def rays_per_second(self):
        """Rays this plugin casts per sim second (ray sensors; ``~ray_process: auto`` counts them)."""
        return 0.0

    def next_publish(self):
        """Sim time at which ``after_step`` has work (publishing): the next scheduled publication
        (``self.next``, which ``take_due`` moves on). A plugin that publishes nothing returns inf."""
        return self.next

    def before_step(self, now):
        """Apply new commands and run control that is due (called once before each run of physics steps, at the
        sim time of its first step; ``next_control`` says when it must be called again)."""

    def after_step(self, now, stamp, transforms):
        """Publish what is due; TF transforms go into ``transforms`` (one TFMessage per step)."""

    #: Sim time of the next publication, for plugins that publish on a schedule (``take_due``); none until
    #: started.
    next = math.inf
    #: Period [s] of that schedule (0: every step), for plugins that keep it here.
    period = 0.0

    def start(self, now):
        """The plugin starts at sim time ``now``: the loop's start, a spawn, reset_world or reset_simulation
        (sim time back to 0). Its first publication is scheduled as Gazebo's (:meth:`first_due`)."""
        self.next = self.first_due(now, self.period)

    def first_due(self, now, period):
        """Sim time of the first publication of a schedule of ``period`` after a start at ``now``, Gazebo's one
        rule for each kind (:mod:`diffbot_sim.control.schedule`): a model plugin one period after its (re)start
        (gazebo_ros_diff_drive's 30 Hz odometry first at 1/30 s); a sensor at ``period`` on sim time from 0
        (a 5 Hz laser first at 0.2 s after a start or reset_simulation), its schedule kept by reset_world."""
        if self.sensor_timer:
            return first_due_sensor(self.next, period, now)
        return first_due_model(now, period)

    def reset(self, now):
        """Brake and forget pending commands (reset_simulation)."""

    def close(self):
        """The robot is deleted: give back what the plugin holds outside ROS (its topics go with the context)."""

    def summary(self):
        """Effective settings for the start-up report: {name: value}."""
        return {}

    def take_due(self, now, period):
        """True when the plugin's next publication (``self.next``) is due at sim time ``now``, and moves it
        one ``period`` on (0: every step; missed slots are skipped, not burst)."""
        if now + 1e-9 < self.next:
            return False
        self.next = next_due(self.next, period, now)
        return True
