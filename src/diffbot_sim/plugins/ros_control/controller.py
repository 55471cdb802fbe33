"""What the controller manager asks of a controller it runs (one module per ros_controllers type beside this).

A controller is built by ``load`` from its parameters (``<manager ns>/<name>``), started and stopped by
``switch``, and updated every control period on the simulator's loop (the only thread that touches the
hardware). Callbacks of its topics, actions and services run on rospy's threads: they only post work to the
loop (``ctx.sim.post`` / ``ctx.sim.call``).
"""
from diffbot_sim.errors import ModelError


class Controller:
    """Base of the simulated controllers.

    Attributes:
        type: the controller type string (``position_controllers/JointTrajectoryController``).
        interface: the hardware interface it claims (``PositionJointInterface``...), or None (reads only).
    """

    type = ""
    interface: str | None = None

    def __init__(self, ctx, hw, name, params):
        self.ctx, self.hw, self.name = ctx, hw, name
        self.params = params
        self.running = False
        self._handles = []

    # -- what the manager asks ----------------------------------------------------------------------------
    def joints(self):
        """Joints whose command this controller owns (a joint has one owner among running controllers)."""
        return set()

    def publishers(self):
        """Publishers the loop writes to (their connections are tuned and batched by the simulator)."""
        return []

    def handles(self):
        """Every topic, service and action endpoint, released when the controller is unloaded."""
        return list(self._handles)

    def start(self, now):
        self.running = True

    def stop(self, now):
        self.running = False

    def update(self, now, period, stamp, transforms):
        """One control period at sim time ``now`` (s), ``period`` s after the last."""

    def summary(self):
        return {}

    # -- helpers for subclasses ---------------------------------------------------------------------------
    def own(self, handle):
        self._handles.append(handle)
        return handle

    def require_interface(self, joint, interface):
        """Upstream's init: every joint must be in the hardware under this controller's interface."""
        self.ctx.model.joint(joint, self.name)
        have = self.hw.interface(joint)
        offered = getattr(self.hw, "interfaces", None)  # a hardware whose joints offer several (FrankaHWSim)
        if interface not in (offered(joint) if offered is not None else [have]):
            found = f"it has {have}" if have else "it has no transmission"
            raise ModelError(f"controller {self.name} needs joint '{joint}' with a {interface} transmission "
                             f"({found})", self.ctx.model.source)

    def substitute_unstable(self, joints, gains, loop, mode="position", force=None):
        """Joints of ``joints`` whose controller PID (``gains``, one per joint) is no well-damped explicit loop
        at our step (gains tuned for Gazebo's 1 ms step on light links): each is handed to PyBullet's
        ``mode`` motor within the effort limit (or ``force``), with one warning naming it, and returned: the
        controller then writes its desired positions to them instead of efforts."""
        from diffbot_sim.control.pid import STABILITY_MARGIN, loop_verdict

        out = set()
        for joint, joint_gains in zip(joints, gains):
            if joint_gains is None:
                continue
            margin, inertia = self.hw.explicit_margin(joint, joint_gains, loop)
            if margin > STABILITY_MARGIN:
                self.hw.drive_by_targets(joint, mode, force)
                self.ctx.warnings.append(
                    f"{self.name}: gains of {joint} (p={joint_gains.p:g}, d={joint_gains.d:g}) are "
                    f"{loop_verdict(joint_gains, margin, loop)} explicit loop at a "
                    f"{self.ctx.cfg.time_step * 1000:.2f} ms step on this joint (it moves {inertia:.3g}, "
                    f"{margin:.2g} of the stability bound); the joint follows the controller's desired "
                    f"{mode} through PyBullet's motor within its effort limit instead")
                out.add(joint)
        return out

    def urdf_joints(self):
        """URDF joints as the controllers' configs take them: name -> (type, lower, upper)."""
        return {name: (j.type, j.lower, j.upper) for name, j in self.ctx.model.joints.items()}


def action_server(name, spec, goal_cb, cancel_cb):
    """A started actionlib ActionServer (Debian's python3-actionlib) whose endpoints and status timer go with
    ``unregister()``, so that unloading the controller or deleting the robot removes them from the master."""
    import actionlib

    class OwnedActionServer(actionlib.ActionServer):
        def unregister(self):
            self.stop()  # its subscribers, publishers and status timer

    server = OwnedActionServer(name, spec, goal_cb, cancel_cb, auto_start=False)
    server.start()
    return server
