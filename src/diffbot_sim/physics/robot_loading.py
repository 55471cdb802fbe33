"""A prepared model (:mod:`diffbot_sim.description.prepared_model`) put into a world where bullet_sim puts it:
the one placing rule bullet_sim (``simulator/robots.py``) and the Gymnasium scene (``gym/scene.py``) share.

``World.load_robot`` lumps the model as Gazebo does, loads it and sets it down calmly (its landing: lifted
out of what it was placed into, contacts damped until it rests). bullet_sim then lets it land while sim time
runs; a learning environment first lets it land with its wheels braked (:func:`settle`) and snapshots it.
"""
from diffbot_sim.physics.world import LANDING_MAX_TIME


def place_robot(world, prepared, x, y, z=0.0, yaw=0.0):
    """Load ``prepared`` with its root link at (``x``, ``y``) [m], turned by ``yaw`` [rad], raised onto the
    world: at the top of the highest world surface under (x, y) when that is above ``z`` (a robot spawned over
    a table stands on it), else at ``z``. A robot joined to the world stays at ``z``: Gazebo holds it where it is
    spawned. Returns the physics Robot.

    Raises:
        ModelError: PyBullet could not load the model.
    """
    if world.world_bodies and not prepared.model.fixed_to_world:
        z = max(z, world.top_at(x, y))
    return world.load_robot(prepared.text, prepared.model, (x, y, z), yaw)


def settle(world, robot, max_time=LANDING_MAX_TIME):
    """Step ``world`` until ``robot`` has landed (rests on what it was set down on; at most ``max_time`` s of
    sim time, after which the world ends its landing anyway). Whatever drives it is not run: set its motors
    first. Returns the physics steps taken."""
    steps = 0
    for _ in range(round(max_time / world.time_step) + 1):
        if robot not in world.landing:
            break
        world.step()
        steps += 1
    return steps
