"""gazebo_ros's joint services (``gazebo_ros_api_plugin``): get_joint_properties, apply_joint_effort,
clear_joint_forces, under ``~gazebo_namespace``, and the effort jobs they schedule.

As upstream: a joint is found by name over every model (the first robot that has it); apply_joint_effort
queues a job timed as :class:`diffbot_sim.gazebo.world_api.JointEffortSchedule` and its effort adds to whatever
else pushes the joint in a step; clear_joint_forces drops the jobs of that joint name and always succeeds.
get_joint_properties answers the joint's position and rate; its ``type`` is the joint's real one (upstream
always answers REVOLUTE, a FIXME in its code) and ``damping`` is empty, as upstream.
"""
import math

from gazebo_msgs import srv as gsrv

from diffbot_sim.gazebo import world_api

#: gazebo_msgs/GetJointProperties type codes
JOINT_TYPES = {"revolute": 0, "continuous": 1, "prismatic": 2, "fixed": 3,
               "floating": 4, "planar": 5}


class JointServices:
    """The joint services of one GazeboApi (its ``_run`` and robots)."""

    def __init__(self, api):
        self.api = api
        self.efforts = world_api.JointEffortSchedule()

    def advertise(self, service):
        service("get_joint_properties", gsrv.GetJointProperties, self._properties)
        service("apply_joint_effort", gsrv.ApplyJointEffort, self._apply)
        service("clear_joint_forces", gsrv.JointRequest, self._clear)

    def _find(self, name):
        """(robot runtime, PyBullet joint index, URDF joint) of the first robot with joint ``name``."""
        for runtime in self.api.sim.robots:
            robot = runtime.ctx.robot
            if name in robot.joint_index:
                return runtime, robot.joint_index[name], runtime.ctx.model.joints.get(name)
        return None

    # -- on the loop ----------------------------------------------------------------------------------------
    def before_step(self, now):
        """Efforts due during the coming step (the time it will reach, as the body wrenches)."""
        if not len(self.efforts):
            return
        for joint, effort in self.efforts.active(now + self.api.cfg.time_step):
            found = self._find(joint)
            if found is not None:
                found[0].ctx.robot.set_efforts([found[1]], [effort])

    # -- services -----------------------------------------------------------------------------------------
    def _properties(self, req):
        response = gsrv.GetJointPropertiesResponse()

        def action():
            found = self._find(req.joint_name)
            if found is None:
                raise world_api.RequestError("GetJointProperties: joint not found")
            runtime, index, joint = found
            (position,), (rate,), _ = runtime.ctx.robot.joint_states([index])
            response.type = JOINT_TYPES.get(joint.type if joint is not None else "revolute", 0)
            response.position, response.rate = [position], [rate]
            return "GetJointProperties: got properties"
        return self.api._run(action, response)

    def _apply(self, req):
        def action():
            if self._find(req.joint_name) is None:
                raise world_api.RequestError("ApplyJointEffort: joint not found")
            if not math.isfinite(req.effort):
                raise world_api.RequestError(f"ApplyJointEffort: effort is {req.effort}")
            self.efforts.add(req.joint_name, req.effort, req.start_time.to_sec(), req.duration.to_sec(),
                             self.api.sim.sim_time)
            return "ApplyJointEffort: effort set"
        return self.api._run(action, gsrv.ApplyJointEffortResponse())

    def _clear(self, req):
        self.api.sim.call(lambda: self.efforts.clear(req.joint_name))
        return gsrv.JointRequestResponse()

