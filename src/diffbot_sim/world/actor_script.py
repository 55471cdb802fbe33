"""An actor's ``<script>`` played back as Gazebo-classic 11 plays it (pure): ``gazebo/physics/Actor.cc``
``Actor::Update`` with gazebo-classic pull request 2773, the trajectories interpolated by
:mod:`diffbot_sim.world.actor_splines`; the ``<actor>`` itself is read by :mod:`diffbot_sim.world.actor_sdf`.

* A new frame is computed at most every ``frame_period`` (1/30 s) of sim time; steps between frames hold
  the last frame. ``script time = sim - delay_start - play start``; before it reaches 0 nothing moves.
* At the end of the script: without ``loop`` the actor stops at its *last rendered* frame (a frame at or
  past the end is never drawn, so the last waypoint itself is not shown); with ``loop`` the time wraps
  and the play start moves to the wrap, so ``delay_start`` is waited again each cycle (period = length +
  delay), holding the first frame of the new cycle meanwhile.
* Trajectories play back to back.

The pose returned is what Gazebo reports for the actor's model (``/gazebo/model_states``,
``get_model_state``): for an actor without a skeleton (links of its own, or a skin we do not animate) the
trajectory pose itself, in the world frame (the actor's ``<pose>`` only places it before the first
frame). With a skeleton Gazebo reports the trajectory pose composed with the animated root bone (its X
zeroed); we have no skeleton, so the trajectory pose is the actor's feet frame (actor.world's waypoints
sit at z = 0 and its skin stands on the ground).

Deliberately not reproduced: skeleton animation (``interpolate_x``, ``PoseAtX``, bone links); a
trajectory without waypoints (Gazebo gives it the length of the animation of its type, which we do not
read, and puts the actor at the world origin while it plays): here it lasts 0 s and holds the pose.
"""
from diffbot_sim.values import check_number
from diffbot_sim.world.actor_splines import PoseTrack

#: Actor::Update draws a new frame at most this often, in s of sim time ("do not refresh animation faster
#: than 30 Hz sim time").
FRAME_PERIOD = 1.0 / 30.0


class ActorScript:
    """An actor's ``<script>`` played as ``Actor::Update`` plays it, one call per simulation step.

    ``frame_period`` s: at most one new frame per this much sim time, the steps in between holding the
    last frame (Gazebo: 1/30 s); 0 draws a frame at every call (for tests and smooth bodies).
    The object keeps Gazebo's state (play start, last frame), so call :meth:`pose_at` with non-decreasing
    sim times; a time earlier than the last call (a world reset) restarts the script.
    """

    def __init__(self, description, frame_period=FRAME_PERIOD):
        self.description = description
        self.frame_period = check_number("frame_period", frame_period, low=0.0)
        self.initial_pose = description.world_pose
        self._segments = []  # (start s, end s, PoseTrack or None), back to back
        start = 0.0
        for trajectory in description.script.trajectories:
            track = PoseTrack(trajectory) if trajectory.waypoints else None
            self._segments.append((start, start + trajectory.duration, track))
            start += trajectory.duration
        #: Total length of the script in s (sum of the trajectories' durations).
        self.script_length = start
        # Update returns at once when nothing is translated (and, ours, there is no skeleton).
        self._moves = any(track for _, _, track in self._segments)
        self._loaded_at = None
        self.reset(0.0)

    # -- Gazebo's Actor::Reset/Init, Play and Stop
    def reset(self, sim_time=0.0):
        """Actor::Reset + Init at ``sim_time``: back to the ``<pose>``, script from its start (playing at once
        when ``auto_start``)."""
        self._loaded_at = sim_time
        self._last_call = sim_time
        self._prev_frame = sim_time
        self._play_start = sim_time
        self.active = self.description.script.auto_start
        self._held = self.initial_pose
        #: Time into the current trajectory of the last frame drawn, s.
        self.script_time = 0.0
        self.drawn = False  # a frame has been drawn since the reset

    @property
    def about_to_move(self):
        """Playing from its start with no delay, but before its first frame (1/30 s into the run): the actor
        stands at its ``<pose>`` only until then (often the world's origin, where a robot is spawned)."""
        return (self.active and self._moves and not self.drawn
                and self.description.script.delay_start <= 0.0)

    def play(self, sim_time):
        """Actor::Play: (re)start the script at ``sim_time`` (what a plugin does when auto_start is false)."""
        self.active = True
        self._play_start = sim_time

    def stop(self):
        """Actor::Stop: hold the current pose until :meth:`play`."""
        self.active = False

    # -- the pose
    def trajectory_pose(self, script_time):
        """The pose at ``script_time`` s into the script (clamped to 0..length), with no frames, loop or
        delay: the first trajectory whose span holds the time, as Gazebo picks it. None when that
        trajectory has no waypoints or the script has none."""
        script_time = min(max(script_time, 0.0), self.script_length)
        for start, end, track in self._segments:
            if start <= script_time <= end:
                return track.pose_at(script_time - start) if track else None
        return None

    def pose_at(self, sim_time, play_start_time=None):
        """The actor's world pose ((x, y, z), (qx, qy, qz, qw)) at ``sim_time`` s.

        ``play_start_time``: the sim time Gazebo's ``Actor::Init`` ran (0.0 at construction: the world's
        start, for actors of the world file); with ``auto_start`` the script plays from then. A value other
        than the current one restarts the script from it (as :meth:`reset` does); None keeps the current.
        Before the first frame, while waiting for ``delay_start``, when not playing, or when the script has
        no waypoints, the pose is the last one shown: the ``<pose>`` until a frame has been drawn (Gazebo
        leaves the model where it was loaded).
        """
        if play_start_time is not None and play_start_time != self._loaded_at:
            self.reset(play_start_time)
        elif sim_time < self._last_call:
            self.reset(self._loaded_at)
        self._last_call = sim_time
        if not self.active or not self._moves:
            return self._held
        # common::Time differences are whole nanoseconds
        if round((sim_time - self._prev_frame) * 1e9) / 1e9 < self.frame_period:
            return self._held
        script_time = sim_time - self.description.script.delay_start - self._play_start
        if script_time < 0:
            return self._held
        if script_time >= self.script_length:
            if not self.description.script.loop:
                self.active = False  # PR 2773: stop, keeping the last frame
                return self._held
            script_time -= self.script_length
            self._play_start = sim_time - script_time
        segment = next((s for s in self._segments if s[0] <= script_time <= s[1]), None)
        if segment is None:  # Gazebo: "Trajectory not found" (a script of length 0)
            return self._held
        start, _, track = segment
        self._prev_frame = sim_time
        self.drawn = True
        self.script_time = script_time - start
        if track is not None:
            self._held = track.pose_at(self.script_time)
        return self._held
