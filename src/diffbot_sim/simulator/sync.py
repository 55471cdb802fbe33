"""Fast, and never faster than the nodes in the loop: the simulator waits, after each sensor message, until the
nodes it fed have answered it.

Why: unbounded, the simulator steps as fast as PyBullet allows while gmapping, amcl, move_base or a learning
agent read its sensors when they can; a node that cannot keep up then sees a run nobody meant (gmapping skipped
three scans in four; a step-and-wait client held each action for a random stretch of sim time). A fixed factor
picked for one machine is too fast on a slower or busier one and wastes time on a faster one.

How (``~wait_for_nodes``, on by default whenever the simulator is not paced to the wall clock): the nodes in the
loop are the subscribers of its sensor topics (lasers, rangers, point clouds, cameras) and the publishers of its
command topics (``cmd_vel``, controller commands, ``/gazebo/set_model_state``): a node that steers the robot by
odometry or TF alone (a waypoint tour, a path follower) acts on the clock as at real time too. After a step that
published /clock, sim time holds until none of them is busy (their timers, woken by the tick, have run); after
one that published on a sensor topic, until every node that was subscribed to it

* is idle: none of its threads is running or runnable (``/proc/<pid>/task/*/stat``: a thread woken by our
  message is runnable at once, so there is no race), i.e. it has done what the message caused, and
* if it dropped its subscription after the message (``rospy.wait_for_message``: a step-and-wait client),
  has subscribed again: it has sent its answer and waits for the next message — lockstep; a client known to
  drop each connection after one message is waited for until it does, however long it stays runnable on a
  busy machine (a new subscriber is given FRESH_GRACE of idleness to drop it before it counts as one that stays);
* and the commands it published (``cmd_vel``, ...) have reached our callbacks (:class:`Inflow`): they are in
  our socket by the time it is idle, but our own rospy thread may not have read them yet, and sim time must not
  run on under the old command.

A node is found by the subscriber's caller id (the master's ``lookupNode``, then its own ``getPid``); one on
another host, or one matching ``~wait_for_nodes_ignore`` (rviz by default: it renders all the time), is not
waited for. A node that keeps the simulator waiting longer than ``~wait_for_nodes_timeout`` wall seconds at
one message is named in one warning and not waited for while it stays busy: the lag is bounded, and meanwhile
sim time runs no faster than real time (:meth:`NodeSync.lagging`), so the node misses no more than it would at
real time. It is waited for again once it is seen idle (it caught up: amcl, gmapping and move_base are busy for
seconds while they start, and dropped for good they then lagged the whole run) or subscribes anew; after
MAX_DROPS drops, only anew.
While it waits, the loop keeps serving requests (services, spawns, resets). A reset first waits until its
caller's subscriptions to the simulator's topics are connected (:meth:`NodeSync.connect_first`).
"""
import fnmatch
import math
import os
import select
import socket
import struct
import time
import xmlrpc.client
from urllib.parse import urlparse

import rosgraph

#: wall seconds between two looks at the waited-for nodes
POLL = 0.0002
#: wall seconds of idleness a subscriber that connected since the previous message is given to drop its connection
#: (a rospy.wait_for_message client drops it within its 10 ms poll) before it counts as one that stays
FRESH_GRACE = 0.05
#: How often a node that outlasted ``~wait_for_nodes_timeout`` is taken back once idle; then only when it
#: subscribes anew (a node busy nearly all the time would otherwise cost a timeout again and again).
MAX_DROPS = 3
LOCAL_HOSTS = ("localhost", "127.0.0.1", "::1")


class WatchedNode:
    """A subscriber node's process, as /proc shows it (one open file per thread: a re-read costs ~4 us)."""

    def __init__(self, name, pid):
        self.name, self.pid = name, pid
        self.task_dir = f"/proc/{pid}/task"
        self._fds = {}  # tid -> open /proc/<pid>/task/<tid>/stat
        self._listed = -1.0
        self.dropped = False  # exceeded the timeout: not waited for until it is idle again (or subscribes anew)
        self.drops = 0  # times it was dropped since it last subscribed anew

    def alive(self):
        return os.path.exists(self.task_dir)

    def _list(self, now_wall):
        try:
            tids = set(os.listdir(self.task_dir))
        except OSError:
            tids = set()
        for tid in set(self._fds) - tids:
            os.close(self._fds.pop(tid))
        for tid in tids - set(self._fds):
            try:
                self._fds[tid] = os.open(f"{self.task_dir}/{tid}/stat", os.O_RDONLY)
            except OSError:
                pass
        self._listed = now_wall

    def busy(self, now_wall):
        """Whether one of its threads runs or is runnable now (its threads listed again every 0.5 s)."""
        if now_wall - self._listed > 0.5:
            self._list(now_wall)
        for fd in self._fds.values():
            try:
                stat = os.pread(fd, 512, 0)
            except OSError:
                continue
            close = stat.rfind(b")")
            if close >= 0 and stat[close + 2:close + 3] == b"R":
                return True
        return False

    def close(self):
        for fd in self._fds.values():
            os.close(fd)
        self._fds = {}


class NodeSync:
    """The waiting of one simulator: which publishers are sensors, who listened to the last message of each."""

    def __init__(self, timeout, ignore, own_name, warn):
        self.timeout = timeout
        self.ignore = list(ignore)
        self.own_name = own_name
        self.warn = warn
        self.nodes = {}  # caller id -> WatchedNode, or None (not watchable: other host, ignored, gone)
        self.listeners = {}  # publisher -> {caller id: (its connection, fresh)} when it last published
        self.oneshot = {}  # publisher -> caller ids among them that drop each connection after one message
        self.busy_seen = {}  # caller id -> wall time it was last seen busy while we waited
        self._connections = {}  # publisher -> the connections it had at its previous message
        self.commanders = set()  # caller ids publishing to the simulator's command topics (note_commanders)
        self.inflow = Inflow()  # what those publishers sent that has not reached the callbacks yet
        self.seq = {}  # publisher -> its message count when last looked at
        self.waited = 0.0  # wall seconds spent waiting, for the achieved-RTF report
        self.holds = 0

    # -- who is subscribed --------------------------------------------------------------------------------
    @staticmethod
    def connections(pub, peek=True):
        """{connection: caller id} of ``pub``'s subscribers. A subscriber that unsubscribed has closed its end,
        but rospy notices only at its next write: with ``peek`` such connections are left out (a subscriber
        never sends after the handshake: a readable socket at end of file is gone)."""
        impl = pub.impl
        if impl is None:
            return {}
        out = {}
        for conn in list(impl.connections):
            sock = getattr(conn, "socket", None)
            name = getattr(conn, "endpoint_id", None)
            if name is None or _closed(conn, sock) or (peek and sock is not None and _closed_by_peer(sock)):
                continue
            out[conn] = name
        return out

    def _node(self, name):
        if name not in self.nodes:
            self.nodes[name] = self._find(name)
        node = self.nodes[name]
        if node is not None and not node.alive():
            self.nodes.pop(name).close()
            return None
        return node

    def _find(self, name):
        """The WatchedNode of caller id ``name``, or None when it is not a local process we may wait for."""
        if name == self.own_name or any(fnmatch.fnmatch(name, pattern) for pattern in self.ignore):
            return None
        try:
            uri = rosgraph.Master(self.own_name).lookupNode(name)
            host = urlparse(uri).hostname or ""
            code, _, pid = xmlrpc.client.ServerProxy(uri).getPid(self.own_name)
        except Exception:  # the node left, or does not answer: nothing to wait for
            return None
        if code != 1 or not os.path.exists(f"/proc/{pid}") or not _is_local(host):
            return None
        return WatchedNode(name, int(pid))

    # -- the loop's side ----------------------------------------------------------------------------------
    def published(self, publishers):
        """The sensor publishers that sent a message since the last call, with their subscribers noted."""
        fresh = []
        for pub in publishers:
            impl = pub.impl
            seq = getattr(impl, "seq", 0) if impl is not None else 0
            if seq != self.seq.get(pub):
                self.seq[pub] = seq
                conns = self.connections(pub, peek=False)  # who was sent the message (a closed one is seen later)
                before = self._connections.get(pub, {})
                self._connections[pub] = conns
                if conns:
                    self._note_listeners(pub, conns, before)
                    fresh.append(pub)
        return fresh

    def _note_listeners(self, pub, conns, before):
        """Who got ``pub``'s message: {caller id: (connection, fresh)}, fresh meaning connected since the previous
        message, as a ``wait_for_message`` client's is. A node listed twice (its old connection closed, not yet
        noticed by rospy, and a new one) is taken on its new connection. One-shot: a node fresh now that was
        fresh at the previous message on another connection dropped that one after one message, and will drop
        this one too (a step-and-wait client)."""
        previous = self.listeners.get(pub, {})
        listeners = {}
        for conn, name in conns.items():
            fresh = conn not in before
            if name not in listeners or fresh:
                listeners[name] = (conn, fresh)
        self.listeners[pub] = listeners
        self.oneshot[pub] = {name for name, (conn, fresh) in listeners.items()
                             if fresh and previous.get(name, (conn, False))[1] and previous[name][0] is not conn}

    def note_commanders(self, subscribers):
        """Take the publishers connected to ``subscribers`` (the simulator's command topics) as nodes in the
        loop: after each /clock tick sim time holds until they are idle, as it does for the sensor listeners.
        A node found by its caller id as the publisher named itself in the connection's header."""
        names = set()
        for sub in subscribers:
            impl = getattr(sub, "impl", None)
            for conn in list(impl.connections) if impl is not None else ():
                name = getattr(conn, "callerid_pub", None)
                if name and name != "unknown":  # rospy's value before the header is read
                    names.add(name)
        self.commanders = names
        self.inflow.watch(subscribers)

    def watched(self):
        """The nodes in the loop: every node subscribed to a sensor topic when it last published, and every
        publisher to a command topic."""
        names = set(self.commanders)
        for listeners in self.listeners.values():
            names |= set(listeners)
        return names

    def in_loop(self):
        """Whether a node the simulator waits for is subscribed to a sensor topic (alive, not dropped)."""
        for name in self.watched():
            node = self._node(name)
            if node is not None and not node.dropped:
                return True
        return False

    def busy_nodes(self, now_wall):
        """(name, "busy") of the nodes in the loop that are working now (after a /clock tick woke their
        timers)."""
        out = []
        for name in self.watched():
            node = self._node(name)
            if node is not None and not node.dropped and node.busy(now_wall):
                out.append((name, "busy"))
        return out

    def pending(self, publishers, now_wall, elapsed=0.0):
        """The nodes the simulator still waits for, ``elapsed`` wall seconds after ``publishers`` sent a message,
        as (name, why) pairs; no publishers: after a /clock tick (busy nodes only).

        A listener has answered when it is idle and: still on the connection that got the message (a subscriber
        that stays), unless that connection was fresh (made since the previous message, as a
        ``wait_for_message`` client's is) and the node either dropped its previous connection after one message
        (one-shot: it will drop this one too) or has not been idle for FRESH_GRACE yet (a new node: given the
        time to drop it; idle, as a client between two 10 ms polls of ``wait_for_message``, not busy: on a busy
        machine a client can stay runnable that long); or on a new connection (a client that dropped the old
        one and waits again). Then its commands must have reached our callbacks (:meth:`undelivered`)."""
        if not publishers:
            return self.busy_nodes(now_wall) or self.undelivered()
        out = []
        for pub in publishers:
            now = None
            for name, (conn, fresh) in self.listeners.get(pub, {}).items():
                node = self._node(name)
                if node is None or node.dropped:
                    continue
                if node.busy(now_wall):
                    self.busy_seen[name] = now_wall
                    out.append((name, "busy"))
                    continue
                if now is None:
                    now = self.connections(pub)
                if conn in now:
                    idle = now_wall - max(now_wall - elapsed, self.busy_seen.get(name, -math.inf))
                    if fresh and (name in self.oneshot.get(pub, ()) or idle < FRESH_GRACE):
                        out.append((name, "a new subscriber: dropping it after one message?"))
                elif name not in now.values():
                    out.append((name, f"not subscribed to {pub.resolved_name} again yet"))
        return out or self.undelivered()

    def undelivered(self):
        """(name, why) of the waited-for nodes whose commands have not reached the simulator's callbacks yet.
        Why: a node's answer is the command it published before it went idle (a step-and-wait client also
        subscribed again after it); the command's bytes are then in our socket already (loopback), but our
        rospy thread may not have read them: resumed at once, sim time ran on under the old command for
        steps (a step-and-wait client's action started 12.5 ms of sim time late and was held 0.1875 s, not
        0.2 s)."""
        out = []
        for name in self.inflow.pending():
            node = self._node(name)
            if node is not None and not node.dropped:
                out.append((name, "its command is not taken in yet"))
        return out

    def wait(self, publishers, serve, stop):
        """Hold until every listener of ``publishers`` has answered (see the module docstring); ``serve()``
        handles the loop's requests meanwhile, ``stop()`` ends the wait early (pause, shutdown). No publishers:
        after a /clock tick, until no node in the loop is busy."""
        started = time.monotonic()
        self.holds += 1
        self.take_back_idle(publishers, started)
        waiting_since = {}
        while True:
            now = time.monotonic()
            pending = self.pending(publishers, now, now - started)
            if not pending or stop():
                break
            for name, why in pending:
                since = waiting_since.setdefault(name, now)
                if now - since > self.timeout:
                    node = self.nodes.get(name)
                    if node is not None:
                        node.dropped = True
                        node.drops += 1
                    again = ("until it subscribes again" if node is not None and node.drops >= MAX_DROPS
                             else "while it is busy")
                    self.warn(f"sync:{name}", f"bullet_sim: {name} kept the simulator waiting {now - since:.1f} s "
                              f"({why}); not waiting for it {again} (~wait_for_nodes_timeout)")
            time.sleep(POLL)
            serve()
        self.waited += time.monotonic() - started

    def lagging(self):
        """Whether a node dropped for outlasting the timeout is alive and expected back (it has drops left): while
        one is, the loop runs sim time no faster than real time, so that node falls no further behind than it would
        at real time (gmapping, busy 5 s with its first scan, was not waited for while a fast tour ran on, and mapped
        it askew)."""
        return any(node.dropped and node.drops < MAX_DROPS and node.alive() for node in self.nodes.values())

    def take_back_idle(self, publishers, now_wall):
        """Wait again for the nodes in this hold that were dropped and are idle now: they have caught up (a node
        is busy for seconds while it starts: amcl computing its likelihood field, gmapping its first map)."""
        names = ({name for pub in publishers for name in self.listeners.get(pub, {})} if publishers
                 else self.watched())
        for name in names:
            node = self.nodes.get(name)
            if node is not None and node.dropped and node.drops < MAX_DROPS and not node.busy(now_wall):
                node.dropped = False

    def connect_first(self, request, publishers):
        """Hold the calling thread (a service's, before ``request`` reaches the loop) until the node that sent it
        is connected to each of ``publishers`` it subscribes to, at most ``timeout`` wall seconds.

        Why: a client that subscribes (odometry) and at once calls reset_simulation (TurtleBot3's learning
        environment does) needs its connection up before sim time runs on from 0: in fast mode the first
        odometry (1/30 s) and scan (0.2 s) come within milliseconds of wall time, and its connection, made by
        a thread of its own, can come later: it got a scan and no odometry, and crashed. At real time in Gazebo
        the connection has time to spare."""
        caller = (getattr(request, "_connection_header", None) or {}).get("callerid")
        if not caller or caller == self.own_name or any(fnmatch.fnmatch(caller, p) for p in self.ignore):
            return
        try:
            uri = rosgraph.Master(self.own_name).lookupNode(caller)
            if not _is_local(urlparse(uri).hostname or ""):
                return
            code, _, subscribed = xmlrpc.client.ServerProxy(uri).getSubscriptions(self.own_name)
        except Exception:  # the node left, or does not answer: nothing to wait for
            return
        topics = {topic for topic, _ in subscribed} if code == 1 else set()
        mine = [pub for pub in publishers if getattr(pub, "resolved_name", None) in topics]
        started = time.monotonic()
        while True:
            missing = [pub.resolved_name for pub in mine if caller not in self.connections(pub).values()]
            if not missing:
                return
            if time.monotonic() - started > self.timeout:
                self.warn(f"sync-connect:{caller}", f"bullet_sim: {caller} subscribed to {', '.join(missing)} but "
                          f"did not connect within {self.timeout:g} s; going on (~wait_for_nodes_timeout)")
                return
            time.sleep(0.001)

    def forget_drops(self, publishers):
        """A node that subscribes anew (a fresh connection got this message) is waited for again."""
        for pub in publishers:
            for name, (_, fresh) in self.listeners.get(pub, {}).items():
                node = self.nodes.get(name)
                if fresh and node is not None:
                    node.dropped, node.drops = False, 0


class Inflow:
    """Which publishers to the simulator's command topics have sent messages its callbacks have not had yet.

    A connection is drained when (1) its socket has nothing to read; (2) every byte the kernel received on it
    (TCP_INFO's ``tcpi_bytes_received``) has been taken by rospy's receive thread (its ``stat_bytes``, less the
    handshake's, the smallest difference seen): a thread that read a message while the loop held Python's
    lock has it in hand, unparsed, until it gets the lock; and (3) every message rospy read from it
    (``stat_num_msg``) has been through the subscriber's callbacks: a counting callback, added after the
    plugin's own, notes each message's connection (rospy sets ``msg._connection_header`` to the connection's
    header)."""

    def __init__(self):
        self.impls = []  # the command subscribers' rospy impls
        self.counted = set()  # id() of impls with the counting callback
        self.done = {}  # id(connection header) -> messages through the callbacks
        self.base = {}  # id(connection header) -> messages read before the count began
        self.offset = {}  # id(connection header) -> bytes received that rospy never counts (its handshake)

    def watch(self, subscribers):
        """Count the deliveries of ``subscribers`` (rospy.Subscriber), from now on."""
        impls = []
        for sub in subscribers:
            impl = getattr(sub, "impl", None)
            if impl is None or not hasattr(impl, "add_callback"):
                continue
            impls.append(impl)
            if id(impl) not in self.counted:
                for conn in list(impl.connections):  # read before the count: taken as delivered
                    header = getattr(conn, "header", None)
                    if header is not None:
                        self.base[id(header)] = getattr(conn, "stat_num_msg", 0)
                try:
                    impl.add_callback(self._delivered, None)
                except Exception:  # closed meanwhile (unregistered): nothing to count
                    continue
                self.counted.add(id(impl))
        live = {id(getattr(c, "header", None)) for impl in impls for c in list(impl.connections)}
        for table in (self.done, self.base, self.offset):  # connections gone: forget them
            for key in [k for k in list(table) if k not in live]:
                del table[key]
        self.impls = impls

    def _delivered(self, msg):
        """The last callback of a command subscriber (rospy's receive thread): one more message delivered."""
        key = id(getattr(msg, "_connection_header", None))
        self.done[key] = self.done.get(key, 0) + 1

    def pending(self):
        """Caller ids of the publishers whose connection is not drained (see the class docstring)."""
        out = set()
        for impl in self.impls:
            for conn in list(impl.connections):
                name = getattr(conn, "callerid_pub", None)
                if not name or name == "unknown" or name in out:
                    continue
                sock = getattr(conn, "socket", None)
                header = getattr(conn, "header", None)
                if sock is None or header is None:  # closed, or its handshake not done: nothing sent yet
                    continue
                if _readable(sock):
                    out.add(name)
                    continue
                received = _bytes_received(sock)
                if received is not None:
                    unread = received - getattr(conn, "stat_bytes", 0)
                    offset = self.offset.get(id(header))
                    if offset is None or unread < offset:
                        self.offset[id(header)] = offset = unread
                    if unread > offset:
                        out.add(name)
                        continue
                if getattr(conn, "stat_num_msg", 0) - self.base.get(id(header), 0) > self.done.get(id(header), 0):
                    out.add(name)
        return out


def _bytes_received(sock):
    """Bytes the kernel has received on TCP socket ``sock`` (Linux TCP_INFO ``tcpi_bytes_received``), or None."""
    try:
        return struct.unpack_from("Q", sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_INFO, 136), 128)[0]
    except (OSError, ValueError, AttributeError, struct.error):
        return None


def _readable(sock):
    """Whether ``sock`` has something to read now (data, or the peer's close), without waiting."""
    try:
        readable, _, _ = select.select([sock], [], [], 0.0)
        return bool(readable)
    except (OSError, ValueError):
        return False


def _closed(conn, sock):
    """Whether rospy closed ``conn`` already (its transport ``done``, its socket dropped): it stays in the
    publisher's list until rospy's cleanup removes it, and must not count as a subscriber that stays."""
    return getattr(conn, "done", False) or (sock is None and hasattr(conn, "done"))


def _closed_by_peer(sock):
    """Whether the other end closed ``sock``: readable now (a poll that does not wait: the socket's own timeout,
    set for sending, would make a peeking recv block for it) and reading end of file."""
    try:
        readable, _, _ = select.select([sock], [], [], 0.0)
        return bool(readable) and sock.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b""
    except (BlockingIOError, InterruptedError):
        return False
    except (OSError, ValueError):
        return True


def _is_local(host):
    if host in LOCAL_HOSTS:
        return True
    try:
        return host in (socket.gethostname(), socket.getfqdn()) or socket.gethostbyname(host).startswith("127.")
    except OSError:
        return False
