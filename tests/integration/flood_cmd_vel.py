#!/usr/bin/env python3
"""Helper process of slow_flood.test (not a test itself): floods /cmd_vel with geometry_msgs/Twist.

    flood_cmd_vel.py ID RATE DURATION   (started by test_flood.py, one process per publisher)

Registers as ``/flood_<ID>``, waits until the simulator's /cmd_vel subscriber is connected, prints ``READY``
and waits for a line on standard input (so that every flooder starts at the same moment). It then
publishes for DURATION wall seconds, paced to RATE messages per second (or as fast as it can, if that is
less), and prints one JSON line with what it achieved.

The publisher is synchronous (``queue_size=None``): ``publish()`` returns once the bytes are in the socket,
so the count is what went on the wire, not what a queue dropped. Each Twist says who sent it and when:
``linear.x = 0.2 + 0.01 * ID`` and ``angular.z = seq * 1e-7`` (seq = 1, 2, ...), so the test can check on
``~debug/cmd_applied`` that a command applied later is never older than one applied earlier.
"""
import json
import sys
import time
import warnings

import rospy
from geometry_msgs.msg import Twist

SEQ_SCALE = 1e-7


def linear_of(ident):
    return 0.2 + 0.01 * ident


def main():
    ident, rate, duration = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
    rospy.init_node(f"flood_{ident}", disable_signals=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SyntaxWarning)  # rospy warns on queue_size=None, which we mean
        pub = rospy.Publisher("/cmd_vel", Twist, queue_size=None)
    deadline = time.monotonic() + 60.0
    while pub.get_num_connections() == 0:
        if time.monotonic() > deadline:
            print(json.dumps({"id": ident, "error": "no subscriber on /cmd_vel within 60 s"}), flush=True)
            return 1
        time.sleep(0.01)
    print("READY", flush=True)
    if not sys.stdin.readline():
        return 1
    period = 1.0 / rate
    linear = linear_of(ident)
    sent = 0
    behind = 0  # slots we were late for (the machine could not keep the rate)
    start = time.monotonic()
    end = start + duration
    due = start
    now = start
    while now < end:
        msg = Twist()  # a fresh message per publish (never refill one after publish)
        sent += 1
        msg.linear.x = linear
        msg.angular.z = sent * SEQ_SCALE
        pub.publish(msg)
        due += period
        now = time.monotonic()
        if due > now:
            time.sleep(due - now)
            now = time.monotonic()
        elif now - due > period:
            behind += 1
            due = now  # do not burst to catch up: the target is a rate, not a count
    elapsed = now - start
    print(json.dumps({"id": ident, "sent": sent, "seconds": elapsed, "rate": sent / elapsed,
                      "late_slots": behind, "last_seq": sent}), flush=True)
    rospy.signal_shutdown("done")
    return 0


if __name__ == "__main__":
    sys.exit(main())
