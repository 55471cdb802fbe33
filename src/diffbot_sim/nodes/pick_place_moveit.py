"""``rosrun diffbot_sim pick_place --moveit``: the pick-and-place of :mod:`diffbot_sim.nodes.pick_place` with the arm
and the gripper planned and executed by MoveIt (``roslaunch diffbot_arm_moveit_config demo_gazebo.launch``: the
simulator with move_group), as a MoveIt user's script does it with ``moveit_commander``: the tables are collision
objects of the planning scene (so the arm plans around them), each arm step is a pose goal for
``gripper_tcp_link`` (fingers down, turned towards the object: a pose the 4-joint arm can take), the gripper
steps are joint goals of the ``gripper`` group (executed by the simulator's GripperCommand action), the held box
is attached to the hand while carried. The base drives as in the plain variant (cmd_vel, closing on odom).

Parameters: those of the plain variant, and ``~planning_time`` (s, default 5) and ``~planning_attempts``
(default 3) per arm step. Exit status: 0 when every step succeeded, 1 otherwise (the step and why in one line).
"""
import functools
import sys

import rospy

from diffbot_sim.check.arm_check import forward_kinematics
from diffbot_sim.control import pick_place as pp
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.errors import DiffbotSimError
from diffbot_sim.nodes._arm_moves import JointStates, settle
from diffbot_sim.values import check_number

ARM_GROUP, GRIPPER_GROUP = "arm", "gripper"
TOOL = "gripper_tcp_link"
FINGER = "left_finger_joint"
HELD = "held_box"  # the attached collision object while the box is carried
#: The links the held box may touch (the fingers squeeze it, the palm is next to it).
TOUCH_LINKS = ["left_finger_link", "right_finger_link", "wrist_link", TOOL]
SERVER_WAIT = 60.0  # s (wall) for move_group's action servers
#: Before an arm step is planned the arm must hold within STILL_BAND rad over STILL_WINDOW s of joint_states'
#: stamps (MoveIt refuses a plan whose start is more than 0.01 rad from the state at execution: after the box is
#: let go on the table the shoulder swung 0.012 rad in the 0.3 s between planning and execution); at most
#: STILL_WAIT s of sim time, then the step is planned anyway.
STILL_BAND, STILL_WINDOW, STILL_WAIT = 0.002, 0.2, 5.0
ATTACH_MARGIN = 0.005  # m the attached box is smaller than the box


class MoveItArm:
    """moveit_commander's side: the planning scene, the arm and the gripper groups."""

    def __init__(self, scene, planning_time, attempts, joints):
        import moveit_commander

        moveit_commander.roscpp_initialize([sys.argv[0]])
        self.robot = moveit_commander.RobotCommander()
        self.frame = self.robot.get_planning_frame()
        self.scene_if = moveit_commander.PlanningSceneInterface(synchronous=True)
        self.arm = moveit_commander.MoveGroupCommander(ARM_GROUP, wait_for_servers=SERVER_WAIT)
        self.gripper = moveit_commander.MoveGroupCommander(GRIPPER_GROUP, wait_for_servers=SERVER_WAIT)
        self.arm.set_end_effector_link(TOOL)
        self.arm.set_pose_reference_frame(self.frame)
        self.arm.set_planning_time(planning_time)
        self.arm.set_num_planning_attempts(attempts)
        self.scene = scene
        self.joints = joints
        self.arm_joints = self.arm.get_active_joints()
        self.plan_times = []

    def add_tables(self):
        """The tables as boxes in the planning frame (odom: the world's frame for this robot's odometry)."""
        from geometry_msgs.msg import PoseStamped

        for name, centre, size in pp.TABLES:
            pose = PoseStamped()
            pose.header.frame_id = self.frame
            pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = centre
            pose.pose.orientation.w = 1.0
            self.scene_if.add_box(name, pose, size)
        rospy.loginfo(f"pick_place: {len(pp.TABLES)} tables in the planning scene ({self.frame})")

    def remove_tables(self):
        self.scene_if.remove_attached_object(TOOL, HELD)
        for name, _, _ in pp.TABLES:
            self.scene_if.remove_world_object(name)
        self.scene_if.remove_world_object(HELD)

    def _run(self, group, what):
        """Plan the group's target, from the arm at rest, and execute the plan; raises StepFailed with MoveIt's
        error code."""
        from moveit_msgs.msg import MoveItErrorCodes

        # the samples of the last second (JointStates keeps them): an arm already at rest is not waited for
        still, why = settle(self.joints, self.arm_joints, STILL_BAND, STILL_WINDOW, STILL_WAIT,
                            since=rospy.get_time() - 1.0)
        if not still:
            rospy.logwarn(f"pick_place: {what}: the arm did not come to rest within {STILL_WAIT} s ({why}); "
                          f"planning anyway")
        ok, plan, seconds, error = group.plan()
        if not ok:
            raise StepFailed(f"{what}: no plan ({_code_name(error.val, MoveItErrorCodes)})")
        self.plan_times.append(seconds)
        if not group.execute(plan, wait=True):
            raise StepFailed(f"{what}: the plan's execution failed")
        group.stop()

    def tool_to(self, step, base_pose, arm_geometry):
        target = pp.top_down_pose(step.target, pp.shoulder_xy(arm_geometry, *base_pose))
        self.arm.clear_pose_targets()
        self.arm.set_pose_target(list(target), TOOL)
        self._run(self.arm, step.name)

    def named(self, step):
        self.arm.set_named_target(step.target[0])
        self._run(self.arm, step.name)

    def fingers(self, step, finger_position):
        self.gripper.set_joint_value_target({FINGER: step.target[0]})
        self._run(self.gripper, step.name)
        if step.expect == pp.HOLD:
            position = finger_position()
            held = abs(position - self.scene.object_size / 2.0) <= 0.008
            if not held:
                raise StepFailed(f"{step.name}: the finger stopped at {position:.4f} m, not on a "
                                 f"{self.scene.object_size:.3f} m object: nothing grasped")
            self.attach()
            rospy.loginfo(f"pick_place: {step.name}: holding, finger at {position:.4f} m")
        elif self.scene_if.get_attached_objects([HELD]):
            self.scene_if.remove_attached_object(TOOL, HELD)
            self.scene_if.remove_world_object(HELD)

    def attach(self):
        """The held box as an object attached to the tool (carried plans keep it clear of the tables). The tool's
        z axis runs along the fingers, pointing down in a grasp: the box's centre is ``grasp_above`` further along
        it. Attached ATTACH_MARGIN smaller than it is: the box stands on the table when it is attached and when it
        is put down, and a box touching the table would be a start state in collision."""
        from geometry_msgs.msg import PoseStamped

        pose = PoseStamped()
        pose.header.frame_id = TOOL
        pose.pose.position.z = self.scene.grasp_above
        pose.pose.orientation.w = 1.0
        size = self.scene.object_size - ATTACH_MARGIN
        self.scene_if.attach_box(TOOL, HELD, pose, (size, size, size), touch_links=TOUCH_LINKS)


class StepFailed(Exception):
    """A step did not do what it was for."""


def _code_name(value, codes):
    for name in dir(codes):
        if name.isupper() and getattr(codes, name) == value:
            return name
    return str(value)


def _latest(joints, name):
    """``name``'s latest position on joint_states (waits up to 5 s of sim time for one)."""
    deadline = rospy.get_time() + 5.0
    while not rospy.is_shutdown() and rospy.get_time() < deadline:
        positions = joints.get()[0]
        if name in positions:
            return positions[name]
        rospy.sleep(0.02)
    raise StepFailed(f"no {name} on joint_states")


def run(Robot, BaseStepFailed, scene_from_params):
    """The MoveIt variant's body; returns the exit status. The node is initialised by the caller,
    :mod:`diffbot_sim.nodes.pick_place`, which hands over its base driver (``Robot``), its step failure and its
    parameter reading (this module does not import it back)."""
    try:
        step_timeout = check_number("~step_timeout", rospy.get_param("~step_timeout", 20.0), low=0.0, low_open=True)
        planning_time = check_number("~planning_time", rospy.get_param("~planning_time", 5.0), low=0.0,
                                     low_open=True)
        attempts = int(check_number("~planning_attempts", rospy.get_param("~planning_attempts", 3), low=1))
        scene = scene_from_params()
        model = parse_urdf(rospy.get_param("robot_description"))
        origins = {link: pose[0] for link, pose in forward_kinematics(model, {}).items()}
        geometry = pp.arm_geometry(origins)
        robot = Robot(step_timeout)
        joints = JointStates("joint_states")
        moveit = MoveItArm(scene, planning_time, attempts, joints)
        steps = pp.moveit_steps(scene, robot.current_pose())
    except (DiffbotSimError, KeyError, ValueError, BaseStepFailed, StepFailed, RuntimeError) as err:
        rospy.logfatal(f"pick_place: {err}")
        return 1
    rospy.loginfo("pick_place (MoveIt): the steps:\n" + "\n".join(pp.describe(steps)))
    finger = functools.partial(_latest, joints, FINGER)
    moveit.add_tables()
    try:
        for index, step in enumerate(steps, 1):
            rospy.loginfo(f"pick_place: step {index}/{len(steps)}: {step.name}")
            if step.kind in (pp.DRIVE, pp.TURN):
                robot.move_base(step)
            elif step.kind == pp.POSE:
                moveit.tool_to(step, robot.current_pose(), geometry)
            elif step.kind == pp.NAMED:
                moveit.named(step)
            else:
                moveit.fingers(step, finger)
    except (StepFailed, BaseStepFailed) as err:
        robot.stop()
        rospy.logerr(f"pick_place: failed: {err}")
        return 1
    except rospy.ROSInterruptException:
        return 1
    finally:
        moveit.remove_tables()
    times = moveit.plan_times
    rospy.loginfo(f"pick_place: done: {len(steps)} steps succeeded; {len(times)} MoveIt plans, planning time "
                  f"{min(times):.3f}-{max(times):.3f} s (median {sorted(times)[len(times) // 2]:.3f} s)")
    return 0
