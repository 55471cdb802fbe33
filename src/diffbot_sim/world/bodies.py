"""A world as plain data (pure): what the SDF reader (:mod:`diffbot_sim.world.sdf_reader`) and the map-image
converter (:mod:`diffbot_sim.world.map_image`) produce and the physics layer builds.

Every pose is ``(xyz, quaternion xyzw)`` with plain float tuples. A body is one SDF ``<link>`` (a model with
several links gives several bodies; joints between them are not simulated and are named in ``warnings``).
Mesh shapes carry the mesh file's absolute path and its scale; the physics layer converts and caches them
(:mod:`diffbot_sim.description.meshes`), so COLLADA units are honoured as for robots.
"""
from dataclasses import dataclass, field

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]
Pose = tuple[Vec3, Quat]
IDENTITY: Pose = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


@dataclass
class Shape:
    """One collision shape, posed in its body's link frame.

    ``kind``: ``box`` (``size`` = x, y, z), ``cylinder`` (radius, length; axis z), ``sphere`` (radius,),
    ``plane`` (normal x, y, z; infinite, as Gazebo's plane collision), ``mesh`` (``mesh`` = absolute file
    path, ``scale``), or ``trimesh`` (``vertices``/``indices`` given in place: a map image's walls).
    ``surface``: Gazebo surface values that apply (``mu``, ``mu2``, ``kp``, ``kd``, ``laser_retro``...).
    """

    kind: str
    size: tuple[float, ...] = ()
    pose: Pose = IDENTITY
    mesh: str | None = None
    scale: Vec3 = (1.0, 1.0, 1.0)
    vertices: object | None = None  # numpy (N, 3) float for kind trimesh
    indices: object | None = None  # numpy (M, 3) int for kind trimesh
    surface: dict[str, float] = field(default_factory=dict)
    name: str = ""


@dataclass
class Body:
    """One rigid body of the world: an SDF link (``model::link``), static or dynamic.

    ``mass`` kg and ``inertia`` (ixx, iyy, izz, ixy, ixz, iyz) about the centre of mass, whose pose in the
    link frame is ``inertial_pose`` (SDF's default inertial where the file gives none: mass 1, unit inertia).
    """

    name: str
    model: str
    pose: Pose
    static: bool
    shapes: list[Shape] = field(default_factory=list)
    mass: float = 1.0
    inertia: tuple[float, float, float, float, float, float] = (1.0, 1.0, 1.0, 0.0, 0.0, 0.0)
    inertial_pose: Pose = IDENTITY
    color: tuple[float, float, float, float] | None = None  # rgba of its first <visual>'s material
    model_pose: Pose = IDENTITY  # world pose of its top-level model's frame at start (the /gazebo model pose)

    @property
    def top_model(self):
        """The top-level model it belongs to (``outer`` of ``outer::inner::link``): what /gazebo names."""
        return self.model.split("::")[0]


@dataclass
class WorldDescription:
    """Everything a world file asks of the simulator.

    ``gravity`` m/s^2 (vector); ``real_time_factor``, ``real_time_update_rate``, ``max_step_size`` and
    ``solver_iterations`` from ``<physics>`` (None when the file gives none; ``sdf`` True: a Gazebo world,
    whose unstated ones are SDF's defaults); ``not_simulated``: lights, scene, GUI camera, plugins, other
    ``<physics>`` settings, named once at start; ``warnings``: one line each (unknown geometry skipped, missing
    mesh skipped...).
    """

    name: str
    source: str
    bodies: list[Body] = field(default_factory=list)
    gravity: Vec3 = (0.0, 0.0, -9.8)
    real_time_factor: float | None = None
    real_time_update_rate: float | None = None  # Hz of world updates; 0: as fast as possible
    max_step_size: float | None = None
    solver_iterations: int | None = None  # <physics><ode><solver><iters>
    not_simulated: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    has_ground: bool = False  # a ground plane is among the bodies (else the simulator adds its own)
    actors: list[object] = field(default_factory=list)  # world.actor_sdf.ActorDescription, in file order
    sdf: bool = False  # an SDF world file (not a map_server map): SDF's <physics> defaults apply
