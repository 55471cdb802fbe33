"""Item ``world_api``: the ``/gazebo`` services of a simulator started as ``gazebo_ros empty_world.launch`` starts
it (real time, no robot): ``spawn_urdf_model`` called -> first odometry of the new robot (robots spawned one by
one), and ``set_model_state`` round trips through a persistent service connection."""
import json
import os
import statistics
import time

from benchkit.common import ROBOTS
from benchkit.launching import Launch
from benchkit.report import Item
from benchkit.stats import percentile

from diffbot_sim.waiting import wait_for


def probe_world_api(options):
    """Spawn latency (spawn_urdf_model call -> first odom of the new robot, wall) and set_model_state round
    trips, through the /gazebo services and gazebo_msgs' types, against a simulator started empty."""
    import rospy
    from gazebo_msgs.msg import ModelState
    from gazebo_msgs.srv import SetModelState, SpawnModel
    from geometry_msgs.msg import Pose, Twist
    from nav_msgs.msg import Odometry
    rospy.init_node("bench_world_api", disable_signals=True)
    rospy.wait_for_service("/gazebo/spawn_urdf_model", 60)
    spawn = rospy.ServiceProxy("/gazebo/spawn_urdf_model", SpawnModel, persistent=True)
    set_state = rospy.ServiceProxy("/gazebo/set_model_state", SetModelState, persistent=True)
    with open(options["model"]) as f:
        urdf = f.read()
    spawns = []
    for i in range(options["spawns"]):
        first = []
        sub = rospy.Subscriber(f"/b{i}/odom", Odometry, lambda m, first=first: first or first.append(time.time()),
                               queue_size=1)
        pose = Pose()
        pose.position.x, pose.position.y, pose.orientation.w = 2.0 * i, 0.0, 1.0
        t0 = time.time()
        resp = spawn(f"b{i}", urdf, f"/b{i}", pose, "world")
        if not resp.success:
            raise RuntimeError(resp.status_message)
        wait_for(lambda first=first: first, 30, f"the first /b{i}/odom")
        spawns.append(first[0] - t0)
        sub.unregister()
    trips = []
    for i in range(options["round_trips"]):
        state = ModelState("b0", Pose(), Twist(), "world")
        state.pose.position.x, state.pose.position.y, state.pose.orientation.w = 0.0, 0.001 * (i % 100), 1.0
        t0 = time.perf_counter()
        resp = set_state(state)
        trips.append(1000.0 * (time.perf_counter() - t0))
        if not resp.success:
            raise RuntimeError(resp.status_message)
    print(json.dumps({"spawn_to_first_odom_s": spawns, "spawn_median_s": statistics.median(spawns),
                      "set_model_state_p50_ms": percentile(trips, 50), "set_model_state_p99_ms": percentile(trips, 99),
                      "round_trips": len(trips)}), flush=True)


def world_api(spawns, round_trips):
    """The simulator as empty_world.launch starts it (real time, no robot); robots spawned one by one."""
    with Launch(["gazebo_ros", "empty_world.launch", "gui:=false"], "world_api") as launch:
        return launch.probe("world_api", model=os.path.join(ROBOTS, "fixed_caster.urdf"), spawns=spawns,
                            round_trips=round_trips)


def rows(r):
    if not r.get("world_api"):
        return []
    w = r["world_api"]
    return [("spawn_urdf_model -> first odom of the robot (median)", f"{w['spawn_median_s']:.3f} s", "<= 0.5 s"),
            ("set_model_state round trip p50 / p99 (real time)",
             f"{w['set_model_state_p50_ms']:.2f} / {w['set_model_state_p99_ms']:.2f} ms", "<= 5 ms")]


ITEMS = [Item("world_api", lambda q: world_api(3 if q else 7, 100 if q else 1000), rows)]
PROBES = {"world_api": probe_world_api}
