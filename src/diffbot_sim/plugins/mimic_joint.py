"""Mimic joints: roboticsgroup's MimicJointPlugin (``libroboticsgroup_gazebo_mimic_joint_plugin.so`` and
``libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so``) and URDF ``<mimic>`` where no plugin drives the joint.

The plugin's logic is :mod:`diffbot_sim.control.mimic_joint`: every physics step the mimic joint goes to
``master * multiplier + offset``, kinematically (Gazebo's SetPosition; here PyBullet's position motor that
removes the whole error each step) or, with ``<hasPID>``, by the PID's effort clamped to ``maxEffort`` (added to
whatever else pushes the joint that step, as Gazebo's SetForce adds up). A PID unstable at our step (gains for
1 ms on a finger of grams) runs as PyBullet's position motor capped at ``maxEffort`` instead, with one warning,
as gazebo_ros_control's PID joints do. Gazebo classic ignores URDF ``<mimic>`` in its physics; here a mimic
joint no plugin drives follows its master the kinematic way, so the body matches what robot_state_publisher
draws from the master alone.
"""
import math

from diffbot_sim.control.mimic_joint import MimicCore, mimic_config, urdf_mimic_target
from diffbot_sim.control.pid import STABILITY_MARGIN, explicit_loop_margin, loop_verdict, pid_gains
from diffbot_sim.errors import PluginNotLoaded
from diffbot_sim.plugins.base import Plugin, get_param
from diffbot_sim.plugins.joint_motors import UNLIMITED_EFFORT
from diffbot_sim.plugins.ros_control.hardware import KINEMATIC_POSITION_GAIN


class MimicJoint(Plugin):
    filename = "libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so"

    def __init__(self, ctx, cfg, filename):
        self.ctx, self.cfg, self.filename = ctx, cfg, filename
        robot = ctx.robot
        self.master, self.mimic = robot.indices([cfg.joint, cfg.mimic_joint])
        self.pair = [self.master, self.mimic]
        gains = pid_gains(get_param(cfg.pid_namespace, None), cfg.pid_namespace) if cfg.has_pid else None
        self.core = MimicCore(cfg, gains)
        self.motor = not cfg.has_pid  # a position motor (kinematic, or standing in for an unstable PID)
        self.force = UNLIMITED_EFFORT
        if cfg.has_pid and gains is not None:
            inertia = robot.joint_inertias([self.mimic])[0]
            margin = explicit_loop_margin(gains, ctx.cfg.time_step, inertia, "position")
            if margin > STABILITY_MARGIN:
                ctx.warnings.append(
                    f"{cfg.path}: the PID at {cfg.pid_namespace} (p={gains.p:g}, d={gains.d:g}) is "
                    f"{loop_verdict(gains, margin, 'position')} explicit loop at a "
                    f"{ctx.cfg.time_step * 1000:.2f} ms step on {cfg.mimic_joint} (it moves {inertia:.3g}); "
                    f"it runs as PyBullet's position motor capped at maxEffort {abs(cfg.max_effort):g} instead")
                self.motor, self.force = True, abs(cfg.max_effort) if cfg.max_effort else UNLIMITED_EFFORT
        ctx.warnings.extend(cfg.notes)
        if not self.motor:
            robot.free_joints([self.mimic])

    def next_control(self):
        return self.ctx.sim.sim_time

    def before_step(self, now):
        robot = self.ctx.robot
        master, mimic = robot.joint_positions(self.pair)
        if self.motor:
            target = self.core.target(master)
            if math.isfinite(target) and abs(target - mimic) >= self.core.config.sensitiveness:
                robot.set_positions([self.mimic], [target], [self.force],
                                    KINEMATIC_POSITION_GAIN if not self.core.config.has_pid else None)
            return
        effort = self.core.effort(master, mimic, self.ctx.cfg.time_step)
        if effort is not None:
            robot.set_efforts([self.mimic], [effort])

    def summary(self):
        cfg = self.cfg
        return {f"mimic/{cfg.mimic_joint}": f"{cfg.joint} x {cfg.multiplier:g} + {cfg.offset:g}"
                                           + (" (PID)" if cfg.has_pid and not self.motor else "")}


class UrdfMimic(Plugin):
    """URDF ``<mimic>`` joints no plugin drives: each follows its master kinematically every step."""

    filename = "(URDF) mimic joints"

    def __init__(self, ctx, joints):
        self.ctx = ctx
        robot = ctx.robot
        self.names = [j.name for j in joints]
        self.couplings = [(robot.joint_index[j.mimic.joint], robot.joint_index[j.name], j.mimic) for j in joints]

    def next_control(self):
        return self.ctx.sim.sim_time

    def before_step(self, now):
        robot = self.ctx.robot
        masters = robot.joint_positions([m for m, _, _ in self.couplings])
        for (_master, mimic, spec), position in zip(self.couplings, masters):
            robot.set_positions([mimic], [urdf_mimic_target(position, spec)], [UNLIMITED_EFFORT],
                                KINEMATIC_POSITION_GAIN)

    def summary(self):
        return {"urdf_mimic_joints": ",".join(self.names)}


def create(ctx, element, path, params):
    """A MimicJointPlugin; PluginNotLoaded (one warning, the robot loads without it) when its joints are
    missing, as upstream stays inactive."""
    def effort_limit_of(name):
        joint = ctx.model.joints[name]
        return joint.effort_limit if joint.effort_limit is not None else -1.0
    cfg = mimic_config(_with_namespace(ctx, element), path, effort_limit_of)
    for name in (cfg.joint, cfg.mimic_joint):
        if name not in ctx.robot.joint_index:
            raise PluginNotLoaded(f"joint '{name}' is not movable in the simulated model; MimicJointPlugin could "
                                  "not be loaded", element=path)
    return MimicJoint(ctx, cfg, element.get("filename", MimicJoint.filename))


def _with_namespace(ctx, element):
    """The plugin's tags, with the robot's namespace (``~robots``) standing in for its robotNamespace."""
    tags: dict[str, str] = {}
    for child in element:
        tags.setdefault(child.tag, (child.text or "").strip())
    namespace = ctx.plugin_namespace(tags.get("robotNamespace") or None, "")
    tags["robotNamespace"] = (namespace or "").strip("/")
    return tags


def urdf_mimics(ctx, driven):
    """The UrdfMimic plugin for the model's ``<mimic>`` joints not in ``driven`` (joints a plugin drives as
    mimics), or None."""
    joints = [j for j in ctx.model.joints.values()
              if j.mimic is not None and j.name not in driven and j.name in ctx.robot.joint_index
              and j.mimic.joint in ctx.robot.joint_index]
    return UrdfMimic(ctx, joints) if joints else None
