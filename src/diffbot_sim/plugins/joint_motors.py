"""Motors for the transmissions no drive or controller owns, as gazebo_ros_control makes them, with the
command topics ros_controllers' per-joint controllers would have:
``<joint>_velocity_controller/command``, ``<joint>_position_controller/command``,
``<joint>_effort_controller/command`` (std_msgs/Float64, in the robot's namespace).

Velocity joints are velocity motors with the URDF effort limit as force (unlimited in Gazebo without one:
here UNLIMITED_EFFORT); position joints position motors; effort joints get the commanded torque, clamped,
and zero until commanded (gazebo_ros_control writes zero effort to an effort joint no one commands).
"""
import math
import threading

from std_msgs.msg import Float64

from diffbot_sim.plugins.base import Plugin, join

#: Force/torque limit [N or N·m] of a motor whose joint has no URDF <limit effort>. Gazebo's is DBL_MAX: the
#: motor reaches any commanded velocity at once. PyBullet's velocity motor is a constraint whose impulse is
#: bounded by force * dt: 1e4 N·m is far above what any mobile robot's wheel needs (it never limits) and,
#: measured on the fixture robots, stays stable (no jitter at rest, no launch when a wheel is blocked).
UNLIMITED_EFFORT = 1.0e4

_SUFFIX = {"VelocityJointInterface": "velocity", "EffortJointInterface": "effort",
           "PositionJointInterface": "position"}


def effort_limit(model, joint):
    limit = model.joints[joint].effort_limit
    return limit if limit else UNLIMITED_EFFORT


class JointMotors(Plugin):
    filename = "(transmissions) joint motors"

    def __init__(self, ctx, transmissions):
        self.ctx = ctx
        self.transmissions = {t.joint: t for t in transmissions}
        self._lock = threading.Lock()
        self._commands = {}
        self.subs = []
        robot = ctx.robot
        for joint, trans in self.transmissions.items():
            if trans.interface != "PositionJointInterface":
                robot.free_joints(robot.indices([joint]))
            topic = join(ctx.namespace, f"{joint}_{_SUFFIX[trans.interface]}_controller/command")
            self.subs.append(ctx.subscriber(topic, Float64, self._on_command, callback_args=joint, queue_size=1))

    def joints(self):
        return set(self.transmissions)

    def next_publish(self):
        """Never: the motors only take commands; ``after_step`` has nothing to do."""
        return math.inf

    def _on_command(self, msg, joint):
        """Keep the newest finite command per joint (validated here, like cmd_vel)."""
        if not math.isfinite(msg.data):
            self.ctx.sim.warn(f"joint:{joint}", f"ignored a non-finite command for joint {joint}")
            return
        with self._lock:
            self._commands[joint] = msg.data
        self.ctx.sim.wake.set()

    def before_step(self, now):
        if not self._commands:
            return
        with self._lock:
            commands, self._commands = self._commands, {}
        robot, model = self.ctx.robot, self.ctx.model
        for joint, value in commands.items():
            trans = self.transmissions[joint]
            idx = robot.indices([joint])
            force = effort_limit(model, joint)
            if trans.interface == "VelocityJointInterface":
                robot.set_velocities(idx, [value], [force])
            elif trans.interface == "PositionJointInterface":
                robot.set_positions(idx, [value], [force])
            else:
                robot.set_efforts(idx, [max(-force, min(force, value))])

    def reset(self, now):
        with self._lock:
            self._commands = {}
