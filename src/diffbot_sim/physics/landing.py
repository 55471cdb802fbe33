"""Setting a placed robot down calmly: lifted out of what it was placed into, its contacts damped until it
rests (Gazebo's ``<max_vel>`` cap on correcting velocities, which Bullet lacks)."""
import math

from diffbot_sim.physics.client import pybullet

#: How fast [1/s] Bullet may push a robot being set down out of what it lands on: a penetration ``d`` is undone
#: at most at ``LANDING_CORRECTION_RATE * d`` m/s (the contact ERP is this times the step). Gazebo caps each
#: body's correcting velocity at its SDF ``<max_vel>`` (0.01 m/s by default), so what lands on a contact lands
#: dead; Bullet has no such cap, and a Gazebo kp/kd taken as is (kp 1e7, kd 1 on published 4-wheel robots: an
#: undamped spring) gives an ERP of ~1. Measured, dropped from 1 m such a robot rebounds 0.26 m at ERP 1.0,
#: 0.13 m at 0.7, 0.017 m at 0.3 and 0.005 m at 0.2, landing dead within 0.1 s. The same damping kept on while
#: driving makes a four-wheel robot's turn in place wander (its origin moved 0.04 m at ERP 1.0 and 0.7, up to
#: 0.18 m at 0.2), so it is on only while the robot is set down (:meth:`Landings.lift_out`), until it rests.
LANDING_CORRECTION_RATE = 0.2 * 240.0
#: A robot being set down rests once it touches something and its base moves slower than these
#: (m/s, rad/s) for LANDING_REST_TIME s; it gets its own contacts back then, or after LANDING_MAX_TIME s.
LANDING_REST_SPEED = (0.05, 0.2)
LANDING_REST_TIME = 0.1
LANDING_MAX_TIME = 3.0
#: Placement (spawn, teleport, reset) lifts a robot out of what it would sit in, within this many passes.
DEPENETRATION_PASSES = 4


class Landings:
    """The robots of one PyBullet world being set down: ``robot in landings`` while its contacts are damped.

    Args:
        client: the world's PyBullet client. time_step: s, the world's step.
    """

    def __init__(self, client, time_step):
        self.client = client
        self.time_step = time_step
        #: the contact ERP while a robot is set down (LANDING_CORRECTION_RATE times the step, at most 1)
        self.erp = min(1.0, LANDING_CORRECTION_RATE * time_step)
        self._landing = {}  # Robot -> [steps it has rested, steps left]

    def set_time_step(self, time_step):
        """The world's step changed: the landing contact ERP follows it."""
        self.time_step = time_step
        self.erp = min(1.0, LANDING_CORRECTION_RATE * time_step)

    def __contains__(self, robot):
        return robot in self._landing

    def __len__(self):
        return len(self._landing)

    def lift_out(self, robot):
        """Set ``robot`` down where it was placed: lift it out of whatever it was placed into (the ground, a
        world body, another robot) so that its deepest collision point just touches, and damp its contacts
        until it rests (LANDING_CORRECTION_RATE). Returns the lift [m].

        Called wherever the robot is placed: spawn, reset, teleport. Gazebo pushes such a robot out at its
        ``<max_vel>`` (0.01 m/s by default: 6 s for a robot spawned 6 cm deep) and ends where this starts;
        Bullet would push it out in one step and throw it (measured: a robot 6 cm deep left at 14 m/s, one
        13 cm deep flew 18 m up). Only contacts whose surface faces up count (a normal within 60 degrees of
        +z): a robot is lifted off what it stands in, never pushed sideways out of a wall.

        A robot joined to the world is left where it is (0.0): Gazebo neither lifts nor sets down a model
        its joint to the world holds, and PyBullet holds its base.
        """
        if robot.model.fixed_to_world:
            return 0.0
        robot.damp_contacts(True)
        self._landing[robot] = [0, round(LANDING_MAX_TIME / self.time_step)]
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

    def watch(self):
        """After a step: give each robot being set down its own contacts back once it rests on something (or
        in time)."""
        rest_steps = round(LANDING_REST_TIME / self.time_step)
        for robot, state in list(self._landing.items()):
            state[1] -= 1
            linear, angular = pybullet.getBaseVelocity(robot.body, physicsClientId=self.client)
            still = (math.sqrt(sum(v * v for v in linear)) < LANDING_REST_SPEED[0]
                     and math.sqrt(sum(w * w for w in angular)) < LANDING_REST_SPEED[1])
            if still and state[0] == 0 and not pybullet.getContactPoints(robot.body, physicsClientId=self.client):
                still = False  # at rest in the air: it has not landed yet
            state[0] = state[0] + 1 if still else 0
            if state[0] >= rest_steps or state[1] <= 0:
                robot.damp_contacts(False)
                del self._landing[robot]

    def forget(self, robot):
        """``robot`` was removed: stop watching it."""
        self._landing.pop(robot, None)
