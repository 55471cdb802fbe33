"""Everything the keyboard teleop does with its terminal; the only module that touches termios.

Keys are read one byte at a time with ``select`` and a timeout, so the caller's single-threaded loop also
gets to run key timeouts, repeats and signal checks. While keys are read the terminal is in a "raw input,
cooked output" mode: no echo, no line buffering, and no signal keys (Ctrl-C arrives as the byte ``\\x03``,
so quitting goes through the same path as any key). Output processing stays on, so a log line printed by
another thread still starts at the left margin.
"""
import contextlib
import errno
import os
import select
import termios

from diffbot_sim import streams
from diffbot_sim.errors import TerminalError

#: What :func:`read_key` returns when standard input is closed (end of file, or the terminal hung up).
EOF = ""

NOT_A_TTY = ("teleop_key: standard input is not a terminal; run it with `rosrun diffbot_sim teleop_key` in a "
             "terminal, or `roslaunch diffbot_sim teleop.launch` (it opens an xterm)")

# termios attribute list indices (see termios.tcgetattr).
_IFLAG, _LFLAG, _CC = 0, 3, 6


def require_tty(fd):
    """Check that ``fd`` is a terminal before anything else starts.

    Raises:
        TerminalError: ``fd`` is closed, a file, a pipe or /dev/null (e.g. under roslaunch without an xterm).
    """
    if not os.isatty(fd):
        raise TerminalError(NOT_A_TTY)


def key_mode(attrs):
    """Return a copy of termios ``attrs`` with raw input and unchanged output (see the module docstring)."""
    mode = [list(item) if isinstance(item, list) else item for item in attrs]
    # IXON off: Ctrl-S would otherwise freeze our output, and a blocked status write would stall the loop.
    mode[_IFLAG] &= ~(termios.IXON | termios.ICRNL | termios.INLCR | termios.IGNCR | termios.ISTRIP)
    mode[_LFLAG] &= ~(termios.ECHO | termios.ECHONL | termios.ICANON | termios.ISIG | termios.IEXTEN)
    mode[_CC][termios.VMIN] = 1
    mode[_CC][termios.VTIME] = 0
    return mode


@contextlib.contextmanager
def raw_terminal(fd):
    """Put terminal ``fd`` in key mode for the ``with`` block, and always put the saved attributes back.

    The restore runs in ``finally``, so it also happens when the block raises (including from a signal
    handler). A terminal that is gone by then (hung up, closed) cannot be restored, and is left alone.

    Raises:
        TerminalError: ``fd`` is not a terminal.
    """
    try:
        saved = termios.tcgetattr(fd)
    except termios.error as err:
        raise TerminalError(NOT_A_TTY) from err
    try:
        termios.tcsetattr(fd, termios.TCSANOW, key_mode(saved))
        yield
    finally:
        # TCSANOW rather than TCSADRAIN: draining waits for the reader of our output, which may never come.
        with contextlib.suppress(termios.error, OSError):
            termios.tcsetattr(fd, termios.TCSANOW, saved)


def read_key(fd, timeout, wake_fd=None):
    """Wait up to ``timeout`` seconds for one key.

    Args:
        fd: the terminal to read.
        timeout: seconds to wait; None waits until a key (or a wake-up) arrives.
        wake_fd: optional readable end of a pipe (e.g. ``signal.set_wakeup_fd``) that ends the wait early;
            its pending bytes are drained.

    Returns:
        A one-character string; None when the time ran out or ``wake_fd`` woke us; :data:`EOF` when
        standard input is closed or the terminal hung up.
    """
    fds = [fd] if wake_fd is None else [fd, wake_fd]
    ready, _, _ = select.select(fds, [], [], timeout)
    if wake_fd is not None and wake_fd in ready:
        _drain(wake_fd)
        return None
    if fd not in ready:
        return None
    try:
        data = os.read(fd, 1)
    except OSError as err:
        # A pty whose other side closed reads as EIO on Linux: that is the terminal's end of file.
        if err.errno == errno.EIO:
            return EOF
        raise
    # latin-1 maps every byte to one character, so a stray byte of a multi-byte key never raises.
    return data.decode("latin-1") if data else EOF


def _drain(fd):
    with contextlib.suppress(BlockingIOError, InterruptedError):
        while os.read(fd, 512):
            pass


class StatusLine:
    """One line of the terminal, rewritten in place (carriage return + clear to end of line) on change.

    The text is cut to the terminal's width, because a wrapped line could not be rewritten by ``\\r``.
    When ``stream`` is not a terminal nothing is written: a log file full of ``\\r`` rewrites helps nobody.
    A terminal that goes away (EIO, broken pipe) silently ends the status line.

    Args:
        stream: a text stream, normally ``sys.stdout``.
    """

    def __init__(self, stream):
        self._stream = stream
        try:
            self._enabled = stream.isatty()
        except (AttributeError, ValueError, OSError):
            self._enabled = False
        self._shown = None

    def show(self, text):
        """Replace the line with ``text`` (no-op when it is unchanged)."""
        if not self._enabled or text == self._shown:
            return
        try:
            width = os.get_terminal_size(self._stream.fileno()).columns
        except (OSError, ValueError):
            width = 0
        width = width or 80  # a pseudo-terminal nobody sized reports 0 columns
        self._write("\r" + text[:max(width - 1, 1)] + "\x1b[K")
        self._shown = text

    def end(self):
        """Move below the status line, so whatever is printed next starts on a fresh line."""
        if self._enabled and self._shown is not None:
            self._write("\n")
            self._shown = None

    def _write(self, data):
        if not streams.write(self._stream, data):
            self._enabled = False  # the terminal is gone (its descriptor now writes to /dev/null)
