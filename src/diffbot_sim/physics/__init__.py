"""The only package that talks to PyBullet.

One ``World`` owns one physics client (its own, never the module-global one, so tests can run several
worlds side by side) and is used from one thread. Robots are loaded from URDF text; everything returned is
plain numbers, in URDF link frames (not PyBullet's centre-of-mass frames).
"""
from diffbot_sim.physics.client import egl_probe
from diffbot_sim.physics.rays import RAY_BATCH_LIMIT
from diffbot_sim.physics.robot import Robot, contact_damping
from diffbot_sim.physics.world import World

__all__ = ["RAY_BATCH_LIMIT", "Robot", "World", "contact_damping", "egl_probe"]
