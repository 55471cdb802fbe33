"""One PyBullet world: the ground, the world's bodies, the robots placed and set down in it, rays and camera
images cast into it, stepped only by ``step()``."""
import contextlib
import math
import os
import tempfile

from diffbot_sim.description import lumping
from diffbot_sim.errors import ModelError
from diffbot_sim.physics.client import egl_probe, pybullet, pybullet_data, quiet
from diffbot_sim.physics.robot import Robot, point_velocity

#: How fast [1/s] Bullet may push a robot being set down out of what it lands on: a penetration ``d`` is undone
#: at most at ``LANDING_CORRECTION_RATE * d`` m/s (the contact ERP is this times the step). Gazebo caps each
#: body's correcting velocity at its SDF ``<max_vel>`` (0.01 m/s by default), so what lands on a contact lands
#: dead; Bullet has no such cap, and a Gazebo kp/kd taken as is (kp 1e7, kd 1 on published 4-wheel robots: an
#: undamped spring) gives an ERP of ~1. Measured, dropped from 1 m such a robot rebounds 0.26 m at ERP 1.0,
#: 0.13 m at 0.7, 0.017 m at 0.3 and 0.005 m at 0.2, landing dead within 0.1 s. The same damping kept on while
#: driving makes a four-wheel robot's turn in place wander (its origin moved 0.04 m at ERP 1.0 and 0.7, up to
#: 0.18 m at 0.2), so it is on only while the robot is set down (:meth:`World.lift_out`), until it rests.
LANDING_CORRECTION_RATE = 0.2 * 240.0
#: A robot being set down rests once it touches something and its base moves slower than these
#: (m/s, rad/s) for LANDING_REST_TIME s; it gets its own contacts back then, or after LANDING_MAX_TIME s.
LANDING_REST_SPEED = (0.05, 0.2)
LANDING_REST_TIME = 0.1
LANDING_MAX_TIME = 3.0
#: Placement (spawn, teleport, reset) lifts a robot out of what it would sit in, within this many passes.
DEPENETRATION_PASSES = 4
#: Rays per rayTestBatch call. PyBullet's limit is MAX_RAY_INTERSECTION_BATCH_SIZE_STREAMING (16 x 1024 on
#: Linux); at exactly 16384 it returns 16383 results for list input and none for numpy input (bullet3 #4215,
#: measured here: sensors.md section 6.1), and above it raises. 16383 works both ways.
RAY_BATCH_LIMIT = 16383
#: m above the world where :meth:`World.reset` parks the moving bodies to drop their contacts
FAR_AWAY = 1.0e5


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
        self.landing_erp = min(1.0, LANDING_CORRECTION_RATE * time_step)
        self.landing = {}  # Robot -> [steps it has rested, steps left] while it is set down (lift_out)
        self.ray_threads = 0  # rayTestBatch's numThreads (0: Bullet's pool picks)
        self.steps = 0  # physics steps taken
        self._boxes = []  # add_kinematic_box's bodies
        self._state_sent = None  # self.steps when the mirror was last sent the state
        self.ray_helper = None  # the ray process (physics.ray_process.RayProcess), once started
        # What the ray process must replay to build this world, kept until it starts ("later"); None: never
        self._journal = [] if ray_process in (True, "later") else None
        self._setup()
        self._mirror("plane", self.plane)
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

    def load_robot(self, urdf_text, model, position=(0.0, 0.0, 0.0), yaw=0.0, orientation=None):
        """Load a robot; returns a Robot. ``model`` is the parsed RobotModel of the same text. The root link
        frame is placed at ``position`` turned by ``yaw``, or by the quaternion ``orientation`` when given.

        Fixed links are lumped as Gazebo lumps them (:mod:`diffbot_sim.description.lumping`), not by PyBullet's
        URDF_MERGE_FIXED_LINKS, which would give inertia-less links 1 kg and a merged body one friction.
        """
        prepared = lumping.lump(urdf_text, model.root, model.surface)
        handle, path = tempfile.mkstemp(prefix=f"{model.name or 'robot'}_", suffix=".urdf")
        with os.fdopen(handle, "w") as out:
            out.write(prepared.text)
        self._files.append(path)
        flags = pybullet.URDF_USE_INERTIA_FROM_FILE | pybullet.URDF_USE_IMPLICIT_CYLINDER
        if orientation is None:
            orientation = pybullet.getQuaternionFromEuler((0.0, 0.0, yaw))
        with quiet(1):
            body = pybullet.loadURDF(path, position, orientation, flags=flags, physicsClientId=self.client)
        if body < 0:
            raise ModelError("PyBullet could not load the model", model.source)
        robot = Robot(self.client, body, model, position, orientation, prepared.frames, self.time_step,
                      self.landing_erp)
        robot.gravity = self.gravity
        self.robots.append(robot)
        self.lift_out(robot)
        self.laser_retro.update(robot.laser_retro())
        self._mirror("replay", "load_robot", (urdf_text, model, position, yaw, orientation), [body])
        return robot

    def load_world(self, world, mesh_cache):
        """Build a :class:`diffbot_sim.world.bodies.WorldDescription`: one PyBullet body per world body.

        Static bodies get mass 0; their meshes collide as the triangles they are (a hollow ring stays
        hollow), dynamic ones as convex hulls (what Bullet can simulate). Mesh files are converted and cached
        as for robots (COLLADA units honoured). The world's own ground plane replaces ours. World surfaces
        combine with a robot's by multiplication in Bullet where ODE takes the lower one; so a world friction
        is capped at 1 (Gazebo's ground plane says 100), which makes the product the lower of the two
        whenever either is 1 or more.

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
            shapes = [s for s in body.shapes if s.kind != "plane" or body.static]
            if not shapes:
                continue
            c = self.client
            index = self._compound(shapes, body.static, mesh_cache)
            mass = 0.0 if body.static else max(body.mass, 1e-6)
            (px, py, pz), orientation = body.pose
            com, com_orn = body.inertial_pose
            uid = pybullet.createMultiBody(baseMass=mass, baseCollisionShapeIndex=index, basePosition=(0, 0, 0),
                                           baseInertialFramePosition=com, baseInertialFrameOrientation=com_orn,
                                           physicsClientId=c)
            # createMultiBody takes the inertial frame's pose as the base pose: place the link frame instead.
            self._place(uid, body.pose, body.inertial_pose)
            options = {}
            mus = [body.shapes[0].surface[k] for k in ("mu", "mu2") if k in body.shapes[0].surface]
            options["lateralFriction"] = min(min(mus), 1.0) if mus else 1.0
            if not body.static:
                ixx, iyy, izz = body.inertia[:3]
                options["localInertiaDiagonal"] = (ixx, iyy, izz)
            pybullet.changeDynamics(uid, -1, physicsClientId=c, **options)
            if body.color is not None:  # the collision-derived visual, coloured (what cameras see)
                pybullet.changeVisualShape(uid, -1, rgbaColor=body.color, physicsClientId=c)
            self.world_bodies.append((uid, body))
            if body.shapes[0].surface.get("laser_retro"):
                self.laser_retro[(uid, -1)] = float(body.shapes[0].surface["laser_retro"])
            built += 1
        self._mirror("replay", "load_world", (world, mesh_cache), [uid for uid, _ in self.world_bodies[before:]])
        self._mirror("plane", self.plane)
        return built

    def _compound(self, shapes, static, mesh_cache):
        """One collision shape index for a body's shapes (a compound when there are several)."""
        from diffbot_sim.description import meshes  # pure; here only to convert world meshes

        c = self.client
        concave = pybullet.GEOM_FORCE_CONCAVE_TRIMESH if static else 0
        if len(shapes) == 1 and shapes[0].kind == "trimesh":
            shape = shapes[0]
            return pybullet.createCollisionShape(
                pybullet.GEOM_MESH, vertices=shape.vertices.tolist(), indices=shape.indices.ravel().tolist(),
                flags=pybullet.GEOM_FORCE_CONCAVE_TRIMESH, collisionFramePosition=shape.pose[0],
                collisionFrameOrientation=shape.pose[1], physicsClientId=c)
        kinds, radii, halves, lengths, files, scales, normals, flags, positions, orientations = \
            [], [], [], [], [], [], [], [], [], []
        for shape in shapes:
            kind = {"box": pybullet.GEOM_BOX, "cylinder": pybullet.GEOM_CYLINDER, "sphere": pybullet.GEOM_SPHERE,
                    "plane": pybullet.GEOM_PLANE, "mesh": pybullet.GEOM_MESH}.get(shape.kind)
            if kind is None:
                continue  # the reader named it already
            kinds.append(kind)
            size = tuple(shape.size) + (0.0, 0.0, 0.0)
            radii.append(size[0] if shape.kind in ("cylinder", "sphere") else 0.0)
            lengths.append(size[1] if shape.kind == "cylinder" else 0.0)
            halves.append(tuple(v / 2.0 for v in size[:3]) if shape.kind == "box" else (0.0, 0.0, 0.0))
            normals.append(size[:3] if shape.kind == "plane" else (0.0, 0.0, 1.0))
            files.append(meshes.convert_cached(shape.mesh, mesh_cache) if shape.kind == "mesh" else "")
            scales.append(tuple(shape.scale) if shape.kind == "mesh" else (1.0, 1.0, 1.0))
            flags.append(concave if shape.kind == "mesh" else 0)
            positions.append(shape.pose[0])
            orientations.append(shape.pose[1])
        if len(kinds) == 1:
            return pybullet.createCollisionShape(
                kinds[0], radius=radii[0], halfExtents=halves[0], height=lengths[0], fileName=files[0],
                meshScale=scales[0], planeNormal=normals[0], flags=flags[0],
                collisionFramePosition=positions[0], collisionFrameOrientation=orientations[0],
                physicsClientId=c)
        return pybullet.createCollisionShapeArray(
            kinds, radii=radii, halfExtents=halves, lengths=lengths, fileNames=files, meshScales=scales,
            planeNormals=normals, flags=flags, collisionFramePositions=positions,
            collisionFrameOrientations=orientations, physicsClientId=c)

    def _place(self, uid, pose, inertial_pose):
        """Put body ``uid``'s link frame at ``pose`` (PyBullet places the inertial frame)."""
        com = pybullet.multiplyTransforms(pose[0], pose[1], inertial_pose[0], inertial_pose[1])
        pybullet.resetBasePositionAndOrientation(uid, com[0], com[1], physicsClientId=self.client)
        pybullet.resetBaseVelocity(uid, (0, 0, 0), (0, 0, 0), physicsClientId=self.client)

    def body_pose(self, uid, inertial_pose):
        """Link-frame pose of world body ``uid`` (whose inertial frame sits at ``inertial_pose``)."""
        com = pybullet.getBasePositionAndOrientation(uid, physicsClientId=self.client)
        inv = pybullet.invertTransform(inertial_pose[0], inertial_pose[1])
        return pybullet.multiplyTransforms(com[0], com[1], inv[0], inv[1])

    def lift_out(self, robot):
        """Set ``robot`` down where it was placed: lift it out of whatever it was placed into (the ground, a
        world body, another robot) so that its deepest collision point just touches, and damp its contacts
        until it rests (LANDING_CORRECTION_RATE). Returns the lift [m].

        Called wherever the robot is placed: spawn, reset, teleport. Gazebo pushes such a robot out at its
        ``<max_vel>`` (0.01 m/s by default: 6 s for a robot spawned 6 cm deep) and ends where this starts;
        Bullet would push it out in one step and throw it (measured: a robot 6 cm deep left at 14 m/s, one
        13 cm deep flew 18 m up). Only contacts whose surface faces up count (a normal within 60 degrees of
        +z): a robot is lifted off what it stands in, never pushed sideways out of a wall.
        """
        robot.damp_contacts(True)
        self.landing[robot] = [0, round(LANDING_MAX_TIME / self.time_step)]
        c = self.client
        others = [b for b in range(pybullet.getNumBodies(physicsClientId=c))]
        others = [pybullet.getBodyUniqueId(i, physicsClientId=c) for i in others]
        others = [b for b in others if b != robot.body]
        lifted = 0.0
        for _ in range(DEPENETRATION_PASSES):
            lift = 0.0
            for other in others:
                for point in pybullet.getClosestPoints(robot.body, other, 0.0, physicsClientId=c):
                    depth, normal_z = -point[8], point[7][2]
                    if depth > 1e-6 and normal_z > 0.5:
                        lift = max(lift, depth / normal_z)
            if lift <= 0.0:
                break
            robot.shift((0.0, 0.0, lift))
            lifted += lift
        return lifted

    def top_at(self, x, y, ignore=()):
        """Height [m] of the highest world surface at (x, y) (a ray from 100 m down), 0 when none."""
        hits = pybullet.rayTestBatch([(x, y, 100.0)], [(x, y, -100.0)], physicsClientId=self.client)
        top = 0.0
        for hit in hits:
            if hit[0] >= 0 and hit[0] not in ignore:
                top = max(top, hit[3][2])
        return top

    def ray_batch(self, starts, ends):
        """Cast rays from ``starts`` to ``ends`` (world, (N, 3)) against everything: world bodies, every
        robot and the casting robot's own links (Gazebo's CPU ray sensor filters nothing either). Cast in
        calls of at most RAY_BATCH_LIMIT rays (PyBullet's per-call limit), numpy in and out.

        Returns:
            (hit fractions along start->end, 1.0 for a miss; hit PyBullet body ids, -1 for a miss; hit link
            indices, -1 for a base or a miss): numpy arrays of N values.
        """
        import numpy as np

        starts = np.ascontiguousarray(starts, dtype=np.float64).reshape(-1, 3)
        ends = np.ascontiguousarray(ends, dtype=np.float64).reshape(-1, 3)
        count = len(starts)
        fractions = np.ones(count)
        bodies = np.full(count, -1, dtype=np.int64)
        links = np.full(count, -1, dtype=np.int64)
        for lo in range(0, count, RAY_BATCH_LIMIT):
            hi = min(lo + RAY_BATCH_LIMIT, count)
            # numThreads 0: PyBullet picks max(1, rays / 16) threads of its pool.
            hits = pybullet.rayTestBatch(starts[lo:hi], ends[lo:hi], numThreads=self.ray_threads,
                                         physicsClientId=self.client)
            if len(hits) != hi - lo:
                raise RuntimeError(f"rayTestBatch returned {len(hits)} results for {hi - lo} rays")
            bodies[lo:hi] = [h[0] for h in hits]
            links[lo:hi] = [h[1] for h in hits]
            fractions[lo:hi] = [h[2] for h in hits]
        fractions[bodies < 0] = 1.0
        return fractions, bodies, links

    # -- rays cast in the helper process (``ray_process``): the same answers, later in wall time ----------------
    def _mirror(self, request, *args):
        """A change of the world's bodies, for the ray process: sent now, kept for when it starts, or dropped.
        A kept body that is removed again leaves the journal (a fast-mode run that spawns and deletes models for
        hours keeps nothing of them)."""
        if self.ray_helper is not None:
            getattr(self.ray_helper, request)(*args)
        elif self._journal is not None:
            if request == "remove":
                made = [k for k, (kind, entry) in enumerate(self._journal)
                        if kind == "replay" and entry[2] == [args[0]]]
                if made:
                    del self._journal[made[-1]]
                    return
            self._journal.append((request, args))

    def start_ray_process(self):
        """Start the ray process (``World(ray_process="later")``: it is built from every change made so far)."""
        if self.ray_helper is not None:
            return
        from diffbot_sim.physics.ray_process import RayProcess
        helper = RayProcess(self.time_step, self.gravity)
        for request, args in self._journal or ():
            getattr(helper, request)(*args)
        self.ray_helper, self._journal = helper, None

    def cast_later(self, key, directions, near, far, position, rotation):
        """Hand a ray sensor's rays to the ray process: ``directions`` ((N, 3), its frame; sent once per ``key``,
        again only when a different array is given) from ``near`` to ``far`` [m], the sensor at ``position``
        (3,) / ``rotation`` (3, 3), cast against the world as it is now (the state is sent with the first cast
        after each step). The rays are ``transforms.rays_along`` of these. Returns a ticket for
        :meth:`cast_answer`."""
        state = None
        if self._state_sent != self.steps:
            state, self._state_sent = self._moving_state(), self.steps
        return self.ray_helper.cast(state, key, directions, near, far, position, rotation)

    def cast_answer(self, ticket, wait=False):
        """The answer to :meth:`cast_later` as :meth:`ray_batch` gives it, or None while it is not back."""
        return self.ray_helper.answer(ticket, wait)

    def cast_drop(self, ticket):
        """Throw away the answer to a cast nobody wants any more."""
        self.ray_helper.drop(ticket)

    def _moving_state(self):
        """{body: (position, orientation, ((joint, position), ...))} of every robot and world body (PyBullet's
        base frame): what the mirror must match before it casts."""
        c = self.client
        state = {}
        for robot in self.robots:
            joints = sorted(robot.joint_index.values())
            positions = robot.joint_states(joints)[0] if joints else []
            state[robot.body] = (*pybullet.getBasePositionAndOrientation(robot.body, physicsClientId=c),
                                 tuple(zip(joints, positions)))
        for uid in [u for u, _ in self.world_bodies] + self._boxes:
            state[uid] = (*pybullet.getBasePositionAndOrientation(uid, physicsClientId=c), ())
        return state

    def retro(self, bodies, links):
        """Gazebo ``laser_retro`` of each hit (body, link) (0 where none is given, and for misses)."""
        import numpy as np

        if not self.laser_retro:
            return np.zeros(len(bodies))
        table = self.laser_retro
        return np.array([table.get((b, k), 0.0) for b, k in zip(bodies.tolist(), links.tolist())], dtype=float)

    def step(self):
        pybullet.stepSimulation(physicsClientId=self.client)
        self.steps += 1
        if self.landing:
            self._watch_landings()

    def _watch_landings(self):
        """Give each robot being set down its own contacts back once it rests on something (or in time)."""
        rest_steps = round(LANDING_REST_TIME / self.time_step)
        for robot, state in list(self.landing.items()):
            state[1] -= 1
            linear, angular = pybullet.getBaseVelocity(robot.body, physicsClientId=self.client)
            still = (math.sqrt(sum(v * v for v in linear)) < LANDING_REST_SPEED[0]
                     and math.sqrt(sum(w * w for w in angular)) < LANDING_REST_SPEED[1])
            if still and state[0] == 0 and not pybullet.getContactPoints(robot.body, physicsClientId=self.client):
                still = False  # at rest in the air: it has not landed yet
            state[0] = state[0] + 1 if still else 0
            if state[0] >= rest_steps or state[1] <= 0:
                robot.damp_contacts(False)
                del self.landing[robot]

    def render(self, view_pose, width, height, hfov, near, far, renderer="tiny"):
        """A camera image from ``view_pose`` ((x, y, z), (qx, qy, qz, qw)) looking along that frame's +x, up
        its +z (a Gazebo camera): (rgb uint8 (h, w, 3), z-depth float32 (h, w) [m], NaN where nothing was hit
        or beyond ``far``). ``hfov`` [rad] is SDF's horizontal FOV. ``renderer`` "tiny": PyBullet's CPU
        TinyRenderer; "egl": the EGL plugin (``use_egl`` must have succeeded; else TinyRenderer draws)."""
        import numpy as np

        from diffbot_sim.sensors import camera as camera_sensor
        c = self.client
        eye, target, up = camera_sensor.look_at(view_pose)
        view = pybullet.computeViewMatrix(eye, target, up, physicsClientId=c)
        proj = pybullet.computeProjectionMatrixFOV(camera_sensor.vertical_fov_degrees(hfov, width, height),
                                                   width / height, near, far, physicsClientId=c)
        kind = pybullet.ER_BULLET_HARDWARE_OPENGL if renderer == "egl" else pybullet.ER_TINY_RENDERER
        _, _, rgba, depth, _ = pybullet.getCameraImage(width, height, view, proj, renderer=kind,
                                                       flags=pybullet.ER_NO_SEGMENTATION_MASK, physicsClientId=c)
        rgb = np.ascontiguousarray(np.asarray(rgba, np.uint8).reshape(height, width, 4)[:, :, :3])
        return rgb, camera_sensor.linear_depth(np.asarray(depth, np.float32).reshape(height, width), near, far)

    def use_egl(self):
        """Load PyBullet's EGL renderer plugin (OpenGL off screen; Mesa's llvmpipe without a GPU). Returns
        None when it draws this world, else why not (the caller falls back to TinyRenderer). The plugin only
        sees bodies created after it loads, so it must be loaded before the world and robots are."""
        if getattr(self, "_egl", None) is not None:
            return None
        if self.world_bodies or self.robots:
            return "the EGL plugin only draws bodies created after it loads, and this world is built already"
        import pkgutil
        loader = pkgutil.get_loader("eglRenderer")
        if loader is None:
            return "pybullet has no eglRenderer module"
        problem = egl_probe(loader.get_filename())
        if problem is not None:
            return problem
        with quiet(1), quiet(2):
            plugin = pybullet.loadPlugin(loader.get_filename(), "_eglRendererPlugin", physicsClientId=self.client)
        if plugin < 0:
            return "pybullet could not load its EGL plugin (no EGL/OpenGL library?)"
        self._egl = plugin
        if self.plane is not None:  # recreate our plane so that the plugin draws it
            pybullet.removeBody(self.plane, physicsClientId=self.client)
            self.plane = pybullet.loadURDF("plane.urdf", physicsClientId=self.client)
            self._mirror("plane", self.plane)
        return None

    # -- the world API (gazebo_ros's /gazebo services): move, remove, push ------------------------------
    def remove_robot(self, robot):
        """Delete a robot's body (delete_model)."""
        pybullet.removeBody(robot.body, physicsClientId=self.client)
        self.robots.remove(robot)
        self.landing.pop(robot, None)
        for key in [k for k in self.laser_retro if k[0] == robot.body]:
            del self.laser_retro[key]
        self._mirror("remove", robot.body)

    def remove_body(self, uid):
        """Delete one world body (delete_model of a world model)."""
        pybullet.removeBody(uid, physicsClientId=self.client)
        self.world_bodies = [(u, b) for u, b in self.world_bodies if u != uid]
        self._boxes = [u for u in self._boxes if u != uid]
        self.laser_retro.pop((uid, -1), None)
        self._mirror("remove", uid)

    def body_motion(self, uid, inertial_pose):
        """World body ``uid``'s link frame: (pose, linear velocity of its origin, angular velocity), world
        axes (as Robot.link_motion)."""
        com, _ = pybullet.getBasePositionAndOrientation(uid, physicsClientId=self.client)
        linear, angular = pybullet.getBaseVelocity(uid, physicsClientId=self.client)
        pose = self.body_pose(uid, inertial_pose)
        v = point_velocity(linear, angular, [pose[0][i] - com[i] for i in range(3)])
        return (tuple(pose[0]), tuple(pose[1])), v, tuple(angular)

    def set_body_motion(self, uid, inertial_pose, pose, linear, angular):
        """Teleport world body ``uid``'s link frame to ``pose`` with the given velocity of its origin (world
        axes); a static body only moves."""
        self._place(uid, pose, inertial_pose)
        com, _ = pybullet.getBasePositionAndOrientation(uid, physicsClientId=self.client)
        v = point_velocity(linear, angular, [com[i] - pose[0][i] for i in range(3)])
        pybullet.resetBaseVelocity(uid, v, angular, physicsClientId=self.client)

    def apply_wrench(self, uid, link, force, torque, point=None):
        """Push body ``uid`` (PyBullet link index ``link``) for the coming step: ``force`` [N] at the world
        ``point`` (None: the link's centre of mass, as Gazebo's Link::SetForce) and ``torque`` [N·m], world
        axes (PyBullet clears external forces after each step)."""
        if point is None:
            point = (pybullet.getBasePositionAndOrientation(uid, physicsClientId=self.client)[0] if link == -1
                     else pybullet.getLinkState(uid, link, physicsClientId=self.client)[0])
        if any(force):
            pybullet.applyExternalForce(uid, link, force, point, pybullet.WORLD_FRAME, physicsClientId=self.client)
        if any(torque):
            pybullet.applyExternalTorque(uid, link, torque, pybullet.WORLD_FRAME, physicsClientId=self.client)

    def set_gravity(self, gravity):
        """Gravity [m/s^2] along z for every body from the next step (set_physics_properties)."""
        self.gravity = gravity
        pybullet.setGravity(0, 0, gravity, physicsClientId=self.client)
        for robot in self.robots:
            robot.gravity = gravity

    def reset(self):
        """Put every robot back at its spawn pose and every world body at its start (a static one too: the
        world API may have moved it), at rest, with no memory of the run before: Bullet keeps each touching
        pair's contact points and their impulses from step to step (to warm-start its solver), and a robot
        reset to where it rested would inherit them, so a run after a reset would depend on what came before
        it (measured: 1.1 mm apart after 2 s of driving, by how long the robot had rested). Every moving body
        is first taken far away and the contacts recomputed, which drops them."""
        self._forget_contacts()
        for uid, body in self.world_bodies:
            self._place(uid, body.pose, body.inertial_pose)
        for robot in self.robots:
            robot.reset()
        for robot in self.robots:
            self.lift_out(robot)

    def _forget_contacts(self):
        c = self.client
        moving = [robot.body for robot in self.robots] + [uid for uid, body in self.world_bodies if not body.static]
        for k, uid in enumerate(moving):  # apart from each other and from everything else
            pybullet.resetBasePositionAndOrientation(uid, (0.0, 10.0 * k, FAR_AWAY), (0.0, 0.0, 0.0, 1.0),
                                                     physicsClientId=c)
        pybullet.performCollisionDetection(physicsClientId=c)

    def close(self):
        if self.ray_helper is not None:
            self.ray_helper.close()
            self.ray_helper = None
        if self.client is not None and pybullet.isConnected(self.client):
            pybullet.disconnect(self.client)
        self.client = None
        for path in self._files:
            with contextlib.suppress(OSError):
                os.remove(path)
        self._files = []

    # -- actors: bodies moved by a script, not by forces -----------------------------------------------------
    def add_kinematic_box(self, size, pose):
        """A box of ``size`` (x, y, z) [m] centred at ``pose`` ((x, y, z), (qx, qy, qz, qw)) that forces never
        move (mass 0) and :meth:`move_body` places: rays, cameras and robots meet it where it was put. Returns
        its PyBullet id."""
        c = self.client
        shape = pybullet.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[v / 2.0 for v in size],
                                              physicsClientId=c)
        visual = pybullet.createVisualShape(pybullet.GEOM_BOX, halfExtents=[v / 2.0 for v in size],
                                            rgbaColor=(0.85, 0.6, 0.45, 1.0), physicsClientId=c)
        uid = pybullet.createMultiBody(0.0, shape, visual, pose[0], pose[1], physicsClientId=c)
        self._boxes.append(uid)
        self._mirror("replay", "add_kinematic_box", (size, pose), [uid])
        return uid

    def move_body(self, uid, pose):
        """Place body ``uid`` (its base frame) at ``pose``."""
        pybullet.resetBasePositionAndOrientation(uid, pose[0], pose[1], physicsClientId=self.client)

    # -- learning environments (diffbot_sim.gym): snapshots, free space, contacts --------------------------
    def save_state(self):
        """Snapshot every body's pose, velocity and joint positions and velocities, and the contact caches
        (PyBullet's in-memory ``saveState``); returns its id for :meth:`restore_state`.

        A snapshot does not hold motor targets and modes, ``changeDynamics`` values (a robot's landing
        damping), gravity or the time step: after a restore the motors keep what was last set (bullet3 #4364),
        so the caller sets them again. Bodies may not be added or removed between save and restore.
        """
        return pybullet.saveState(physicsClientId=self.client)

    def restore_state(self, state):
        """Put every body back as snapshot ``state`` (:meth:`save_state`) holds it."""
        pybullet.restoreState(stateId=state, physicsClientId=self.client)

    def discard_state(self, state):
        """Free snapshot ``state``."""
        pybullet.removeState(state, physicsClientId=self.client)

    def bounds(self, uid):
        """Axis-aligned box (lo (x, y, z), hi (x, y, z)) [m], world axes, around every link of body ``uid``
        (PyBullet's collision bounds; an infinite plane reads about +-1e30)."""
        c = self.client
        boxes = [pybullet.getAABB(uid, link, physicsClientId=c)
                 for link in range(-1, pybullet.getNumJoints(uid, physicsClientId=c))]
        lo = tuple(min(box[0][i] for box in boxes) for i in range(3))
        hi = tuple(max(box[1][i] for box in boxes) for i in range(3))
        return lo, hi

    def free_of_bodies(self, points, radius, bottom, top, ignore=()):
        """For each (x, y) of ``points``: True when an upright cylinder of ``radius`` [m] from height
        ``bottom`` to ``top`` [m] there touches no body other than those in ``ignore`` (PyBullet ids), judged
        on collision shapes (the broadphase names the candidates, then their closest points)."""
        c = self.client
        height = top - bottom
        shape = pybullet.createCollisionShape(pybullet.GEOM_CYLINDER, radius=radius, height=height,
                                              physicsClientId=c)
        ignore = set(ignore)
        free = []
        try:
            for x, y in points:
                z = bottom + height / 2.0
                lo, hi = (x - radius, y - radius, bottom), (x + radius, y + radius, top)
                candidates = {(uid, link) for uid, link in
                              (pybullet.getOverlappingObjects(lo, hi, physicsClientId=c) or ())
                              if uid not in ignore}
                free.append(not any(pybullet.getClosestPoints(
                    bodyA=-1, bodyB=uid, distance=0.0, linkIndexB=link, collisionShapeA=shape,
                    collisionShapePositionA=(x, y, z), physicsClientId=c) for uid, link in candidates))
        finally:
            with quiet(1), quiet(2):  # PyBullet prints a "TODO: dealloc" warning for every removed shape
                pybullet.removeCollisionShape(shape, physicsClientId=c)
        return free

    def touching(self, body, ignore=()):
        """PyBullet ids of the bodies that body ``body`` touches or penetrates after the last step (a contact
        point at distance <= 0), other than itself and those in ``ignore``: a frozenset."""
        return frozenset(point[2] for point in pybullet.getContactPoints(bodyA=body, physicsClientId=self.client)
                         if point[8] <= 0.0 and point[2] != body and point[2] not in ignore)
