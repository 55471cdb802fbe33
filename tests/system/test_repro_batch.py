"""Reproducible in lockstep: the same scenario with the same seed gives the same trajectory, run
after run, alone or among 8 parallel batch runs.

The scenario is tests/rostest/loop_repro.test (a Gazebo-style step-and-wait client driving the laser robot with
actions from numpy's default_rng(seed), reset_simulation between its two episodes, random wall time of work between
steps; the simulator in fast mode with ~wait_for_nodes). Here it runs as a user runs it: `rostest` twice, one after
the other, then once with another seed; then examples/batch/repro.yaml (8 runs of the same seed) through
`batch --jobs 8`. Each run writes the body's ground-truth pose at every scan stamp; all runs of the seed must have
the same stamps and poses within TOLERANCE (x, y in m, yaw in rad). The trajectory must be worth comparing (the
body travelled and turned), and another seed must give another one (the comparison can fail).
"""
import json
import math
import os
import signal
import subprocess
import xml.etree.ElementTree as ET

import pytest
import yaml
from proctools import ROOT, SETUP

EXAMPLE = os.path.join(ROOT, "examples", "batch", "repro.yaml")
TOLERANCE = 1e-9  # m, rad: "identical"; not to be loosened (a difference is a fault to find, not noise)
MIN_PATH = 0.3  # m
MIN_TURN = 0.5  # rad
OTHER_SEED_DIFFERENCE = 1e-3  # m or rad: another seed's trajectory differs at least this much somewhere
RUN_TIMEOUT = 240.0  # wall s for one rostest run
BATCH_TIMEOUT = 600.0  # wall s for the batch of 8

pytestmark = pytest.mark.slow  # minutes of rostests: `make test-slow`


def example():
    """The example's scenario: (seed, steps, runs)."""
    with open(EXAMPLE) as f:
        scenario = yaml.safe_load(f)["scenarios"][0]
    return int(scenario["args"]["seed"]), int(scenario["args"]["steps"]), int(scenario.get("repeat", 1))


def in_workspace(command, **kw):
    """``command`` in a fresh bash that sources the workspace (a user's new terminal), in its own session."""
    return subprocess.Popen(["bash", "-c", f"source {SETUP} && exec {command}"], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True, **kw)


def finish(proc, timeout):
    """The output of ``proc`` once it ends; on timeout its whole session (ours) is killed and None returned."""
    try:
        return proc.communicate(timeout=timeout)[0]
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        return None


def verdict(results_dir):
    """(test cases, failure messages) of the rosunit result files under ``results_dir``."""
    cases, failures = 0, []
    for folder, _, files in os.walk(results_dir):
        for name in files:
            if not (name.startswith("rosunit-") and name.endswith(".xml")):
                continue
            for case in ET.parse(os.path.join(folder, name)).getroot().iter("testcase"):
                cases += 1
                bad = case.find("failure") if case.find("failure") is not None else case.find("error")
                if bad is not None:
                    text = (bad.get("message") or bad.text or bad.tag).split("\n  File ")[0]  # not the traceback
                    failures.append(" ".join(text.split())[:600])
    return cases, failures


def run_alone(tmp_path, name, seed, steps):
    """One `rostest diffbot_sim loop_repro.test` (its own master on a free port, its own ROS_HOME); returns the
    trajectory file and a list of what went wrong (exit status, result XML)."""
    base = tmp_path / name
    trajectory = base / "trajectory.json"
    env = dict(os.environ, ROS_HOME=str(base / "ros_home"))
    proc = in_workspace(f"rostest --results-base-dir {base / 'results'} diffbot_sim loop_repro.test seed:={seed} "
                        f"steps:={steps} trajectory_file:={trajectory}", env=env)
    out = finish(proc, RUN_TIMEOUT)
    problems = []
    if out is None:
        problems.append(f"{name}: rostest did not end within {RUN_TIMEOUT:.0f} s")
    cases, failures = verdict(base / "results")
    if cases == 0:
        problems.append(f"{name}: no test result (exit {proc.returncode}): {(out or '')[-800:]}")
    problems += [f"{name}: {message}" for message in failures]
    if proc.returncode != 0 and not problems:
        problems.append(f"{name}: rostest exited {proc.returncode}: {(out or '')[-800:]}")
    return str(trajectory), problems


def load(path):
    with open(path) as f:
        return {(r["episode"], r["stamp_ns"]): r for r in json.load(f)["rows"]}


def gap(a, b):
    """The largest difference of two samples' x, y (m) and yaw (rad, wrapped)."""
    dyaw = math.atan2(math.sin(b["yaw"] - a["yaw"]), math.cos(b["yaw"] - a["yaw"]))
    return max(abs(b["x"] - a["x"]), abs(b["y"] - a["y"]), abs(dyaw))


def difference(reference, other):
    """None when ``other`` has ``reference``'s stamps and poses within TOLERANCE; else what differs first, by how
    much, and the worst."""
    if reference.keys() != other.keys():
        missing, extra = sorted(reference.keys() - other.keys()), sorted(other.keys() - reference.keys())
        return f"other scan stamps (episode, ns): missing {missing[:6]}, extra {extra[:6]}"
    differing = [(key, gap(reference[key], other[key])) for key in sorted(reference)
                 if gap(reference[key], other[key]) > TOLERANCE]
    if not differing:
        return None
    (episode, stamp), first = differing[0]
    worst_key, worst = max(differing, key=lambda item: item[1])
    row, ref = other[(episode, stamp)], reference[(episode, stamp)]
    return (f"{len(differing)} of {len(reference)} poses differ; first at episode {episode} step {row['step']} "
            f"(sim {stamp / 1e9:.4f} s) by {first:.3g} (dx {row['x'] - ref['x']:.3g} m, "
            f"dy {row['y'] - ref['y']:.3g} m, "
            f"dyaw {row['yaw'] - ref['yaw']:.3g} rad); worst {worst:.3g} at episode {worst_key[0]} sim "
            f"{worst_key[1] / 1e9:.4f} s")


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Every run: {"alone": [(trajectory, problems)] x 2, "other_seed": (...), "batch": (records, stdout)}."""
    tmp_path = tmp_path_factory.mktemp("repro")
    seed, steps, repeat = example()
    got = {"seed": seed, "repeat": repeat}
    got["alone"] = [run_alone(tmp_path, f"alone{k}", seed, steps) for k in (1, 2)]
    got["other_seed"] = run_alone(tmp_path, "other_seed", seed + 1, steps)
    out = str(tmp_path / "batch")
    proc = in_workspace(f"rosrun diffbot_sim batch {EXAMPLE} --out {out} --jobs {repeat}")
    stdout = finish(proc, BATCH_TIMEOUT)
    records = []
    if os.path.exists(os.path.join(out, "results.jsonl")):
        with open(os.path.join(out, "results.jsonl")) as f:
            records = [json.loads(line) for line in f if line.strip()]
    got["batch"] = (records, stdout)
    return got


def test_the_same_seed_alone_twice_gives_the_same_trajectory(runs):
    (first, problems1), (second, problems2) = runs["alone"]
    assert os.path.exists(first) and os.path.exists(second), problems1 + problems2
    assert difference(load(first), load(second)) is None, (
        f"rostest run 2 against run 1: {difference(load(first), load(second))}; the runs said: {problems1 + problems2}")
    assert problems1 + problems2 == []


def test_the_trajectory_is_worth_comparing_and_another_seed_changes_it(runs):
    (first, _), _ = runs["alone"]
    other, problems = runs["other_seed"]
    reference = load(first)
    rows = [reference[key] for key in sorted(reference)]
    path = sum(math.hypot(b["x"] - a["x"], b["y"] - a["y"]) for a, b in zip(rows, rows[1:])
               if a["episode"] == b["episode"])
    turn = sum(abs(math.atan2(math.sin(b["yaw"] - a["yaw"]), math.cos(b["yaw"] - a["yaw"])))
               for a, b in zip(rows, rows[1:]) if a["episode"] == b["episode"])
    assert path > MIN_PATH and turn > MIN_TURN, f"the body travelled {path:.3f} m and turned {turn:.3f} rad"
    assert os.path.exists(other), problems
    changed = load(other)
    common = reference.keys() & changed.keys()
    assert max(gap(reference[k], changed[k]) for k in common) > OTHER_SEED_DIFFERENCE, \
        "seed+1 gave the seed's trajectory: the comparison could not fail"


def test_eight_parallel_batch_runs_give_the_trajectory_of_a_run_alone(runs):
    records, stdout = runs["batch"]
    assert stdout is not None, f"the batch did not end within {BATCH_TIMEOUT:.0f} s"
    assert len(records) == runs["repeat"], stdout
    (alone, _), _ = runs["alone"]
    reference = load(alone)
    differences, problems = {}, []
    for record in sorted(records, key=lambda r: r["name"]):
        path = os.path.join(record["log_dir"], "ros_home", "loop_repro", f"trajectory_seed{runs['seed']}.json")
        if not os.path.exists(path):
            problems.append(f"{record['name']}: {record['status']}, no trajectory ({record['reason']})")
            continue
        why = difference(reference, load(path))
        if why is not None:
            differences[record["name"]] = why
        if record["status"] != "passed":
            problems.append(f"{record['name']}: {record['status']}: {record['reason']}")
    assert differences == {}, f"batch runs against the first run alone: {differences}; runs: {problems}"
    assert problems == []
    digests = {r["metrics"].get("trajectory_digest") for r in records}
    assert len(digests) == 1 and None not in digests, f"METRIC trajectory_digest of the runs: {digests}"
