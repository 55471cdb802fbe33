"""control_toolbox::Pid (ros-controls/control_toolbox noetic-devel, 1.19: ``src/pid.cpp``, ``pid.h``) in Python:
the PID that gazebo_ros_control's DefaultRobotHWSim (``pid_gains/<joint>``), joint_trajectory_controller,
gripper_action_controller and the effort_controllers all use.

Reproduced:

* ``Pid::init(NodeHandle)`` parameter reading (:func:`pid_gains`): ``p`` is required (without it upstream
  logs ``No p gain specified for pid.  Namespace: <ns>`` and the caller falls back); ``i``, ``d`` default to 0;
  ``i_clamp`` (default 0) sets ``i_max = |i_clamp|``, ``i_min = -|i_clamp|``; ``i_clamp_min`` / ``i_clamp_max``
  override them as ``-|v|`` / ``+|v|``; ``antiwindup`` defaults to false.
* ``computeCommand``: ``p = P e``; ``i_error += dt e``; with antiwindup and ``I != 0`` the ``i_error`` is clamped to
  ``[i_min/I, i_max/I]`` (ordered), otherwise the *term* ``I i_error`` is clamped to ``[i_min, i_max]`` — so
  with the default ``i_clamp: 0`` the integral term is always 0; ``d = D error_dot``.
* The derivative from the last error: after ``reset()`` (and on construction) the last error 0 counts as valid,
  so the first call kicks by ``D e / dt``. ``dt == 0`` or a non-finite error returns 0 and changes nothing;
  a negative ``dt`` reuses the previous ``error_dot`` and still integrates, as upstream.

Not reproduced: dynamic_reconfigure and the ``control_msgs/PidState`` publisher themselves (a ROS node can
publish :attr:`Pid.terms`, which holds every field of that message but the stamp); ``updatePid`` (deprecated,
negated) and ``initXml``.
"""
import math
from dataclasses import dataclass

from diffbot_sim.errors import ConfigError
from diffbot_sim.values import check_bool, check_number


@dataclass(frozen=True)
class PidGains:
    """Gains as control_toolbox::Pid::Gains holds them. ``i_clamp_max`` >= 0 >= ``i_clamp_min`` when read
    by :func:`pid_gains`; they bound the integral term (or ``i_error`` times I with ``antiwindup``)."""

    p: float
    i: float = 0.0
    d: float = 0.0
    i_clamp_max: float = 0.0
    i_clamp_min: float = 0.0
    antiwindup: bool = False


@dataclass(frozen=True)
class PidTerms:
    """The state of the last computation: the fields of ``control_msgs/PidState`` (but its header)."""

    timestep: float = 0.0
    error: float = 0.0
    error_dot: float = 0.0
    p_error: float = 0.0
    i_error: float = 0.0
    d_error: float = 0.0
    p_term: float = 0.0
    i_term: float = 0.0
    d_term: float = 0.0
    i_max: float = 0.0
    i_min: float = 0.0
    output: float = 0.0


def _namespace_dict(params, name):
    """The PID namespace's parameters as a dict ({} when absent); anything else is a user error."""
    if params is None:
        return {}
    if not isinstance(params, dict):
        raise ConfigError(name, params, "a dictionary of PID gains (p, i, d, i_clamp, ...)")
    return params


def pid_gains(params, name) -> PidGains | None:
    """The gains in the rosparam dict ``params`` of the PID namespace ``name`` (e.g.
    ``/gazebo_ros_control/pid_gains/joint1``), read as ``Pid::init`` reads them.

    Returns:
        None when there is no ``p``; upstream then logs ``No p gain specified for pid.  Namespace: <name>``
        (see :func:`no_p_gain_message`) and the caller does without a PID.

    Raises:
        ConfigError: a gain is not a finite number or ``antiwindup`` not a bool, naming ``<name>/<key>``; or
            ``params`` is not a dictionary.
    """
    params = _namespace_dict(params, name)
    if "p" not in params:
        return None

    def number(key, default=0.0):
        value = params.get(key, default)
        return check_number(f"{name}/{key}", value)

    i_clamp = abs(number("i_clamp"))
    i_clamp_max, i_clamp_min = i_clamp, -i_clamp
    if "i_clamp_min" in params:
        i_clamp_min = -abs(number("i_clamp_min"))
    if "i_clamp_max" in params:
        i_clamp_max = abs(number("i_clamp_max"))
    antiwindup = check_bool(f"{name}/antiwindup", params.get("antiwindup", False))
    return PidGains(p=number("p"), i=number("i"), d=number("d"),
                    i_clamp_max=i_clamp_max, i_clamp_min=i_clamp_min, antiwindup=antiwindup)


def pid_publish_state(params, name) -> bool:
    """``<name>/publish_state`` (default false): whether upstream publishes ``control_msgs/PidState`` on
    ``<name>/state`` (queue 1) at every computation."""
    params = _namespace_dict(params, name)
    return check_bool(f"{name}/publish_state", params.get("publish_state", False))


def no_p_gain_message(name):
    """Upstream's ROS_ERROR text when a PID namespace has no ``p`` (two spaces before "Namespace")."""
    return f"No p gain specified for pid.  Namespace: {name}"


def boost_clamp(value, low, high):
    """``boost::algorithm::clamp``: ``low`` below it, else ``high`` above it (so ``low`` > ``high`` gives
    ``low`` for values under ``low``, ``high`` otherwise), else ``value``."""
    if value < low:
        return low
    if high < value:
        return high
    return value


class Pid:
    """One PID loop with control_toolbox semantics. Units are the caller's: error in rad, m or rad/s, dt in s,
    the output in N, N·m or whatever the gains map to.

    Args:
        gains: the :class:`PidGains` (replaceable later through :attr:`gains`, as setGains does, without
            resetting the state).

    It runs every physics step for each effort joint, so a computation allocates nothing but the tuple of its
    terms; :attr:`terms` makes the :class:`PidTerms` from it when asked (a PidState publisher).
    """

    def __init__(self, gains: PidGains):
        self.gains = gains
        self._p_error_last = 0.0
        self._valid_p_error_last = True
        self._i_error = 0.0
        self._d_error = 0.0
        self._last = None  # the last computation's terms as a tuple (see ``terms``), None: ``_terms`` holds them
        self._terms = PidTerms()
        self.reset()

    @property
    def terms(self):
        """The state of the last computation (or of the last ``reset``): :class:`PidTerms`."""
        if self._last is not None:
            dt, error, error_dot, i_error, p_term, i_term, d_term, i_max, i_min, output = self._last
            self._terms = PidTerms(timestep=dt, error=error, error_dot=error_dot, p_error=error, i_error=i_error,
                                   d_error=error_dot, p_term=p_term, i_term=i_term, d_term=d_term, i_max=i_max,
                                   i_min=i_min, output=output)
            self._last = None
        return self._terms

    def reset(self):
        """Forget the integral and the last error; the next call's derivative is measured from error 0
        (upstream's ``reset()`` marks the zeroed last error valid)."""
        self._p_error_last = 0.0
        self._i_error = 0.0
        self._d_error = 0.0
        self._valid_p_error_last = True
        self._last = None
        self._terms = PidTerms(i_max=self.gains.i_clamp_max, i_min=self.gains.i_clamp_min)

    def compute(self, error, dt, error_dot=None):
        """The command for ``error`` over the step ``dt`` (s).

        ``error_dot`` None: the derivative is ``(error - last error) / dt`` (``computeCommand(error, dt)``);
        otherwise the given error rate is used (``computeCommand(error, error_dot, dt)``, e.g. a velocity
        error in joint_trajectory_controller). ``dt == 0`` or a non-finite error returns 0.
        """
        if error_dot is None:
            if dt == 0 or not _isfinite(error):
                return 0.0
            error_dot = self._d_error
            if dt > 0:
                if self._valid_p_error_last:
                    error_dot = (error - self._p_error_last) / dt
                self._p_error_last = error
                self._valid_p_error_last = True
        # computeCommand(error, error_dot, dt): upstream stores the errors before its validity check
        gains = self.gains
        self._d_error = error_dot
        if dt == 0 or not _isfinite(error) or not _isfinite(error_dot):
            return 0.0

        p_term = gains.p * error
        i_error = self._i_error + dt * error
        i_min, i_max = gains.i_clamp_min, gains.i_clamp_max
        if gains.antiwindup:
            if gains.i != 0:
                low, high = sorted((i_min / gains.i, i_max / gains.i))
                i_error = boost_clamp(i_error, low, high)
            i_term = gains.i * i_error
        else:
            i_term = gains.i * i_error
            if i_term < i_min:  # boost_clamp(i_term, i_min, i_max)
                i_term = i_min
            elif i_max < i_term:
                i_term = i_max
        self._i_error = i_error
        d_term = gains.d * error_dot
        output = p_term + i_term + d_term
        self._last = (dt, error, error_dot, i_error, p_term, i_term, d_term, i_max, i_min, output)
        return output


_isfinite = math.isfinite


#: Share of the stability bound an explicit loop may use before the simulator runs it as an implicit motor
#: instead (half: the discrete loop is then not only stable but settles without ringing).
STABILITY_MARGIN = 0.5


def explicit_loop_margin(gains: PidGains, dt, inertia, loop):
    """How much of its discrete stability bound a PID acting as an explicit force on ``inertia`` uses
    (< 1 stable, <= STABILITY_MARGIN well damped), at a step of ``dt`` s.

    Why: gains tuned for Gazebo's 1 ms step on tiny links (p = 300 on an OpenMANIPULATOR joint) diverge at a
    4 ms step. With the force applied for a whole step and semi-implicit Euler integration,

    * a velocity loop (``loop`` "velocity": force = P (v* - v)) is stable while ``b = P dt / I < 2``;
    * a position loop (``loop`` "position": force = P e + D de/dt) has the characteristic polynomial
      ``z^2 - (2 - a - b) z + (1 - b)`` with ``a = P dt^2 / I`` and ``b = D dt / I``: stable while
      ``b < 2`` and ``a + 2 b < 4``. Without a damping term (``D = 0``, a P-only effort gain) both roots lie
      on the unit circle whatever ``a``: nothing damps the loop but friction and the joint's limits, so it is
      never rated stable (at least 1).

    ``inertia`` is what the joint really moves (``Robot.joint_inertias``: the whole chain beyond it, with a
    free base's freedom). Returns the larger ratio of a quantity to its bound (inf for a non-positive inertia).
    """
    if inertia <= 0:
        return math.inf
    if loop == "velocity":
        return abs(gains.p) * dt / inertia / 2.0
    a = abs(gains.p) * dt * dt / inertia
    b = abs(gains.d) * dt / inertia
    margin = max(b / 2.0, (a + 2.0 * b) / 4.0)
    return max(margin, 1.0) if gains.d == 0 and gains.p != 0 else margin


def loop_verdict(gains: PidGains, margin, loop):
    """The words a warning uses for an explicit loop that is not well damped: "an undamped" (a position loop
    without a damping term), "an unstable" (beyond its bound) or "a ringing" (stable, but over
    STABILITY_MARGIN)."""
    if loop == "position" and gains.d == 0 and gains.p != 0:
        return "an undamped"
    return "an unstable" if margin >= 1 else "a ringing"
