"""The teleop's terminal handling, on pseudo-terminals: mode and restore, key reads, status line."""
import fcntl
import io
import os
import pty
import struct
import termios
import time

import pytest

from diffbot_sim.errors import DiffbotSimError, TerminalError
from diffbot_sim.teleop.terminal import EOF, NOT_A_TTY, StatusLine, key_mode, raw_terminal, read_key, require_tty


@pytest.fixture
def pty_pair():
    """(master, slave) file descriptors of a fresh pseudo-terminal; closed afterwards."""
    master, slave = pty.openpty()
    fds = {"master": master, "slave": slave}
    yield fds
    for fd in fds.values():
        if fd is not None:
            try:
                os.close(fd)
            except OSError:
                pass


def lflag(fd):
    return termios.tcgetattr(fd)[3]


def test_raw_terminal_sets_key_mode_and_restores_exactly(pty_pair):
    slave = pty_pair["slave"]
    before = termios.tcgetattr(slave)
    with raw_terminal(slave):
        inside = lflag(slave)
        assert not inside & termios.ECHO
        assert not inside & termios.ICANON
        assert not inside & termios.ISIG  # Ctrl-C must arrive as a byte
        assert termios.tcgetattr(slave)[1] == before[1]  # output processing untouched
    assert termios.tcgetattr(slave) == before


def test_raw_terminal_restores_when_the_block_raises(pty_pair):
    slave = pty_pair["slave"]
    before = termios.tcgetattr(slave)
    with pytest.raises(KeyboardInterrupt), raw_terminal(slave):
        raise KeyboardInterrupt  # what a signal handler raising looks like to the block
    assert termios.tcgetattr(slave) == before
    with pytest.raises(ValueError), raw_terminal(slave):
        raise ValueError("boom")
    assert termios.tcgetattr(slave) == before


def test_raw_terminal_keeps_a_non_default_mode(pty_pair):
    slave = pty_pair["slave"]
    custom = termios.tcgetattr(slave)
    custom[3] &= ~termios.ECHOCTL
    custom[6][termios.VINTR] = b"\x07"
    termios.tcsetattr(slave, termios.TCSANOW, custom)
    before = termios.tcgetattr(slave)
    with raw_terminal(slave):
        pass
    assert termios.tcgetattr(slave) == before


def test_raw_terminal_tolerates_a_terminal_that_hangs_up(pty_pair):
    with raw_terminal(pty_pair["slave"]):
        os.close(pty_pair["master"])
        pty_pair["master"] = None
    # No exception: there is nothing left to restore.


def test_key_mode_does_not_modify_its_argument(pty_pair):
    attrs = termios.tcgetattr(pty_pair["slave"])
    copy = [list(a) if isinstance(a, list) else a for a in attrs]
    key_mode(attrs)
    assert attrs == copy


def test_read_key_returns_each_key_and_ctrl_c_as_byte(pty_pair):
    master, slave = pty_pair["master"], pty_pair["slave"]
    with raw_terminal(slave):
        os.write(master, b"ik\x03")
        assert [read_key(slave, 1.0) for _ in range(3)] == ["i", "k", "\x03"]


def test_read_key_times_out_with_none(pty_pair):
    """It waits the timeout (0.05 s), not less; the upper bound (60x) only catches a wait that ignores it,
    and no busy machine stalls that long."""
    with raw_terminal(pty_pair["slave"]):
        started = time.monotonic()
        assert read_key(pty_pair["slave"], 0.05) is None
        assert 0.04 <= time.monotonic() - started < 3.0


def test_read_key_non_ascii_byte_is_one_char(pty_pair):
    with raw_terminal(pty_pair["slave"]):
        os.write(pty_pair["master"], "é".encode())
        assert len(read_key(pty_pair["slave"], 1.0)) == 1
        assert len(read_key(pty_pair["slave"], 1.0)) == 1


def test_read_key_eof_when_the_terminal_hangs_up(pty_pair):
    with raw_terminal(pty_pair["slave"]):
        os.close(pty_pair["master"])
        pty_pair["master"] = None
        assert read_key(pty_pair["slave"], 1.0) == EOF


def test_read_key_eof_on_closed_pipe():
    read_end, write_end = os.pipe()
    os.close(write_end)
    try:
        assert read_key(read_end, 1.0) == EOF
    finally:
        os.close(read_end)


def test_read_key_wakes_on_wake_fd_and_drains_it(pty_pair):
    wake_r, wake_w = os.pipe()
    os.set_blocking(wake_r, False)
    try:
        os.write(wake_w, b"\x0f\x0f")
        started = time.monotonic()
        # the wake returns at once (well under 0.01 s); a 10 s bound tells it from the 60 s timeout on any machine
        assert read_key(pty_pair["slave"], 60.0, wake_fd=wake_r) is None
        assert time.monotonic() - started < 10.0
        with pytest.raises(BlockingIOError):
            os.read(wake_r, 1)
    finally:
        os.close(wake_r)
        os.close(wake_w)


def test_require_tty_accepts_a_pty(pty_pair):
    require_tty(pty_pair["slave"])


def test_require_tty_refuses_a_pipe_and_devnull():
    read_end, write_end = os.pipe()
    devnull = os.open(os.devnull, os.O_RDONLY)
    try:
        for fd in (read_end, devnull):
            with pytest.raises(TerminalError) as info:
                require_tty(fd)
            assert str(info.value) == NOT_A_TTY
            assert isinstance(info.value, DiffbotSimError)
    finally:
        for fd in (read_end, write_end, devnull):
            os.close(fd)


def test_not_a_tty_message_is_one_helpful_line():
    assert "\n" not in NOT_A_TTY
    assert NOT_A_TTY.startswith("teleop_key: standard input is not a terminal")
    assert "rosrun diffbot_sim teleop_key" in NOT_A_TTY and "teleop.launch" in NOT_A_TTY


def test_raw_terminal_on_a_non_tty_raises_terminal_error():
    read_end, write_end = os.pipe()
    try:
        with pytest.raises(TerminalError), raw_terminal(read_end):
            pass
    finally:
        os.close(read_end)
        os.close(write_end)


def read_all(master, size, timeout=5.0):
    """Read ``size`` bytes from a pty master: the line discipline may pass several writes on in pieces, so
    one os.read can return only the first (seen once under load)."""
    import select
    import time

    data, deadline = b"", time.monotonic() + timeout
    while len(data) < size and time.monotonic() < deadline:
        ready, _, _ = select.select([master], [], [], 0.05)
        if ready:
            data += os.read(master, 4096)
    return data


def test_status_line_rewrites_in_place(pty_pair):
    master, slave = pty_pair["master"], pty_pair["slave"]
    with open(os.dup(slave), "w", encoding="utf-8") as stream:
        status = StatusLine(stream)
        status.show("one")
        status.show("one")  # unchanged: not written again
        status.show("two")
        status.end()
    expected = b"\rone\x1b[K\rtwo\x1b[K\r\n"
    out = read_all(master, len(expected))
    # The final "\n" reaches the master as "\r\n": output processing (ONLCR) stays on.
    assert out == expected


def test_status_line_is_cut_to_the_terminal_width(pty_pair):
    master, slave = pty_pair["master"], pty_pair["slave"]
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 20, 0, 0))
    with open(os.dup(slave), "w", encoding="utf-8") as stream:
        StatusLine(stream).show("x" * 100)
    expected = b"\r" + b"x" * 19 + b"\x1b[K"
    assert read_all(master, len(expected)) == expected


def test_status_line_writes_nothing_when_not_a_terminal():
    stream = io.StringIO()
    status = StatusLine(stream)
    status.show("text")
    status.end()
    assert stream.getvalue() == ""


def test_status_line_survives_a_dead_terminal():
    class Dead(io.StringIO):
        def isatty(self):
            return True

        def write(self, _data):
            raise OSError(5, "Input/output error")

    status = StatusLine(Dead())
    status.show("a")
    status.show("b")
    status.end()
