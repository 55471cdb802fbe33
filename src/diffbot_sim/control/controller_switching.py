"""controller_manager's rules for loading, switching and unloading controllers (pure: no rospy).

ROS 1 ``controller_manager`` (ros_control, noetic) semantics, which the user's ``spawner`` relies on:

* a name loads once ("already loaded"); loading needs ``<manager ns>/<name>/type`` on the parameter server;
* ``switch_controller`` stops, then starts. With ``strictness`` STRICT (2) any unknown name, a start of a
  running controller or a stop of a stopped one fails the whole request and nothing changes; with
  BEST_EFFORT (1) those names are skipped. Strictness 0 means BEST_EFFORT, as in controller_manager;
* two running controllers may not claim one joint (a resource conflict fails the request either way);
* a running controller cannot be unloaded.
"""

BEST_EFFORT = 1
STRICT = 2


class SwitchError(ValueError):
    """A request the controller manager refuses; the message is what it would log."""


def plan_switch(loaded, running, claims, start, stop, strictness):
    """What a SwitchController request does.

    Args:
        loaded: names of loaded controllers.
        running: names of running controllers (a subset of ``loaded``).
        claims: {controller name: set of joints it commands}.
        start, stop: the request's lists. strictness: 0, BEST_EFFORT or STRICT.

    Returns:
        (to_stop, to_start): lists, in request order.

    Raises:
        SwitchError: a STRICT request naming an unknown, already running or not running controller, or any
            request that would leave two running controllers commanding one joint.
    """
    strict = strictness == STRICT
    to_stop, to_start = [], []
    for name in stop:
        if name not in loaded:
            if strict:
                raise SwitchError(f"Could not stop controller with name '{name}' because no controller with "
                                  "this name exists")
        elif name not in running:
            if strict:
                raise SwitchError(f"Could not stop controller with name '{name}' because it is not running")
        elif name not in to_stop:
            to_stop.append(name)
    for name in start:
        if name not in loaded:
            if strict:
                raise SwitchError(f"Could not start controller with name '{name}' because no controller with "
                                  "this name exists")
        elif name in running and name not in to_stop:
            if strict:
                raise SwitchError(f"Could not start controller with name '{name}' because it is already running")
        elif name not in to_start:
            to_start.append(name)
    after = [n for n in running if n not in to_stop] + to_start
    owner = {}
    for name in after:
        for joint in sorted(claims.get(name, ())):
            if joint in owner:
                raise SwitchError(f"Resource conflict: controllers '{owner[joint]}' and '{name}' both claim "
                                  f"joint '{joint}'")
            owner[joint] = name
    return to_stop, to_start


def check_unload(name, loaded, running):
    """Raise SwitchError when ``name`` cannot be unloaded (unknown or running)."""
    if name not in loaded:
        raise SwitchError(f"Could not unload controller with name '{name}' because no controller with this "
                          "name exists")
    if name in running:
        raise SwitchError(f"Could not unload controller with name '{name}' because it is still running")


def check_load(name, loaded, params, known_types):
    """The controller type to build for ``name``, or SwitchError saying why it cannot be loaded.

    Args:
        params: the controller's parameter dict from ``<manager ns>/<name>`` (None when absent).
        known_types: the types this simulator runs.
    """
    if name in loaded:
        raise SwitchError(f"A controller named '{name}' was already loaded inside the controller manager")
    if not isinstance(params, dict) or "type" not in params:
        raise SwitchError(f"Could not load controller '{name}' because the type was not specified. Did you "
                          "load the controller configuration on the parameter server?")
    kind = params["type"]
    if kind not in known_types:
        raise SwitchError(f"Could not load controller '{name}' because controller type '{kind}' does not "
                          f"exist here (simulated types: {', '.join(sorted(known_types))})")
    return kind
