"""``~ground_truth`` (nav_msgs/Odometry in ``world``): the physics pose and twist of the robot's base, as
Gazebo's p3d plugin gives them; for judging odometry. Enabled by ``~publish_ground_truth``."""
from nav_msgs.msg import Odometry

from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import Plugin


class GroundTruth(Plugin):
    filename = "(simulator) ~ground_truth"

    def __init__(self, ctx, child_frame, rate=100.0):
        self.ctx = ctx
        self.pub = ctx.publisher(ctx.private + "ground_truth", Odometry)
        self.builder = ros_msgs.OdometryBuilder("world", child_frame, 0.0, 0.0, 0.0)
        self.period = 1.0 / rate

    def publishers(self):
        return [self.pub]

    def after_step(self, now, stamp, transforms):
        if not self.take_due(now, self.period):
            return
        if self.pub.get_num_connections():
            robot = self.ctx.robot
            pose = robot.base_pose()
            linear, angular = robot.base_twist(pose)
            self.pub.publish(self.builder.build(stamp, pose[0], pose[1], linear, angular))
