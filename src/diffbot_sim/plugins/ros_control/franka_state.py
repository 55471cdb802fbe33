"""``franka_control/FrankaStateController`` (franka_ros 0.10.1, ``franka_control/src/franka_state_controller.cpp``) on
the franka_hw state FrankaHWSim serves (:mod:`.franka_hardware`): at ``publish_rate`` (default 30 Hz), relative
to the controller's namespace,

* ``franka_states`` (franka_msgs/FrankaState), ``joint_states`` (``joint_names``: q, dq, tau_J) and
  ``joint_states_desired`` (q_d, dq_d, tau_J_d), ``F_ext`` (geometry_msgs/WrenchStamped, K_F_ext_hat_K in
  ``<arm_id>_K``);
* on /tf: ``<arm_id>_link8`` -> ``<arm_id>_NE`` (F_T_NE) -> ``<arm_id>_EE`` (NE_T_EE) -> ``<arm_id>_K`` (EE_T_K).

Parameters: ``arm_id`` (required), ``publish_rate``, ``joint_names`` (exactly 7). It claims no joint.
"""
from sensor_msgs.msg import JointState

from diffbot_sim.control import franka as fk
from diffbot_sim.errors import ConfigError, ModelError
from diffbot_sim.messages import common as ros_msgs, franka as franka_messages
from diffbot_sim.plugins.base import join, next_due
from diffbot_sim.plugins.ros_control.controller import Controller
from diffbot_sim.transforms import matrix_rpy, rpy_quaternion
from diffbot_sim.values import check_number

CONTROLLER_TYPE = "franka_control/FrankaStateController"
DEFAULT_PUBLISH_RATE = 30.0  # [Hz]


class FrankaStateController(Controller):
    type = CONTROLLER_TYPE

    def __init__(self, ctx, hw, name, params):
        super().__init__(ctx, hw, name, params)
        if not hasattr(hw, "robot_state"):
            raise ModelError(f"{CONTROLLER_TYPE} {name}: Could not get Franka state interface from hardware "
                             f"(robotSimType {fk.SIM_TYPE} serves it)", ctx.model.source)
        arm_id = params.get("arm_id")
        if not isinstance(arm_id, str) or not arm_id:
            raise ConfigError(f"{name}/arm_id", arm_id, "the arm's name (FrankaStateController: Could not get "
                              "parameter arm_id)")
        if arm_id != hw.arm_id():
            raise ConfigError(f"{name}/arm_id", arm_id, f"the hardware's arm, {hw.arm_id()} (FrankaStateController: "
                              f"Exception getting franka state handle: no {arm_id}_robot)")
        joints = params.get("joint_names")
        if not isinstance(joints, list) or len(joints) != 7 or not all(isinstance(j, str) for j in joints):
            raise ConfigError(f"{name}/joint_names", joints, "7 joint names (FrankaStateController: Invalid or no "
                              "joint_names parameters provided)")
        self.arm_id, self.joint_names = arm_id, joints
        self.period = 1.0 / check_number(f"{name}/publish_rate", params.get("publish_rate", DEFAULT_PUBLISH_RATE),
                                         low=0.0, low_open=True)
        msg, _ = franka_messages.franka_msgs()
        self.state_pub = self.own(ctx.publisher(join(name, "franka_states"), msg.FrankaState))
        self.joint_pub = self.own(ctx.publisher(join(name, "joint_states"), JointState))
        self.desired_pub = self.own(ctx.publisher(join(name, "joint_states_desired"), JointState))
        self.wrench_pub = self.own(ctx.publisher(join(name, "F_ext"), franka_messages.WrenchStamped))
        self.joint_builder = ros_msgs.JointStateBuilder(joints)
        self.desired_builder = ros_msgs.JointStateBuilder(joints)
        frames = [ctx.frame(f"{arm_id}_{f}") for f in ("link8", "NE", "EE", "K")]
        self.tf_builders = [ros_msgs.TransformBuilder(a, b) for a, b in zip(frames, frames[1:])]
        self.k_frame = frames[-1]
        self.next = 0.0
        self.seq = 0

    def publishers(self):
        return [self.state_pub, self.joint_pub, self.desired_pub, self.wrench_pub]

    def start(self, now):
        """franka_hw's TriggerRate: the first publication one period after the start."""
        super().start(now)
        self.next = now + self.period

    def update(self, now, period, stamp, transforms):
        if now + 1e-9 < self.next:
            return
        self.next = next_due(self.next, self.period, now)
        state = self.hw.robot_state(now)
        if self.state_pub.get_num_connections():
            self.state_pub.publish(franka_messages.franka_state(stamp, self.seq, state))
        if self.joint_pub.get_num_connections():
            self.joint_pub.publish(self.joint_builder.build(stamp, list(state.q), list(state.dq), list(state.tau_J)))
        if self.desired_pub.get_num_connections():
            self.desired_pub.publish(self.desired_builder.build(stamp, list(state.q_d), list(state.dq_d),
                                                                list(state.tau_J_d)))
        if self.wrench_pub.get_num_connections():
            self.wrench_pub.publish(franka_messages.external_wrench(stamp, self.k_frame, state.K_F_ext_hat_K))
        for builder, array in zip(self.tf_builders, (state.F_T_NE, state.NE_T_EE, state.EE_T_K)):
            transforms.append(builder.build(stamp, *_pose(array)))
        self.seq += 1

    def summary(self):
        return {f"{self.name}/topic": join(self.name, "franka_states")}


def _pose(array16):
    """A libfranka transform as ((x, y, z), (qx, qy, qz, qw))."""
    m = fk.matrix(array16)
    return tuple(float(v) for v in m[:3, 3]), rpy_quaternion(*matrix_rpy(m[:3, :3]))
