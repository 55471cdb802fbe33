"""The only module that talks to PyBullet.

One ``World`` owns one physics client (its own, never the module-global one, so tests can run several
worlds side by side) and is used from one thread. Robots are loaded from URDF text; everything returned is
plain numbers, in URDF link frames (not PyBullet's centre-of-mass frames).
"""
import contextlib
import os
import tempfile
import xml.etree.ElementTree as ET

from .errors import ModelError

#: Mass [kg] given to a root link that has no <inertial>. PyBullet would give it 1 kg (a phantom kilo
#: that changes how the robot drives); 0 would make the base static. One milligram changes nothing.
ROOT_PLACEHOLDER_MASS = 1e-6


@contextlib.contextmanager
def _quiet(fd):
    """Silence a file descriptor: PyBullet's C code prints a build banner on import (stderr) and
    link-merging chatter while loading (stdout), which would break the one-line error contract."""
    try:
        saved = os.dup(fd)
    except OSError:
        yield
        return
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), fd)
        yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)


with _quiet(1), _quiet(2):
    import pybullet
    import pybullet_data


def prepare_urdf(text, root_link):
    """Return URDF text PyBullet can load faithfully: a root link without <inertial> gets a 1 mg one."""
    root = ET.fromstring(text)
    for link in root.findall("link"):
        if link.get("name") == root_link and link.find("inertial") is None:
            inertial = ET.SubElement(link, "inertial")
            ET.SubElement(inertial, "origin", xyz="0 0 0", rpy="0 0 0")
            ET.SubElement(inertial, "mass", value=repr(ROOT_PLACEHOLDER_MASS))
            ET.SubElement(inertial, "inertia", ixx="1e-12", ixy="0", ixz="0", iyy="1e-12", iyz="0", izz="1e-12")
    return ET.tostring(root, encoding="unicode")


class World:
    """A PyBullet world: ground plane, gravity, fixed time step, stepped only by ``step()``.

    Args:
        gui: open PyBullet's window (the caller checks a display exists).
        time_step: s. gravity: m/s^2 along z.
    """

    def __init__(self, time_step, gravity=-9.81, gui=False):
        self.client = pybullet.connect(pybullet.GUI if gui else pybullet.DIRECT)
        if self.client < 0:
            raise RuntimeError("could not connect to PyBullet")
        self.time_step = time_step
        self.gravity = gravity
        self._files = []
        self.robots = []
        self._setup()

    def _setup(self):
        c = self.client
        pybullet.setGravity(0, 0, self.gravity, physicsClientId=c)
        pybullet.setTimeStep(self.time_step, physicsClientId=c)
        pybullet.setRealTimeSimulation(0, physicsClientId=c)
        pybullet.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=c)
        self.plane = pybullet.loadURDF("plane.urdf", physicsClientId=c)

    def load_robot(self, urdf_text, model, position=(0.0, 0.0, 0.0), yaw=0.0):
        """Load a robot; returns a Robot. ``model`` is the parsed RobotModel of the same text."""
        prepared = prepare_urdf(urdf_text, model.root)
        handle, path = tempfile.mkstemp(prefix=f"{model.name or 'robot'}_", suffix=".urdf")
        with os.fdopen(handle, "w") as out:
            out.write(prepared)
        self._files.append(path)
        flags = (pybullet.URDF_USE_INERTIA_FROM_FILE | pybullet.URDF_MERGE_FIXED_LINKS
                 | pybullet.URDF_USE_IMPLICIT_CYLINDER)
        orientation = pybullet.getQuaternionFromEuler((0.0, 0.0, yaw))
        with _quiet(1):
            body = pybullet.loadURDF(path, position, orientation, flags=flags, physicsClientId=self.client)
        if body < 0:
            raise ModelError("PyBullet could not load the model", model.source)
        robot = Robot(self.client, body, model, position, orientation)
        self.robots.append(robot)
        return robot

    def step(self):
        pybullet.stepSimulation(physicsClientId=self.client)

    def reset(self):
        """Put every robot back at its spawn pose, at rest."""
        for robot in self.robots:
            robot.reset()

    def close(self):
        if self.client is not None and pybullet.isConnected(self.client):
            pybullet.disconnect(self.client)
        self.client = None
        for path in self._files:
            with contextlib.suppress(OSError):
                os.remove(path)
        self._files = []


class Robot:
    """One loaded robot body: joint lookup, motors, state read-out. Created by ``World.load_robot``."""

    def __init__(self, client, body, model, position, orientation):
        self.client = client
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

    def _apply_surfaces(self):
        """Gazebo's per-link <mu1>/<mu2> become PyBullet's lateral friction (it has one coefficient)."""
        for link, index in self._link_index.items():
            surface = self.model.surface(link)
            if "mu1" in surface or "mu2" in surface:
                mu = min(surface.get("mu1", surface.get("mu2")), surface.get("mu2", surface.get("mu1")))
                pybullet.changeDynamics(self.body, index, lateralFriction=mu, physicsClientId=self.client)

    def indices(self, names):
        return [self.joint_index[name] for name in names]

    def total_mass(self):
        """Mass [kg] PyBullet simulates, over every link (merged fixed links included)."""
        count = pybullet.getNumJoints(self.body, physicsClientId=self.client)
        return sum(pybullet.getDynamicsInfo(self.body, i, physicsClientId=self.client)[0]
                   for i in range(-1, count))

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

    def set_positions(self, indices, positions, max_forces):
        pybullet.setJointMotorControlArray(self.body, indices, pybullet.POSITION_CONTROL,
                                           targetPositions=positions, forces=max_forces,
                                           physicsClientId=self.client)

    def set_efforts(self, indices, efforts):
        """Torque control; PyBullet needs the joint's velocity motor off first (``free_joints``)."""
        pybullet.setJointMotorControlArray(self.body, indices, pybullet.TORQUE_CONTROL, forces=efforts,
                                           physicsClientId=self.client)

    def joint_states(self, indices):
        """(positions [rad], velocities [rad/s], efforts [N·m]) of the given joints, in one call."""
        states = pybullet.getJointStates(self.body, indices, physicsClientId=self.client)
        return [s[0] for s in states], [s[1] for s in states], [s[3] for s in states]

    def base_pose(self):
        """Root link frame in the world: ((x, y, z), (qx, qy, qz, qw))."""
        com_pos, com_orn = pybullet.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
        return pybullet.multiplyTransforms(com_pos, com_orn, *self._inertial_inv)

    def base_twist(self, pose=None):
        """Root link frame velocity, in that frame: ((vx, vy, vz) [m/s], (wx, wy, wz) [rad/s])."""
        com_pos, _ = pybullet.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
        linear, angular = pybullet.getBaseVelocity(self.body, physicsClientId=self.client)
        position, orientation = pose or self.base_pose()
        # Velocity of the link origin, not of the centre of mass: v + w x (origin - com).
        r = [position[i] - com_pos[i] for i in range(3)]
        v = [linear[0] + angular[1] * r[2] - angular[2] * r[1],
             linear[1] + angular[2] * r[0] - angular[0] * r[2],
             linear[2] + angular[0] * r[1] - angular[1] * r[0]]
        _, inverse = pybullet.invertTransform((0, 0, 0), orientation)
        local_v, _ = pybullet.multiplyTransforms((0, 0, 0), inverse, v, (0, 0, 0, 1))
        local_w, _ = pybullet.multiplyTransforms((0, 0, 0), inverse, angular, (0, 0, 0, 1))
        return tuple(local_v), tuple(local_w)

    def reset(self):
        """Back to the spawn pose with every joint at 0 and at rest."""
        position, orientation = self.spawn
        com = pybullet.multiplyTransforms(position, orientation,
                                          *pybullet.invertTransform(*self._inertial_inv))
        pybullet.resetBasePositionAndOrientation(self.body, com[0], com[1], physicsClientId=self.client)
        pybullet.resetBaseVelocity(self.body, (0, 0, 0), (0, 0, 0), physicsClientId=self.client)
        for index in self.joint_index.values():
            pybullet.resetJointState(self.body, index, 0.0, 0.0, physicsClientId=self.client)

