"""Item ``sensors``: a robot with a 360-beam laser at 5 Hz and an IMU at 100 Hz, both subscribed (with /odom and
/tf), in worlds/room.world: fast-mode RTF (median of 3) and real-time simulator CPU (30 s). Cameras:
tools/camera_speed.py."""
import os

from benchkit.common import RESULTS, ROBOTS, ROOT
from benchkit.launching import Launch, sim_args, subscriber
from benchkit.report import Item
from benchkit.stats import median_trial


def sensor_robot():
    """tests/data/robots/laser_robot.urdf with its IMU given libgazebo_ros_imu_sensor.so at 100 Hz."""
    with open(os.path.join(ROBOTS, "laser_robot.urdf")) as f:
        text = f.read()
    plain = '<sensor type="imu" name="imu"><always_on>true</always_on><update_rate>100</update_rate></sensor>'
    if plain not in text:
        raise RuntimeError("laser_robot.urdf changed: its plugin-less imu sensor is gone")
    text = text.replace(plain, plain.replace("</sensor>", '<plugin name="imu_plugin" filename="libgazebo_ros_imu_sensor'
                                             '.so"><topicName>imu</topicName><frameName>imu_link</frameName>'
                                             "<updateRateHZ>100.0</updateRateHZ></plugin></sensor>"))
    os.makedirs(RESULTS, exist_ok=True)
    path = os.path.join(RESULTS, "sensor_robot.urdf")
    with open(path, "w") as f:
        f.write(text)
    return path


def sensors(runs, seconds, realtime_seconds):
    """Laser (360 beams, 5 Hz) + IMU (100 Hz), both subscribed, in the example world."""
    model, world = sensor_robot(), os.path.join(ROOT, "worlds", "room.world")
    args = (f"model:={model}", f"world:={world}", "robot_state_publisher:=false", "x:=-1.0")
    topics = ["/scan", "/imu", "/odom", "/tf"]
    trials = []
    for _ in range(runs):
        with Launch(sim_args("real_time:=false", *args), "sensors_fast") as launch:
            for topic in topics:
                subscriber(launch, [topic])
            trial = launch.probe("rtf", seconds=seconds, warmup=3.0, leave=True)
            trial["subscriber_messages"] = launch.subscriber_messages()
        trials.append(trial)
    with Launch(sim_args(*args), "sensors_realtime") as launch:
        for topic in topics:
            subscriber(launch, [topic])
        realtime = launch.probe("rtf", seconds=realtime_seconds, warmup=3.0, timeout=realtime_seconds + 120)
    return {"fast": median_trial(trials), "realtime": realtime}


def rows(r):
    if not r.get("sensors"):
        return []
    se = r["sensors"]
    return [("fast-mode RTF, laser 360 beams @5 Hz + IMU @100 Hz subscribed, room.world", f"{se['fast']['rtf']:.1f}",
             ">= 30"),
            ("  the same in real time: simulator CPU", f"{se['realtime']['cpu_percent']:.1f} % of a core", "<= 15 %")]


ITEMS = [Item("sensors", lambda q: sensors(1 if q else 3, 4 if q else 10, 10 if q else 30), rows)]
PROBES = {}
