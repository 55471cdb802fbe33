"""Our publishers' TCP connections to their subscribers, tuned from outside rospy: a send timeout and
TCP_NODELAY on each, and TCP_CORK batching in fast mode.

rospy offers no hook for this, so :class:`SubscriberLinks` reaches into its internals: a ``rospy.Publisher``'s
``impl.connections`` (``rospy.topics._TopicImpl``) and each connection's ``socket``
(``rospy.impl.tcpros_base.TCPROSTransport``), as in rospy 1.15 (Debian bookworm's) and noetic's 1.16. It only
reads them and sets socket options; a connection rospy closes under it is skipped. Nothing here imports rospy:
the publishers are handed in.
"""
import socket


class SubscriberLinks:
    """Our publishers' TCP connections to subscribers: tuned once each, and batched in fast mode.

    Publishers are synchronous (the loop's thread writes; no queue thread per connection, which costs
    more CPU than the write itself), so a subscriber that stops reading must not stall the loop: each
    connection gets a send timeout, after which rospy closes and drops it (the loop goes on, the
    subscriber sees the connection end). TCP_NODELAY stops Nagle holding a small message for an ACK.

    In fast mode, a message to a subscriber that is asleep costs ~100-150 us of wall time (the loopback
    write wakes the receiver, a cross-CPU wake-up that is dear in a VM), far more than building it; so the
    connections are corked (TCP_CORK) while the loop publishes and uncorked every ``batch`` wall seconds:
    N writes become one wake-up per subscriber; messages and their order are unchanged, each arrives at
    most ``batch`` late. Real-time mode does not batch.
    """

    def __init__(self, publishers, send_timeout, batch):
        self.publishers = publishers  # callable returning the current publishers
        self.send_timeout = send_timeout
        self.batch = batch
        self.held_since = None
        self._tuned = set()  # the live sockets, as of the last scan (every 0.1 s at most)
        self._corked = []  # the sockets corked by the open batch
        self._next_scan = 0.0

    def _sockets(self):
        for pub in self.publishers():
            for conn in list(pub.impl.connections) if pub.impl is not None else ():
                sock = getattr(conn, "socket", None)
                if sock is not None and sock.family in (socket.AF_INET, socket.AF_INET6):
                    yield sock

    def tune_new(self, now_wall):
        """Give new connections their send timeout and TCP_NODELAY (a scan at most every 0.1 s)."""
        if now_wall < self._next_scan:
            return
        self._next_scan = now_wall + 0.1
        live = set()  # the socket objects themselves: an id() could be reused by a later socket
        for sock in self._sockets():
            live.add(sock)
            if sock not in self._tuned:
                try:
                    sock.settimeout(self.send_timeout)
                    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                except OSError:
                    pass  # closing under us: rospy drops it on its next write
        self._tuned = live

    @staticmethod
    def _cork(sockets, value):
        for sock in sockets:
            try:
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_CORK, value)
            except OSError:
                pass

    def hold(self, now_wall):
        """Fast mode, before publishing: start a batch unless one is open (on the sockets of the last scan: a
        connection newer than that is written at once, as in real time)."""
        if self.batch > 0 and self.held_since is None:
            self._corked = list(self._tuned)
            self._cork(self._corked, 1)
            self.held_since = now_wall

    def release_if_due(self, now_wall):
        if self.held_since is not None and now_wall - self.held_since >= self.batch:
            self.release()

    def release(self):
        """Send everything held now (also before the loop pauses, and at close)."""
        if self.held_since is not None:
            self._cork(self._corked, 0)
            self._corked = []
            self.held_since = None
