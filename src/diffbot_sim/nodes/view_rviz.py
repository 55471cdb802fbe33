"""``rosrun diffbot_sim view_rviz [--view top|3d] [--template FILE] [--config FILE]``: rviz for this run.

``view.launch`` starts this instead of ``rviz`` directly because no fixed rviz file fits every robot (see
:mod:`diffbot_sim.view.rviz_config`). It waits until the simulator has loaded its robots (their effective
parameters appear on the parameter server), asks the master which LaserScan and Image topics the simulator
publishes, reads the world file for the view's extent, writes the config to
``$ROS_HOME/diffbot_sim/view.rviz`` and then *becomes* rviz (``exec``): the process roslaunch watches, the
node ``/rviz`` and its windows are Debian's rviz 1.14 itself, unchanged.

Options:
    ``--view top|3d``: top-down orthographic (default) or orbit view.
    ``--template FILE``: the config to start from (default: the package's ``rviz/diffbot.rviz``).
    ``--config FILE``: skip all of the above and open this config as it is (your own saved view).
    ``--sim NAME``: the simulator node (default ``/bullet_sim``).
    ``--timeout S``: wall seconds to wait for the simulator (default 60).
Arguments of the form ``name:=value`` (roslaunch's ``__name:=``, ``__log:=``, remappings) go to rviz.

Exit status 1 with one line when the simulator never reports or a file cannot be read; otherwise the
status is rviz's.
"""
import argparse
import os
import sys

from diffbot_sim import streams
from diffbot_sim.errors import DiffbotSimError
from diffbot_sim.view import rviz_config
from diffbot_sim.waiting import wait_for


def default_template():
    """The package's ``rviz/diffbot.rviz``, found as roslaunch finds package files (rospkg): in a source
    checkout and in an install space alike, where this module lives far from the package's share folder."""
    import rospkg

    try:
        return os.path.join(rospkg.RosPack().get_path("diffbot_sim"), "rviz", "diffbot.rviz")
    except rospkg.ResourceNotFound:
        return os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
            os.path.realpath(__file__))))), "rviz", "diffbot.rviz")


def parse_argv(argv):
    """``(options, passthrough)``: our options, and the ``name:=value`` arguments meant for rviz."""
    passthrough = [a for a in argv if ":=" in a]
    parser = argparse.ArgumentParser(prog="view_rviz", description="rviz for the running simulator")
    parser.add_argument("--view", choices=rviz_config.VIEWS, default="top")
    parser.add_argument("--template", default=None, help="default: the package's rviz/diffbot.rviz")
    parser.add_argument("--config", default="")
    parser.add_argument("--sim", default="/bullet_sim")
    parser.add_argument("--timeout", type=float, default=60.0)
    return parser.parse_args([a for a in argv if ":=" not in a]), passthrough


def _param(master, name, default=None):
    try:
        return master.getParam(name)
    except Exception:  # rosgraph.MasterError (unset) or the master not up yet: both mean "not yet"
        return default


def _wait_param(master, name, timeout):
    """The parameter ``name`` once it exists (an empty value counts), through ``waiting.wait_for``."""
    def present():
        value = _param(master, name)
        return None if value is None else [value]
    return wait_for(present, timeout, f"parameter {name}", 0.2, error=lambda message: DiffbotSimError(
        f"view_rviz: {message}: the simulator did not report its robots (is bullet_sim running?)"))[0]


def robot_views(master, sim, timeout):
    """A :class:`rviz_config.RobotView` per robot of the simulator at ``sim``, from its effective
    parameters and the topics it publishes."""
    from diffbot_sim.world.loading import robot_namespaces

    entries = _param(master, sim + "/robots")
    names = robot_namespaces(entries)
    privates = [f"{sim}/{name}/" if name else f"{sim}/" for name in names]
    for private in privates:
        _wait_param(master, private + "odom_topic", timeout)
    state = master.getSystemState()
    types = dict(master.getTopicTypes())
    published = [(topic, types.get(topic, "")) for topic, nodes in state[0] if sim in nodes]
    views = []
    for i, (name, private) in enumerate(zip(names, privates)):
        namespace = _param(master, private + "namespace", "") if name else ""
        frame = _param(master, private + "odometry_frame", "odom")
        scans, images = rviz_config.sensor_topics(published, namespace)
        spawn = rviz_config.spawn_of(entries[i]) if entries else (float(_param(master, sim + "/x", 0.0)),
                                                                  float(_param(master, sim + "/y", 0.0)))
        description = rviz_config.description_param(namespace, lambda p: _param(master, p) is not None)
        views.append(rviz_config.RobotView(name, rviz_config.prefix_of(frame), description,
                                           _param(master, private + "odom_topic"), frame, scans, images,
                                           spawn))
    return views, _param(master, privates[0] + "odometry_source", "world")


def world_bounds(sim):
    """The world's static geometry extent in the world frame, or None without a world."""
    import rospy

    from diffbot_sim.world.loading import simulator_world
    from diffbot_sim.world.markers import bounds_xy, marker_specs

    world = simulator_world(sim, rospy.get_param)
    return bounds_xy(marker_specs(world)) if world is not None else None


def main(argv=None):
    """Entry point of ``rosrun diffbot_sim view_rviz``."""
    argv = sys.argv[1:] if argv is None else argv
    try:
        path, passthrough = _prepare(argv)
    except (DiffbotSimError, OSError, ValueError) as err:
        streams.write(sys.stderr, f"{err}\n")
        streams.finish()
        return 1
    streams.finish()
    os.execvp("rviz", ["rviz", "-d", path, "--splash-screen", ""] + passthrough)
    return 1  # not reached: exec replaced this process


def _prepare(argv):
    import rosgraph

    options, passthrough = parse_argv(argv)
    if options.config:
        if not os.path.isfile(options.config):
            raise DiffbotSimError(f"view_rviz: --config {options.config}: no such file")
        return options.config, passthrough
    sim = options.sim.rstrip("/")
    master = rosgraph.Master("/view_rviz")
    robots, source = robot_views(master, sim, options.timeout)
    bounds = world_bounds(sim)
    if bounds is not None and source == "encoder":
        # Encoder odometry starts at 0 at the spawn pose: the world sits shifted by it in the fixed frame.
        sx, sy = robots[0].spawn
        bounds = (bounds[0] - sx, bounds[1] - sy, bounds[2] - sx, bounds[3] - sy)
        for robot in robots:
            robot.spawn = (robot.spawn[0] - sx, robot.spawn[1] - sy)
    try:
        options.template = options.template or default_template()
        template = rviz_config.load_template(options.template)
    except Exception as err:  # yaml.YAMLError or OSError: either way the file is unusable
        raise DiffbotSimError(f"view_rviz: --template {options.template}: {err}") from None
    config = rviz_config.build(template, robots, bounds, options.view)
    home = os.environ.get("ROS_HOME") or os.path.join(os.path.expanduser("~"), ".ros")
    out_dir = os.path.join(home, "diffbot_sim")
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, "view.rviz")
    with open(path + ".tmp", "w") as f:
        f.write(rviz_config.dump(config))
    os.replace(path + ".tmp", path)
    streams.write(sys.stdout, f"view_rviz: {path}: fixed frame {robots[0].odom_frame}, "
                  + "; ".join(f"{r.name or 'robot'}: scans {r.scans or 'none'}, images {r.images or 'none'}"
                              for r in robots) + "\n")
    return path, passthrough
