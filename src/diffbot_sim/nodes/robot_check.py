"""``rosrun diffbot_sim robot_check <model> [controller.yaml ...] [-- xacro args]``: the migration check.

Someone moving a robot from Gazebo wants one screen that says whether it drives here, and if not, why. The
static part (mass, drive and where its geometry came from, plugins, warnings) comes from
:mod:`diffbot_sim.check.robot_report`, in this process. Then the robot is driven for real: a private master
(``roscore -p <free port>``), the controller YAMLs loaded onto it, ``bullet_sim`` headless at 3x real time
with ground truth, and this process as a node publishing the commands and judging the motions with
:mod:`diffbot_sim.check.drive_check` (the rules the fixture-robot rostests use).

Paced at 3x real time, not fast mode (measured, 4 runs each on tests/data/robots/ros_control_4wd.urdf with
its YAML, whose DiffDriveController has ``cmd_vel_timeout: 0.25``): in fast mode the tool's 20 Hz commands
and its samples of odometry ride on ``/clock`` arriving in bursts, so the start and end of each motion are
caught late by a varying number of sim steps: turn on odometry 1.82..2.05 rad with ``~fast_batch`` 0, and
straight 0.70..0.78 m with the default 5 ms batches (0.68 m fails); at 3x real time, 1.966..1.975 rad and
0.790..0.794 m, for about 3 s more wall time (7-8 s in all).

A robot with arm joints (transmission joints that are not drive wheels nor mimic joints) has them moved too,
after the drive: each controller of the YAMLs that commands them (trajectory, gripper action or position
command) takes its joints a small step and back, and the body is judged by ground truth (every link Gazebo keeps
against where joint_states + the URDF put it): :mod:`diffbot_sim.nodes._arm_moves`. The report lists every
transmission joint's interface, limits and controller (:mod:`diffbot_sim.check.arm_report`).

Exit status: 0 when both motions (and the arm's moves) pass, 1 when they do not (or the model or the simulator
fails: one line naming the file, element or parameter), 2 on bad usage. Every process started is stopped, by its pid and
its session, before the exit.
"""
import os
import signal
import sys
import threading
import time

from diffbot_sim import streams
from diffbot_sim.check import arc_check, drive_check, report_text, robot_report
from diffbot_sim.check.session import SIM, Session, SessionError
from diffbot_sim.description.model_files import package_path
from diffbot_sim.errors import DiffbotSimError, ModelError
from diffbot_sim.nodes._entry import entry_point
from diffbot_sim.waiting import wait_for

USAGE = ("usage: rosrun diffbot_sim robot_check <model.urdf|model.urdf.xacro> [controller.yaml ...] "
         "[-- xacro args name:=value ...]")
START_TIMEOUT = 60.0  # s (wall) for bullet_sim to load the model and report its settings
TOPIC_TIMEOUT = 20.0  # s (wall) for the first odometry, ground truth and the command connection
DRIVE_TIMEOUT = 120.0  # s (wall) for the whole drive (sim time stops if bullet_sim dies)
SETTLE, PAUSE = 1.0, 1.5  # s (sim) at rest before the first motion and after each


class UsageError(Exception):
    """The command line is not ``<model> [controller.yaml ...] [-- xacro args]``."""


def parse_argv(argv):
    """``(model, [yaml, ...], "xacro args")`` from the arguments after the program name.

    Tokens with ``:=`` count as xacro arguments also before ``--`` (what a user forgetting it means).

    Raises:
        UsageError: no model, or an option this tool does not have.
    """
    files, xacro_args = [], []
    rest = list(argv)
    if "--" in rest:
        cut = rest.index("--")
        rest, xacro_args = rest[:cut], rest[cut + 1:]
    for token in rest:
        if ":=" in token:
            xacro_args.append(token)
        elif token.startswith("-"):
            raise UsageError(f"unknown option {token}")
        else:
            files.append(token)
    if not files:
        raise UsageError("no model given")
    return files[0], files[1:], " ".join(xacro_args)


def _say(line=""):
    streams.write(sys.stdout, line + "\n")


@entry_point
def main(argv=None):
    """Entry point; returns the exit status (0 drives, 1 does not or bad input, 2 bad usage).

    Output that cannot be written (``robot_check ... | head -3``) never changes the status (:mod:`._entry`).
    """
    argv = sys.argv[1:] if argv is None else argv
    if any(a in ("-h", "--help") for a in argv[:argv.index("--") if "--" in argv else len(argv)]):
        _say(USAGE)
        return 0
    try:
        model, yamls, model_args = parse_argv(argv)
    except UsageError as err:
        streams.write(sys.stderr, f"robot_check: {err}\n{USAGE}\n")
        return 2
    model = os.path.abspath(os.path.expanduser(model))
    yamls = [os.path.abspath(os.path.expanduser(y)) for y in yamls]
    try:
        files = [(path, _load_yaml(path)) for path in yamls]
        from diffbot_sim.plugins.registry import KNOWN, KNOWN_SENSORS  # the plugin modules (rospy): here only
        from diffbot_sim.plugins.ros_control.manager import KNOWN_TYPES
        report = robot_report.build_report(model, model_args, [(p, tree) for p, (tree, _) in files], KNOWN,
                                           KNOWN_SENSORS, package_path, known_controllers=KNOWN_TYPES)
    except DiffbotSimError as err:
        streams.write(sys.stderr, f"robot_check: {err}\n")
        return 1
    for line in report_text.format_report(report):
        _say(line)
    if report.drive is None and not report.arm_joints:
        _say("result: FAIL: no drive was found, so there is nothing to drive")
        return 1
    signal.signal(signal.SIGTERM, _terminate)
    try:
        with Session(model, model_args, [docs for _, (_, docs) in files]) as session:
            try:
                return _check(session, report)
            finally:
                _leave_ros()  # before the session stops the master this node talks to
    except SessionError as err:
        _say(f"result: FAIL: {err}")
        return 1
    except KeyboardInterrupt as err:
        streams.write(sys.stderr, "robot_check: interrupted\n")
        return 128 + (err.args[0] if err.args else signal.SIGINT)


def _leave_ros():
    """Shut this process's node down (when the drive got as far as starting it)."""
    import rospy

    if rospy.core.is_initialized():
        rospy.signal_shutdown("robot_check done")


def _terminate(signum, frame):
    """SIGTERM ends the check as Ctrl-C does: the processes it started are stopped on the way out."""
    raise KeyboardInterrupt(signum)


def _load_yaml(path):
    """``(tree, documents)`` of a controller YAML as rosparam loads it (``!degrees`` and all).

    Raises:
        ModelError: the file is missing or not YAML rosparam can load (naming the file).
    """
    import rosparam

    if not os.path.isfile(path):
        raise ModelError("no such file", path)
    try:
        docs = rosparam.load_file(path, default_namespace="/")
    except Exception as err:  # rosparam raises RosParamException, yaml errors, ...
        detail = " ".join(str(err).split()) or type(err).__name__
        raise ModelError(f"not a controller YAML rosparam can load ({detail})", path) from None
    tree = {}
    for values, ns in docs:
        if not isinstance(values, dict):
            raise ModelError(f"not a mapping of parameters (a {type(values).__name__})", path)
        robot_report.merge_params(tree, ns or "/", values)
    return tree, docs


# ----------------------------------------------------------------------------------------------- drive

class _Latest:
    """The newest message of a topic as an ``(x, y, yaw)`` pose, and every message since ``start_span`` as
    a :class:`diffbot_sim.check.drive_check.BodySample` (callbacks only store)."""

    def __init__(self):
        self.lock = threading.Lock()
        self.pose = None
        self.span = []

    def __call__(self, msg):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        sample = drive_check.body_sample(msg.header.stamp.to_sec(), (p.x, p.y, p.z), (q.x, q.y, q.z, q.w))
        with self.lock:
            self.pose = (sample.x, sample.y, sample.yaw)
            self.span.append(sample)

    def get(self):
        with self.lock:
            return self.pose

    def start_span(self):
        with self.lock:
            self.span = []

    def take_span(self):
        with self.lock:
            span, self.span = self.span, []
            return span


def _wait(predicate, timeout, what, session):
    """``waiting.wait_for`` that fails at once, with bullet_sim's own last word, when bullet_sim has exited."""
    def check():
        failure = session.sim_failure()
        if failure:
            raise SessionError(failure)
        return predicate()
    return wait_for(check, timeout, what, error=lambda message: SessionError(
        f"{message} (bullet_sim log: {session.sim.log_path}, removed at exit)"))


def _check(session, report):
    """Join the session, drive (when the robot has a drive), move the arm joints (when it has some); the
    exit status and the final ``result:`` line."""
    import rospy

    from diffbot_sim.nodes import _arm_moves

    rospy.init_node("robot_check", anonymous=True, argv=[sys.argv[0]], disable_signals=True)
    _wait(lambda: rospy.has_param(SIM + "/loaded_mass"), START_TIMEOUT, "bullet_sim to load the model", session)
    verdicts = []
    if report.drive is not None:
        verdicts.append(_drive(session, report))
    if report.arm_joints and (not verdicts or verdicts[0][0]):
        logged = session.sim_warnings()
        watchdog = threading.Thread(target=_watch, args=(session, time.monotonic() + DRIVE_TIMEOUT), daemon=True)
        watchdog.start()
        try:
            passed, lines, moved = _arm_moves.check_arm(report, lambda p, t, w: _wait(p, t, w, session))
        except rospy.ROSInterruptException:
            raise SessionError(session.sim_failure() or f"the arm check took longer than {DRIVE_TIMEOUT:g} s "
                               "of wall time (sim time stopped?)") from None
        for line in lines:
            _say(line)
        during = [w for w in session.sim_warnings() if w not in logged and w not in report.warnings]
        for text in during[:3]:
            _say(f"  bullet_sim warned while moving the arm: {text}")
        if moved or not verdicts:  # joints with no controller to move them: a driving robot is judged by its drive
            verdicts.append((passed, "its arm joints move as commanded, the body where joint_states + the URDF "
                                     "put it" if passed else "the arm does not move as commanded (ground truth)"))
    failed = [text for ok, text in verdicts if not ok]
    if failed:
        _say(f"result: FAIL: {failed[0]}")
        return 1
    if report.drive is None:
        _say(f"result: PASS: {verdicts[0][1]} (no drive)")
    elif len(verdicts) == 1:
        _say(f"result: PASS: {verdicts[0][1]}")
    else:
        _say("result: PASS: the robot drives and its arm joints move as commanded")
    return 0


def _drive(session, report):
    """Drive the robot and judge it: (passed, verdict)."""
    import rospy
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry

    cmd_topic = rospy.get_param(SIM + "/cmd_vel_topic", None)
    odom_topic = rospy.get_param(SIM + "/odom_topic", None)
    _say(f"drive test (bullet_sim headless, 3x real time): {cmd_topic} -> {odom_topic}, {SIM}/ground_truth")
    logged = session.sim_warnings()
    extra = [w for w in logged if w not in report.warnings]
    for text in extra[:report_text.MAX_WARNINGS]:
        _say(f"  bullet_sim also warned: {text}")
    if not cmd_topic or not odom_topic:
        raise SessionError("bullet_sim reports no command or odometry topic for the drive "
                           f"({SIM}/cmd_vel_topic, {SIM}/odom_topic)")
    odom, truth = _Latest(), _Latest()
    subs = [rospy.Subscriber(odom_topic, Odometry, odom, queue_size=1),
            rospy.Subscriber(SIM + "/ground_truth", Odometry, truth, queue_size=1)]
    pub = rospy.Publisher(cmd_topic, Twist, queue_size=1)
    _wait(lambda: odom.get() is not None and truth.get() is not None, TOPIC_TIMEOUT,
          f"{odom_topic} and {SIM}/ground_truth", session)
    _wait(lambda: pub.get_num_connections() > 0, TOPIC_TIMEOUT, f"bullet_sim to subscribe {cmd_topic}", session)

    watchdog = threading.Thread(target=_watch, args=(session, time.monotonic() + DRIVE_TIMEOUT), daemon=True)
    watchdog.start()
    try:
        _command(pub, 0.0, 0.0, SETTLE)  # a robot placed in the air lands (Gazebo's launch files say z 1.0)
        truth.start_span()
        _command(pub, 0.0, 0.0, SETTLE)
        rest = drive_check.rest(truth.take_span(), report.rest_height)
        start = (odom.get(), truth.get())
        _command(pub, drive_check.SPEED, 0.0, drive_check.SECONDS)
        end = (odom.get(), truth.get())
        straight_body = drive_check.ride(truth.take_span(), rest.height, "driving straight")
        _command(pub, 0.0, 0.0, PAUSE)
        straight = drive_check.straight(start[0], end[0], start[1], end[1])
        strafe = strafe_body = None
        if report.holonomic:  # a planar or force-based base also moves sideways (drive_check.STRAFE_RUN)
            start = (odom.get(), truth.get())
            truth.start_span()
            _command(pub, 0.0, 0.0, drive_check.SECONDS, lateral=drive_check.SPEED)
            end = (odom.get(), truth.get())
            strafe_body = drive_check.ride(truth.take_span(), rest.height, "driving sideways")
            _command(pub, 0.0, 0.0, PAUSE)
            strafe = drive_check.strafe(start[0], end[0], start[1], end[1])
        if report.car:  # a car cannot turn in place: an arc at a fixed steering angle, judged by arc_check
            arc, arc_body = _arc(pub, truth, odom, report, rest)
            _command(pub, 0.0, 0.0, PAUSE)
            return _verdict(session, report, logged, rest, straight, straight_body, arc=(arc, arc_body))
        start = (odom.get(), truth.get())
        truth.start_span()
        _command(pub, 0.0, drive_check.TURN, drive_check.SECONDS)
        end = (odom.get(), truth.get())
        turn_body = drive_check.ride(truth.take_span(), rest.height, "turning")
        _command(pub, 0.0, 0.0, PAUSE)
        turned = drive_check.wrap(end[1][2] - start[1][2])
        drift = drive_check.skid_turn_drift(*report.footprint, turned) if report.skid and report.footprint \
            else drive_check.MAX_TURN_DRIFT
        turn = drive_check.turn(start[0], end[0], start[1], end[1], max_moved=drift, centre=report.wheel_centre,
                                truth_fraction=drive_check.SKID_TURN_FRACTION if report.skid
                                else drive_check.TRUTH_TURN_FRACTION)
    except rospy.ROSInterruptException:
        raise SessionError(session.sim_failure() or f"the drive took longer than {DRIVE_TIMEOUT:g} s "
                           "of wall time (sim time stopped?)") from None
    finally:
        for sub in subs:
            sub.unregister()
    return _verdict(session, report, logged, rest, straight, straight_body, (turn, turn_body), (strafe, strafe_body))


def _arc(pub, truth, odom, report, rest):
    """Drive the car in an arc (arc_check.ARC_SPEED at arc_check.ARC_STEER, past the first second: the steering's
    travel) and judge the rear axle's circle and slip by ground truth."""
    _command(pub, arc_check.ARC_SPEED, arc_check.ARC_STEER, 1.0)
    truth.start_span()
    _command(pub, arc_check.ARC_SPEED, arc_check.ARC_STEER, arc_check.ARC_SECONDS - 1.0)
    span = truth.take_span()
    body = drive_check.ride(span, rest.height, "driving in an arc")
    drive = report.drive
    samples = arc_check.axle_samples([(s.t, s.x, s.y, s.yaw) for s in span], drive.rear_axle)
    return arc_check.arc(samples, drive.wheelbase, arc_check.ARC_STEER, radius_range=drive.radius_range), body


def _verdict(session, report, logged, rest, straight, straight_body, turned=(None, None), strafed=(None, None),
             arc=None):
    """Print the drive's judgements and return (passed, verdict)."""
    (turn, turn_body), (strafe, strafe_body) = turned, strafed
    for line in report_text.format_rest(rest):
        _say(line)
    if arc is None:
        for line in report_text.format_motions(straight, turn, straight_body, turn_body, strafe, strafe_body):
            _say(line)
    else:
        result, body = arc
        for line in report_text.format_motions(straight, None, straight_body):
            _say(line)
        gives = (f"{result.expected:.3f} m (L / tan {arc_check.ARC_STEER:g})" if report.drive.radius_range is None
                 else "{:.3f}..{:.3f} m (its front wheels' angles)".format(*sorted(map(abs,
                                                                                        report.drive.radius_range))))
        _say(f"arc {arc_check.ARC_SPEED:g} m/s at steer {arc_check.ARC_STEER:g} rad x {arc_check.ARC_SECONDS:g} s: "
             f"rear axle radius {result.radius:.3f} m (the geometry gives {gives}), slip up to "
             f"{result.max_slip:.4f} rad, turned {result.turned:.2f} rad: {'PASS' if result.passed else 'FAIL'}")
        for text in result.failures:
            _say(f"  {text}")
        turn, turn_body = result, body
    during = [w for w in session.sim_warnings() if w not in logged and w not in report.warnings]
    for text in during[:3]:
        _say(f"  bullet_sim warned while driving: {text}")
    if len(during) > 3:
        _say(f"  ... and {len(during) - 3} more")
    if not rest.passed:
        return False, "the robot does not rest upright on the ground before driving (ground truth)"
    sideways_ok = strafe is None or (strafe.passed and strafe_body.passed)
    if straight.passed and turn.passed and straight_body.passed and turn_body.passed and sideways_ok:
        return True, "the robot drives" + (" (straight and in an arc)" if arc is not None else "")
    return False, "the robot does not drive as commanded"


def _command(pub, linear, angular, seconds, lateral=0.0):
    """Publish (linear, angular; ``lateral`` to the left, m/s) at COMMAND_RATE of sim time for ``seconds`` of
    sim time."""
    import rospy
    from geometry_msgs.msg import Twist

    msg = Twist()
    msg.linear.x, msg.linear.y, msg.angular.z = linear, lateral, angular
    end = rospy.get_time() + seconds
    while rospy.get_time() < end:
        pub.publish(msg)
        rospy.sleep(1.0 / drive_check.COMMAND_RATE)


def _watch(session, deadline):
    """Shut rospy down (so a sim-time sleep returns) when bullet_sim dies or the drive overruns."""
    import rospy

    while not rospy.is_shutdown():
        if session.sim_failure() or time.monotonic() > deadline:
            rospy.signal_shutdown("bullet_sim stopped or the drive overran")
            return
        time.sleep(0.1)
