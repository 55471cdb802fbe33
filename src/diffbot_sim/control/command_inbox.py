"""The newest command for a drive, handed from whoever sends it to the loop that applies it (pure).

Under ROS the sender is a subscriber callback on one of rospy's threads and the taker is the simulator's loop;
in a Gymnasium environment both are the caller's thread. Either way only the newest command counts (the
plugins subscribe to ``cmd_vel`` with a queue of one), and it takes effect at the sim time the loop takes it
(:meth:`CommandInbox.take`): that is its arrival time as the plugin sees it, the time a command timeout
counts from (Gazebo's plugins likewise stamp a command in their world-update callback, not when ROS
delivered it).
"""
import threading


class CommandInbox:
    """A queue of one: :meth:`put` replaces what was not yet taken, :meth:`take` empties it.

    Args:
        wake: called after each :meth:`put` (the simulator's ``wake.set``, so that the loop applies a new
            command at once in real time); None: nothing to wake.
    """

    def __init__(self, wake=None):
        self._wake = wake
        self._lock = threading.Lock()
        self._pending = None

    def put(self, command):
        """Hand over ``command`` (any value but None), replacing one not yet taken."""
        with self._lock:
            self._pending = command
        if self._wake is not None:
            self._wake()

    def take(self):
        """The command put since the last call, or None."""
        if self._pending is None:  # the common case, without the lock: a put in between is taken next time
            return None
        with self._lock:
            command, self._pending = self._pending, None
        return command

    def clear(self):
        """Forget a command not yet taken (a reset)."""
        with self._lock:
            self._pending = None
