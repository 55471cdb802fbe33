"""The loop's bookkeeping without a master: simulator.subscriber_links's SubscriberLinks (each connection tuned
once, corked batches in fast mode) and simulator.loop's RobotRuntime (what the loop asks a robot, answered from
its plugins)."""
import math
import socket

from diffbot_sim.simulator.loop import RobotRuntime
from diffbot_sim.simulator.subscriber_links import SubscriberLinks


class Sock:
    """A TCP socket as SubscriberLinks sees it: it records the options set on it."""

    def __init__(self, family=socket.AF_INET, broken=False):
        self.family, self.broken = family, broken
        self.timeouts, self.options = [], []

    def settimeout(self, value):
        if self.broken:
            raise OSError("closing")
        self.timeouts.append(value)

    def setsockopt(self, level, option, value):
        if self.broken:
            raise OSError("closing")
        self.options.append((option, value))

    def corks(self):
        return [value for option, value in self.options if option == socket.TCP_CORK]


class Conn:
    def __init__(self, sock):
        self.socket = sock


class Impl:
    def __init__(self, *socks):
        self.connections = [Conn(s) for s in socks]


class Pub:
    def __init__(self, *socks):
        self.impl = Impl(*socks)


def links_of(pubs, batch=0.002):
    return SubscriberLinks(lambda: pubs, send_timeout=0.5, batch=batch)


def test_each_new_connection_gets_its_timeout_and_nodelay_once():
    first, second = Sock(), Sock()
    pubs = [Pub(first)]
    links = links_of(pubs)
    links.tune_new(10.0)
    assert first.timeouts == [0.5] and first.options == [(socket.TCP_NODELAY, 1)]
    pubs[0].impl.connections.append(Conn(second))
    links.tune_new(10.05)  # within 0.1 s of the last scan: not looked at
    assert second.timeouts == []
    links.tune_new(10.1)
    assert first.timeouts == [0.5] and second.timeouts == [0.5]


def test_only_tcp_sockets_are_tuned_and_a_closing_one_is_skipped():
    unix, broken, tcp6 = Sock(socket.AF_UNIX), Sock(broken=True), Sock(socket.AF_INET6)
    gone = Pub()
    gone.impl = None
    pubs = [Pub(unix, broken, tcp6), gone, Pub(None)]
    links = links_of(pubs)
    links.tune_new(1.0)
    assert unix.timeouts == [] and tcp6.timeouts == [0.5]
    assert links._tuned == {broken, tcp6}


def test_a_batch_corks_the_scanned_sockets_until_it_is_due():
    sock = Sock()
    links = links_of([Pub(sock)], batch=0.002)
    links.tune_new(1.0)
    links.hold(1.0)
    assert sock.corks() == [1] and links.held_since == 1.0
    links.hold(1.001)  # the batch is open: not corked again
    links.release_if_due(1.0015)
    assert sock.corks() == [1] and links.held_since == 1.0
    links.release_if_due(1.002)
    assert sock.corks() == [1, 0] and links.held_since is None
    links.release()  # nothing held: nothing done
    assert sock.corks() == [1, 0]


def test_a_connection_newer_than_the_last_scan_is_not_corked():
    old, new = Sock(), Sock()
    pub = Pub(old)
    links = links_of([pub])
    links.tune_new(1.0)
    pub.impl.connections.append(Conn(new))
    links.hold(1.01)
    assert old.corks() == [1] and new.corks() == []
    links.release()
    assert old.corks() == [1, 0] and new.corks() == []


def test_real_time_mode_does_not_batch():
    sock = Sock()
    links = links_of([Pub(sock)], batch=0.0)
    links.tune_new(1.0)
    links.hold(1.0)
    assert links.held_since is None and sock.corks() == []


def test_a_closed_connection_leaves_the_scan():
    sock = Sock()
    pub = Pub(sock)
    links = links_of([pub])
    links.tune_new(1.0)
    pub.impl.connections.clear()
    links.tune_new(2.0)
    assert links._tuned == set()
    links.hold(2.0)
    assert sock.corks() == []


# -- RobotRuntime --------------------------------------------------------------------------------------------

class Plugin:
    def __init__(self, name, calls, due=math.inf, publish=math.inf, pubs=()):
        self.name, self.calls, self.due, self.publish, self.pubs = name, calls, due, publish, list(pubs)

    def publishers(self):
        return self.pubs

    def next_control(self):
        return self.due

    def next_publish(self):
        return self.publish

    def before_step(self, now):
        self.calls.append((self.name, "before", now))

    def after_step(self, now, stamp, transforms):
        self.calls.append((self.name, "after", now))
        transforms.append(self.name)

    def reset(self, now):
        self.calls.append((self.name, "reset", now))

    def start(self, now):
        self.calls.append((self.name, "start", now))

    def close(self):
        self.calls.append((self.name, "close", None))


class Context:
    closed = False

    def close(self):
        self.closed = True


def test_a_robot_without_plugins_is_never_due():
    runtime = RobotRuntime("r", Context(), [])
    assert runtime.next_work() == math.inf and runtime.next_publish() == math.inf and runtime.publishers() == []


def test_the_robot_is_due_at_its_earliest_plugin():
    calls = []
    drive = Plugin("drive", calls, due=0.01, publish=0.02, pubs=["odom", "tf"])
    laser = Plugin("laser", calls, publish=0.1, pubs=["scan"])
    runtime = RobotRuntime("r", Context(), [drive, laser])
    assert runtime.publishers() == ["odom", "tf", "scan"]
    assert runtime.next_publish() == 0.02
    assert runtime.next_work() == 0.01
    drive.due = 0.5
    assert runtime.next_work() == 0.02  # a publication is due first


def test_every_plugin_is_called_in_order_and_close_goes_to_the_context():
    calls = []
    ctx = Context()
    runtime = RobotRuntime("r", ctx, [Plugin("a", calls), Plugin("b", calls)])
    runtime.start(0.0)
    runtime.before_step(0.001)
    transforms = []
    runtime.after_step(0.002, None, transforms)
    runtime.reset(0.003)
    assert calls == [("a", "start", 0.0), ("b", "start", 0.0), ("a", "before", 0.001), ("b", "before", 0.001),
                     ("a", "after", 0.002), ("b", "after", 0.002), ("a", "reset", 0.003), ("b", "reset", 0.003)]
    assert transforms == ["a", "b"]  # one list for the step's TF message
    runtime.close()
    assert calls[-2:] == [("a", "close", None), ("b", "close", None)] and ctx.closed



# -- how many physics steps run with no Python between them, and real-time pacing after a stall ---------------

class Due:
    """A plugin as the loop asks it: when its control and its next publication are due."""

    def __init__(self, control=math.inf, publish=math.inf):
        self.control, self.publish = control, publish

    def next_control(self):
        return self.control

    def next_publish(self):
        return self.publish


def bare_loop(time_step=0.001, plugins=(), next_publish=math.inf, landing=(), actors=None, api=None):
    """A Simulator with only what _batch and _real_time_room read (no master, no physics)."""
    from types import SimpleNamespace

    from diffbot_sim.simulator.loop import Simulator
    sim = Simulator.__new__(Simulator)
    sim.cfg = SimpleNamespace(time_step=time_step, real_time_factor=1.0)
    sim.steps, sim._time_base, sim._steps_base = 0, 0.0, 0
    sim.world = SimpleNamespace(landing=list(landing))
    sim.actors, sim.api = actors, api
    sim.robots = [RobotRuntime("r", None, list(plugins))]
    sim._next_publish = next_publish
    sim.wall0, sim.sim0 = 0.0, 0.0
    return sim


def test_steps_run_in_one_go_up_to_the_first_work_due():
    """1 ms steps, odometry due at 10 ms and nothing else: ten steps with no Python between them; a plugin with
    work every step (a torque, a wrench) or a robot being set down: one."""
    sim = bare_loop(next_publish=0.010)
    assert sim._batch(100) == 10
    assert sim._batch(4) == 4  # real-time pacing allows only 4 now
    sim.steps = 3
    assert sim._batch(100) == 7
    assert bare_loop(plugins=[Due(control=0.004)], next_publish=0.010)._batch(100) == 4
    assert bare_loop(plugins=[Due(control=0.0)], next_publish=0.010)._batch(100) == 1
    assert bare_loop(next_publish=0.010, landing=["robot"])._batch(100) == 1
    assert bare_loop(next_publish=0.010, actors=object())._batch(100) == 1
    busy = type("Api", (), {"busy": lambda self: True})()
    assert bare_loop(next_publish=0.010, api=busy)._batch(100) == 1
    assert bare_loop(next_publish=math.inf)._batch(100) == 100


def test_real_time_pacing_does_not_race_to_make_up_a_stall():
    """Paced at RTF 1 with 1 ms steps: 3 ms of wall time due is 3 steps; after a 0.6 s stall (a spawn) the
    simulation does not run 600 steps to catch up (Gazebo paces each step from the last): one step is due and
    pacing goes on from there. A lag under MAX_CATCH_UP (a late wake-up) is made up."""
    from diffbot_sim.simulator.loop import MAX_CATCH_UP
    sim = bare_loop()
    assert sim._real_time_room(0.0035, 1.0)[0] == 3
    sim.steps = 3
    assert sim._real_time_room(0.6035, 1.0)[0] == 1
    sim.steps = 4
    assert sim._real_time_room(0.6045, 1.0)[0] == 1  # and on at the wall clock's pace, from the stall's end
    assert sim._real_time_room(0.6045 + MAX_CATCH_UP / 2, 1.0)[0] == 1 + round(MAX_CATCH_UP / 2 / 0.001)
    assert bare_loop()._real_time_room(0.0005, 1.0)[0] == 0  # not yet: wait


def test_fast_mode_is_paced_at_real_time_while_a_lagging_node_is_expected_back():
    """A node in the loop dropped for outlasting ~wait_for_nodes_timeout (gmapping busy 5 s with its first scan):
    fast mode runs at real time until it is taken back, re-anchored where it begins, not held back to where the
    wall clock would have put a real-time run from the start."""
    from types import SimpleNamespace

    sim = bare_loop()
    sim.cfg.wait_for_nodes = True
    lagging = [False]
    sim.sync = SimpleNamespace(lagging=lambda: lagging[0])
    sim._paced_for_lag = False
    sim.steps = 5000  # 5 s of sim time run fast, in far less wall time
    assert not sim._lagging_node()
    lagging[0] = True
    assert sim._lagging_node() and sim.sim0 == 5.0  # re-anchored at the sim time now
    wall = sim.wall0
    assert sim._real_time_room(wall + 0.0035, 1.0)[0] == 3  # real time from here
    sim.wall0 = -1.0
    assert sim._lagging_node() and sim.wall0 == -1.0  # still lagging: not re-anchored again
    lagging[0] = False
    assert not sim._lagging_node()
    sim.cfg.wait_for_nodes = False
    lagging[0] = True
    assert not sim._lagging_node()  # ~wait_for_nodes off: nobody is waited for, nobody lags
