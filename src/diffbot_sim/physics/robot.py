"""One robot's PyBullet body: its surfaces (Gazebo's friction and contact tags), joint motors and state,
link poses and velocities in URDF link frames."""
import math

import numpy as np

from diffbot_sim.physics.client import pybullet

#: Gazebo's friction coefficient for a surface that gives none (SDF <surface><friction><ode><mu> default).
GAZEBO_DEFAULT_MU = 1.0
#: Gazebo's contact stiffness [N/m] and damping [N·s/m] defaults (SDF <ode><kp>/<kd>), used to complete a
#: link that gives only one of the two.
GAZEBO_DEFAULT_KP = 1e12
GAZEBO_DEFAULT_KD = 1.0


def contact_damping(kp, kd, time_step, max_erp):
    """The damping [N·s/m] to give Bullet for a Gazebo contact of stiffness ``kp`` [N/m] and damping ``kd``.

    Bullet (like ODE) turns them into ERP = dt·kp / (dt·kp + kd) and CFM = 1 / (dt·kp + kd): the stiffness is
    kept whatever the damping, while the ERP, how much of a penetration is undone per step, grows to ~1 for
    the stiff, lightly damped contacts real models give (kp 1e7, kd 1). Gazebo caps that correction at
    ``<max_vel>``; Bullet cannot, so the damping is raised until the ERP is at most ``max_erp``: the same
    spring, damped enough not to throw what lands on it (see landing.LANDING_CORRECTION_RATE).
    """
    stiff = time_step * kp
    return max(kd, 0.0, stiff * (1.0 / max_erp - 1.0)) if max_erp < 1.0 else max(kd, 0.0)


def point_velocity(linear, angular, r):
    """Velocity of a point ``r`` away from where ``linear`` is measured on a rigid body turning at
    ``angular``: v + w x r (all world axes)."""
    return (linear[0] + angular[1] * r[2] - angular[2] * r[1],
            linear[1] + angular[2] * r[0] - angular[0] * r[2],
            linear[2] + angular[0] * r[1] - angular[1] * r[0])


def into_frame(orientation, *vectors):
    """World-axes ``vectors`` expressed in the axes of a frame with world ``orientation`` (x, y, z, w)."""
    _, inverse = pybullet.invertTransform((0, 0, 0), orientation)
    return tuple(tuple(pybullet.multiplyTransforms((0, 0, 0), inverse, v, (0, 0, 0, 1))[0]) for v in vectors)


class Robot:
    """One loaded robot body: joint lookup, motors, state read-out. Created by ``World.load_robot``."""

    def __init__(self, client, body, model, position, orientation, frames=None, time_step=1 / 240, landing_erp=1.0):
        self.client = client
        self.time_step, self.landing_erp = time_step, landing_erp
        self.frames = dict(frames or {})  # URDF link -> (PyBullet link carrying it, xyz, quaternion)
        self.gravity = -9.81  # set by World.load_robot
        self.body = body
        self.model = model
        self.spawn = (tuple(position), tuple(orientation))
        self.joint_index = {}
        for index in range(pybullet.getNumJoints(body, physicsClientId=client)):
            info = pybullet.getJointInfo(body, index, physicsClientId=client)
            if info[2] != pybullet.JOINT_FIXED:
                self.joint_index[info[1].decode()] = index
        # Root link frame relative to PyBullet's base (centre-of-mass) frame.
        dyn = pybullet.getDynamicsInfo(body, -1, physicsClientId=client)
        self._inertial_inv = pybullet.invertTransform(dyn[3], dyn[4])
        self._link_index = {pybullet.getBodyInfo(body, physicsClientId=client)[0].decode(): -1}
        for index in range(pybullet.getNumJoints(body, physicsClientId=client)):
            info = pybullet.getJointInfo(body, index, physicsClientId=client)
            self._link_index[info[12].decode()] = index
        self._apply_surfaces()
        self.free_joints(list(self.joint_index.values()))
        self._joints = list(range(pybullet.getNumJoints(body, physicsClientId=client)))
        #: every joint's PyBullet state as of now (``joint_states``), read once after each step or reset
        self._states = None

    def _apply_surfaces(self):
        """Each PyBullet link gets the Gazebo surface of the URDF link it is (lumping only merged links of
        equal surface): friction from mu1/mu2 (PyBullet has one coefficient per link: the lower one),
        Gazebo's default 1.0 when none is given; kp/kd as contact stiffness/damping (:meth:`damp_contacts`)."""
        self._contacts = {}  # PyBullet link index -> (kp, kd) of the links that give them
        for link, index in self._link_index.items():
            surface = self.model.surface(link)
            mus = [surface[k] for k in ("mu1", "mu2") if k in surface]
            pybullet.changeDynamics(self.body, index, lateralFriction=min(mus) if mus else GAZEBO_DEFAULT_MU,
                                    physicsClientId=self.client)
            if "kp" in surface or "kd" in surface:
                kp = surface.get("kp", GAZEBO_DEFAULT_KP)
                if kp > 0:
                    self._contacts[index] = (kp, max(surface.get("kd", GAZEBO_DEFAULT_KD), 0.0))
        self.damp_contacts(False)

    def damp_contacts(self, landing):
        """The links' kp/kd as contact stiffness/damping: as the model gives them, or (``landing``) with the
        damping raised so that the contact ERP stays within ``landing_erp`` (:func:`contact_damping`): the
        same springs, damped enough not to throw a robot being set down."""
        for index, (kp, kd) in self._contacts.items():
            damping = contact_damping(kp, kd, self.time_step, self.landing_erp) if landing else kd
            pybullet.changeDynamics(self.body, index, contactStiffness=kp, contactDamping=damping,
                                    physicsClientId=self.client)

    def laser_retro(self):
        """{(body, PyBullet link index): laserRetro} of links whose ``<gazebo reference>`` gives one. A
        PyBullet link carrying lumped links takes its own value, else the first lumped link's (PyBullet does
        not say which shape of a link a ray hit)."""
        table = {}
        frames = self.frames or {name: (name, None, None) for name in self._link_index}
        for link, (carrier, _, _) in sorted(frames.items(), key=lambda item: item[0] != item[1][0]):
            value = self.model.surface(link).get("laserRetro")
            key = (self.body, self._link_index.get(carrier, -1))
            if value and key not in table:
                table[key] = float(value)
        return table

    def link_pose(self, name):
        """World pose ((x, y, z), (qx, qy, qz, qw)) of URDF link ``name``'s frame, lumped or not.

        Raises:
            KeyError: the model has no such link.
        """
        carrier, xyz, quat = self.frames[name] if self.frames else (name, (0, 0, 0), (0, 0, 0, 1))
        index = self._link_index[carrier]
        if index == -1:
            base = self.base_pose()
        else:
            state = pybullet.getLinkState(self.body, index, physicsClientId=self.client)
            base = (state[4], state[5])
        return pybullet.multiplyTransforms(base[0], base[1], xyz, quat)

    def position_in_base(self, name):
        """Where URDF link ``name``'s frame is in the root link's frame: (x, y, z) [m]."""
        base = pybullet.invertTransform(*self.base_pose())
        return tuple(pybullet.multiplyTransforms(*base, self.link_pose(name)[0], (0, 0, 0, 1))[0])

    def indices(self, names):
        return [self.joint_index[name] for name in names]

    def total_mass(self):
        """Mass [kg] PyBullet simulates, over every link (merged fixed links included). A base held fixed (a
        robot joined to the world) reads 0 kg in PyBullet: its mass is the URDF's, of the links it carries."""
        count = pybullet.getNumJoints(self.body, physicsClientId=self.client)
        mass = sum(pybullet.getDynamicsInfo(self.body, i, physicsClientId=self.client)[0] for i in range(count))
        if self.model.fixed_to_world:
            carried = [name for name, (carrier, _, _) in self.frames.items() if carrier == self.model.root]
            return mass + sum(self.model.links[name].mass or 0.0 for name in carried or [self.model.root])
        return mass + pybullet.getDynamicsInfo(self.body, -1, physicsClientId=self.client)[0]

    def smallest_inertia(self, index):
        """The smallest principal moment [kg·m^2] of joint ``index``'s child link (a bound on its inertia
        about the joint axis, for stability checks)."""
        return min(pybullet.getDynamicsInfo(self.body, index, physicsClientId=self.client)[2])

    def free_joints(self, indices):
        """Passive joints: PyBullet's default velocity motor would brake them; force 0 lets them roll."""
        if indices:
            pybullet.setJointMotorControlArray(self.body, indices, pybullet.VELOCITY_CONTROL,
                                               targetVelocities=[0.0] * len(indices), forces=[0.0] * len(indices),
                                               physicsClientId=self.client)

    def set_velocities(self, indices, velocities, max_forces):
        """Velocity motors: drive each joint towards its target [rad/s] with at most ``max_forces`` [N·m]."""
        pybullet.setJointMotorControlArray(self.body, indices, pybullet.VELOCITY_CONTROL,
                                           targetVelocities=velocities, forces=max_forces,
                                           physicsClientId=self.client)

    def set_positions(self, indices, positions, max_forces, position_gain=None):
        """Position motors: each joint towards its target [rad or m] with at most ``max_forces`` [N·m or N].
        ``position_gain`` (PyBullet's, default 0.1): the share of the position error the motor's velocity
        constraint removes in one step (1: all of it, as a kinematic set would)."""
        extra = {} if position_gain is None else {"positionGains": [position_gain] * len(indices)}
        pybullet.setJointMotorControlArray(self.body, indices, pybullet.POSITION_CONTROL,
                                           targetPositions=positions, forces=max_forces,
                                           physicsClientId=self.client, **extra)

    def joint_inertias(self, indices):
        """Inertia [kg·m^2 or kg] each joint's motor really moves at the current configuration, for stability
        checks of explicit control loops: ``1 / (M^-1)_ii`` of the joint-space mass matrix M (the Schur
        complement), i.e. what a torque on that joint alone accelerates while every other degree of freedom,
        a free base's six included, moves as it is pushed. The diagonal ``M_ii`` (the rest held still)
        overstates it: a shoulder on a 4 kg free base moved 470 times less inertia than its diagonal said."""
        movable = sorted(self.joint_index.values())
        positions = [s[0] for s in pybullet.getJointStates(self.body, movable, physicsClientId=self.client)]
        matrix = np.array(pybullet.calculateMassMatrix(self.body, positions, physicsClientId=self.client))
        offset = len(matrix) - len(movable)  # 6 base degrees of freedom first on a free base, none on a fixed one
        try:
            inverse = np.linalg.inv(matrix)
        except np.linalg.LinAlgError:
            return [float(matrix[offset + movable.index(i), offset + movable.index(i)]) for i in indices]
        return [1.0 / float(inverse[offset + movable.index(i), offset + movable.index(i)]) for i in indices]

    def gravity_torques(self, indices, load=None):
        """Torque [N·m or N] on each joint of ``indices`` that holds the body still against the world's gravity
        at its current configuration: inverse dynamics at zero velocity and acceleration (every link beyond the
        joint as PyBullet has it, lumped links included; a base counts as held). ``load``: (URDF link, (x, y, z)
        in its frame [m], mass [kg]), a point mass the body does not have (a payload) whose weight is added."""
        movable = sorted(self.joint_index.values())
        c = self.client
        positions = [s[0] for s in pybullet.getJointStates(self.body, movable, physicsClientId=c)]
        zero = [0.0] * len(movable)
        torques = pybullet.calculateInverseDynamics(self.body, positions, zero, zero, physicsClientId=c)
        out = [float(torques[movable.index(i)]) for i in indices]
        link, point, mass = load or (None, None, 0.0)
        if mass:  # the weight F at p: each joint holds -(r x F) . axis (a slide: -F . axis), r from the joint to p
            at = pybullet.multiplyTransforms(*self.link_pose(link), point, (0, 0, 0, 1))[0]
            weight = (0.0, 0.0, mass * self.gravity)
            for k, index in enumerate(indices):
                info = pybullet.getJointInfo(self.body, index, physicsClientId=c)
                origin, orientation = pybullet.getLinkState(self.body, index, physicsClientId=c)[4:6]
                axis = pybullet.multiplyTransforms((0, 0, 0), orientation, info[13], (0, 0, 0, 1))[0]
                if info[2] == pybullet.JOINT_PRISMATIC:
                    out[k] -= float(np.dot(weight, axis))
                else:
                    out[k] -= float(np.dot(np.cross(np.subtract(at, origin), weight), axis))
        return out

    def joint_limits(self, index):
        """(lower, upper) [rad or m] PyBullet enforces on joint ``index`` (upper < lower: none)."""
        info = pybullet.getJointInfo(self.body, index, physicsClientId=self.client)
        return info[8], info[9]

    def set_efforts(self, indices, efforts):
        """Torque control; PyBullet needs the joint's velocity motor off first (``free_joints``)."""
        pybullet.setJointMotorControlArray(self.body, indices, pybullet.TORQUE_CONTROL, forces=efforts,
                                           physicsClientId=self.client)

    def joint_states(self, indices):
        """(positions [rad], velocities [rad/s], efforts [N·m]) of the given joints.

        Every joint is read in one call the first time after a step or a reset, and later calls answer from that
        read: an effort arm's hardware (its write before the step, its read after), its controllers and its
        mimic plugins all ask each step, and a PyBullet call's fixed cost is most of it. Motor commands given
        between steps do not change what PyBullet reports until the next step, so the read stays true until
        :meth:`stepped` (``World.step``) or a reset here forgets it."""
        states = self._states
        if states is None:
            states = self._states = pybullet.getJointStates(self.body, self._joints, physicsClientId=self.client)
        rows = [states[i] for i in indices]
        return [s[0] for s in rows], [s[1] for s in rows], [s[3] for s in rows]

    def joint_positions(self, indices):
        """Positions [rad or m] of the given joints (:meth:`joint_states`' first list, from the same read)."""
        states = self._states
        if states is None:
            states = self._states = pybullet.getJointStates(self.body, self._joints, physicsClientId=self.client)
        return [states[i][0] for i in indices]

    def stepped(self):
        """The world stepped or was put back (``World.step``, ``World.restore_state``): the joint states read
        before are stale."""
        self._states = None

    def base_pose(self):
        """Root link frame in the world: ((x, y, z), (qx, qy, qz, qw))."""
        com_pos, com_orn = pybullet.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
        return pybullet.multiplyTransforms(com_pos, com_orn, *self._inertial_inv)

    def base_twist(self, pose=None):
        """Root link frame velocity, in that frame: ((vx, vy, vz) [m/s], (wx, wy, wz) [rad/s])."""
        com_pos, _ = pybullet.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
        linear, angular = pybullet.getBaseVelocity(self.body, physicsClientId=self.client)
        position, orientation = pose or self.base_pose()
        # Velocity of the link origin, not of the centre of mass.
        v = point_velocity(linear, angular, [position[i] - com_pos[i] for i in range(3)])
        return into_frame(orientation, v, angular)

    def link_motion(self, name):
        """URDF link ``name``'s frame (lumped or not) in the world: (pose ((x, y, z), (qx, qy, qz, qw)),
        linear velocity of the frame's origin (v + w x r from the carrier's centre of mass) [m/s], angular
        velocity [rad/s]), both velocities in world axes. A lumped link moves with its carrier.

        Raises:
            KeyError: the model has no such link.
        """
        carrier, xyz, quat = self.frames[name] if self.frames else (name, (0, 0, 0), (0, 0, 0, 1))
        index = self._link_index[carrier]
        c = self.client
        if index == -1:
            com, _ = pybullet.getBasePositionAndOrientation(self.body, physicsClientId=c)
            linear, angular = pybullet.getBaseVelocity(self.body, physicsClientId=c)
            frame = self.base_pose()
        else:
            state = pybullet.getLinkState(self.body, index, computeLinkVelocity=1, computeForwardKinematics=1,
                                          physicsClientId=c)
            com, frame, linear, angular = state[0], (state[4], state[5]), state[6], state[7]
        pose = pybullet.multiplyTransforms(frame[0], frame[1], xyz, quat)
        v = point_velocity(linear, angular, [pose[0][i] - com[i] for i in range(3)])
        return (tuple(pose[0]), tuple(pose[1])), v, tuple(angular)

    def link_twist(self, name):
        """(pose, linear velocity [m/s], angular velocity [rad/s]) of URDF link ``name``'s frame, the
        velocities in that frame's own axes (as ``base_twist`` for the root)."""
        pose, linear, angular = self.link_motion(name)
        local_v, local_w = into_frame(pose[1], linear, angular)
        return pose, local_v, local_w

    def link_imu(self, name, previous_velocity, dt, offset=None):
        """What an IMU on URDF link ``name`` (lumped or not) reads, in the link's frame (or in the frame at
        ``offset`` = ((x, y, z), (qx, qy, qz, qw)) in the link's, an SDF sensor ``<pose>``): (pose, angular
        velocity [rad/s], proper acceleration [m/s^2], world velocity of the frame origin). The acceleration
        is the finite difference of the origin's world velocity since ``previous_velocity`` (the value this
        call returned ``dt`` seconds ago; None or dt <= 0: taken as unchanged) minus gravity, so it reads
        +9.81 on an upward z at rest (REP 145). The caller keeps the velocity: no state here."""
        pose, linear, angular = self.link_motion(name)
        if offset is not None:
            moved = pybullet.multiplyTransforms(pose[0], pose[1], offset[0], offset[1])
            linear = point_velocity(linear, angular, [moved[0][i] - pose[0][i] for i in range(3)])
            pose = (tuple(moved[0]), tuple(moved[1]))
        if previous_velocity is None or dt <= 0:
            accel = [0.0, 0.0, 0.0]
        else:
            accel = [(linear[i] - previous_velocity[i]) / dt for i in range(3)]
        accel[2] -= self.gravity
        local_w, local_a = into_frame(pose[1], angular, accel)
        return pose, local_w, local_a, linear

    def link_carrier(self, name):
        """PyBullet link index carrying URDF link ``name`` (lumped links: their carrier). KeyError if none."""
        carrier = self.frames[name][0] if self.frames else name
        return self._link_index[carrier]

    def set_base_motion(self, pose, linear, angular):
        """Teleport the root link frame to ``pose`` with the given velocity of its origin [m/s] and angular
        velocity [rad/s], world axes (set_model_state); joints keep their angles."""
        com = pybullet.multiplyTransforms(pose[0], pose[1], *pybullet.invertTransform(*self._inertial_inv))
        pybullet.resetBasePositionAndOrientation(self.body, com[0], com[1], physicsClientId=self.client)
        v = point_velocity(linear, angular, [com[0][i] - pose[0][i] for i in range(3)])
        pybullet.resetBaseVelocity(self.body, v, angular, physicsClientId=self.client)

    def shift(self, offset):
        """Move the whole robot by ``offset`` (x, y, z) [m], world axes, keeping its velocities."""
        com, orientation = pybullet.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
        moved = tuple(com[i] + offset[i] for i in range(3))
        pybullet.resetBasePositionAndOrientation(self.body, moved, orientation, physicsClientId=self.client)

    def set_joint_velocities(self, indices, velocities):
        """Gazebo's Joint::SetVelocity: each joint's velocity [rad/s or m/s] set now, its position kept, no motor
        holding it during the step (free the joints first): friction then acts on a free joint, as in Gazebo."""
        states = pybullet.getJointStates(self.body, indices, physicsClientId=self.client)
        self._states = None
        for index, state, velocity in zip(indices, states, velocities):
            pybullet.resetJointState(self.body, index, state[0], velocity, physicsClientId=self.client)

    def set_joint_positions(self, indices, positions):
        """Joint angles [rad] set at rest (set_model_configuration)."""
        self._states = None
        for index, position in zip(indices, positions):
            pybullet.resetJointState(self.body, index, position, 0.0, physicsClientId=self.client)

    def reset(self):
        """Back to the spawn pose with every joint at 0 and at rest."""
        self._states = None
        position, orientation = self.spawn
        com = pybullet.multiplyTransforms(position, orientation,
                                          *pybullet.invertTransform(*self._inertial_inv))
        pybullet.resetBasePositionAndOrientation(self.body, com[0], com[1], physicsClientId=self.client)
        pybullet.resetBaseVelocity(self.body, (0, 0, 0), (0, 0, 0), physicsClientId=self.client)
        for index in self.joint_index.values():
            pybullet.resetJointState(self.body, index, 0.0, 0.0, physicsClientId=self.client)

    # -- grasping (gazebo_grasp_fix) ------------------------------------------------------------------------
    def link_contacts(self, links):
        """This step's contacts of the robot's URDF ``links`` with other bodies: [(link, other body, other link
        index, point on the other body (world, m), force on the other body (world axes, N: normal and
        friction))]."""
        out = []
        c = self.client
        for link in links:
            index = self.link_carrier(link)
            for point in pybullet.getContactPoints(bodyA=self.body, linkIndexA=index, physicsClientId=c):
                other, other_link, on_b, normal, normal_force = point[2], point[4], point[6], point[7], point[9]
                if other == self.body:
                    continue
                f1, d1, f2, d2 = point[10], point[11], point[12], point[13]
                force = tuple(-(normal_force * normal[i] + f1 * d1[i] + f2 * d2[i]) for i in range(3))
                out.append((link, other, other_link, tuple(on_b), force))
        return out

    def attach(self, link, body, body_link=-1, collide=True):
        """Hold ``body`` (its ``body_link``) to URDF ``link`` where it is now, by a fixed constraint; with
        ``collide`` False the two stop colliding. Returns a handle for :meth:`detach`."""
        c = self.client
        index = self.link_carrier(link)
        if index == -1:
            frame = pybullet.getBasePositionAndOrientation(self.body, physicsClientId=c)
        else:
            state = pybullet.getLinkState(self.body, index, physicsClientId=c)
            frame = (state[0], state[1])  # the link's centre-of-mass frame, which constraints use
        if body_link == -1:
            other = pybullet.getBasePositionAndOrientation(body, physicsClientId=c)
        else:
            state = pybullet.getLinkState(body, body_link, physicsClientId=c)
            other = (state[0], state[1])
        inverse = pybullet.invertTransform(*frame)
        rel = pybullet.multiplyTransforms(inverse[0], inverse[1], other[0], other[1])
        cid = pybullet.createConstraint(self.body, index, body, body_link, pybullet.JOINT_FIXED, (0, 0, 0),
                                        rel[0], (0, 0, 0), rel[1], (0, 0, 0, 1), physicsClientId=c)
        pybullet.changeConstraint(cid, maxForce=1e4, physicsClientId=c)
        if not collide:
            for i in range(-1, pybullet.getNumJoints(self.body, physicsClientId=c)):
                pybullet.setCollisionFilterPair(self.body, body, i, body_link, 0, physicsClientId=c)
        return cid, body, body_link, collide

    def detach(self, handle):
        """Undo :meth:`attach` (collisions back on)."""
        cid, body, body_link, collide = handle
        c = self.client
        pybullet.removeConstraint(cid, physicsClientId=c)
        if not collide:
            for i in range(-1, pybullet.getNumJoints(self.body, physicsClientId=c)):
                pybullet.setCollisionFilterPair(self.body, body, i, body_link, 1, physicsClientId=c)

    def body_origin(self, body, link=-1):
        """World position of another body's link frame origin (its centre of mass for PyBullet's base)."""
        if link == -1:
            return tuple(pybullet.getBasePositionAndOrientation(body, physicsClientId=self.client)[0])
        return tuple(pybullet.getLinkState(body, link, physicsClientId=self.client)[4])

    # -- holonomic base plugins (gazebo_ros_planar_move, the force-based move family) ------------------------
    def heading_velocity(self):
        """(vx, vy, wz): the velocity [m/s] of the root's centre of mass along the axes of the root link's
        heading (its yaw alone) and the yaw rate [rad/s] about the world z; what :meth:`set_heading_velocity`
        sets, read back after a step to see what contacts and joint motors took of it."""
        linear, angular = pybullet.getBaseVelocity(self.body, physicsClientId=self.client)
        _, orientation = self.base_pose()
        yaw = pybullet.getEulerFromQuaternion(orientation)[2]
        c, s = math.cos(yaw), math.sin(yaw)
        return c * linear[0] + s * linear[1], -s * linear[0] + c * linear[1], angular[2]

    def set_heading_velocity(self, vx, vy, wz):
        """Gazebo's Model::SetLinearVel((vx, vy) [m/s] turned by the root link's yaw, z 0) and
        SetAngularVel((0, 0, wz) [rad/s]) as gazebo_ros_planar_move calls them: the root's centre of mass gets
        that velocity, its roll and pitch rates and its vertical velocity are zeroed. Joint rates are kept, so
        every other link moves rigidly with the root (Gazebo gives each link the same velocity and lets ODE's
        joints reconcile them)."""
        _, orientation = self.base_pose()
        yaw = pybullet.getEulerFromQuaternion(orientation)[2]
        c, s = math.cos(yaw), math.sin(yaw)
        pybullet.resetBaseVelocity(self.body, (c * vx - s * vy, s * vx + c * vy, 0.0), (0.0, 0.0, wz),
                                   physicsClientId=self.client)

    def planar_inertia(self):
        """(mass [kg], moment of inertia [kg·m^2] about the vertical axis through the centre of mass) of the
        whole robot in its present configuration: what a horizontal force and a yaw torque on its body move
        (stability checks of the force-based move plugin's P loops)."""
        c = self.client
        parts = []  # (mass, centre of mass (world), izz about a vertical axis through it)
        for index in range(-1, pybullet.getNumJoints(self.body, physicsClientId=c)):
            info = pybullet.getDynamicsInfo(self.body, index, physicsClientId=c)
            if index == -1:
                com, orientation = pybullet.getBasePositionAndOrientation(self.body, physicsClientId=c)
            else:
                state = pybullet.getLinkState(self.body, index, computeForwardKinematics=1, physicsClientId=c)
                com, orientation = state[0], state[1]
            row = pybullet.getMatrixFromQuaternion(orientation)[6:9]  # world z in the inertia's principal axes
            parts.append((info[0], com, sum(row[k] ** 2 * info[2][k] for k in range(3))))
        mass = sum(m for m, _, _ in parts)
        if mass <= 0:
            return 0.0, 0.0
        cx = sum(m * p[0] for m, p, _ in parts) / mass
        cy = sum(m * p[1] for m, p, _ in parts) / mass
        return mass, sum(izz + m * ((p[0] - cx) ** 2 + (p[1] - cy) ** 2) for m, p, izz in parts)

    def push_link(self, name, force, torque):
        """For the coming step (PyBullet clears it after), ``force`` [N] along the axes of URDF link ``name``'s
        frame, at the centre of mass of the link carrying it, and ``torque`` [N·m] in world axes: Gazebo's
        Link::AddRelativeForce and Link::AddTorque. KeyError if the model has no such link."""
        c = self.client
        index = self.link_carrier(name)
        _, orientation = self.link_pose(name)
        world_force, _ = pybullet.multiplyTransforms((0, 0, 0), orientation, force, (0, 0, 0, 1))
        if index == -1:
            com = pybullet.getBasePositionAndOrientation(self.body, physicsClientId=c)[0]
        else:
            com = pybullet.getLinkState(self.body, index, physicsClientId=c)[0]
        if any(world_force):
            pybullet.applyExternalForce(self.body, index, world_force, com, pybullet.WORLD_FRAME, physicsClientId=c)
        if any(torque):
            pybullet.applyExternalTorque(self.body, index, torque, pybullet.WORLD_FRAME, physicsClientId=c)
