"""The ROS-side measurements the items share. Each runs in its own process (``bench.py --probe KIND``), as one
ROS node against the launch's master, and prints one JSON line; rospy is imported there only."""
import json
import os
import signal
import statistics
import time

from benchkit.common import CIRCLE
from benchkit.stats import percentile
from diffbot_sim.waiting import wait_for


def sim_pid(node="/bullet_sim"):
    """The pid of the simulator node (``/bullet_sim``; ``/gazebo`` when empty_world.launch started it), asked
    through its XML-RPC API."""
    import xmlrpc.client

    import rosnode
    uri = rosnode.get_api_uri(rosnode.rosgraph.Master("/bench"), node, skip_cache=True)
    return xmlrpc.client.ServerProxy(uri).getPid("/bench")[2]


def cpu_seconds(pid):
    """utime + stime of process ``pid`` [s], from /proc."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def probe_count(options):
    """Subscribe (AnyMsg: no deserialisation, like `rostopic hz`) and print the count on SIGINT."""
    import rospy
    rospy.init_node("bench_sub", anonymous=True, disable_signals=True)
    counts = {topic: 0 for topic in options["topics"]}

    def keep(_msg, topic):
        counts[topic] += 1
    subs = [rospy.Subscriber(t, rospy.AnyMsg, keep, callback_args=t, queue_size=100) for t in counts]
    stop = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))
    while not stop:
        time.sleep(0.05)
    for sub in subs:
        sub.unregister()
    print(json.dumps(counts), flush=True)


def probe_rtf(options):
    """RTF from /clock over a window after a warm-up; simulator CPU; /odom receipt-period percentiles.

    Options: ``seconds`` (the window), ``warmup``, ``namespaces`` or ``cmd_topics`` (whom to drive in the
    circle), ``leave`` (close the command publishers after the warm-up), ``odom_jitter`` (and ``odom``)."""
    import rospy
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from rosgraph_msgs.msg import Clock
    if not rospy.core.is_initialized():  # a probe that set up its scenario first (the arm's) already is
        rospy.init_node("bench_rtf", disable_signals=True)
    clock, odom = [], []
    rospy.Subscriber("/clock", Clock, lambda m: clock.append((time.monotonic(), m.clock.to_sec())),
                     queue_size=1000)
    if options.get("odom_jitter"):
        rospy.Subscriber(options.get("odom", "/odom"), Odometry,
                         lambda m: odom.append((time.monotonic(), m.header.stamp.to_sec())), queue_size=1000)
    wait_for(lambda: len(clock) > 2, 60, "/clock")
    topics = options.get("cmd_topics") or [f"{ns}/cmd_vel" for ns in options.get("namespaces", [""])]
    pubs = [rospy.Publisher(topic, Twist, queue_size=1, latch=True) for topic in topics]
    circle = Twist()
    circle.linear.x, circle.angular.z = CIRCLE
    for pub in pubs:  # drive in circles: wheels, casters and contacts all busy
        pub.publish(circle)
    time.sleep(options.get("warmup", 3.0))
    if options.get("leave"):
        # Fast mode waits after each /clock tick for the nodes that publish its commands (~wait_for_nodes):
        # with its publishers kept, this probe would be measured, not the simulator. The simulator holds the
        # last command (cmd_vel_timeout 0, as Gazebo), so the robot keeps driving its circle.
        for pub in pubs:
            pub.unregister()
        time.sleep(1.0)
    pid = sim_pid(options.get("sim_node", "/bullet_sim"))
    cpu0, n0 = cpu_seconds(pid), len(clock)
    time.sleep(options["seconds"])
    cpu1, n1 = cpu_seconds(pid), len(clock)
    (w0, s0), (w1, s1) = clock[n0 - 1], clock[n1 - 1]
    result = {"rtf": (s1 - s0) / (w1 - w0), "cpu_percent": 100.0 * (cpu1 - cpu0) / (w1 - w0),
              "wall_s": w1 - w0, "sim_s": s1 - s0}
    if options.get("odom_jitter"):
        window = [(t, s) for t, s in odom if w0 <= t <= w1]
        periods = [1000.0 * (b[0] - a[0]) for a, b in zip(window, window[1:])]
        # Delivery jitter: how far each message's arrival strays from where its sim stamp puts it. The
        # stamps themselves alternate 8.33/12.5 ms (a 100 Hz rate on a 240 Hz step), which is not jitter.
        offsets = [t - s for t, s in window]
        middle = statistics.median(offsets)
        result.update({"odom_period_p50_ms": percentile(periods, 50), "odom_period_p99_ms": percentile(periods, 99),
                       "odom_jitter_p99_ms": percentile([1000.0 * abs(o - middle) for o in offsets], 99),
                       "odom_messages": len(window)})
    print(json.dumps(result), flush=True)


def probe_first_odom(options):
    """Wall time (epoch) of the first /odom message; started before the master exists."""
    import rosgraph
    master = rosgraph.Master("/bench_first_odom")
    wait_for(master.is_online, 60, "the master")
    import rospy
    from nav_msgs.msg import Odometry
    rospy.init_node("bench_first_odom", disable_signals=True)
    first = []
    rospy.Subscriber(options.get("odom", "/odom"), Odometry, lambda m: first or first.append(time.time()),
                     queue_size=1)
    wait_for(lambda: first, 60, "the first /odom")
    print(json.dumps({"first_odom_epoch": first[0]}), flush=True)


PROBES = {"count": probe_count, "rtf": probe_rtf, "first_odom": probe_first_odom}
