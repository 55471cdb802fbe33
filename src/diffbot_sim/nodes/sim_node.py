"""``bullet_sim``: the PyBullet simulator node (the thin ROS shell around the pure modules).

Loads a URDF/xacro robot into PyBullet, turns its transmissions into joint motors, runs the model's
gazebo_ros_diff_drive plugin on ``cmd_vel`` and publishes what gazebo_ros would. One thread owns PyBullet:
subscriber and service callbacks only hand data to the loop.

Topics (names as the model's plugins set them; defaults shown, relative to the namespace):
    cmd_vel (geometry_msgs/Twist, in): body velocity command; linear.x and angular.z are used.
    odom (nav_msgs/Odometry): pose in ``odom``, twist in ``base_footprint``, at the drive's update rate.
    /tf (tf2_msgs/TFMessage): odom -> base_footprint, when publish_odom_tf.
    joint_states (sensor_msgs/JointState): the joint-state plugin's joints (+ wheels if asked).
    /clock (rosgraph_msgs/Clock): sim time, at ~clock_rate.
    <joint>_velocity_controller/command etc. (std_msgs/Float64, in): joints whose transmission is not
        a drive wheel, named as gazebo_ros_control + ros_controllers would name them.
    ~debug/cmd_applied (geometry_msgs/TwistStamped): when ~debug_cmd_applied, the wall time a command
        reached the motors (for latency measurement).
Services: ~pause_physics, ~unpause_physics, ~reset_simulation (std_srvs/Empty).
Parameters: see diffbot_sim.config.SimConfig and DriveConfig (README table).
"""
import math
import os
import socket
import threading
import time
import warnings

import rospy
from geometry_msgs.msg import Twist, TwistStamped
from rosgraph_msgs.msg import Clock
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64
from std_srvs.srv import Empty, EmptyResponse
from tf2_msgs.msg import TFMessage

from .. import config as cfgmod
from .. import ros_msgs, streams
from ..controller import DiffDriveController, non_finite_field
from ..description import load_file, parse_args, resolve_meshes
from ..errors import DiffbotSimError, ModelError
from ..model import parse_urdf
from ..odometry import EncoderOdometry
from ..kinematics import quaternion_from_yaw
from ..physics import World
from ..plugins import read_plugins
from ..throttle import Throttle

_CONTROLLER_SUFFIX = {"VelocityJointInterface": "velocity", "EffortJointInterface": "effort",
                      "PositionJointInterface": "position"}


def _publisher(name, msg_class):
    """A synchronous publisher: publish() writes on the loop's thread. Measured here, rospy's queued
    publishers cost more CPU (a thread hand-off per message and connection) than the write itself; a
    stalled subscriber is handled by SubscriberLinks' send timeout instead of by a queue."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SyntaxWarning)  # rospy warns on queue_size=None, which we mean
        return rospy.Publisher(name, msg_class, queue_size=None)


class SubscriberLinks:
    """Our publishers' TCP connections to subscribers: tuned once each, and batched in fast mode.

    Publishers are synchronous (the loop's thread writes; no queue thread per connection, which costs
    more CPU than the write itself), so a subscriber that stops reading must not stall the loop: each
    connection gets a send timeout, after which rospy closes and drops it (the loop goes on, the
    subscriber sees the connection end). TCP_NODELAY stops Nagle holding a small message for an ACK.

    In fast mode, a message to a subscriber that is asleep costs ~100-150 us of wall time (the loopback
    write wakes the receiver, a cross-CPU wake-up that is dear in a VM), far more than building it; so the
    connections are corked (TCP_CORK) while the loop publishes and uncorked every ``batch`` wall seconds:
    N writes become one wake-up per subscriber; messages and their order are unchanged, each arrives at
    most ``batch`` late. Real-time mode does not batch.
    """

    def __init__(self, publishers, send_timeout, batch):
        self.publishers = publishers  # callable returning the current publishers
        self.send_timeout = send_timeout
        self.batch = batch
        self.held_since = None
        self._tuned = set()
        self._next_scan = 0.0

    def _sockets(self):
        for pub in self.publishers():
            for conn in list(pub.impl.connections) if pub.impl is not None else ():
                sock = getattr(conn, "socket", None)
                if sock is not None and sock.family in (socket.AF_INET, socket.AF_INET6):
                    yield sock

    def tune_new(self, now_wall):
        """Give new connections their send timeout and TCP_NODELAY (a scan at most every 0.1 s)."""
        if now_wall < self._next_scan:
            return
        self._next_scan = now_wall + 0.1
        live = set()  # the socket objects themselves: an id() could be reused by a later socket
        for sock in self._sockets():
            live.add(sock)
            if sock not in self._tuned:
                try:
                    sock.settimeout(self.send_timeout)
                    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                except OSError:
                    pass  # closing under us: rospy drops it on its next write
        self._tuned = live

    def _cork(self, value):
        for sock in self._sockets():
            try:
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_CORK, value)
            except OSError:
                pass

    def hold(self, now_wall):
        """Fast mode, before publishing: start a batch unless one is open."""
        if self.batch > 0 and self.held_since is None:
            self._cork(1)
            self.held_since = now_wall

    def release_if_due(self, now_wall):
        if self.held_since is not None and now_wall - self.held_since >= self.batch:
            self.release()

    def release(self):
        """Send everything held now (also before the loop pauses, and at close)."""
        if self.held_since is not None:
            self._cork(0)
            self.held_since = None


def _join(namespace, name):
    """Resolve ``name`` under a plugin namespace (None: the node's namespace, i.e. a relative name)."""
    if name.startswith("/") or namespace is None or namespace == "":
        return name
    return namespace.rstrip("/") + "/" + name


class RobotRuntime:
    """One robot: its physics body, controller, odometry and ROS endpoints."""

    def __init__(self, sim, model, robot, drive, joint_cfg, cfg, spec):
        self.sim = sim
        self.spec = spec
        self.namespace = "/" + spec.name if spec.name else None
        self.private = f"~{spec.name}/" if spec.name else "~"  # private topics: ~<name>/ground_truth
        self.model = model
        self.robot = robot
        self.drive = drive
        self.joint_cfg = joint_cfg
        self.cfg = cfg
        self.motor_joints = {}  # joint -> transmission (non-drive motors)
        drive_joints = set(drive.left_joints + drive.right_joints) if drive else set()
        for trans in model.transmissions:
            if trans.joint not in drive_joints:
                self.motor_joints[trans.joint] = trans
        self.command_subs = []
        self._joint_commands = {}
        self._lock = threading.Lock()
        self._pending_twist = None
        self.next_odom = 0.0
        self.next_js = 0.0
        self.max_wheel_velocity = None
        self.odom_pub = self.truth_pub = self.debug_pub = self.js_pub = None
        if drive is not None:
            self._setup_drive()
        else:
            self.controller = None
        if joint_cfg is not None:
            self.js_indices = robot.indices(joint_cfg.joints)
            self.js_names = list(joint_cfg.joints)
            self.js_pub = _publisher(_join(joint_cfg.namespace, joint_cfg.topic), JointState)
            self.js_builder = ros_msgs.JointStateBuilder(self.js_names)
            self.js_period = 1.0 / joint_cfg.update_rate if joint_cfg.update_rate > 0 else 0.0
        for joint, trans in self.motor_joints.items():
            suffix = _CONTROLLER_SUFFIX[trans.interface]
            topic = _join(self.namespace, f"{joint}_{suffix}_controller/command")
            if trans.interface != "PositionJointInterface":
                self.robot.free_joints(self.robot.indices([joint]))
            self.command_subs.append(rospy.Subscriber(topic, Float64, self._on_joint_command,
                                                      callback_args=joint, queue_size=1))

    # -- drive --------------------------------------------------------------------------------------
    def _setup_drive(self):
        drive, cfg, robot = self.drive, self.cfg, self.robot
        radius = drive.wheel_radius
        self.max_wheel_velocity = cfgmod.max_wheel_velocity(cfg, robot.model, drive)
        self.controller = DiffDriveController(drive.wheel_separation, radius, self.max_wheel_velocity,
                                              drive.max_wheel_acceleration, cfg.cmd_vel_timeout)
        self.left_idx = robot.indices(drive.left_joints)
        self.right_idx = robot.indices(drive.right_joints)
        self.wheel_idx = self.left_idx + self.right_idx
        self.wheel_forces = cfgmod.wheel_efforts(robot.model, drive)
        self.update_period = 1.0 / drive.update_rate if drive.update_rate > 0 else 0.0
        self.next_update = 0.0
        self.last_update = 0.0
        self.encoder = EncoderOdometry(radius, drive.wheel_separation)
        ns = drive.namespace
        self.cmd_sub = rospy.Subscriber(_join(ns, drive.command_topic), Twist, self._on_twist, queue_size=1)
        if drive.publish_odom:
            self.odom_pub = _publisher(_join(ns, drive.odometry_topic), Odometry)
        self.odom_builder = ros_msgs.OdometryBuilder(drive.odometry_frame, drive.robot_base_frame,
                                                     drive.covariance_x, drive.covariance_y, drive.covariance_yaw)
        self.tf_builder = ros_msgs.TransformBuilder(drive.odometry_frame, drive.robot_base_frame)
        if cfg.publish_ground_truth:
            self.truth_pub = _publisher(self.private + "ground_truth", Odometry)
            self.truth_builder = ros_msgs.OdometryBuilder("world", drive.robot_base_frame, 0.0, 0.0, 0.0)
        if cfg.debug_cmd_applied:
            self.debug_pub = _publisher(self.private + "debug/cmd_applied", TwistStamped)

    def _on_twist(self, msg):
        """Subscriber thread: keep the newest *valid* command and wake the loop, which applies it (at once
        in real time, at the next step in fast mode).

        Validating here (not in the loop) means a burst of a good command followed by a NaN one keeps the
        good one, as diff_drive_controller does.
        """
        values = ros_msgs.twist_values(msg)
        bad = non_finite_field(values)
        if bad is not None:
            self.sim.warn(f"nonfinite:{id(self)}", f"ignored a cmd_vel with a non-finite {bad} {values}; "
                          "the robot keeps its last valid command")
            return
        with self._lock:
            self._pending_twist = values
        self.sim.wake.set()

    def _on_joint_command(self, msg, joint):
        """Subscriber thread: keep the newest finite command per joint (validated here, like cmd_vel)."""
        if not math.isfinite(msg.data):
            self.sim.warn(f"joint:{joint}", f"ignored a non-finite command for joint {joint}")
            return
        with self._lock:
            self._joint_commands[joint] = msg.data
        self.sim.wake.set()

    def take_pending(self):
        """The newest twist and joint commands since the last call (None, {} when there are none)."""
        if self._pending_twist is None and not self._joint_commands:
            return None, {}  # the common case, checked without the lock (attribute reads are atomic)
        with self._lock:
            twist, self._pending_twist = self._pending_twist, None
            joints, self._joint_commands = self._joint_commands, {}
        return twist, joints

    # -- loop work ----------------------------------------------------------------------------------
    def before_step(self, now):
        """Apply new commands and run the controller when due. Called by the loop before each step."""
        twist, joint_commands = self.take_pending()
        for joint, value in joint_commands.items():
            self._apply_joint_command(joint, value)
        if self.controller is None:
            return
        fresh = False
        if twist is not None:
            fresh = self.controller.set_command(twist[0], twist[5], now)
        elif now + 1e-9 < self.next_update:
            expiry = self.controller.expiry()
            if expiry is None or now < expiry:
                return  # nothing new, nothing due: the motors keep their targets
        _, velocities, _ = self.robot.joint_states(self.wheel_idx)
        n = len(self.left_idx)
        left_v = sum(velocities[:n]) / n
        right_v = sum(velocities[n:]) / n
        dt = max(now - self.last_update, self.cfg.time_step)
        left, right = self.controller.update(now, left_v, right_v, dt)
        self.robot.set_velocities(self.wheel_idx, [left] * n + [right] * n, self.wheel_forces)
        self.last_update = now
        if now + 1e-9 >= self.next_update:
            self.next_update = _next_due(self.next_update, self.update_period, now)
        if fresh and self.debug_pub is not None:
            self.debug_pub.publish(ros_msgs.twist_stamped(rospy.Time.from_sec(time.time()), twist[0], twist[5]))

    def _apply_joint_command(self, joint, value):
        trans = self.motor_joints[joint]
        idx = self.robot.indices([joint])
        limit = self.model.joints[joint].effort_limit
        force = limit if limit else cfgmod.FALLBACK_JOINT_EFFORT
        if trans.interface == "VelocityJointInterface":
            self.robot.set_velocities(idx, [value], [force])
        elif trans.interface == "PositionJointInterface":
            self.robot.set_positions(idx, [value], [force])
        else:
            self.robot.set_efforts(idx, [max(-force, min(force, value))])

    def publishers(self):
        """This robot's publishers that the loop writes to."""
        return [p for p in (self.odom_pub, self.truth_pub, self.debug_pub, self.js_pub) if p is not None]

    def next_publish(self):
        """Sim time of this robot's next odom/TF or joint_states publication."""
        due = [self.next_odom] if self.controller is not None else []
        if self.joint_cfg is not None:
            due.append(self.next_js)
        return min(due) if due else math.inf

    def next_due(self):
        """Sim time of the next thing this robot must do (controller update, odom, joint_states)."""
        update = self.next_update if self.controller is not None else math.inf
        return min(update, self.next_publish())

    def after_step(self, now, stamp, transforms):
        """Publish what is due at sim time ``now``; TF transforms go into ``transforms`` (one TFMessage for
        every robot is cheaper than one each). Called by the loop after each step."""
        if self.controller is not None and now + 1e-9 >= self.next_odom:
            self.next_odom = _next_due(self.next_odom, self.update_period, now)
            self._publish_odometry(now, stamp, transforms)
        if self.joint_cfg is not None and now + 1e-9 >= self.next_js:
            self.next_js = _next_due(self.next_js, self.js_period, now)
            if self.js_pub.get_num_connections():  # nobody listening: skip the read-out and the message
                positions, velocities, efforts = self.robot.joint_states(self.js_indices)
                self.js_pub.publish(self.js_builder.build(stamp, positions, velocities, efforts))

    def _publish_odometry(self, now, stamp, transforms):
        drive = self.drive
        if self.truth_pub is not None and self.truth_pub.get_num_connections():
            pose = self.robot.base_pose()
            linear, angular = self.robot.base_twist(pose)
            self.truth_pub.publish(self.truth_builder.build(stamp, pose[0], pose[1], linear, angular))
        if drive.odometry_source == "encoder":
            positions, _, _ = self.robot.joint_states([self.left_idx[0], self.right_idx[0]])
            self.encoder.update(positions[0], positions[1], now)
            enc = self.encoder
            position = (enc.x, enc.y, 0.0)
            orientation = quaternion_from_yaw(enc.yaw)
            linear, angular = (enc.linear, 0.0, 0.0), (0.0, 0.0, enc.angular)
        else:
            position, orientation = self.robot.base_pose()
            linear, angular = self.robot.base_twist((position, orientation))
        if self.odom_pub is not None and self.odom_pub.get_num_connections():
            self.odom_pub.publish(self.odom_builder.build(stamp, position, orientation, linear, angular))
        if drive.publish_odom_tf:
            transforms.append(self.tf_builder.build(stamp, position, orientation))

    def reset(self):
        """Brake and drop pending commands; the caller re-anchors the encoder (start_encoder)."""
        if self.controller is not None:
            self.controller.brake()
            self.robot.set_velocities(self.wheel_idx, [0.0] * len(self.wheel_idx), self.wheel_forces)
        with self._lock:
            self._pending_twist = None
            self._joint_commands = {}

    def start_encoder(self, now):
        if self.controller is not None:
            positions, _, _ = self.robot.joint_states([self.left_idx[0], self.right_idx[0]])
            self.encoder.reset(positions[0], positions[1], now)


def _next_due(due, period, now):
    """Next publish time after ``due``; skips missed slots instead of bursting to catch up."""
    if period <= 0:
        return now
    due += period
    if due < now:
        due = now + period
    return due


class Simulator:
    """The single-threaded loop: apply commands -> step -> publish, paced to the wall clock or not."""

    def __init__(self, cfg):
        self.cfg = cfg
        self.wake = threading.Event()
        self.throttle = Throttle(5.0)
        self.paused = False
        self._requests = []
        self._requests_lock = threading.Lock()
        self.steps = 0
        self.world = World(cfg.time_step, cfg.gravity, gui=cfg.gui)
        self.clock_pub = _publisher("/clock", Clock)
        self.tf_pub = _publisher("/tf", TFMessage)
        self.robots = []
        self.clock_period = 1.0 / cfg.clock_rate
        self.next_clock = 0.0
        self._next_publish = 0.0  # sim time of the earliest publication due, over clock and every robot
        self._tf_msg = ros_msgs.tf_message([])
        self._clock_msg = ros_msgs.clock(rospy.Time(0))
        self.owns_clock = False  # main() sets it when use_sim_time made rospy follow /clock
        self.links = SubscriberLinks(self.publishers, cfg.send_timeout, 0.0 if cfg.real_time else cfg.fast_batch)

    def publishers(self):
        """Every publisher the loop writes to (SubscriberLinks tunes and batches their connections)."""
        pubs = [self.clock_pub, self.tf_pub]
        for runtime in self.robots:
            pubs += runtime.publishers()
        return pubs

    def warn(self, key, text):
        """A throttled warning (wall time): at most one per key per 5 s, with a count of what was held back."""
        if self.throttle.ready(key, time.monotonic()):
            held = self.throttle.take_suppressed(key)
            rospy.logwarn(text + (f" ({held} more since the last warning)" if held else ""))

    def add_robot(self, runtime):
        self.robots.append(runtime)

    # -- services (called on rospy's threads; the loop does the work) -------------------------------
    def _request(self, action):
        done = threading.Event()
        with self._requests_lock:
            self._requests.append((action, done))
        self.wake.set()
        if not done.wait(5.0):
            raise rospy.ServiceException(f"simulator loop did not handle '{action}' within 5 s")
        return EmptyResponse()

    def _handle_requests(self):
        with self._requests_lock:
            requests, self._requests = self._requests, []
        for action, done in requests:
            if action == "pause":
                self.paused = True
            elif action == "unpause":
                if self.paused:
                    self.paused = False
                    self._rebase()
            elif action == "reset":
                self.world.reset()
                now = self.sim_time
                for runtime in self.robots:
                    runtime.reset()
                    runtime.start_encoder(now)
            done.set()

    @property
    def sim_time(self):
        return self.steps * self.cfg.time_step

    def _rebase(self):
        """Re-anchor real-time pacing at the current sim time (after a pause or a start)."""
        self.wall0 = time.monotonic()
        self.sim0 = self.sim_time

    def advertise_services(self):
        rospy.Service("~pause_physics", Empty, lambda _req: self._request("pause"))
        rospy.Service("~unpause_physics", Empty, lambda _req: self._request("unpause"))
        rospy.Service("~reset_simulation", Empty, lambda _req: self._request("reset"))

    # -- the loop -----------------------------------------------------------------------------------
    def run(self):
        cfg = self.cfg
        dt = cfg.time_step
        for runtime in self.robots:
            runtime.start_encoder(0.0)
        self._publish_clock(0.0)
        self._rebase()
        while not rospy.is_shutdown():
            self._handle_requests()
            if self.paused:
                self.links.release()
                self.wake.wait(0.1)
                self.wake.clear()
                continue
            if cfg.real_time:
                target = self.sim0 + (time.monotonic() - self.wall0) * cfg.real_time_factor
                if self.sim_time + dt > target + 1e-9:
                    # Sleep until the next thing due, or until a command wakes us. Publishing and control,
                    # not stepping, set the wake rate, so CPU stays low.
                    due = min([self.next_clock] + [r.next_due() for r in self.robots])
                    # Wake at the step that reaches ``due`` (steps land on multiples of dt), not at ``due``
                    # itself: waking between steps would only find nothing to do and sleep again.
                    step_at = math.ceil(due / dt - 1e-6) * dt
                    wait = (max(step_at, self.sim_time + dt) - target) / cfg.real_time_factor
                    if self.wake.wait(min(max(wait, 0.0), 0.1)):
                        self.wake.clear()
                        # A command woke us: set the motor targets now rather than at the next step
                        # (up to one step later). Same sim time, so the physics sees no difference.
                        self._handle_requests()
                        if not self.paused:
                            for runtime in self.robots:
                                runtime.before_step(self.sim_time)
                    continue
            self._step_once()

    def _step_once(self):
        now = self.sim_time
        for runtime in self.robots:
            runtime.before_step(now)
        self.world.step()
        self.steps += 1
        now = self.sim_time
        if now + 1e-9 < self._next_publish:
            if self.links.held_since is not None:
                self.links.release_if_due(time.monotonic())
            return  # most steps publish nothing: skip building a stamp and asking every robot
        stamp = self._stamp()
        wall = time.monotonic()
        self.links.tune_new(wall)
        self.links.hold(wall)
        transforms = []
        for runtime in self.robots:
            runtime.after_step(now, stamp, transforms)
        if transforms and self.tf_pub.get_num_connections():
            self._tf_msg.transforms = transforms
            self.tf_pub.publish(self._tf_msg)
        if now + 1e-9 >= self.next_clock:
            self._publish_clock(now)
        self._next_publish = min([self.next_clock] + [r.next_publish() for r in self.robots])
        self.links.release_if_due(wall)

    def _stamp(self):
        """Sim time as a rospy.Time, via integer nanoseconds (cheaper than Time.from_sec's float path)."""
        secs, nsecs = divmod(round(self.steps * self.cfg.time_step * 1e9), 1_000_000_000)
        return rospy.Time(secs, nsecs)

    def _publish_clock(self, now):
        stamp = self._stamp()
        if self.owns_clock:
            rospy.rostime._set_rostime(stamp)  # this node's own sim time (see _own_the_clock)
        if self.clock_pub.get_num_connections():
            self._clock_msg.clock = stamp
            self.clock_pub.publish(self._clock_msg)
        self.next_clock = _next_due(self.next_clock, self.clock_period, now)

    def close(self):
        self.links.release()
        self.world.close()


def _load_model(spec):
    """URDF text and its source name: the spec's file, else ``/<name>/robot_description``, else the
    ``robot_description`` parameter found from the node's namespace (one model shared by every robot)."""
    if spec.model:
        path = os.path.abspath(os.path.expanduser(spec.model))
        return load_file(path, parse_args(spec.model_args)), path
    name = f"/{spec.name}/robot_description" if spec.name else None
    if name is None or not rospy.has_param(name):
        name = rospy.search_param("robot_description")
    if not name or not rospy.has_param(name):
        raise ModelError("no ~model given and no robot_description parameter found",
                         f"robot {spec.name}" if spec.name else "robot_description")
    text = rospy.get_param(name)
    if not isinstance(text, str) or not text.strip():
        raise ModelError("parameter is empty or not a string", name)
    return text, name


class LoadedRobot:
    """What build() learned about one robot, kept for the start-up report."""

    def __init__(self, spec, model, plugins, drive, joint_cfg, runtime):
        self.spec, self.model, self.plugins = spec, model, plugins
        self.drive, self.joint_cfg, self.runtime = drive, joint_cfg, runtime


def _build_robot(sim, cfg, spec, params):
    text, source = _load_model(spec)
    model = parse_urdf(text, source)
    text = resolve_meshes(text, source)
    plugins = read_plugins(model)
    drive = cfgmod.drive_config(model, plugins.diff_drive, params)
    joint_cfg = cfgmod.joint_state_config(model, plugins.joint_state, drive)
    cfgmod.place_in_namespace(spec, drive, joint_cfg)
    for trans in model.transmissions:
        model.joint(trans.joint, f"/robot/transmission[@name='{trans.name}']")
    robot = sim.world.load_robot(text, model, (spec.x, spec.y, spec.z), spec.yaw)
    runtime = RobotRuntime(sim, model, robot, drive, joint_cfg, cfg, spec)
    sim.add_robot(runtime)
    return LoadedRobot(spec, model, plugins, drive, joint_cfg, runtime)


def build(cfg, params):
    """Build the simulator with every robot of ``~robots`` (or the one robot); raises DiffbotSimError on
    bad input, naming the robot's file, element or parameter."""
    specs = cfgmod.robot_specs(cfg, params)
    sim = Simulator(cfg)
    try:
        loaded = [_build_robot(sim, cfg, spec, params) for spec in specs]
    except BaseException:
        sim.close()
        raise
    return sim, loaded


def _report(cfg, loaded):
    """Log the effective configuration once and write it back to the private parameters."""
    for key, value in cfgmod.as_params(cfg).items():
        rospy.set_param("~" + key, value)
    for item in loaded:
        plugins, drive, model = item.plugins, item.drive, item.model
        who = f"robot {item.spec.name}: " if item.spec.name else ""
        for text in plugins.warnings:
            rospy.logwarn(who + text)
        if plugins.unsupported:
            rospy.logwarn(who + "not simulated (ignored): " + "; ".join(plugins.unsupported))
        for block in (plugins.diff_drive, plugins.joint_state):
            if block is not None and block.unknown_tags:
                rospy.logwarn(f"{who}{block.path}: unknown tags ignored: {', '.join(block.unknown_tags)}")
        if drive is None:
            rospy.logwarn(who + "the model has no gazebo_ros_diff_drive plugin (and no ~left_joints): nothing "
                          "subscribes cmd_vel")
        params = {}
        if drive is not None:
            params.update(cfgmod.as_params(drive))
            params["wheel_radius"] = drive.wheel_radius
            params["effective_max_wheel_velocity"] = item.runtime.max_wheel_velocity
        params["loaded_mass"] = item.runtime.robot.total_mass()
        params["urdf_mass"] = model.total_mass()
        if item.spec.name:
            params.update({k: v for k, v in cfgmod.as_params(item.spec).items() if k != "name"})
        for key, value in params.items():
            rospy.set_param(item.runtime.private + key, value)
        params.update(cfgmod.as_params(cfg))
        summary = ", ".join(f"{k}={v}" for k, v in sorted(params.items()))
        rospy.loginfo(f"bullet_sim: {who}model {model.source} ({model.name}); {summary}")


def _own_the_clock():
    """Stop rospy listening to /clock in this node: with use_sim_time, init_node subscribes every node to
    /clock, so the simulator would receive (a loopback wake-up and a deserialization) each tick it
    publishes. rospy's time is set directly in _publish_clock instead, through the hook rospy's own /clock
    callback uses (rospy.rostime._set_rostime)."""
    from rospy.impl import simtime
    sub = getattr(simtime, "_clock_sub", None)
    if sub is not None:
        sub.unregister()
        simtime._clock_sub = None
    return sub is not None


def main(argv=None):
    """Entry point of ``rosrun diffbot_sim bullet_sim``. Exits 1 with one line on bad input.

    Output that cannot be written (roslaunch's terminal closed, a pipe whose reader left) never changes the
    exit status: :func:`diffbot_sim.streams.finish` empties the buffers first.
    """
    try:
        return _main()
    finally:
        streams.finish()


def _main():
    rospy.init_node("bullet_sim")
    owns_clock = _own_the_clock()
    try:
        params = rospy.get_param("~", {})
        cfg = cfgmod.sim_config(params)
        if cfg.gui and not os.environ.get("DISPLAY"):
            rospy.logwarn("~gui is true but there is no display (DISPLAY unset): running headless (DIRECT)")
            cfg.gui = False
        sim, loaded = build(cfg, params)
        sim.owns_clock = owns_clock
    except DiffbotSimError as err:
        rospy.logfatal(f"bullet_sim: {err}")
        rospy.signal_shutdown("bad input")
        return 1
    try:
        _report(cfg, loaded)
        sim.advertise_services()
        sim.run()
    finally:
        sim.close()
    return 0
