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
  has subscribed again: it has sent its answer and waits for the next message — lockstep.

A node is found by the subscriber's caller id (the master's ``lookupNode``, then its own ``getPid``); one on
another host, or one matching ``~wait_for_nodes_ignore`` (rviz by default: it renders all the time), is not
waited for. A node that keeps the simulator waiting longer than ``~wait_for_nodes_timeout`` wall seconds at
one message is named in one warning and not waited for again until it subscribes anew: the lag is bounded.
While it waits, the loop keeps serving requests (services, spawns, resets).
"""
import fnmatch
import os
import select
import socket
import time
import xmlrpc.client
from urllib.parse import urlparse

import rosgraph

#: wall seconds between two looks at the waited-for nodes
POLL = 0.0002
#: wall seconds a subscriber that connected since the previous message is given to drop its connection (a
#: rospy.wait_for_message client drops it within its 10 ms poll) before it counts as one that stays
FRESH_GRACE = 0.05
LOCAL_HOSTS = ("localhost", "127.0.0.1", "::1")


class WatchedNode:
    """A subscriber node's process, as /proc shows it (one open file per thread: a re-read costs ~4 us)."""

    def __init__(self, name, pid):
        self.name, self.pid = name, pid
        self.task_dir = f"/proc/{pid}/task"
        self._fds = {}  # tid -> open /proc/<pid>/task/<tid>/stat
        self._listed = -1.0
        self.dropped = False  # exceeded the timeout: not waited for until it subscribes anew

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
        self._connections = {}  # publisher -> the connections it had at its previous message
        self.commanders = set()  # caller ids publishing to the simulator's command topics (note_commanders)
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
            if name is None or (peek and sock is not None and _closed_by_peer(sock)):
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
                    # fresh: connected since the previous message, as a one-shot (wait_for_message) subscriber is
                    self.listeners[pub] = {name: (conn, conn not in before) for conn, name in conns.items()}
                    fresh.append(pub)
        return fresh

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
        ``wait_for_message`` client's is) and FRESH_GRACE has not passed, in which case the client is given
        the time to drop it; or on a new connection (a client that dropped the old one and waits again)."""
        if not publishers:
            return self.busy_nodes(now_wall)
        out = []
        for pub in publishers:
            now = None
            for name, (conn, fresh) in self.listeners.get(pub, {}).items():
                node = self._node(name)
                if node is None or node.dropped:
                    continue
                if node.busy(now_wall):
                    out.append((name, "busy"))
                    continue
                if now is None:
                    now = self.connections(pub)
                if conn in now:
                    if fresh and elapsed < FRESH_GRACE:
                        out.append((name, "a new subscriber: dropping it after one message?"))
                elif name not in now.values():
                    out.append((name, f"not subscribed to {pub.resolved_name} again yet"))
        return out

    def wait(self, publishers, serve, stop):
        """Hold until every listener of ``publishers`` has answered (see the module docstring); ``serve()``
        handles the loop's requests meanwhile, ``stop()`` ends the wait early (pause, shutdown). No publishers:
        after a /clock tick, until no node in the loop is busy."""
        started = time.monotonic()
        self.holds += 1
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
                    self.warn(f"sync:{name}", f"bullet_sim: {name} kept the simulator waiting {now - since:.1f} s "
                              f"({why}); not waiting for it until it subscribes again (~wait_for_nodes_timeout)")
            time.sleep(POLL)
            serve()
        self.waited += time.monotonic() - started

    def forget_drops(self, publishers):
        """A node that subscribes anew (a fresh connection got this message) is waited for again."""
        for pub in publishers:
            for name, (_, fresh) in self.listeners.get(pub, {}).items():
                node = self.nodes.get(name)
                if fresh and node is not None:
                    node.dropped = False


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
