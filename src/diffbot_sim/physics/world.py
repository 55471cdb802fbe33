"""One PyBullet world: the ground, the world's bodies, the robots placed and set down in it, rays and camera
images cast into it, stepped only by ``step()``.

``World`` is the one object the rest of the package holds; it keeps the world's state (its client, robots,
bodies, ``laser_retro`` table, step count) and hands each job to the module that does it:
:mod:`~diffbot_sim.physics.building` (making bodies), :mod:`~diffbot_sim.physics.landing` (setting robots down),
:mod:`~diffbot_sim.physics.rays` (rays, in place or by the ray process), :mod:`~diffbot_sim.physics.rendering`
(camera images), :mod:`~diffbot_sim.physics.motion` (the /gazebo services' moves and wrenches),
:mod:`~diffbot_sim.physics.snapshots` (putting the world back) and :mod:`~diffbot_sim.physics.queries`
(bounds, free space, contacts)."""
import contextlib
import os

# Its parts as modules (``import ... as``: ``from diffbot_sim.physics import x`` would import the package,
# whose ``__init__`` imports this module: a circle).
import diffbot_sim.physics.building as building
import diffbot_sim.physics.motion as motion
import diffbot_sim.physics.queries as queries
import diffbot_sim.physics.rays as rays
import diffbot_sim.physics.rendering as rendering
import diffbot_sim.physics.snapshots as snapshots
from diffbot_sim.physics.client import pybullet, pybullet_data
from diffbot_sim.physics.landing import LANDING_MAX_TIME, Landings
from diffbot_sim.physics.rays import RAY_BATCH_LIMIT
from diffbot_sim.physics.robot import Robot

#: PyBullet's default numSolverIterations (the installed client reports 50; Gazebo's ODE quickstep default too)
SOLVER_ITERATIONS = 50

# World, and the limits callers plan by: how long a robot may take to be set down, how many rays a call casts
__all__ = ["LANDING_MAX_TIME", "RAY_BATCH_LIMIT", "World"]


class World:
    """A PyBullet world: ground plane, gravity, fixed time step, stepped only by ``step()``.

    Args:
        gui: open PyBullet's window (the caller checks a display exists).
        time_step: s. gravity: m/s^2 along z.
        ray_process: True starts the ray process (:meth:`cast_later`) now, "later" keeps what it needs to start
            it with :meth:`start_ray_process`, False never starts one.
    """

    def __init__(self, time_step, gravity=-9.81, gui=False, ray_process=False):
        self.client = pybullet.connect(pybullet.GUI if gui else pybullet.DIRECT)
        if self.client < 0:
            raise RuntimeError("could not connect to PyBullet")
        self.time_step = time_step
        self.gravity = gravity
        self._files = []
        self.robots = []
        self.world_bodies = []  # (PyBullet id, world.Body)
        self.laser_retro = {}  # (PyBullet body, link index) -> Gazebo laser_retro, for hits that have one
        self.landing = Landings(self.client, time_step)  # the robots being set down (``robot in world.landing``)
        self.ray_threads = 0  # rayTestBatch's numThreads (0: Bullet's pool picks)
        self.steps = 0  # physics steps taken
        self.solver_iterations = SOLVER_ITERATIONS
        self._boxes = []  # add_kinematic_box's bodies
        self._egl = None  # the EGL renderer plugin, once loaded (use_egl)
        self.ray_link = rays.RayProcessLink(keep=ray_process in (True, "later"))
        self._setup()
        self.ray_link.record("plane", self.plane)
        if ray_process is True:
            self.start_ray_process()

    def _setup(self):
        c = self.client
        pybullet.setGravity(0, 0, self.gravity, physicsClientId=c)
        pybullet.setTimeStep(self.time_step, physicsClientId=c)
        pybullet.setRealTimeSimulation(0, physicsClientId=c)
        # Gazebo's ODE clamps friction per direction (its default pyramid model), where PyBullet by default
        # couples the two into a cone. Measured on the skid-steer fixture: a turn in place reaches 70 % of
        # what the wheels say with the pyramid, 31 % with the cone, so the pyramid is Gazebo's behaviour.
        pybullet.setPhysicsEngineParameter(enableConeFriction=0, physicsClientId=c)
        pybullet.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=c)
        self.plane = pybullet.loadURDF("plane.urdf", physicsClientId=c)

    @property
    def ray_helper(self):
        """The ray process (:class:`diffbot_sim.physics.ray_process.RayProcess`) once started, else None."""
        return self.ray_link.helper

    # -- building: robots, the world's bodies, actors' boxes -------------------------------------------------
    def load_robot(self, urdf_text, model, position=(0.0, 0.0, 0.0), yaw=0.0, orientation=None):
        """Load a robot and set it down; returns a Robot. ``model`` is the parsed RobotModel of the same text. The
        model frame is placed at ``position`` turned by ``yaw``, or by the quaternion ``orientation`` when given:
        a free robot's root link frame is the model frame; a robot joined to the world by a fixed joint has its
        root where that joint's origin puts it in the model frame, held there (no landing: Gazebo does not set
        such a model down either). Fixed links are lumped as Gazebo lumps them (:func:`building.load_robot_body`)."""
        if orientation is None:
            orientation = pybullet.getQuaternionFromEuler((0.0, 0.0, yaw))
        root_pose = (position, orientation)
        if model.anchor is not None:
            joint = model.anchor
            root_pose = pybullet.multiplyTransforms(position, orientation, joint.xyz,
                                                    pybullet.getQuaternionFromEuler(joint.rpy))
        body, frames = building.load_robot_body(self.client, urdf_text, model, *root_pose, self._files)
        robot = Robot(self.client, body, model, *root_pose, frames, self.time_step, self.landing.erp)
        robot.gravity = self.gravity
        self.robots.append(robot)
        for box in self._boxes:
            self._pass_through(box, robot.body)
        self.lift_out(robot)
        self.laser_retro.update(robot.laser_retro())
        self.ray_link.record("replay", "load_robot", (urdf_text, model, position, yaw, orientation), [body])
        return robot

    def load_world(self, world, mesh_cache):
        """Build a :class:`diffbot_sim.world.bodies.WorldDescription`: one PyBullet body per world body
        (:func:`building.world_body`: static meshes as triangles, dynamic ones as hulls, frictions capped at 1).
        Mesh files are converted and cached as for robots (COLLADA units honoured). The world's own ground plane
        replaces ours.

        Returns:
            the number of bodies built. Dynamic bodies go back to their start on ``reset``.

        Raises:
            ModelError: a mesh that cannot be read (its file named).
        """
        if world.has_ground and self.plane is not None:
            pybullet.removeBody(self.plane, physicsClientId=self.client)
            self.plane = None
        built, before = 0, len(self.world_bodies)
        for body in world.bodies:
            uid = building.world_body(self.client, body, mesh_cache)
            if uid is None:
                continue
            self.world_bodies.append((uid, body))
            if body.shapes[0].surface.get("laser_retro"):
                self.laser_retro[(uid, -1)] = float(body.shapes[0].surface["laser_retro"])
            built += 1
        self.ray_link.record("replay", "load_world", (world, mesh_cache),
                             [uid for uid, _ in self.world_bodies[before:]])
        self.ray_link.record("plane", self.plane)
        return built

    def add_kinematic_box(self, size, pose):
        """A box of ``size`` (x, y, z) [m] centred at ``pose`` ((x, y, z), (qx, qy, qz, qw)) that forces never
        move (mass 0) and :meth:`move_body` places (an actor): rays and cameras meet it where it was put, robots
        pass through it. Gazebo's actors collide with nothing (its actor tutorial: they "won't fall due to gravity
        or collide with other objects"); a solid box walking its script blind would shove a robot that stopped for
        it. Returns its PyBullet id."""
        uid = building.kinematic_box(self.client, size, pose)
        self._boxes.append(uid)
        for robot in self.robots:
            self._pass_through(uid, robot.body)
        self.ray_link.record("replay", "add_kinematic_box", (size, pose), [uid])
        return uid

    def _pass_through(self, box, body):
        """No contact between ``box`` and any link of ``body``. A pair filter, not a group mask: Bullet's ray
        tests honour masks but not pairs, so rays still meet the box."""
        for link in range(-1, pybullet.getNumJoints(body, physicsClientId=self.client)):
            pybullet.setCollisionFilterPair(box, body, -1, link, 0, physicsClientId=self.client)

    def move_body(self, uid, pose):
        """Place body ``uid`` (its base frame) at ``pose``."""
        pybullet.resetBasePositionAndOrientation(uid, pose[0], pose[1], physicsClientId=self.client)

    def body_pose(self, uid, inertial_pose):
        """Link-frame pose of world body ``uid`` (whose inertial frame sits at ``inertial_pose``)."""
        return building.link_pose(self.client, uid, inertial_pose)

    # -- setting robots down ------------------------------------------------------------------------------------
    def lift_out(self, robot):
        """Set ``robot`` down where it was placed (spawn, reset, teleport): lifted out of what it was placed
        into, its contacts damped until it rests (:meth:`landing.Landings.lift_out`). Returns the lift [m]."""
        return self.landing.lift_out(robot)

    def top_at(self, x, y, ignore=()):
        """Height [m] of the highest world surface at (x, y) (a ray from 100 m down), 0 when none."""
        return queries.top_at(self.client, x, y, ignore)

    def step(self, count=1):
        """``count`` physics steps, nothing else between them (what PyBullet's motors hold stays; torques and
        external forces last one step, so the caller steps one at a time while it applies them). A robot
        being set down is watched after each. The robots' joint states read before are stale after it
        (``Robot.stepped``)."""
        client = self.client
        for _ in range(count):
            pybullet.stepSimulation(physicsClientId=client)
            self.steps += 1
            if self.landing:
                self.landing.watch()
        for robot in self.robots:
            robot.stepped()

    def set_solver_iterations(self, iterations):
        """Bullet's constraint solver iterations per step (a world's ``<ode><solver><iters>``, Gazebo's
        sor_pgs_iters)."""
        self.solver_iterations = int(iterations)
        pybullet.setPhysicsEngineParameter(numSolverIterations=self.solver_iterations, physicsClientId=self.client)

    def set_time_step(self, time_step):
        """The physics step [s] from the next step on (set_physics_properties)."""
        self.time_step = time_step
        pybullet.setTimeStep(time_step, physicsClientId=self.client)
        self.landing.set_time_step(time_step)
        for robot in self.robots:
            robot.time_step, robot.landing_erp = time_step, self.landing.erp

    # -- rays: in place, or in the ray process (``ray_process``: the same answers, later in wall time) ----------
    def ray_batch(self, starts, ends):
        """Cast rays from ``starts`` to ``ends`` (world, (N, 3)) against everything: world bodies, every robot
        and the casting robot's own links (Gazebo's CPU ray sensor filters nothing either); numpy in and out.

        Returns:
            (hit fractions along start->end, 1.0 for a miss; hit PyBullet body ids, -1 for a miss; hit link
            indices, -1 for a base or a miss): numpy arrays of N values (:func:`rays.ray_batch`).
        """
        return rays.ray_batch(self.client, starts, ends, self.ray_threads)

    def retro(self, bodies, links):
        """Gazebo ``laser_retro`` of each hit (body, link) (0 where none is given, and for misses)."""
        return rays.retro(self.laser_retro, bodies, links)

    def start_ray_process(self):
        """Start the ray process (``World(ray_process="later")``: it is built from every change made so far)."""
        self.ray_link.start(self.time_step, self.gravity)

    def cast_later(self, key, directions, near, far, position, rotation):
        """Hand a ray sensor's rays to the ray process: ``directions`` ((N, 3), its frame; sent once per ``key``,
        again only when a different array is given) from ``near`` to ``far`` [m], the sensor at ``position``
        (3,) / ``rotation`` (3, 3), cast against the world as it is now (the state is sent with the first cast
        after each step). The rays are ``transforms.rays_along`` of these. Returns a ticket for
        :meth:`cast_answer`."""
        return self.ray_link.cast(self.steps, self._moving_state, key, directions, near, far, position, rotation)

    def cast_answer(self, ticket, wait=False):
        """The answer to :meth:`cast_later` as :meth:`ray_batch` gives it, or None while it is not back."""
        return self.ray_link.helper.answer(ticket, wait)

    def cast_drop(self, ticket):
        """Throw away the answer to a cast nobody wants any more."""
        self.ray_link.helper.drop(ticket)

    def _moving_state(self):
        return rays.moving_state(self.client, self.robots, [u for u, _ in self.world_bodies] + self._boxes)

    # -- camera images ------------------------------------------------------------------------------------------
    def render(self, view_pose, width, height, hfov, near, far, renderer="tiny"):
        """A camera image from ``view_pose`` ((x, y, z), (qx, qy, qz, qw)) looking along that frame's +x, up
        its +z (a Gazebo camera): (rgb uint8 (h, w, 3), z-depth float32 (h, w) [m], NaN where nothing was hit
        or beyond ``far``). ``hfov`` [rad] is SDF's horizontal FOV. ``renderer`` "tiny": PyBullet's CPU
        TinyRenderer; "egl": the EGL plugin (``use_egl`` must have succeeded; else TinyRenderer draws)."""
        return rendering.render(self.client, view_pose, width, height, hfov, near, far, renderer)

    def use_egl(self):
        """Load PyBullet's EGL renderer plugin (OpenGL off screen; Mesa's llvmpipe without a GPU). Returns
        None when it draws this world, else why not (the caller falls back to TinyRenderer). The plugin only
        sees bodies created after it loads, so it must be loaded before the world and robots are."""
        if self._egl is not None:
            return None
        if self.world_bodies or self.robots:
            return "the EGL plugin only draws bodies created after it loads, and this world is built already"
        plugin, problem = rendering.load_egl(self.client)
        if problem is not None:
            return problem
        self._egl = plugin
        if self.plane is not None:  # recreate our plane so that the plugin draws it
            pybullet.removeBody(self.plane, physicsClientId=self.client)
            self.plane = pybullet.loadURDF("plane.urdf", physicsClientId=self.client)
            self.ray_link.record("plane", self.plane)
        return None

    # -- the world API (gazebo_ros's /gazebo services): move, remove, push ------------------------------
    def remove_robot(self, robot):
        """Delete a robot's body (delete_model)."""
        pybullet.removeBody(robot.body, physicsClientId=self.client)
        self.robots.remove(robot)
        self.landing.forget(robot)
        for key in [k for k in self.laser_retro if k[0] == robot.body]:
            del self.laser_retro[key]
        self.ray_link.record("remove", robot.body)

    def remove_body(self, uid):
        """Delete one world body (delete_model of a world model)."""
        pybullet.removeBody(uid, physicsClientId=self.client)
        self.world_bodies = [(u, b) for u, b in self.world_bodies if u != uid]
        self._boxes = [u for u in self._boxes if u != uid]
        self.laser_retro.pop((uid, -1), None)
        self.ray_link.record("remove", uid)

    def body_motion(self, uid, inertial_pose):
        """World body ``uid``'s link frame: (pose, linear velocity of its origin, angular velocity), world
        axes (as Robot.link_motion)."""
        return motion.body_motion(self.client, uid, inertial_pose)

    def set_body_motion(self, uid, inertial_pose, pose, linear, angular):
        """Teleport world body ``uid``'s link frame to ``pose`` with the given velocity of its origin (world
        axes); a static body only moves."""
        motion.set_body_motion(self.client, uid, inertial_pose, pose, linear, angular)

    def apply_wrench(self, uid, link, force, torque, point=None):
        """Push body ``uid`` (PyBullet link index ``link``) for the coming step: ``force`` [N] at the world
        ``point`` (None: the link's centre of mass, as Gazebo's Link::SetForce) and ``torque`` [N·m], world
        axes (PyBullet clears external forces after each step)."""
        motion.apply_wrench(self.client, uid, link, force, torque, point)

    def set_gravity(self, gravity):
        """Gravity [m/s^2] along z for every body from the next step (set_physics_properties)."""
        self.gravity = gravity
        pybullet.setGravity(0, 0, gravity, physicsClientId=self.client)
        for robot in self.robots:
            robot.gravity = gravity

    # -- putting the world back -------------------------------------------------------------------------------
    def reset(self):
        """Put every robot back at its spawn pose and every world body at its start (a static one too: the
        world API may have moved it), at rest, with no memory of the run before: Bullet keeps each touching
        pair's contact points and their impulses from step to step (to warm-start its solver), and a robot
        reset to where it rested would inherit them, so a run after a reset would depend on what came before
        it (measured: 1.1 mm apart after 2 s of driving, by how long the robot had rested). Every moving body
        is first taken far away and the contacts recomputed, which drops them (:func:`snapshots.forget_contacts`)."""
        moving = [robot.body for robot in self.robots] + [uid for uid, body in self.world_bodies if not body.static]
        snapshots.forget_contacts(self.client, moving)
        for uid, body in self.world_bodies:
            building.place(self.client, uid, body.pose, body.inertial_pose)
        for robot in self.robots:
            robot.reset()
        for robot in self.robots:
            self.lift_out(robot)

    def save_state(self):
        """Snapshot every body's state and the contact caches; returns its id for :meth:`restore_state`. Motor
        targets and modes, ``changeDynamics`` values, gravity and the time step are not in it
        (:func:`snapshots.save_state`): the caller sets the motors again after a restore. Bodies may not be added or
        removed between save and restore."""
        return snapshots.save_state(self.client)

    def restore_state(self, state):
        """Put every body back as snapshot ``state`` (:meth:`save_state`) holds it."""
        snapshots.restore_state(self.client, state)
        for robot in self.robots:
            robot.stepped()

    def discard_state(self, state):
        """Free snapshot ``state``."""
        snapshots.discard_state(self.client, state)

    # -- questions for learning environments (diffbot_sim.gym): bounds, free space, contacts ----------------
    def bounds(self, uid):
        """Axis-aligned box (lo (x, y, z), hi (x, y, z)) [m], world axes, around every link of body ``uid``
        (PyBullet's collision bounds; an infinite plane reads about +-1e30)."""
        return queries.bounds(self.client, uid)

    def free_of_bodies(self, points, radius, bottom, top, ignore=()):
        """For each (x, y) of ``points``: True when an upright cylinder of ``radius`` [m] from height
        ``bottom`` to ``top`` [m] there touches no body other than those in ``ignore`` (PyBullet ids), judged
        on collision shapes."""
        return queries.free_of_bodies(self.client, points, radius, bottom, top, ignore)

    def touching(self, body, ignore=()):
        """PyBullet ids of the bodies that body ``body`` touches or penetrates after the last step (a contact
        point at distance <= 0), other than itself and those in ``ignore``: a frozenset."""
        return queries.touching(self.client, body, ignore)

    def close(self):
        self.ray_link.close()
        if self.client is not None and pybullet.isConnected(self.client):
            pybullet.disconnect(self.client)
        self.client = None
        for path in self._files:
            with contextlib.suppress(OSError):
                os.remove(path)
        self._files = []
