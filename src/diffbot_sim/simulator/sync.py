"""Fast, and never faster than the nodes in the loop: the simulator waits, after each sensor message, until the
nodes it fed have answered it.

Why: unbounded, the simulator steps as fast as PyBullet allows while gmapping, amcl, move_base or a learning
agent read its sensors when they can; a node that cannot keep up then sees a run nobody meant (gmapping skipped
three scans in four; a step-and-wait client held each action for a random stretch of sim time). A fixed factor
picked for one machine is too fast on a slower or busier one and wastes time on a faster one.

How (``~wait_for_nodes``, on by default whenever the simulator is not paced to the wall clock): the nodes in the
loop are the subscribers of its sensor topics (lasers, rangers, point clouds, cameras). After a step that
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
import socket
import time
import xmlrpc.client
from urllib.parse import urlparse

import rosgraph

#: wall seconds between two looks at the waited-for nodes
POLL = 0.0002
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
        self.listeners = {}  # publisher -> set of caller ids subscribed when it last published
        self.seq = {}  # publisher -> its message count when last looked at
        self.waited = 0.0  # wall seconds spent waiting, for the achieved-RTF report
        self.holds = 0

    # -- who is subscribed --------------------------------------------------------------------------------
    @staticmethod
    def subscribers(pub, peek=True):
        """Caller ids with an open connection to ``pub``. A subscriber that unsubscribed has closed its end,
        but rospy notices only at its next write: with ``peek`` the socket is peeked (a subscriber never sends
        after the handshake: no data means open, end of file means gone)."""
        impl = pub.impl
        if impl is None:
            return set()
        names = set()
        for conn in list(impl.connections):
            sock = getattr(conn, "socket", None)
            if peek and sock is not None:
                try:
                    if sock.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b"":
                        continue
                except (BlockingIOError, InterruptedError):
                    pass
                except OSError:
                    continue
            names.add(getattr(conn, "endpoint_id", None))
        return names - {None}

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
                subs = self.subscribers(pub, peek=False)  # who was sent the message (a closed one is seen later)
                if subs:
                    self.listeners[pub] = subs
                    fresh.append(pub)
        return fresh

    def watched(self):
        """Every node subscribed to a sensor topic when it last published: the nodes in the loop."""
        names = set()
        for listeners in self.listeners.values():
            names |= listeners
        return names

    def busy_nodes(self, now_wall):
        """(name, "busy") of the nodes in the loop that are working now (after a /clock tick woke their
        timers)."""
        out = []
        for name in self.watched():
            node = self._node(name)
            if node is not None and not node.dropped and node.busy(now_wall):
                out.append((name, "busy"))
        return out

    def pending(self, publishers, now_wall):
        """The nodes the simulator still waits for after ``publishers`` sent a message, as (name, why)
        pairs; no publishers: after a /clock tick (busy nodes only)."""
        if not publishers:
            return self.busy_nodes(now_wall)
        out = []
        for pub in publishers:
            now_subscribed = None
            for name in self.listeners.get(pub, ()):
                node = self._node(name)
                if node is None or node.dropped:
                    continue
                if node.busy(now_wall):
                    out.append((name, "busy"))
                    continue
                if now_subscribed is None:
                    now_subscribed = self.subscribers(pub)
                if name not in now_subscribed:
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
            pending = self.pending(publishers, now)
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
        """A node that subscribes anew is waited for again."""
        for pub in publishers:
            for name in self.subscribers(pub) - self.listeners.get(pub, set()):
                node = self.nodes.get(name)
                if node is not None:
                    node.dropped = False


def _is_local(host):
    if host in LOCAL_HOSTS:
        return True
    try:
        return host in (socket.gethostname(), socket.getfqdn()) or socket.gethostbyname(host).startswith("127.")
    except OSError:
        return False
