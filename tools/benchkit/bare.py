"""Bare-PyBullet references: the same model stepped by PyBullet alone, for an item to pair the simulator with.

A reference loads the model as bullet_sim loads it (xacro in-process, meshes converted and cached, the URDF
parsed for its joints and sensors) into ``diffbot_sim.physics.World``, so both sides step the same bodies.
A reference robot that fell over steps fewer contacts and would flatter itself: ``check_upright`` refuses it.
"""
import math
import os


def load(model):
    """``(urdf_text, parsed)`` of ``model`` (a URDF or xacro file) as the simulator loads it, for
    ``World.load_robot``: xacro run, ``package://`` meshes resolved and cached."""
    from diffbot_sim.description import meshes
    from diffbot_sim.description.model_files import load_file, package_path
    from diffbot_sim.description.urdf_model import parse_urdf
    text = load_file(model)
    parsed = parse_urdf(text, model)
    text, _ = meshes.prepare_meshes(text, model, os.path.dirname(model), meshes.default_cache_dir(), package_path)
    return text, parsed


def check_upright(robot, what, limit_deg=30.0):
    """Raise unless ``robot``'s root link is within ``limit_deg`` of upright: a bare-PyBullet reference whose
    robot fell over steps fewer contacts (2 against 10 for the arm) and would flatter itself."""
    from diffbot_sim.check import drive_check
    position, quaternion = robot.base_pose()
    tilt = math.degrees(drive_check.body_sample(0.0, position, quaternion).tilt)
    if tilt > limit_deg:
        raise RuntimeError(f"bare PyBullet's {what} fell over (tilted {tilt:.0f} deg): its figure would be wrong")


def wheel_speeds(circle, separation, radius):
    """(left, right) wheel speeds [rad/s] of a differential drive driving ``circle`` (m/s, rad/s)."""
    v, w = circle
    return (v - w * separation / 2.0) / radius, (v + w * separation / 2.0) / radius
