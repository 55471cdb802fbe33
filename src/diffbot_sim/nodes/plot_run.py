"""``rosrun diffbot_sim plot_run <run.bag | --live SECONDS> [-o run.png]``: a picture of a run.

Three panels: the odometry trajectory against ground truth (and the last laser scan, in the odometry
frame), commanded against measured linear speed, and the same for the turn rate, over sim time. What is
read and how frames are joined is :mod:`diffbot_sim.view.plot_data`; this module reads the bag (rosbag's Python
API) or listens live, and draws with matplotlib's Agg backend (no display needed).

Record a run with ground truth, for example:
    roslaunch diffbot_sim view.launch publish_ground_truth:=true
    rosbag record -O run.bag /odom /bullet_sim/ground_truth /cmd_vel /scan /tf /tf_static
    rosrun diffbot_sim plot_run run.bag            # writes run.png

``--live SECONDS`` subscribes to ``/odom``, ``/bullet_sim/ground_truth``, ``/cmd_vel``, ``/scan``, ``/tf``
and ``/tf_static`` for that many sim seconds instead (``--odom``, ``--truth``, ``--cmd``, ``--scan`` rename
them). Exit status 1 with one line for a missing or unreadable bag or a run without odometry; 2 on bad usage.
"""
import argparse
import os
import sys
import threading
import time

from diffbot_sim import streams
from diffbot_sim.nodes._entry import entry_point
from diffbot_sim.view import plot_data


def parse_argv(argv):
    parser = argparse.ArgumentParser(prog="plot_run", description="a PNG of a run: trajectory, speeds, scan")
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("bag", nargs="?", help="a bag with Odometry, Twist, LaserScan and TF messages")
    source.add_argument("--live", type=float, metavar="SECONDS", help="listen this many sim seconds instead")
    parser.add_argument("-o", "--output", help="the PNG (default: the bag's name with .png, or run.png)")
    parser.add_argument("--odom", default="/odom")
    parser.add_argument("--truth", default="/bullet_sim/ground_truth")
    parser.add_argument("--cmd", default="/cmd_vel")
    parser.add_argument("--scan", default="/scan")
    return parser.parse_args(argv)


def read_bag(path):
    """Every message of the bag at ``path`` as ``(topic, message, t)`` (t: record time, s)."""
    import rosbag

    with rosbag.Bag(path) as bag:
        return [(topic, msg, t.to_sec()) for topic, msg, t in bag.read_messages()]


def listen(options):
    """Subscribe for ``options.live`` sim seconds; the records, as read_bag gives them."""
    import rospy
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import LaserScan
    from tf2_msgs.msg import TFMessage

    rospy.init_node("plot_run", anonymous=True)
    records, lock = [], threading.Lock()

    def keep(msg, topic):
        with lock:
            records.append((topic, msg, rospy.get_time()))
    subs = [rospy.Subscriber(topic, kind, keep, callback_args=topic, queue_size=1000)
            for topic, kind in ((options.odom, Odometry), (options.truth, Odometry), (options.cmd, Twist),
                                (options.scan, LaserScan), ("/tf", TFMessage), ("/tf_static", TFMessage))]
    streams.write(sys.stdout, f"plot_run: listening for {options.live:g} s of sim time...\n")
    start = None
    while not rospy.is_shutdown():
        now = rospy.get_time()
        if start is None and now > 0:
            start = now
        if start is not None and now - start >= options.live:
            break
        time.sleep(0.05)
    for sub in subs:
        sub.unregister()
    with lock:
        return list(records)


def plot(data, path, title=""):
    """Draw ``data`` (plot_data.RunData) into the PNG at ``path``; returns what was drawn (for tests and
    for the summary line): ``{"odom": (N, 2), "truth": (M, 2), "truth_how": str, "scan": (K, 2) or None,
    "summary": Summary}``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    truth, how = plot_data.truth_in_odom(data)
    scan = plot_data.scan_in_odom(data)
    summary = plot_data.summarize(data)
    fig = plt.figure(figsize=(10, 5.2), dpi=80)
    grid = fig.add_gridspec(2, 2, width_ratios=(1.1, 1.0))
    ax = fig.add_subplot(grid[:, 0])
    if scan is not None and len(scan):
        ax.scatter(scan[:, 0], scan[:, 1], s=4, c="tab:green", label="last scan")
    if len(truth):
        ax.plot(truth[:, 0], truth[:, 1], "k-", lw=3, alpha=0.35, label=f"ground truth ({how})")
    if len(data.odom):
        ax.plot(data.odom[:, 1], data.odom[:, 2], "r-", lw=1.2, label="odometry")
        ax.plot(data.odom[-1, 1], data.odom[-1, 2], "ro", ms=5)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"x [m] ({data.odom_frame})")
    ax.set_ylabel("y [m]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    t0 = min([a[0, 0] for a in (data.odom, data.truth, data.cmd) if len(a)] or [0.0])
    for row, (col, unit, label) in enumerate(((4, "m/s", "linear x"), (5, "rad/s", "angular z"))):
        sp = fig.add_subplot(grid[row, 1])
        if len(data.cmd):
            sp.step(data.cmd[:, 0] - t0, data.cmd[:, 1 + row], where="post", color="tab:blue", label="cmd_vel")
        if len(data.odom):
            sp.plot(data.odom[:, 0] - t0, data.odom[:, col], color="tab:red", lw=1, label="odometry")
        if len(data.truth):
            sp.plot(data.truth[:, 0] - t0, data.truth[:, col], color="k", lw=2, alpha=0.3, label="ground truth")
        sp.set_ylabel(f"{label} [{unit}]")
        sp.grid(True, alpha=0.3)
        if row == 1:
            sp.set_xlabel("sim time [s]")
        else:
            sp.legend(loc="best", fontsize=8)
    line = f"{summary.samples} samples, {summary.duration:.1f} s, {summary.distance:.2f} m driven"
    if summary.final_error is not None:
        line += f", final odometry error {summary.final_error * 100:.1f} cm"
    fig.suptitle((title + ": " if title else "") + line, fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return {"odom": data.odom[:, 1:3], "truth": truth, "truth_how": how, "scan": scan, "summary": summary}


@entry_point
def main(argv=None):
    """Entry point of ``rosrun diffbot_sim plot_run``."""
    import rospy

    argv = rospy.myargv(sys.argv[1:] if argv is None else argv)
    options = parse_argv(argv)
    if options.bag is not None:
        if not os.path.isfile(options.bag):
            streams.write(sys.stderr, f"plot_run: {options.bag}: no such file\n")
            return 1
        try:
            records = read_bag(options.bag)
        except Exception as err:  # rosbag raises ROSBagException, ValueError, struct.error... for a bad file
            streams.write(sys.stderr, f"plot_run: {options.bag}: not a readable bag ({err})\n")
            return 1
        output = options.output or os.path.splitext(options.bag)[0] + ".png"
        title = os.path.basename(options.bag)
    else:
        records = listen(options)
        output = options.output or "run.png"
        title = f"live, {options.live:g} s"
    try:
        data = plot_data.collect(records)
    except ValueError as err:
        streams.write(sys.stderr, f"plot_run: {title}: {err}\n")
        return 1
    drawn = plot(data, output, title)
    s = drawn["summary"]
    streams.write(sys.stdout, f"plot_run: {output}: {s.samples} odometry samples over {s.duration:.1f} s, "
                  f"{s.distance:.2f} m; scan {'drawn' if drawn['scan'] is not None else 'none'}\n")
    return 0
