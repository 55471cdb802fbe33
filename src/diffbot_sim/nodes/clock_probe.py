"""The sim time a batch run reached: subscribes ``/clock`` of the run's master (ROS_MASTER_URI) and keeps the
latest value in the file named by its argument (rewritten whole when it changed, checked 20 times a wall second,
and once more when ended). Started and ended by ``diffbot_sim.batch.run``; not a user's executable."""
import os
import signal
import sys
import threading

import rospy
from rosgraph_msgs.msg import Clock


def main(argv=None):
    path = (argv or sys.argv)[1]
    latest = [0.0]
    written = [None]
    lock = threading.Lock()

    def write():
        with lock:
            value = latest[0]
        if value == written[0]:
            return
        tmp = path + ".part"
        with open(tmp, "w") as f:
            f.write(f"{value:.6f}\n")
        os.replace(tmp, path)
        written[0] = value

    def on_clock(msg):
        with lock:
            latest[0] = max(latest[0], msg.clock.to_sec())

    done = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: done.set())
    rospy.init_node("batch_clock_probe", anonymous=True, disable_signals=True, disable_rosout=True)
    rospy.Subscriber("/clock", Clock, on_clock, queue_size=1)
    while not done.wait(0.05):
        write()
    write()
    # The file is written; the run's master ends with us. rospy's orderly shutdown (its XML-RPC server polls
    # every 0.5 s) would only add that much to every batch run, so leave at once.
    sys.stdout.flush()
    os._exit(0)


if __name__ == "__main__":
    main()
