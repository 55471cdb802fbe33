"""`batch` for real: a local batch of real scenario runs (our robots driving, judged by ground truth) beside
runs that fail, hang past their timeout, or are stopped by Ctrl-C; and the same runner on a two-node Ray
cluster started on this machine (Ray's own test-cluster helper: a head and a worker node, loopback, no
dashboard), whose results must show runs on both nodes, and a run whose Ray worker is killed mid-run run
again on the other node and recorded once. Every run's processes must be gone after."""
import contextlib
import glob
import json
import os
import signal
import subprocess
import tempfile
import time

import pytest
from proctools import SETUP

MARKER = b"DIFFBOT_BATCH_RUN="


def batch_processes():
    """Pids of processes of any batch run (their environment carries the run marker)."""
    pids = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/environ", "rb") as f:
                    if MARKER in f.read():
                        pids.append(int(entry))
            except OSError:
                pass
    return pids


def _as_a_terminal_starts_it():
    """Ctrl-C's default action, as a terminal's foreground job has it. Started in the background by a script
    (`make test &`, a CI wrapper), the tests inherit SIGINT ignored, and Python then never raises
    KeyboardInterrupt: a batch would not stop at Ctrl-C because of how the tests were started."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def batch(args, **kw):
    """`rosrun diffbot_sim batch ...` from a fresh bash that sources the workspace (a user's new terminal)."""
    cmd = f"source {SETUP} && exec rosrun diffbot_sim batch " + " ".join(args)
    return subprocess.Popen(["bash", "-c", cmd], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=_as_a_terminal_starts_it, **kw)


def records(out):
    with open(os.path.join(out, "results.jsonl")) as f:
        return {r["name"]: r for r in map(json.loads, f)}


SLEEPER = "diffbot_sim/tests/rostest/sleeper.test"


def test_local_batch_of_real_runs_with_a_failure_and_a_timeout(tmp_path):
    spec = tmp_path / "s.yaml"
    spec.write_text(f"""
scenarios:
  - name: drive-{{robot}}-{{world}}
    test: diffbot_sim/tests/rostest/drive.test
    matrix: {{robot: [diffbot], world: [empty.world, room.world]}}
    args: {{seed: 1}}
    timeout: 240
  - name: drive-4wd-empty
    test: diffbot_sim/tests/rostest/drive.test
    args: {{robot: 4wd, world: empty.world}}
    timeout: 240
  - name: passes
    test: {SLEEPER}
  - name: fails
    test: {SLEEPER}
    args: {{outcome: fail}}
  - name: hangs
    test: {SLEEPER}
    args: {{outcome: hang}}
    timeout: 12
""")
    out = str(tmp_path / "out")
    proc = batch([str(spec), "--out", out, "--jobs", "2"])
    stdout, stderr = proc.communicate(timeout=600)
    assert proc.returncode == 1, stderr  # not every run passed
    got = records(out)
    assert {n: r["status"] for n, r in got.items()} == {
        "drive-diffbot-empty.world": "passed", "drive-diffbot-room.world": "passed", "drive-4wd-empty": "passed",
        "passes": "passed", "fails": "failed", "hangs": "timeout"}, stderr
    for name in ("drive-diffbot-empty.world", "drive-diffbot-room.world", "drive-4wd-empty"):
        r = got[name]
        # The run's sim time came from its /clock, and its RTF is that over its wall time. How fast that is
        # depends on the machine (0.375 on a quarter of a core for a 3x real-time run), so no bound on it.
        assert r["sim_s"] > 8.0 and r["tests"] >= 1 and r["failures"] == 0, r
        assert r["rtf"] > 0 and abs(r["rtf"] - r["sim_s"] / r["wall_s"]) < 0.01, r
        assert r["args"].get("seed", "1") == "1" and r["node"]
    assert got["fails"]["failures"] == 1 and "told to fail" in got["fails"]["reason"]
    assert 12.0 <= got["hangs"]["wall_s"] < 30.0
    assert os.path.isfile(os.path.join(got["hangs"]["log_dir"], "console.log"))  # its log folder is kept
    assert batch_processes() == []  # the hanging node's own-session child too
    assert "timeouts  1" in stdout and "failed    1" in stdout
    assert open(os.path.join(out, "summary.txt")).read() == stdout
    junit = open(os.path.join(out, "junit.xml")).read()
    assert junit.count("<testsuite ") == 6

    # Resume: nothing left to run. --rerun with --filter: that run only, again.
    proc = batch([str(spec), "--out", out])
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 1 and "6 already recorded" in stderr and "running 0" in stderr
    proc = batch([str(spec), "--out", out, "--filter", "^passes$", "--rerun"])
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 0, stderr
    assert list(records(out)) == ["passes"]


def test_bad_input_is_one_line_and_exit_2_before_anything_runs(tmp_path):
    spec = tmp_path / "s.yaml"
    spec.write_text(f"scenarios:\n  - name: run-{{seed}}\n    test: {SLEEPER}\n    matrix: {{world: [a, b]}}\n")
    proc = batch([str(spec), "--out", str(tmp_path / "out")])
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 2
    assert stderr.strip().count("\n") == 0 and "'{seed}' is neither in args nor in matrix" in stderr
    assert not (tmp_path / "out").exists()


def test_ctrl_c_stops_every_run_and_keeps_the_results(tmp_path):
    spec = tmp_path / "s.yaml"
    spec.write_text(f"""
scenarios:
  - name: quick
    test: {SLEEPER}
  - name: hang-{{k}}
    test: {SLEEPER}
    args: {{outcome: hang}}
    matrix: {{k: [1, 2, 3]}}
""")
    out = str(tmp_path / "out")
    proc = batch([str(spec), "--out", out, "--jobs", "2"])
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not os.path.exists(os.path.join(out, "results.jsonl")):
        time.sleep(0.2)
    while time.monotonic() < deadline and not any("sleep" in open(f"/proc/{p}/cmdline").read()
                                                  for p in batch_processes() if os.path.exists(f"/proc/{p}")):
        time.sleep(0.2)  # a hanging run has started its child
    os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C reaches the terminal's whole process group
    try:
        _, stderr = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        # Where it is stuck (batch dumps its threads on SIGUSR1), then nothing of it left for the next tests.
        os.killpg(proc.pid, signal.SIGUSR1)
        time.sleep(2.0)
        os.killpg(proc.pid, signal.SIGKILL)
        _, stderr = proc.communicate(timeout=30)
        for pid in batch_processes():
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        pytest.fail(f"batch did not end within 60 s of Ctrl-C; its threads then:\n{stderr[-6000:]}")
    assert proc.returncode == 130, stderr
    assert list(records(out)) == ["quick"]  # the stopped runs are not recorded: a resume runs them
    deadline = time.monotonic() + 10
    while batch_processes() and time.monotonic() < deadline:
        time.sleep(0.1)
    assert batch_processes() == []


def test_two_node_ray_cluster_runs_on_both_nodes(tmp_path, monkeypatch):
    monkeypatch.setenv("RAY_USAGE_STATS_ENABLED", "0")
    from ray.cluster_utils import Cluster

    work_before = set(glob.glob(os.path.join(tempfile.gettempdir(), "diffbot_batch_*")))
    cluster = Cluster(initialize_head=True, head_node_args={"num_cpus": 1, "include_dashboard": False,
                                                            "node_ip_address": "127.0.0.1"})
    try:
        cluster.add_node(num_cpus=1, node_ip_address="127.0.0.1")
        cluster.wait_for_nodes()
        spec = tmp_path / "s.yaml"
        spec.write_text(f"scenarios:\n  - name: run-{{k}}\n    test: {SLEEPER}\n"
                        f"    args: {{seconds: 3}}\n    matrix: {{k: [1, 2, 3, 4]}}\n"
                        f"  - name: loses-its-worker\n    test: {SLEEPER}\n    args: {{outcome: lose_worker}}\n")
        out = str(tmp_path / "out")
        proc = batch([str(spec), "--out", out, "--ray", cluster.address])
        _, stderr = proc.communicate(timeout=300)
        assert proc.returncode == 0, stderr
        got = records(out)
        lines = open(os.path.join(out, "results.jsonl")).read().splitlines()
        assert sorted(got) == ["loses-its-worker", "run-1", "run-2", "run-3", "run-4"] and len(lines) == 5
        assert len({r["node"] for r in got.values()}) == 2, got  # one CPU a node: both nodes ran some
        # A worker killed mid-run (SIGKILL, as a lost machine): the run ran again on the other node, recorded once.
        lost = got["loses-its-worker"]
        assert lost["status"] == "passed" and lost["attempt"] == 2, lost
        assert lost["retried_from"] and lost["retried_from"] != lost["node"], lost
        assert "worker or node was lost" in stderr
        for r in got.values():  # the run's folder came back to this machine
            assert r["log_dir"].startswith(out) and os.path.isfile(os.path.join(r["log_dir"], "console.log"))
    finally:
        cluster.shutdown()
    # the lost attempt's rostest too: ended, but a loaded machine takes its time to reap what the shut-down
    # cluster's workers leave (a clean-machine run beside other tests still saw two a moment after shutdown)
    deadline = time.monotonic() + 30
    while batch_processes() and time.monotonic() < deadline:
        time.sleep(0.2)
    assert batch_processes() == []
    assert set(glob.glob(os.path.join(tempfile.gettempdir(), "diffbot_batch_*"))) <= work_before  # none left


@pytest.mark.slow
def test_the_drive_example_gives_the_same_verdicts_alone_and_among_8(tmp_path):
    """examples/batch/drive.yaml (12 runs, each judged by ground truth) one at a time and eight at once on this
    machine: no run may disturb another (ports, log folders, mesh cache, /tmp), so every verdict is the same."""
    example = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                           "examples", "batch", "drive.yaml")
    verdicts = {}
    for jobs in (1, 8):
        out = str(tmp_path / f"jobs{jobs}")
        proc = batch([example, "--out", out, "--jobs", str(jobs)])
        _, stderr = proc.communicate(timeout=1800)
        got = records(out)
        assert len(got) == 12, stderr
        verdicts[jobs] = {n: r["status"] for n, r in got.items()}
        for r in got.values():
            assert r["sim_s"] > 8.0, r
        assert batch_processes() == []
    assert verdicts[1] == verdicts[8]
    assert set(verdicts[1].values()) == {"passed"}, verdicts[1]
