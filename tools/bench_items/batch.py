"""Item ``batch``: what ``rosrun diffbot_sim batch`` costs per run (the same rostest alone and through batch,
median of 5), and the drive example (its diffbot and 4wd x {empty, room} runs) at ``--jobs 1`` and ``--jobs 2``:
runs per hour per core and the speed-up on two cores."""
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

from benchkit.common import ROOT
from benchkit.report import Item

DRIVE_SPEC = ("scenarios:\n  - name: drive-{robot}-{world}-{seed}\n    test: diffbot_sim/tests/rostest/drive.test\n"
              "    matrix: {robot: [diffbot, 4wd], world: [empty.world, room.world], seed: [1]}\n")


def run_batch(spec, out, jobs):
    """Run `batch` on ``spec`` (fresh ``out``); its records and wall time."""
    from diffbot_sim.batch import results as batch_results
    shutil.rmtree(out, ignore_errors=True)
    t0 = time.monotonic()
    subprocess.run([sys.executable, "-m", "diffbot_sim.nodes.batch_cli", spec, "--out", out, "--jobs", str(jobs)],
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
    wall = time.monotonic() - t0
    return list(batch_results.load(os.path.join(out, "results.jsonl")).values()), wall


def batch(runs):
    """The overhead per run (median of ``runs``), then the drive example at --jobs 1 and 2."""
    tmp = tempfile.mkdtemp(prefix="bench_batch_")
    test = os.path.join(ROOT, "tests", "rostest", "sleeper.test")
    alone = []
    for _ in range(runs):
        t0 = time.monotonic()
        subprocess.run(["rostest", "--results-base-dir", os.path.join(tmp, "alone"), test],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
        alone.append(time.monotonic() - t0)
    spec = os.path.join(tmp, "one.yaml")
    with open(spec, "w") as f:
        f.write(f"scenarios:\n  - name: one\n    test: {test}\n")
    through = [run_batch(spec, os.path.join(tmp, "one"), 1)[1] for _ in range(runs)]
    spec = os.path.join(tmp, "drive.yaml")
    with open(spec, "w") as f:
        f.write(DRIVE_SPEC)
    result = {"rostest_alone_s": statistics.median(alone), "through_batch_s": statistics.median(through)}
    for jobs in (1, 2):
        records, wall = run_batch(spec, os.path.join(tmp, f"drive{jobs}"), jobs)
        result[f"jobs{jobs}"] = {"wall_s": wall, "runs": len(records),
                                 "passed": sum(r["status"] == "passed" for r in records),
                                 "runs_per_hour_per_core": len(records) / wall * 3600 / jobs,
                                 "median_rtf": statistics.median(r["rtf"] for r in records)}
    shutil.rmtree(tmp, ignore_errors=True)
    return result


def rows(r):
    if not r.get("batch"):
        return []
    b = r["batch"]
    return [("batch: overhead per run over the same rostest alone (median)",
             f"{b['through_batch_s'] - b['rostest_alone_s']:.2f} s", "< 1 s"),
            ("batch: drive runs per hour per core, --jobs 1 / --jobs 2",
             f"{b['jobs1']['runs_per_hour_per_core']:.0f} / {b['jobs2']['runs_per_hour_per_core']:.0f}", ""),
            ("  speed-up of --jobs 2 over --jobs 1 (2 cores)", f"{b['jobs1']['wall_s'] / b['jobs2']['wall_s']:.2f}",
             "")]


ITEMS = [Item("batch", lambda q: batch(2 if q else 5), rows)]
PROBES = {}
