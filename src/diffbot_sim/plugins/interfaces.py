"""What a plugin may use of the simulator, of its world and of its robot's body: the types of RobotContext's
``sim`` and ``robot`` (:mod:`diffbot_sim.plugins.base`).

The Simulator lives in simulator/, a layer above plugins/, so plugins cannot name it: they get it as
:class:`PluginSimulator`, the part of it they are allowed to use. Its world and the robot are physics/'s
``World`` and ``Robot``, which plugins could name; they get them as :class:`PluginWorld` and
:class:`PluginRobot` all the same, so that what a plugin depends on is written down in one place, short enough
to read, and a test's stand-in knows what it must provide. mypy checks both sides: a plugin's typed code
against these Protocols, and the real classes against them (the ``_conforms`` functions below for physics,
``simulator.robots`` for the Simulator), so a method renamed on one side and not the other fails ``make lint``.

Plugins also hand their robot to physics/'s helpers (``physics.contacts``, ``physics.force_torque``), which
read its PyBullet handles: those are physics/'s business with its own Robot and are not listed here.
"""
from __future__ import annotations

import threading
from collections.abc import Callable, Iterable, Sequence
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

from diffbot_sim.world.bodies import Body, Pose, Vec3

T = TypeVar("T")
#: A vector a plugin hands in: any three numbers (the robot's answers are tuples, ``Vec3``).
Vector = Sequence[float]


class PluginRobot(Protocol):
    """One robot's body in the physics (physics.robot.Robot) as its plugins use it. Joints are PyBullet joint
    indices (``joint_index``, :meth:`indices`); links are URDF link names, lumped ones included."""

    # Attributes are read-only properties here: plugins read them; the Robot keeps them up to date.
    @property
    def body(self) -> int:
        """The body's PyBullet id (the ids ``PluginWorld.world_bodies`` and contact queries give)."""
        ...

    @property
    def joint_index(self) -> dict[str, int]:
        """URDF joint name -> index, for every movable joint."""
        ...

    @property
    def frames(self) -> dict[str, tuple[str, Any, Any]]:
        """URDF link -> (PyBullet link carrying it, xyz, quaternion); empty when nothing was lumped."""
        ...

    @property
    def gravity(self) -> float:
        """The world's gravity along z [m/s^2] (negative)."""
        ...

    def indices(self, names: Iterable[str]) -> list[int]: ...

    # -- joints: state and motors -------------------------------------------------------------------------
    def joint_states(self, indices: Sequence[int]) -> tuple[list[float], list[float], list[float]]:
        """(positions, velocities, efforts) of the joints."""
        ...

    def joint_positions(self, indices: Sequence[int]) -> list[float]: ...

    def joint_inertias(self, indices: Sequence[int]) -> list[float]: ...

    def gravity_torques(self, indices: Sequence[int], load: tuple[str, Vector, float] | None = None
                        ) -> list[float]: ...

    def free_joints(self, indices: Sequence[int]) -> None: ...

    def set_velocities(self, indices: Sequence[int], velocities: Sequence[float],
                       max_forces: Sequence[float]) -> None: ...

    def set_positions(self, indices: Sequence[int], positions: Sequence[float], max_forces: Sequence[float],
                      position_gain: float | None = None) -> None: ...

    def set_efforts(self, indices: Sequence[int], efforts: Sequence[float]) -> None: ...

    def set_joint_velocities(self, indices: Sequence[int], velocities: Sequence[float]) -> None: ...

    # -- links and the base ---------------------------------------------------------------------------------
    def link_pose(self, name: str) -> Pose: ...

    def link_motion(self, name: str) -> tuple[Pose, Vec3, Vec3]:
        """(pose, linear velocity, angular velocity), world axes."""
        ...

    def link_imu(self, name: str, previous_velocity: Vector | None, dt: float,
                 offset: Pose | None = None) -> tuple[Pose, Vec3, Vec3, Vec3]: ...

    def base_pose(self) -> Pose: ...

    def base_twist(self, pose: Pose | None = None) -> tuple[Vec3, Vec3]: ...

    def planar_inertia(self) -> tuple[float, float]: ...

    def heading_velocity(self) -> tuple[float, float, float]: ...

    def set_heading_velocity(self, vx: float, vy: float, wz: float) -> None: ...

    def push_link(self, name: str, force: Vector, torque: Vector) -> None: ...

    # -- grasping -------------------------------------------------------------------------------------------
    def link_contacts(self, links: Iterable[str]) -> list[tuple[str, int, int, Vec3, Vec3]]: ...

    def attach(self, link: str, body: int, body_link: int = -1, collide: bool = True) -> Any: ...

    def detach(self, handle: Any) -> None: ...

    def body_origin(self, body: int, link: int = -1) -> Vec3: ...


class PluginWorld(Protocol):
    """The physics world (physics.world.World) as plugins use it: the other bodies, rays and camera images."""

    @property
    def world_bodies(self) -> Sequence[tuple[int, Body]]:
        """(PyBullet id, its SDF body) of each body the world file made."""
        ...

    @property
    def robots(self) -> Sequence[PluginRobot]:
        """Every robot in the world (this plugin's own included)."""
        ...

    def ray_batch(self, starts: Any, ends: Any) -> tuple[Any, Any, Any]:
        """(hit fractions, hit body ids, hit link indices), numpy arrays."""
        ...

    def retro(self, bodies: Any, links: Any) -> Any: ...

    @property
    def ray_helper(self) -> object | None:
        """The ray process once started (casts can then be handed to it: ``cast_later``), else None."""
        ...

    def cast_later(self, key: Any, directions: Any, near: float, far: float, position: Any, rotation: Any) -> Any:
        ...

    def cast_answer(self, ticket: Any, wait: bool = False) -> tuple[Any, Any, Any] | None: ...

    def cast_drop(self, ticket: Any) -> None: ...

    def render(self, view_pose: Pose, width: int, height: int, hfov: float, near: float, far: float,
               renderer: str = "tiny") -> tuple[Any, Any]:
        """(rgb uint8 (h, w, 3), depth float32 (h, w) [m])."""
        ...


class PluginSimulator(Protocol):
    """The Simulator (simulator.loop.Simulator) as plugins use it. Plugins run on the loop's thread; rospy's
    callbacks do not, and reach the loop only through :meth:`post`, :meth:`call` and :attr:`wake`."""

    @property
    def wake(self) -> threading.Event:
        """Set by a callback that stored a command, so that a loop waiting for the wall clock looks at it now."""
        ...

    @property
    def paused(self) -> bool:
        """Physics is paused (/gazebo/pause_physics): no steps, sim time stands still."""
        ...

    @property
    def world(self) -> PluginWorld: ...

    @property
    def sim_time(self) -> float:
        """Seconds of simulated time since the start (or the last reset_simulation)."""
        ...

    def warn(self, key: str, text: str) -> None:
        """A warning, at most one per ``key`` per few seconds of wall time."""

    def post(self, action: Callable[[], object]) -> None:
        """Run ``action()`` on the loop's thread soon, without waiting (a subscriber callback)."""

    def call(self, action: Callable[[], T], timeout: float = ...) -> T:
        """Run ``action()`` on the loop's thread and return its result (a service handler); raises what it
        raised, or rospy.ServiceException when the loop did not get to it within ``timeout`` wall seconds."""
        ...


if TYPE_CHECKING:
    from diffbot_sim.physics.robot import Robot
    from diffbot_sim.physics.world import World

    def _robot_conforms(robot: Robot) -> PluginRobot:
        return robot

    def _world_conforms(world: World) -> PluginWorld:
        return world
