"""streams: output whose reader went away never changes a process's exit status (no exit 120)."""
import os
import subprocess
import sys

import pytest

from diffbot_sim import streams

SRC = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "src")

# Buffered output (as on a user's machine) still in the buffer when the process ends.
PROGRAM = """
import sys
sys.path.insert(0, {src!r})
from diffbot_sim import streams
sys.stdout.write("x" * 100)
{ending}
"""


def _run_with_closed_stdout(ending):
    read_end, write_end = os.pipe()
    os.close(read_end)  # the reader left before anything was written (`prog | head -0`)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    try:
        proc = subprocess.run([sys.executable, "-c", PROGRAM.format(src=SRC, ending=ending)],
                              stdout=write_end, stderr=subprocess.PIPE, env=env, timeout=30)
    finally:
        os.close(write_end)
    return proc.returncode, proc.stderr.decode()


def test_without_finish_the_interpreter_exits_120():
    """The fault itself, so the next test is known to be able to fail."""
    code, err = _run_with_closed_stdout("")
    assert code == 120
    assert "Exception ignored" in err


def test_finish_keeps_status_and_stderr_clean():
    code, err = _run_with_closed_stdout("sys.exit(streams.finish(0))")
    assert code == 0
    assert err == ""


def test_write_reports_a_gone_reader_and_later_writes_succeed(tmp_path):
    read_end, write_end = os.pipe()
    os.close(read_end)
    stream = os.fdopen(write_end, "w")
    try:
        assert streams.write(stream, "hello\n") is False
        assert streams.write(stream, "again\n") is True  # now /dev/null
        assert streams.flush(stream) is True
    finally:
        stream.close()


def test_flush_propagates_other_errors():
    class Full:
        def flush(self):
            raise OSError(28, "No space left on device")

    with pytest.raises(OSError):
        streams.flush(Full())


def test_write_to_a_live_stream(tmp_path):
    path = tmp_path / "out.txt"
    with open(path, "w") as stream:
        assert streams.write(stream, "line\n") is True
    assert path.read_text() == "line\n"
