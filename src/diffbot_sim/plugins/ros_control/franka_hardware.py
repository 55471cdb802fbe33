"""``robotSimType franka_gazebo/FrankaHWSim`` (franka_ros 0.10.1's ``franka_hw_sim.cpp``): a Franka arm's joints as
franka_gazebo drives them, on :class:`.hardware.RobotHWSim`'s joints (buffers, readSim, Gazebo's effort and
velocity truncation). Its parameters are read once (:func:`diffbot_sim.control.franka.franka_hw_config`).

What differs from DefaultRobotHWSim, as upstream:

* Every arm joint offers the Effort, Position and Velocity interfaces its ``<transmission>``s name (franka_
  description gives each joint all three); a joint's control method is the interface of the controller that
  claims it, set when a switch starts it (``doSwitch``). A controller claiming joints by a command interface
  must claim all 7 arm joints, or both fingers by effort; others are refused (``prepareSwitch``).
* writeSim adds **gravity compensation** to each arm joint's effort (``<arm_id>_joint1..7``), as the real
  robot's controller does: here the torque that holds the simulated body still (PyBullet's inverse dynamics at
  zero velocity and acceleration: every link beyond the joint, hand and fingers included) plus the weight of
  ``m_load`` at ``F_x_Cload`` from the flange (``franka_control/set_load``). Upstream's KDL model compensates
  link1..7 and ``m_ee`` + ``m_load`` at the flange instead: the simulated hand's real mass and centre replace
  that estimate.
* While no controller commands the arm (mode Idle, also after a user stop), each arm joint holds the position
  where it was last released through ``motion_generators/position/gains/<joint>``; POSITION and VELOCITY
  joints follow their desired position/velocity through ``motion_generators/{position,velocity}/gains``;
  EFFORT joints take the command. A PID unstable at our step runs as PyBullet's position (velocity) motor
  within the effort limit instead, with one warning (as gazebo_ros_control's pid_gains here).
* ``<robotNamespace>/initialized`` (std_msgs/Bool, latched): false when the plugin loads, true from the first
  physics step on (upstream publishes true every update), which ``spawner --wait-for initialized`` waits for.
* The franka_hw state handle ``<arm_id>_robot`` (:meth:`robot_state`) that ``franka_control/FrankaStateController``
  reads; services ``franka_control/set_EE_frame``, ``set_K_frame``, ``set_load``,
  ``set_force_torque_collision_behavior``, ``set_user_stop`` (std_srvs/SetBool) and the action
  ``franka_control/error_recovery`` (franka_msgs/ErrorRecovery: restarts the running controllers).

The state it serves: q, dq; tau_J the torque each joint applies (the effort written, gravity included; a
PyBullet motor's torque where one stands in); tau_J_d, q_d, dq_d, ddq_d as upstream's Joint getters by mode;
tau_ext_hat_filtered the external torque a quasi-static arm balances, gravity minus tau_J (upstream's
``effort - command + gravity`` with Gazebo's sign), low-pass filtered by ``tau_ext_lowpass_filter``; contact and
collision flags from it against the torque and force thresholds; O_T_EE and the external wrench from the
URDF chain ``FrankaModelInterface`` names (link0 -> flange) at q.
"""
import math

import rospy
from std_msgs.msg import Bool

from diffbot_sim.control import franka as fk
from diffbot_sim.control.angles import shortest_angular_distance, shortest_angular_distance_with_limits
from diffbot_sim.control.controller_switching import SwitchError
from diffbot_sim.control.pid import STABILITY_MARGIN, Pid, explicit_loop_margin, loop_verdict
from diffbot_sim.errors import ConfigError, PluginNotLoaded
from diffbot_sim.plugins.base import get_param, join
from diffbot_sim.plugins.ros_control.franka_services import FrankaServices
from diffbot_sim.plugins.ros_control.hardware import EFFORT, RobotHWSim, SimJoint, _truncate

SIMPLE = "transmission_interface/SimpleTransmission"


class FrankaHWSim(RobotHWSim):
    """The joints of one Franka arm (and its hand) under ``libgazebo_ros_control.so``."""

    #: writeSim has work every step (gravity compensation is a torque)
    busy = True

    def __init__(self, ctx, ns, warnings):
        self.ctx, self.ns, self.estop = ctx, ns, False
        model, robot = ctx.model, ctx.robot
        self.joints: dict[str, SimJoint] = {}
        self._interfaces: dict[str, list[str]] = {}  # joint -> its transmissions' interfaces
        for trans in model.transmissions:
            if trans.type != SIMPLE:
                continue  # upstream reads joints only from SimpleTransmissions
            if trans.joint not in robot.joint_index:
                warnings.append(f"FrankaHWSim: joint '{trans.joint}' of transmission '{trans.name}' is not in the "
                                "simulated model (a fixed joint?); it has no hardware handle")
                continue
            self._interfaces.setdefault(trans.joint, []).append(trans.interface)
            if trans.joint not in self.joints:
                self.joints[trans.joint] = self._make_joint(trans, ns, warnings)
        for joint in self.joints.values():
            # every joint is driven by SetForce, and franka_gazebo has no joint limits interface (Gazebo's
            # truncation only)
            joint.method, joint.limit_handle, joint.pid = EFFORT, None, None
        robot_ns, where = ns.strip("/"), ns.rstrip("/") or "/"  # the namespace as rospy takes it (no "//")
        try:
            self.cfg = fk.franka_hw_config(_params(where, fk.PARAMETERS), where, robot_ns, set(model.joints),
                                           self._hand_mass(get_param(join(ns, "arm_id"), robot_ns)))
        except ConfigError as err:
            raise PluginNotLoaded(f"FrankaHWSim: {err}; the hardware did not initialise (as in Gazebo: no "
                                  "controller manager)") from None
        cfg = self.cfg
        warnings.extend(cfg.warnings)
        self.chain = self._model_chain(model, warnings)
        missing = [j for j in cfg.arm_joints if j not in self.joints]
        if missing:
            raise PluginNotLoaded(f"FrankaHWSim: arm joint(s) {', '.join(missing)} have no SimpleTransmission")
        for name in self.joints:
            other = [i for i in self._interfaces[name] if i not in fk.CONTROL_METHODS]
            if other:
                warnings.append(f"FrankaHWSim: Unsupported transmission interface of joint '{name}': {other[0]}")
        self._order = list(self.joints.values())
        self._indices = [j.index for j in self._order]
        self._arm = [self.joints[n] for n in cfg.arm_joints]
        self._arm_idx = [j.index for j in self._arm]
        self.mode = fk.RobotMode()
        #: per joint: control method (None, or fk.EFFORT/POSITION/VELOCITY; fingers always EFFORT), the buffers
        #: each interface writes, where an idle joint holds, its motion generators
        self.method = {n: (fk.EFFORT if n in cfg.finger_joints else None) for n in self.joints}
        self.desired_position = dict.fromkeys(self.joints, 0.0)
        self.desired_velocity = dict.fromkeys(self.joints, 0.0)
        self.stop_position = dict.fromkeys(self.joints, 0.0)
        self.gravity = dict.fromkeys(cfg.arm_joints, 0.0)  # the compensation written last, per arm joint
        self.position_pid = {n: Pid(g) for n, g in cfg.position_gains.items()}
        self.velocity_pid = {n: Pid(g) for n, g in cfg.velocity_gains.items()}
        self.implicit_loops = self._check_motion_generators(ctx.cfg.time_step, warnings)
        self._drive = {}  # joint -> what PyBullet holds it by: "torque", or a motor setting
        self._written_at = None  # sim time of the last write (a step's torques are written once)
        self._targets, self._loading = {}, None  # controller -> {joint: (motor mode, force)} (drive_by_targets)
        self.initialized = False
        self.state = fk.FrankaState(F_T_NE=cfg.F_T_NE, NE_T_EE=cfg.NE_T_EE, EE_T_K=cfg.EE_T_K, m_ee=cfg.m_ee,
                                    I_ee=cfg.I_ee, F_x_Cee=cfg.F_x_Cee, m_load=cfg.m_load, I_load=cfg.I_load,
                                    F_x_Cload=cfg.F_x_Cload)
        self.state.update_dynamics()
        self.thresholds = [list(cfg.lower_torque_thresholds), list(cfg.upper_torque_thresholds),
                           list(cfg.lower_force_thresholds), list(cfg.upper_force_thresholds)]
        self._last_tau = None
        self.initialized_pub = rospy.Publisher(join(ns, "initialized"), Bool, queue_size=1, latch=True)
        ctx.handles.append(self.initialized_pub)  # removed with the robot
        self.initialized_pub.publish(Bool(False))
        self.services = FrankaServices(ctx, self, warnings)  # franka_control/*

    def attach_manager(self, manager):
        """The controller manager of this hardware: error recovery restarts its running controllers."""
        self.services.manager = manager

    def _hand_mass(self, arm_id):
        link = self.ctx.model.links.get(f"{arm_id}_hand") if isinstance(arm_id, str) else None
        return None if link is None else (link.mass or 0.0)

    def _model_chain(self, model, warnings):
        """The FrankaModelInterface chain: from its ``root`` joint's parent link to its ``tip`` joint's child (franka
        _description: link0 -> link8, the flange), read from the franka_hw transmissions FrankaHWSim requires."""
        kinds = {t.type: t for t in model.other_transmissions}
        cfg = self.cfg
        for kind, size in ((fk.STATE_INTERFACE, 7), (fk.MODEL_INTERFACE, 2)):
            trans = kinds.get(kind)
            if trans is None:
                raise PluginNotLoaded(f"FrankaHWSim: no {kind} transmission for robot '{cfg.arm_id}' (franka_"
                                      "description's transmission-franka-state/-model; upstream asserts both)")
            if len(trans.joints) != size:
                raise PluginNotLoaded(f"FrankaHWSim: Cannot create {kind} for robot '{cfg.arm_id}' because "
                                      f"{len(trans.joints)} joints were found beneath the <transmission> tag, but "
                                      f"{size} are required.")
        for other in model.other_transmissions:
            if other.type not in (fk.STATE_INTERFACE, fk.MODEL_INTERFACE):
                warnings.append(f"FrankaHWSim: {other.warning.replace('DefaultRobotHWSim', 'FrankaHWSim')}")
        trans = kinds[fk.MODEL_INTERFACE]
        roles = dict(zip(trans.roles, trans.joints))
        if "root" not in roles or "tip" not in roles:
            raise PluginNotLoaded(f"FrankaHWSim: Cannot create {fk.MODEL_INTERFACE} for robot '{cfg.arm_id}_model' "
                                  "because no <joint> with <role>root</role> and <role>tip</role> can be found")
        root, tip = (model.joint(roles[r], f"transmission '{trans.name}'") for r in ("root", "tip"))
        try:
            return fk.Chain(model, root.parent, tip.child)
        except ConfigError as err:
            raise PluginNotLoaded(f"FrankaHWSim: {err}") from None

    def _check_motion_generators(self, dt, warnings):
        """The motion generators' PIDs that are no well-damped explicit loop at our step: {joint: "position" |
        "velocity" -> True}, each run as PyBullet's motor within the effort limit, with one warning."""
        implicit = {}
        pids = [(n, "position", p) for n, p in self.position_pid.items()] + \
               [(n, "velocity", p) for n, p in self.velocity_pid.items()]
        inertias = self.ctx.robot.joint_inertias([self.joints[n].index for n, _, _ in pids]) if pids else []
        for (name, loop, pid), inertia in zip(pids, inertias):
            margin = explicit_loop_margin(pid.gains, dt, inertia, loop)
            if margin > STABILITY_MARGIN:
                implicit[(name, loop)] = True
                warnings.append(
                    f"{join(self.ns, 'motion_generators')}/{loop}/gains/{name}: p={pid.gains.p:g} d={pid.gains.d:g} "
                    f"at a {dt * 1000:.2f} ms step is {loop_verdict(pid.gains, margin, loop)} explicit loop on this "
                    f"joint (it moves {inertia:.3g} kg·m^2, {margin:.2g} of the stability bound); it runs as "
                    f"PyBullet's {loop} motor with the same effort limit instead")
        return implicit

    # -- what controllers see -------------------------------------------------------------------------------
    def interfaces(self, joint):
        """Every command interface the joint's transmissions offer (a controller may claim it by any)."""
        return list(self._interfaces.get(joint, ()))

    def interface(self, joint):
        offered = self._interfaces.get(joint)
        return offered[0] if offered else None

    def set_command(self, joint, value):
        """A controller's command, into the buffer of the interface it claims the joint by."""
        method = self.method.get(joint)
        if method == fk.POSITION:
            self.desired_position[joint] = value
        elif method == fk.VELOCITY:
            self.desired_velocity[joint] = value
        else:
            self.joints[joint].command = value

    def loading(self, controller):
        """The controller manager is building ``controller``: its ``drive_by_targets`` calls are its own."""
        self._loading = controller

    def drive_by_targets(self, joint, mode, force=None):
        """A controller whose PID is unstable at our step drives ``joint`` by PyBullet's ``mode`` motor: kept for
        that controller and applied while it runs (do_switch), so the controller that claims the joint next
        (a group effort controller after an effort trajectory controller) commands it as its interface says."""
        self._targets.setdefault(self._loading, {})[joint] = (mode, force)

    # -- controller switches ---------------------------------------------------------------------------------
    def prepare_switch(self, starting):
        """prepareSwitch: ``starting`` is {controller: [(interface, joints)]}; refuses with SwitchError."""
        try:
            fk.verify_switch(starting, self.cfg.arm_joints, self.cfg.finger_joints)
        except fk.SwitchRefused as err:
            raise SwitchError(str(err)) from None

    def do_switch(self, starting, stopping):
        """doSwitch: joints of stopped arm controllers lose their method and hold where they are; joints of started
        ones take the claimed interface's method; then the mode follows (Idle <-> Move)."""
        arm = set(self.cfg.arm_joints)
        for claims, start in ((stopping, False), (starting, True)):
            for controller, resources in claims.items():
                for name, (mode, force) in self._targets.get(controller, {}).items():
                    joint = self.joints[name]
                    joint.target_mode, joint.target_force = (mode, force) if start else (None, None)
                    joint.command = (joint.position or 0.0) if start else 0.0
                if not any(len(set(j)) == 7 and set(j) <= arm for i, j in resources if i in fk.CONTROL_METHODS):
                    continue  # not an arm controller (upstream: isClaimingArmController)
                for iface, names in resources:
                    if iface not in fk.CONTROL_METHODS:
                        continue
                    for name in names:
                        position = self.joints[name].position
                        position = 0.0 if position is None else position
                        self.method[name] = iface if start else None
                        self.desired_position[name] = position
                        self.desired_velocity[name] = 0.0
                        if not start:
                            self.stop_position[name] = position
        self._mode_changed(self.mode.switch_control(any(self.method[n] for n in self.cfg.arm_joints)))

    def _mode_changed(self, changed):
        if changed:
            self.state.robot_mode = self.mode.mode

    def user_stop(self, pressed):
        """set_user_stop: pressed, every arm joint holds where it is (mode UserStopped); released, Idle."""
        if self.mode.user_stop(pressed):
            rospy.logwarn("User stop pressed, stopping robot")
            for name in self.cfg.arm_joints:
                position = self.joints[name].position or 0.0
                self.stop_position[name] = self.desired_position[name] = position
                self.desired_velocity[name] = 0.0
        self.state.robot_mode = self.mode.mode

    # -- readSim / writeSim -----------------------------------------------------------------------------------
    def start(self):
        super().start()
        self._drive, self._written_at = {}, None
        for pid in list(self.position_pid.values()) + list(self.velocity_pid.values()):
            pid.reset()

    def read(self):
        super().read()
        if self.initialized:
            self._update_state()

    def _first_update(self):
        """The first step's readSim (upstream's first updateRobotState): the arm holds where it is now (after any
        spawn_model -J), and ``initialized`` turns true."""
        super().read()
        for name, joint in self.joints.items():
            self.desired_position[name] = self.stop_position[name] = joint.position
        self.initialized = True
        self.initialized_pub.publish(Bool(True))
        self._update_state()

    def write(self, dt):
        now = self.ctx.sim.sim_time
        if now == self._written_at:
            return  # a second write before the same step (a command woke the loop): PyBullet adds torques up
        self._written_at = now
        if not self.initialized:
            self._first_update()
        robot = self.ctx.robot
        load = self.state.m_load
        gravity = robot.gravity_torques(self._arm_idx, (self.chain.joints[-1].child, self.state.F_x_Cload, load)
                                        if load else None)
        for joint, g in zip(self._arm, gravity):
            self.gravity[joint.name] = g
        positions, velocities, _ = robot.joint_states(self._indices)
        torques, torque_idx = [], []
        moving = self.mode.mode == fk.MOVE
        for joint, raw, velocity in zip(self._order, positions, velocities):
            name = joint.name
            position = raw if joint.position is None or joint.joint_type == "prismatic" else \
                joint.position + shortest_angular_distance(joint.position, raw)
            if joint.target_mode is not None:  # a controller's PID handed to PyBullet's motor
                force = joint.motor_force if joint.target_force is None else joint.target_force
                self._motor(joint, joint.target_mode, joint.command, force)
                continue
            arm = name in self.gravity
            method = self.method[name]
            if arm and not moving:
                effort = self._position_control(joint, self.stop_position[name], position, dt)
            elif method == fk.POSITION:
                effort = self._position_control(joint, self.desired_position[name], position, dt)
            elif method == fk.VELOCITY:
                effort = self._velocity_control(joint, self.desired_velocity[name], velocity, dt)
            elif method == fk.EFFORT:
                effort = joint.command
            else:
                effort = 0.0
            if effort is None:
                continue  # run by a motor this step
            effort += self.gravity.get(name, 0.0)
            if not math.isfinite(effort):
                self.ctx.sim.warn(f"franka:{name}", f"FrankaHWSim: Command for {name} is not finite, won't send to "
                                  "robot")
                continue
            effort = _truncate(effort, velocity, joint)
            joint.effort = effort
            if self._drive.get(name) != "torque":
                robot.free_joints([joint.index])
                self._drive[name], joint.implicit = "torque", False
            torques.append(effort)
            torque_idx.append(joint.index)
        if torque_idx:
            robot.set_efforts(torque_idx, torques)

    def _position_control(self, joint, setpoint, position, dt):
        """The position motion generator's effort (None: run as PyBullet's position motor this step)."""
        name = joint.name
        if (name, "position") in self.implicit_loops:
            self._motor(joint, "position", setpoint, joint.motor_force)
            return None
        pid = self.position_pid.get(name)
        if pid is None:
            return 0.0  # upstream's PID without gains
        if joint.joint_type == "prismatic":
            error = min(max(setpoint - position, joint.lower), joint.upper)
        else:
            error = shortest_angular_distance_with_limits(position, setpoint, joint.lower, joint.upper)[1]
        return _clamp(pid.compute(error, dt), joint.effort_limit)

    def _velocity_control(self, joint, setpoint, velocity, dt):
        """The velocity motion generator's effort. Upstream 0.10.1 computes it and drops it (the joint then gets
        gravity compensation only); here it is applied, as the interface promises."""
        name = joint.name
        if (name, "velocity") in self.implicit_loops:
            self._motor(joint, "velocity", setpoint, joint.motor_force)
            return None
        pid = self.velocity_pid.get(name)
        return 0.0 if pid is None else _clamp(pid.compute(setpoint - velocity, dt), joint.effort_limit)

    def _motor(self, joint, mode, target, force):
        setting = (mode, target, force)
        if self._drive.get(joint.name) != setting:
            robot = self.ctx.robot
            if mode == "position":
                robot.set_positions([joint.index], [target], [force])
            else:
                robot.set_velocities([joint.index], [target], [force])
            self._drive[joint.name] = setting
        joint.implicit = True

    # -- the franka_hw state ----------------------------------------------------------------------------------
    def _update_state(self):
        """updateRobotState, every readSim: the joint values and the filtered external torques."""
        state, mode = self.state, self.mode.mode
        tau = []
        for i, joint in enumerate(self._arm):
            name = joint.name
            state.q[i], state.dq[i], state.tau_J[i] = joint.position, joint.velocity, joint.effort
            tau.append(joint.effort)
            method = self.method[name]
            moving = mode == fk.MOVE
            state.q_d[i] = self.desired_position[name] if moving and method != fk.EFFORT else joint.position
            state.dq_d[i] = self.desired_velocity[name] if moving and method == fk.VELOCITY else joint.velocity
            state.ddq_d[i] = 0.0
            state.tau_J_d[i] = joint.command if moving and method == fk.EFFORT else 0.0
            external = self.gravity[name] - joint.effort
            state.tau_ext_hat_filtered[i] = fk.low_pass(state.tau_ext_hat_filtered[i], external,
                                                        self.cfg.tau_ext_lowpass_filter)
            state.joint_contact[i] = float(abs(state.tau_ext_hat_filtered[i]) > self.thresholds[0][i])
            state.joint_collision[i] = float(abs(state.tau_ext_hat_filtered[i]) > self.thresholds[1][i])
        self._last_tau = tau
        state.robot_mode = mode

    def robot_state(self, now):
        """The franka_hw state handle ``<arm_id>_robot``, complete at sim time ``now`` [s]: the joint values of the
        last readSim, the flange pose and the external wrench from the URDF chain at q."""
        state = self.state
        positions = {j.name: (j.position or 0.0) for j in self._arm}
        flange = self.chain.pose(positions)
        f_t_ee, ee_t_k = fk.matrix(state.F_T_EE), fk.matrix(state.EE_T_K)
        state.O_T_EE = fk.array16(flange @ f_t_ee)
        to_k = f_t_ee @ ee_t_k
        jacobian_o = self.chain.zero_jacobian(positions, to_k)
        jacobian_k = fk.body_jacobian(jacobian_o, flange @ to_k)
        state.external(state.tau_ext_hat_filtered, jacobian_o, jacobian_k, self.thresholds[2], self.thresholds[3])
        state.time = now
        return state

    def arm_id(self):
        return self.cfg.arm_id

    def set_frames(self, **arrays):
        """set_EE_frame (NE_T_EE), set_K_frame (EE_T_K), set_load (m_load, F_x_Cload, I_load)."""
        for key, value in arrays.items():
            setattr(self.state, key, tuple(value) if isinstance(value, (list, tuple)) else float(value))
        self.state.update_dynamics()

    def set_collision_behavior(self, lower_torque, upper_torque, lower_force, upper_force):
        self.thresholds = [list(lower_torque), list(upper_torque), list(lower_force), list(upper_force)]


def _params(where, keys):
    """The parameters ``keys`` of the namespace ``where`` that are set, as a dict. One by one: rospy answers a
    whole namespace from its parameter cache when it has cached a key of it (``/`` holds only the cached
    ``/rosout_disable_topics_generation`` then)."""
    missing = object()
    found = {key: get_param(join(where, key), missing) for key in keys}
    return {key: value for key, value in found.items() if value is not missing}


def _clamp(value, limit):
    return max(-limit, min(limit, value)) if math.isfinite(limit) else value
