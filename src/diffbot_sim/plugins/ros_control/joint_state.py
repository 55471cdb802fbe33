"""``joint_state_controller/JointStateController``: ``joint_states`` in the controller manager's namespace at
``publish_rate``: every hardware joint (as readSim reads it), every other movable joint of the model (passive
wheels, casters, fingers a mimic plugin moves: robot_state_publisher needs them all for TF, and their true
positions make TF agree with the body), and ``extra_joints`` with their fixed values."""
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
        robot = ctx.robot
        self.passive = [j for j in sorted(robot.joint_index, key=robot.joint_index.get) if j not in hw.joints]
        self.passive_idx = robot.indices(self.passive)
        self.extra = []
        for item in params.get("extra_joints", []) or []:
            entry = item if isinstance(item, dict) else {"name": item}
            if isinstance(entry.get("name"), str):
                self.extra.append((entry["name"], float(entry.get("position", 0.0)),
                                   float(entry.get("velocity", 0.0)), float(entry.get("effort", 0.0))))
        self.pub = self.own(ctx.publisher(join(manager_ns, "joint_states"), JointState))
        self.builder = ros_msgs.JointStateBuilder(self.hw_joints + self.passive + [e[0] for e in self.extra])
        self.next = 0.0

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
        self.pub.publish(self.builder.build(stamp, positions, velocities, efforts))

    def summary(self):
        return {f"{self.name}/topic": self.pub.resolved_name}
