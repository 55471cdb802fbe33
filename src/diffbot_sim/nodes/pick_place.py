"""``rosrun diffbot_sim pick_place``: diffbot_arm (``roslaunch diffbot_sim manipulator.launch``) drives to the
pick table, picks the box, carries it to the other table and places it there, as a user's script does it: the
base through ``cmd_vel`` closing on ``odom``, the arm through ``arm_controller/follow_joint_trajectory``
(control_msgs/FollowJointTrajectory), the gripper through ``gripper_controller/gripper_cmd``
(control_msgs/GripperCommand). The steps and their targets are :mod:`diffbot_sim.control.pick_place`'s, from
the scene (worlds/pick_place.world) and the arm's geometry (the URDF on ``robot_description``).

Parameters (read once; a bad one is one line and exit 1): ``~pick`` and ``~place`` ([x, y, z] m, the object's
centre now and where it should go; default: the world's), ``~object_model`` (default ``pick_box``: when
``/gazebo/get_model_state`` answers for it, its pose is the pick point; "" to skip), ``~step_timeout`` (s of
sim time beyond a step's own duration, default 20). The odometry is taken as world coordinates (Gazebo's diff
drive plugin with ``odometrySource world``, the seed's).

Exit status: 0 when every step succeeded, 1 when one failed (the step and why in one line) or a parameter is
bad; the base is stopped either way.

``--moveit`` (or ``_moveit:=true``): the arm and the gripper planned and executed by MoveIt instead
(:mod:`diffbot_sim.nodes.pick_place_moveit`; ``roslaunch diffbot_arm_moveit_config demo_gazebo.launch``).
"""
import sys
import threading

import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from diffbot_sim.check.arm_check import forward_kinematics
from diffbot_sim.control import pick_place as pp
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.errors import ConfigError, DiffbotSimError
from diffbot_sim.nodes._arm_moves import wait_for_goal
from diffbot_sim.nodes._entry import entry_point
from diffbot_sim.transforms import yaw_from_quaternion
from diffbot_sim.values import check_number, check_string

SERVER_TIMEOUT = 60.0  # s (wall) for the action servers (the spawner starts the controllers)
SETTLE = 0.3  # s (sim) at rest after each base motion
RATE = 50.0  # Hz (sim) of base commands
MAX_ROUNDS = 5  # drive-stop-settle rounds per base motion


class StepFailed(Exception):
    """A step did not do what it was for (the message says which and why)."""


def read_point(name, default):
    value = rospy.get_param(name, list(default))
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        raise ConfigError(name, value, "[x, y, z] (m)")
    return tuple(check_number(f"{name}[{i}]", v) for i, v in enumerate(value))


class Robot:
    """The ROS side: odometry in, base commands and action goals out."""

    def __init__(self, step_timeout):
        import actionlib
        from control_msgs.msg import FollowJointTrajectoryAction, GripperCommandAction

        self.step_timeout = step_timeout
        self.lock = threading.Lock()
        self.pose = None
        rospy.Subscriber("odom", Odometry, self._on_odom, queue_size=1)
        self.cmd = rospy.Publisher("cmd_vel", Twist, queue_size=1)
        self.arm = actionlib.SimpleActionClient("arm_controller/follow_joint_trajectory", FollowJointTrajectoryAction)
        self.gripper = actionlib.SimpleActionClient("gripper_controller/gripper_cmd", GripperCommandAction)
        for client, what in ((self.arm, "arm_controller"), (self.gripper, "gripper_controller")):
            if not client.wait_for_server(rospy.Duration(SERVER_TIMEOUT)):
                raise StepFailed(f"no action server of {what} (is manipulator.launch running?)")

    def _on_odom(self, msg):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        with self.lock:
            self.pose = (p.x, p.y, yaw_from_quaternion(q.x, q.y, q.z, q.w))

    def current_pose(self, timeout=10.0):
        deadline = rospy.get_time() + timeout
        while not rospy.is_shutdown():
            with self.lock:
                if self.pose is not None:
                    return self.pose
            if rospy.get_time() > deadline:
                break
            rospy.sleep(0.05)
        raise StepFailed("no odometry on odom")

    def stop(self):
        self.cmd.publish(Twist())

    def move_base(self, step):
        """Drive (turn) until the motion is done, stop, settle; again while the settled base is not within
        tolerance (it coasts on, and in fast mode odometry reaches this loop late)."""
        rate = rospy.Rate(RATE)
        deadline = rospy.get_time() + self.step_timeout
        for _ in range(MAX_ROUNDS):
            motion = pp.BaseMotion(step)
            while not rospy.is_shutdown():
                linear, angular = motion.command(*self.current_pose())
                if motion.done:
                    break
                if rospy.get_time() > deadline:
                    self.stop()
                    raise StepFailed(f"{step.name}: not there after {self.step_timeout:g} s (at "
                                     f"{self.current_pose()})")
                msg = Twist()
                msg.linear.x, msg.angular.z = linear, angular
                self.cmd.publish(msg)
                rate.sleep()
            self.stop()
            rospy.sleep(SETTLE)
            if pp.still_there(step, *self.current_pose()):
                return
        raise StepFailed(f"{step.name}: not settled within tolerance after {MAX_ROUNDS} tries (at "
                         f"{self.current_pose()})")

    def move_arm(self, step):
        from actionlib_msgs.msg import GoalStatus
        from control_msgs.msg import FollowJointTrajectoryGoal
        from trajectory_msgs.msg import JointTrajectoryPoint

        goal = FollowJointTrajectoryGoal()
        goal.trajectory.joint_names = list(pp.ARM_JOINTS)
        goal.trajectory.points = [JointTrajectoryPoint(positions=list(step.target),
                                                       time_from_start=rospy.Duration.from_sec(step.duration))]
        self.arm.send_goal(goal)
        if not wait_for_goal(self.arm, step.duration + self.step_timeout):
            self.arm.cancel_goal()
            raise StepFailed(f"{step.name}: no result within {step.duration + self.step_timeout:g} s")
        state, result = self.arm.get_state(), self.arm.get_result()
        if state != GoalStatus.SUCCEEDED or result is None or result.error_code != 0:
            code = result.error_code if result is not None else None
            text = result.error_string if result is not None else ""
            raise StepFailed(f"{step.name}: {GoalStatus.to_string(state)} (error_code {code}) {text}".rstrip())

    def move_gripper(self, step, object_size):
        from actionlib_msgs.msg import GoalStatus
        from control_msgs.msg import GripperCommandGoal

        goal = GripperCommandGoal()
        goal.command.position, goal.command.max_effort = step.target
        self.gripper.send_goal(goal)
        if not wait_for_goal(self.gripper, self.step_timeout):
            self.gripper.cancel_goal()
            raise StepFailed(f"{step.name}: no result within {self.step_timeout:g} s")
        state, result = self.gripper.get_state(), self.gripper.get_result()
        ok, reason = pp.gripper_outcome(step, GoalStatus.to_string(state),
                                        result.position if result is not None else None,
                                        bool(result and result.reached_goal), bool(result and result.stalled),
                                        object_size)
        if not ok:
            raise StepFailed(reason)
        rospy.loginfo(f"pick_place: {reason}")


def scene_from_params():
    """The Scene with ``~pick`` / ``~place`` applied, the pick point from Gazebo's model state if it answers."""
    defaults = pp.Scene()
    pick = read_point("~pick", defaults.pick)
    place = read_point("~place", defaults.place)
    model = check_string("~object_model", rospy.get_param("~object_model", "pick_box"), allow_empty=True)
    if model and not rospy.has_param("~pick"):
        from gazebo_msgs.srv import GetModelState

        try:
            rospy.wait_for_service("/gazebo/get_model_state", 10.0)
            state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)(model, "")
            if state.success:
                p = state.pose.position
                pick = (p.x, p.y, p.z)
                rospy.loginfo(f"pick_place: {model} is at ({p.x:.3f}, {p.y:.3f}, {p.z:.3f})")
        except (rospy.ROSException, rospy.ServiceException) as err:
            rospy.logwarn(f"pick_place: no pose of {model} from /gazebo/get_model_state ({err}); using {pick}")
    return pp.Scene(pick=pick, place=place)


@entry_point
def main(argv=None):
    """Entry point of ``rosrun diffbot_sim pick_place``; returns the exit status."""
    rospy.init_node("pick_place")
    args = rospy.myargv(sys.argv if argv is None else argv)
    if "--moveit" in args[1:] or rospy.get_param("~moveit", False) is True:
        from diffbot_sim.nodes import pick_place_moveit

        return pick_place_moveit.run(Robot, StepFailed, scene_from_params)
    try:
        step_timeout = check_number("~step_timeout", rospy.get_param("~step_timeout", 20.0), low=0.0, low_open=True)
        scene = scene_from_params()
        model = parse_urdf(rospy.get_param("robot_description"))
        origins = {link: pose[0] for link, pose in forward_kinematics(model, {}).items()}
        arm = pp.arm_geometry(origins)
        robot = Robot(step_timeout)
        steps = pp.plan(scene, arm, robot.current_pose())
    except (DiffbotSimError, KeyError, ValueError, StepFailed) as err:
        rospy.logfatal(f"pick_place: {err}")
        return 1
    rospy.loginfo("pick_place: the steps:\n" + "\n".join(pp.describe(steps)))
    try:
        for index, step in enumerate(steps, 1):
            rospy.loginfo(f"pick_place: step {index}/{len(steps)}: {step.name}")
            if step.kind in (pp.DRIVE, pp.TURN):
                robot.move_base(step)
            elif step.kind == pp.ARM:
                robot.move_arm(step)
            else:
                robot.move_gripper(step, scene.object_size)
    except StepFailed as err:
        robot.stop()
        rospy.logerr(f"pick_place: failed: {err}")
        return 1
    except rospy.ROSInterruptException:
        return 1
    rospy.loginfo(f"pick_place: done: {len(steps)} steps succeeded")
    return 0


if __name__ == "__main__":
    sys.exit(main())
