"""What a process does when its standard output or error goes away (pure; no rospy).

A user's terminal can hang up, and ``teleop_key | head -1`` closes the pipe after one line. Python keeps
``sys.stdout`` block-buffered when it is not a terminal, and line-buffered on one, unless
``PYTHONUNBUFFERED`` is set (it is on CI, not on a user's machine). Whatever is still in the buffer when
the stream is gone cannot be written, and the interpreter's final flush then turns a clean exit into status
120 with "Exception ignored ... BrokenPipeError" on stderr. Every entry point of the project therefore ends
through :func:`finish`, and writes that may meet a gone stream go through :func:`write`.

Once a stream is gone, its file descriptor is pointed at ``/dev/null``: later writes (rospy's log handler,
a status line, the interpreter's own flush) then succeed and go nowhere, which is all a reader who left
could ask for.
"""
import contextlib
import errno
import os
import sys

#: errno values meaning "nobody reads this stream any more": a closed pipe, a hung-up terminal, a
#: closed descriptor.
GONE = (errno.EPIPE, errno.EIO, errno.EBADF, errno.ECONNRESET, errno.ENXIO)


def discard(stream):
    """Point ``stream``'s file descriptor at /dev/null, so that it and anything sharing the descriptor
    writes without error from now on. A stream without a descriptor is left alone."""
    try:
        fd = stream.fileno()
    except (AttributeError, ValueError, OSError):
        return
    try:
        null = os.open(os.devnull, os.O_WRONLY)
    except OSError:
        return
    try:
        os.dup2(null, fd)
    except OSError:
        pass
    finally:
        os.close(null)


def _gone(err):
    return isinstance(err, ValueError) or getattr(err, "errno", None) in GONE


def flush(stream):
    """Flush ``stream``; returns False when its reader is gone (the stream is then discarded, and what
    was buffered is dropped). Other errors propagate."""
    try:
        stream.flush()
        return True
    except (OSError, ValueError) as err:
        if not _gone(err):
            raise
    discard(stream)
    with contextlib.suppress(OSError, ValueError):
        stream.flush()  # now to /dev/null: empties the buffer, so the interpreter's final flush succeeds
    return False


def write(stream, text, flush_now=True):
    """Write ``text`` to ``stream`` (and flush); returns False when the reader is gone (then discarded)."""
    try:
        stream.write(text)
    except (OSError, ValueError) as err:
        if not _gone(err):
            raise
        discard(stream)
        return False
    return flush(stream) if flush_now else True


def finish(status=0):
    """Flush standard output and error before the interpreter does, discarding whichever is gone.

    Returns ``status`` unchanged, so an entry point can end with ``return streams.finish(code)``.
    """
    for stream in (sys.stdout, sys.stderr):
        if stream is not None:
            with contextlib.suppress(OSError, ValueError):
                flush(stream)
    return status
