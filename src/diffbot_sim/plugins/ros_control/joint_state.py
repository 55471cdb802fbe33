"""``joint_state_controller/JointStateController``: ``joint_states`` in the controller manager's namespace at
``publish_rate``: every hardware joint (as readSim reads it), every other movable joint of the model (passive
wheels, casters, fingers a mimic plugin moves: robot_state_publisher needs them all for TF, and their true
positions make TF agree with the body) that no model plugin of the robot already publishes on the same topic
(Gazebo's joint_state_controller has only the hardware joints, so a joint never comes from two publishers: two
messages of one step carrying a joint make MoveIt's CurrentStateMonitor drop every joint's time), and
``extra_joints`` with their fixed values."""
from sensor_msgs.msg import JointState

from diffbot_sim.control.schedule import first_due_model
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import join, next_due
from diffbot_sim.plugins.ros_control.controller import Controller
from diffbot_sim.values import check_number


class JointStateController(Controller):
    type = "joint_state_controller/JointStateController"

    def __init__(self, ctx, hw, name, params, manager_ns):
        super().__init__(ctx, hw, name, params)
        rate = params.get("publish_rate")
        if rate is None:
            ctx.warnings.append(f"{name}: no publish_rate (JointStateController requires one); using 50 Hz")
            rate = 50.0
        rate = check_number(f"{name}/publish_rate", rate, low=0.0, low_open=True)
        self.period = 1.0 / rate
        self.hw_joints = hw.names()
        self.passive: list[str] | None = None  # chosen at the first update (_choose_passive)
        self.passive_idx: list[int] = []
        self.extra = []
        for item in params.get("extra_joints", []) or []:
            entry = item if isinstance(item, dict) else {"name": item}
            if isinstance(entry.get("name"), str):
                self.extra.append((entry["name"], float(entry.get("position", 0.0)),
                                   float(entry.get("velocity", 0.0)), float(entry.get("effort", 0.0))))
        self.pub = self.own(ctx.publisher(join(manager_ns, "joint_states"), JointState))
        self.builder = None
        self.next = 0.0

    def _choose_passive(self):
        """The model's other movable joints, less those a model plugin publishes on this topic; returns the
        message builder of every joint published. Chosen at the first update, not at load: an autostarted
        controller is made while the robot's plugins are still being created (the joint state publisher last)."""
        robot = self.ctx.robot
        elsewhere = self.ctx.joint_state_topics.get(self.pub.resolved_name, set())
        self.passive = [j for j in sorted(robot.joint_index, key=robot.joint_index.get)
                        if j not in self.hw.joints and j not in elsewhere]
        self.passive_idx = robot.indices(self.passive)
        return ros_msgs.JointStateBuilder(self.hw_joints + self.passive + [e[0] for e in self.extra])

    def publishers(self):
        return [self.pub]

    def start(self, now):
        """joint_state_controller's starting() (0.21.2, Noetic's last release): its last publication time is
        ``now``, so the first message comes one period later."""
        super().start(now)
        self.next = first_due_model(now, self.period)

    def update(self, now, period, stamp, transforms):
        if now + 1e-9 < self.next:  # its own schedule within the control period
            return
        self.next = next_due(self.next, self.period, now)
        if not self.pub.get_num_connections():
            return
        builder = self.builder
        if builder is None:
            builder = self.builder = self._choose_passive()
        joints = [self.hw.joints[j] for j in self.hw_joints]
        positions = [j.position for j in joints]
        velocities = [j.velocity for j in joints]
        efforts = [j.effort for j in joints]
        if self.passive_idx:
            p, v, e = self.ctx.robot.joint_states(self.passive_idx)
            positions += p
            velocities += v
            efforts += e
        for _, p, v, e in self.extra:
            positions.append(p)
            velocities.append(v)
            efforts.append(e)
        self.pub.publish(builder.build(stamp, positions, velocities, efforts))

    def summary(self):
        return {f"{self.name}/topic": self.pub.resolved_name}
