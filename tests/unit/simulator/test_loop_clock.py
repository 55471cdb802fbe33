"""Simulator's /clock: at ~clock_rate of sim time, but never more often than ~clock_max_wall_rate per wall second
(ticks closer in wall time are coalesced into the next); a start, pause or reset always publishes (no master, no
loop: the methods run on a stand-in that records what was published)."""
import math

import rospy

from diffbot_sim.simulator.loop import Simulator


class ClockPub:
    def __init__(self):
        self.sent = []

    def get_num_connections(self):
        return 1

    def publish(self, msg):
        self.sent.append(msg.clock.to_sec())


class Msg:
    clock = None


class Loop:
    """What _publish_clock reads and writes: sim time, the schedule and the wall-time floor."""

    def __init__(self, clock_rate=100.0, max_wall_rate=500.0):
        self.clock_pub = ClockPub()
        self._clock_msg = Msg()
        self.owns_clock = False
        self.clock_period = 1.0 / clock_rate
        self.next_clock = 0.0
        self.clock_min_gap = 1.0 / max_wall_rate if max_wall_rate > 0 else 0.0
        self._clock_wall = -math.inf
        self._clock_coalesced = False
        self.now = 0.0

    def stamp(self):
        return rospy.Time.from_sec(self.now)

    def _send_clock(self, wall=None):
        return Simulator._send_clock(self, wall)

    def tick(self, now, wall):
        """A step at sim time ``now``, wall time ``wall``: what the loop does with /clock."""
        self.now = now
        if now + 1e-9 >= self.next_clock:
            return Simulator._publish_clock(self, now, wall)
        return False


def run(loop, rtf, sim_seconds, dt=0.01):
    """Ticks every ``dt`` of sim time with the wall clock going at 1/``rtf`` of it."""
    for k in range(1, round(sim_seconds / dt) + 1):
        loop.tick(k * dt, k * dt / rtf)


def test_below_the_cap_every_tick_is_published():
    loop = Loop(clock_rate=100.0, max_wall_rate=500.0)
    run(loop, rtf=4.0, sim_seconds=1.0)  # 400 ticks a wall second: under 500
    assert len(loop.clock_pub.sent) == 100
    assert loop.clock_pub.sent[:3] == [0.01, 0.02, 0.03]


def test_far_above_real_time_ticks_are_coalesced_to_the_wall_cap():
    loop = Loop(clock_rate=100.0, max_wall_rate=500.0)
    run(loop, rtf=50.0, sim_seconds=10.0)  # 5,000 ticks a wall second asked for, 0.2 s of wall time
    sent = loop.clock_pub.sent
    assert 95 <= len(sent) <= 101  # 500 a wall second
    assert all(b > a for a, b in zip(sent, sent[1:]))  # still monotonic, each carrying the newer time
    assert abs(sent[-1] - 10.0) <= 0.1 + 1e-9
    assert loop._clock_coalesced or sent[-1] == 10.0


def test_no_cap_publishes_every_tick():
    loop = Loop(clock_rate=100.0, max_wall_rate=0.0)
    run(loop, rtf=50.0, sim_seconds=1.0)
    assert len(loop.clock_pub.sent) == 100


def test_a_forced_clock_is_published_whatever_the_wall_gap_and_keeps_the_schedule():
    loop = Loop(clock_rate=100.0, max_wall_rate=500.0)
    loop.tick(0.01, 0.0)
    assert not loop.tick(0.02, 0.0001)  # too soon: coalesced
    assert loop._clock_coalesced
    due = loop.next_clock
    loop.now = 0.025
    assert Simulator._send_clock(loop)  # data to waited-for nodes goes with a current clock
    assert loop.clock_pub.sent == [0.01, 0.025] and not loop._clock_coalesced
    assert loop.next_clock == due  # the tick schedule is unchanged
    Simulator._publish_clock(loop, 0.0)  # a reset or a pause: no wall given, always sent
    assert loop.clock_pub.sent[-1] == 0.025
