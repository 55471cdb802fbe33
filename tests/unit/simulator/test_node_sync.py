"""simulator.sync.NodeSync's decisions, with fake publishers and fake watched nodes (no master, no /proc).

A fake publisher has rospy's shape as NodeSync reads it: ``impl.seq`` (messages sent) and ``impl.connections``
(each with the subscriber's ``endpoint_id`` and its ``socket``). Sockets are real socketpairs where a test needs
to see a subscriber's end closed; a fake node's ``busy`` is set by the test.
"""
import socket
import xmlrpc.client

import pytest

from diffbot_sim.simulator import sync
from diffbot_sim.simulator.sync import FRESH_GRACE, NodeSync


class Conn:
    def __init__(self, caller, sock=None):
        self.endpoint_id, self.socket = caller, sock


class Impl:
    def __init__(self):
        self.seq, self.connections = 0, []


class Pub:
    def __init__(self, name="/scan"):
        self.resolved_name, self.impl = name, Impl()

    def send(self):
        """One message published to whoever is connected."""
        self.impl.seq += 1


class Node:
    """A WatchedNode as NodeSync uses it."""

    def __init__(self, name, busy=False, alive=True):
        self.name, self.is_busy, self.is_alive, self.dropped, self.closed = name, busy, alive, False, False
        self.drops = 0

    def alive(self):
        return self.is_alive

    def busy(self, now_wall):
        return self.is_busy

    def close(self):
        self.closed = True


@pytest.fixture
def node_sync():
    """A NodeSync that never asks a master: an unknown caller id is a failure of the test."""
    warnings = []
    result = NodeSync(timeout=5.0, ignore=["/rviz*"], own_name="/bullet_sim",
                      warn=lambda key, text: warnings.append((key, text)))
    result.warnings = warnings
    return result


def watch(node_sync, *nodes):
    for node in nodes:
        node_sync.nodes[node.name] = node
    return nodes


@pytest.fixture
def pair():
    """A connected socket pair: (our end, the subscriber's end); closed at the end of the test."""
    ours, theirs = socket.socketpair()
    yield ours, theirs
    ours.close()
    theirs.close()


# -- who was sent a message -------------------------------------------------------------------------------

def test_published_lists_the_publishers_that_sent_since_the_last_call():
    ns = NodeSync(1.0, [], "/sim", None)
    scan, cloud, idle = Pub("/scan"), Pub("/cloud"), Pub("/idle")
    for pub in (scan, cloud, idle):
        pub.impl.connections.append(Conn("/slam"))
    ns.published([scan, cloud, idle])  # the first look notes every publisher's count
    scan.send()
    cloud.send()
    assert ns.published([scan, cloud, idle]) == [scan, cloud]
    assert ns.published([scan, cloud, idle]) == []  # nothing new
    cloud.send()
    assert ns.published([scan, cloud, idle]) == [cloud]


def test_a_message_nobody_got_is_not_waited_for():
    ns = NodeSync(1.0, [], "/sim", None)
    scan, gone = Pub(), Pub("/gone")
    gone.impl = None  # unregistered
    scan.send()
    assert ns.published([scan, gone]) == [] and ns.listeners == {}


def test_a_listener_is_fresh_when_it_connected_since_the_previous_message():
    ns = NodeSync(1.0, [], "/sim", None)
    scan = Pub()
    staying = Conn("/slam")
    scan.impl.connections.append(staying)
    scan.send()
    ns.published([scan])
    assert ns.listeners[scan] == {"/slam": (staying, True)}  # new at the first message
    one_shot = Conn("/agent")
    scan.impl.connections.append(one_shot)
    scan.send()
    ns.published([scan])
    assert ns.listeners[scan] == {"/slam": (staying, False), "/agent": (one_shot, True)}
    assert ns.watched() == {"/slam", "/agent"}


def test_connections_leave_out_closed_ends_and_unnamed_ones(pair):
    ours, theirs = pair
    scan = Pub()
    live, unnamed, without_socket = Conn("/slam", ours), Conn(None), Conn("/agent")
    scan.impl.connections += [live, unnamed, without_socket]
    assert NodeSync.connections(scan) == {live: "/slam", without_socket: "/agent"}
    theirs.close()  # the subscriber unsubscribed: rospy has not noticed yet
    assert NodeSync.connections(scan) == {without_socket: "/agent"}
    assert NodeSync.connections(scan, peek=False) == {live: "/slam", without_socket: "/agent"}
    scan.impl = None
    assert NodeSync.connections(scan) == {}


def test_unread_data_from_a_subscriber_is_not_a_closed_end(pair):
    ours, theirs = pair
    theirs.sendall(b"x")
    scan = Pub()
    scan.impl.connections.append(Conn("/slam", ours))
    assert list(NodeSync.connections(scan).values()) == ["/slam"]


# -- what is still pending ----------------------------------------------------------------------------------

def sent(ns, pub):
    pub.send()
    assert ns.published([pub]) == [pub]


def test_a_busy_listener_is_pending_and_an_idle_staying_one_is_not(node_sync):
    scan = Pub()
    slam, = watch(node_sync, Node("/slam", busy=True))
    scan.impl.connections.append(Conn("/slam"))
    sent(node_sync, scan)
    sent(node_sync, scan)  # a second message: the connection is no longer fresh
    assert node_sync.pending([scan], 0.0, elapsed=1.0) == [("/slam", "busy")]
    slam.is_busy = False
    assert node_sync.pending([scan], 0.0, elapsed=1.0) == []


def test_a_fresh_listener_is_given_the_grace_to_drop_its_connection(node_sync):
    scan = Pub()
    watch(node_sync, Node("/agent"))
    scan.impl.connections.append(Conn("/agent"))
    sent(node_sync, scan)
    assert node_sync.pending([scan], 0.0, elapsed=0.0) == [
        ("/agent", "a new subscriber: dropping it after one message?")]
    assert node_sync.pending([scan], 0.0, elapsed=FRESH_GRACE) == []  # it stays: a subscriber like any other


def test_a_step_and_wait_client_is_pending_until_it_subscribes_again(node_sync):
    scan = Pub()
    watch(node_sync, Node("/agent"))
    scan.impl.connections.append(Conn("/agent"))
    sent(node_sync, scan)
    scan.impl.connections.clear()  # wait_for_message got its message and unsubscribed
    assert node_sync.pending([scan], 0.0, elapsed=0.0) == [("/agent", "not subscribed to /scan again yet")]
    scan.impl.connections.append(Conn("/agent"))  # it acted and waits for the next message: lockstep
    assert node_sync.pending([scan], 0.0, elapsed=0.0) == []


def test_dropped_unwatchable_and_dead_nodes_are_not_waited_for(node_sync):
    scan = Pub()
    slow, dead = watch(node_sync, Node("/slow", busy=True), Node("/dead", busy=True, alive=False))
    slow.dropped = True
    node_sync.nodes["/remote"] = None  # on another host
    scan.impl.connections += [Conn("/slow"), Conn("/dead"), Conn("/remote")]
    sent(node_sync, scan)
    assert node_sync.pending([scan], 0.0, elapsed=1.0) == []
    assert dead.closed and "/dead" not in node_sync.nodes  # found again if it comes back


def test_after_a_clock_tick_only_busy_nodes_in_the_loop_are_pending(node_sync):
    scan = Pub()
    watch(node_sync, Node("/slam", busy=True), Node("/amcl"), Node("/outside", busy=True))
    scan.impl.connections += [Conn("/slam"), Conn("/amcl")]
    sent(node_sync, scan)
    assert node_sync.pending([], 0.0) == [("/slam", "busy")]
    node_sync.nodes["/slam"].dropped = True
    assert node_sync.busy_nodes(0.0) == []


class Sub:
    """A rospy.Subscriber as note_commanders reads it: ``impl.connections``, each naming its publisher in
    ``callerid_pub`` (rospy's "unknown" until the connection header is read)."""

    def __init__(self, *callers):
        self.impl = Impl()
        for caller in callers:
            conn = Conn(None)
            conn.callerid_pub = caller
            self.impl.connections.append(conn)


def test_command_publishers_are_in_the_loop_and_waited_for_after_a_tick(node_sync):
    tour, mover = watch(node_sync, Node("/tour", busy=True), Node("/mover"))
    assert not node_sync.in_loop()
    node_sync.note_commanders([Sub("/tour", "unknown"), Sub("/mover"), Sub()])
    assert node_sync.commanders == {"/tour", "/mover"}  # "unknown": a connection whose header is not read yet
    assert node_sync.in_loop()
    assert node_sync.pending([], 0.0) == [("/tour", "busy")]
    tour.is_busy = False
    assert node_sync.pending([], 0.0) == []
    node_sync.note_commanders([Sub()])  # both stopped publishing commands
    assert not node_sync.in_loop()


def test_a_subscriber_that_was_unregistered_has_no_commanders(node_sync):
    gone = Sub("/tour")
    gone.impl = None  # rospy.Subscriber.unregister()
    node_sync.note_commanders([gone])
    assert node_sync.commanders == set()


def test_in_loop_while_a_watched_listener_lives_and_is_not_dropped(node_sync):
    scan = Pub()
    assert not node_sync.in_loop()  # nobody ever listened: /clock may be coalesced
    slam, = watch(node_sync, Node("/slam"))
    node_sync.nodes["/remote"] = None
    scan.impl.connections += [Conn("/slam"), Conn("/remote")]
    sent(node_sync, scan)
    assert node_sync.in_loop()
    slam.dropped = True
    assert not node_sync.in_loop()
    slam.dropped, slam.is_alive = False, False
    assert not node_sync.in_loop()


def test_forget_drops_waits_again_for_a_node_that_subscribed_anew(node_sync):
    scan = Pub()
    agent, slam = watch(node_sync, Node("/agent"), Node("/slam"))
    agent.dropped = slam.dropped = True
    scan.impl.connections.append(Conn("/slam"))
    sent(node_sync, scan)
    sent(node_sync, scan)  # /slam's connection is an old one
    scan.impl.connections.append(Conn("/agent"))
    sent(node_sync, scan)
    node_sync.forget_drops([scan])
    assert not agent.dropped and slam.dropped


# -- holding --------------------------------------------------------------------------------------------------

def test_wait_returns_at_once_when_nothing_is_pending(node_sync):
    served = []
    node_sync.wait([], lambda: served.append(1), lambda: False)
    assert served == [] and node_sync.holds == 1 and node_sync.waited >= 0.0


def test_wait_ends_when_told_to_stop(node_sync):
    scan = Pub()
    watch(node_sync, Node("/slam", busy=True))
    scan.impl.connections.append(Conn("/slam"))
    sent(node_sync, scan)
    node_sync.wait([scan], lambda: pytest.fail("served after stop"), lambda: True)
    assert node_sync.warnings == []


def test_a_node_past_the_timeout_is_named_once_and_dropped(node_sync):
    node_sync.timeout = 0.0
    scan = Pub()
    slow, = watch(node_sync, Node("/slow", busy=True))
    scan.impl.connections.append(Conn("/slow"))
    sent(node_sync, scan)
    served = []
    node_sync.wait([scan], lambda: served.append(1), lambda: len(served) > 100)
    assert slow.dropped and served and len(served) < 100
    (key, text), = node_sync.warnings
    assert key == "sync:/slow" and "/slow kept the simulator waiting" in text and "(busy)" in text


def test_a_dropped_node_is_waited_for_again_once_it_is_idle_at_most_max_drops_times(node_sync):
    """amcl, gmapping and move_base are busy for seconds while they start: dropped at their first scan and never
    waited for again, they lagged the whole fast-mode run (amcl's map frame 0.5 s behind: move_base's TF
    extrapolation errors). Idle at a later message, a dropped node is waited for again; after MAX_DROPS drops,
    only once it subscribes anew."""
    node_sync.timeout = 0.0
    scan = Pub()
    starting, = watch(node_sync, Node("/amcl", busy=True))
    scan.impl.connections.append(Conn("/amcl"))
    for drop in range(1, sync.MAX_DROPS + 1):
        starting.is_busy = True
        sent(node_sync, scan)
        served = []
        node_sync.wait([scan], lambda: served.append(1), lambda: len(served) > 100)
        assert starting.dropped and starting.drops == drop
        starting.is_busy = False
        sent(node_sync, scan)
        node_sync.take_back_idle([scan], 0.0)
        assert starting.dropped == (drop == sync.MAX_DROPS)  # idle: waited for again, but not after MAX_DROPS
    assert "until it subscribes again" in node_sync.warnings[-1][1]
    assert not node_sync.lagging()  # dropped for good: fast mode is not held to real time for it
    starting.is_busy = True
    sent(node_sync, scan)
    assert node_sync.pending([scan], 0.0) == []  # dropped for good: not waited for while busy


# -- which nodes can be watched ---------------------------------------------------------------------------------

class Master:
    uri = "http://localhost:1234/"

    def __init__(self, caller_id):
        pass

    def lookupNode(self, name):
        return Master.uri


def test_itself_and_ignored_nodes_are_never_looked_up(node_sync, monkeypatch):
    monkeypatch.setattr(sync.rosgraph, "Master", lambda *a: pytest.fail("the master was asked"))
    assert node_sync._find("/bullet_sim") is None
    assert node_sync._find("/rviz_1700000000") is None


@pytest.mark.parametrize("uri, code, found", [
    ("http://localhost:1234/", 1, True),
    ("http://127.0.0.1:1234/", 1, True),
    ("http://10.255.255.1:1234/", 1, False),  # another host: its /proc is not ours
    ("http://localhost:1234/", -1, False),  # getPid refused
])
def test_a_local_node_that_reports_its_pid_is_watched(node_sync, monkeypatch, uri, code, found):
    import os

    class Proxy:
        def __init__(self, address):
            assert address == uri

        def getPid(self, caller):
            return code, "", os.getpid()
    monkeypatch.setattr(Master, "uri", uri)
    monkeypatch.setattr(sync.rosgraph, "Master", Master)
    monkeypatch.setattr(xmlrpc.client, "ServerProxy", Proxy)
    node = node_sync._find("/slam")
    assert (node is not None) == found
    if found:
        assert (node.name, node.pid, node.dropped) == ("/slam", os.getpid(), False)
        node.close()


def test_a_node_that_does_not_answer_is_not_watched(node_sync, monkeypatch):
    class Gone(Master):
        def lookupNode(self, name):
            raise OSError("connection refused")
    monkeypatch.setattr(sync.rosgraph, "Master", Gone)
    assert node_sync._find("/slam") is None


# -- step-and-wait clients: a dropped connection is not a staying one, a one-shot client is known again ----------

class RospyConn(Conn):
    """A connection as rospy's own transport has it: ``done`` once rospy closed it (its socket then None)."""

    def __init__(self, caller, sock=None):
        super().__init__(caller, sock)
        self.done = False


def test_a_connection_rospy_closed_is_not_a_subscriber(pair):
    ours, _ = pair
    scan = Pub()
    closed, dropped, live = RospyConn("/agent"), RospyConn("/agent", ours), RospyConn("/slam", ours)
    closed.done = True  # rospy closed it: it stays listed until rospy's cleanup removes it
    dropped.socket = None
    scan.impl.connections += [closed, dropped, live]
    assert NodeSync.connections(scan) == {live: "/slam"}
    assert NodeSync.connections(scan, peek=False) == {live: "/slam"}


def test_a_one_shot_client_is_waited_for_past_the_grace(node_sync):
    """A client that dropped its connection after one message will drop this one too: however long it takes
    (a busy machine), it is not taken for a subscriber that stays."""
    scan = Pub()
    watch(node_sync, Node("/agent"))
    first = Conn("/agent")
    scan.impl.connections.append(first)
    sent(node_sync, scan)
    scan.impl.connections[:] = [first, Conn("/agent")]  # the old one closed, not yet noticed; a new one
    sent(node_sync, scan)
    assert node_sync.listeners[scan]["/agent"][0] is not first  # taken on its new connection
    assert node_sync.oneshot[scan] == {"/agent"}
    assert node_sync.pending([scan], 10.0, elapsed=10.0) == [
        ("/agent", "a new subscriber: dropping it after one message?")]


def test_a_new_subscriber_gets_the_grace_counted_from_its_last_busy_moment(node_sync):
    scan = Pub()
    agent, = watch(node_sync, Node("/agent", busy=True))
    scan.impl.connections.append(Conn("/agent"))
    sent(node_sync, scan)
    assert node_sync.pending([scan], 100.0, elapsed=1.0) == [("/agent", "busy")]  # runnable: a busy machine
    agent.is_busy = False
    assert node_sync.pending([scan], 100.0 + FRESH_GRACE / 2, elapsed=1.0) == [
        ("/agent", "a new subscriber: dropping it after one message?")]  # idle only since then
    assert node_sync.pending([scan], 100.0 + 1.01 * FRESH_GRACE, elapsed=1.0) == []  # it stays


# -- commands on their way in ------------------------------------------------------------------------------------

@pytest.fixture
def tcp_pair():
    """A loopback TCP connection: (the publisher's end, our subscriber's end)."""
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen()
    theirs = socket.create_connection(server.getsockname())
    ours, _ = server.accept()
    server.close()
    yield theirs, ours
    theirs.close()
    ours.close()


class SubImpl(Impl):
    """rospy's _SubscriberImpl as Inflow reads it: its connections and its callbacks."""

    def __init__(self):
        super().__init__()
        self.callbacks = []

    def add_callback(self, cb, cb_args):
        self.callbacks.append(cb)

    def deliver(self, conn, count=1):
        """rospy's receive thread: ``count`` messages read from ``conn`` and handed to every callback."""
        conn.stat_num_msg += count
        for _ in range(count):
            msg = type("Msg", (), {"_connection_header": conn.header})()
            for cb in self.callbacks:
                cb(msg)


def commander(sock, caller="/agent"):
    conn = RospyConn(None, sock)
    conn.callerid_pub, conn.header, conn.stat_num_msg, conn.stat_bytes = caller, {"callerid": caller}, 0, 0
    sub = Sub()
    sub.impl = SubImpl()
    sub.impl.connections.append(conn)
    return sub, conn


def drain(sock, conn):
    """Our rospy thread reads what is waiting (it counts the bytes)."""
    sock.setblocking(False)
    try:
        conn.stat_bytes += len(sock.recv(65536))
    except BlockingIOError:
        pass


def test_a_command_is_pending_until_its_callback_ran(node_sync, tcp_pair):
    """The client published its command, then subscribed again and went idle: resumed before our own rospy thread
    read and delivered the command, sim time ran on under the old one (12.5 ms of sim time, measured)."""
    theirs, ours = tcp_pair
    watch(node_sync, Node("/agent"))
    sub, conn = commander(ours)
    node_sync.note_commanders([sub])
    assert node_sync.undelivered() == []
    theirs.sendall(b"x" * 40)  # the command's bytes, in our socket
    wait_for_bytes(ours)
    assert node_sync.undelivered() == [("/agent", "its command is not taken in yet")]
    assert node_sync.pending([], 0.0) == [("/agent", "its command is not taken in yet")]  # after a tick too
    drain(ours, conn)
    conn.stat_num_msg += 1  # read and parsed, its callback not run yet
    assert node_sync.undelivered() == [("/agent", "its command is not taken in yet")]
    conn.stat_num_msg -= 1
    sub.impl.deliver(conn)
    assert node_sync.undelivered() == []


def test_bytes_our_thread_took_from_the_socket_but_has_not_counted_are_pending(node_sync, tcp_pair):
    """Read by rospy's thread while the loop held Python's lock: out of the socket, not yet counted."""
    theirs, ours = tcp_pair
    watch(node_sync, Node("/agent"))
    sub, conn = commander(ours)
    theirs.sendall(b"h" * 30)  # the handshake: read by rospy, never counted in stat_bytes
    wait_for_bytes(ours)
    ours.recv(30)
    node_sync.note_commanders([sub])
    assert node_sync.undelivered() == []  # 30 bytes never counted: the connection's own offset
    theirs.sendall(b"x" * 40)
    wait_for_bytes(ours)
    ours.recv(40)  # taken by the thread, which now waits for the lock
    assert node_sync.undelivered() == [("/agent", "its command is not taken in yet")]
    conn.stat_bytes += 40
    sub.impl.deliver(conn)
    assert node_sync.undelivered() == []


def test_a_dropped_commander_is_not_waited_for(node_sync, tcp_pair):
    theirs, ours = tcp_pair
    agent, = watch(node_sync, Node("/agent"))
    sub, _ = commander(ours)
    node_sync.note_commanders([sub])
    theirs.sendall(b"x")
    wait_for_bytes(ours)
    agent.dropped = True
    assert node_sync.undelivered() == []


def wait_for_bytes(sock):
    import select
    assert select.select([sock], [], [], 2.0)[0], "the bytes never arrived"


# -- a reset's caller is connected first ---------------------------------------------------------------------

def request(caller):
    """A service request as rospy hands it to the handler: its connection header names the caller."""
    return type("Request", (), {"_connection_header": {"callerid": caller}})()


def test_a_reset_waits_until_its_callers_subscriptions_are_connected(node_sync, monkeypatch):
    import threading

    class Proxy:
        def __init__(self, address):
            pass

        def getSubscriptions(self, caller):
            return 1, "", [["/odom", "nav_msgs/Odometry"], ["/elsewhere", "std_msgs/Empty"]]
    monkeypatch.setattr(sync.rosgraph, "Master", Master)
    monkeypatch.setattr(xmlrpc.client, "ServerProxy", Proxy)
    odom, scan = Pub("/odom"), Pub("/scan")
    later = threading.Timer(0.05, lambda: odom.impl.connections.append(Conn("/agent")))
    later.start()
    node_sync.connect_first(request("/agent"), [odom, scan])  # /scan is not one of its subscriptions
    assert odom.impl.connections and node_sync.warnings == []
    node_sync.timeout = 0.02
    node_sync.connect_first(request("/other"), [odom, scan])  # subscribed, never connected: named, goes on
    (key, text), = node_sync.warnings
    assert key == "sync-connect:/other" and "/odom" in text


def test_a_node_dropped_and_expected_back_is_lagging_until_taken_back(node_sync):
    """While a dropped node is expected back (alive, drops left), the loop paces fast mode at real time."""
    node_sync.timeout = 0.0
    scan = Pub()
    starting, = watch(node_sync, Node("/slam_gmapping", busy=True))
    scan.impl.connections.append(Conn("/slam_gmapping"))
    assert not node_sync.lagging()
    sent(node_sync, scan)
    served = []
    node_sync.wait([scan], lambda: served.append(1), lambda: len(served) > 100)
    assert starting.dropped and node_sync.lagging()
    starting.is_alive = False
    assert not node_sync.lagging()  # it died: nobody to wait for
    starting.is_alive, starting.is_busy = True, False
    sent(node_sync, scan)
    node_sync.take_back_idle([scan], 0.0)
    assert not starting.dropped and not node_sync.lagging()
