"""``batch``: run many rostest scenarios in parallel, here or on a Ray cluster, and collect the results.

    rosrun diffbot_sim batch SCENARIOS.yaml --out DIR [--jobs N] [--ray [ADDRESS]] [--filter REGEX] [--rerun]

Writes DIR/results.jsonl (a record per run, as each ends), DIR/junit.xml, DIR/summary.txt and DIR/runs/<name>/
(each run's logs). Runs already recorded in DIR are skipped (resume); --rerun runs them all again. Exit status:
0 when every run passed, 1 when one did not, 2 on bad input (before anything runs), 130 after Ctrl-C (the
results so far are kept). Not a rospy node: every run's ROS processes are its children.
"""
import argparse
import faulthandler
import os
import re
import signal
import sys
import time
import uuid

from diffbot_sim import streams
from diffbot_sim.batch import executors, results, scenarios
from diffbot_sim.nodes._entry import entry_point


def _find_package(name):
    import rospkg

    try:
        return rospkg.RosPack().get_path(name)
    except rospkg.ResourceNotFound:
        raise KeyError(name) from None


def _parser():
    p = argparse.ArgumentParser(prog="batch", description="Run rostest scenarios in parallel and collect results.")
    p.add_argument("scenarios", metavar="SCENARIOS.yaml")
    p.add_argument("--out", required=True, metavar="DIR", help="results folder (created; reused to resume)")
    p.add_argument("--jobs", type=int, default=max(1, (os.cpu_count() or 2) // 2),
                   help="runs at once on this machine (default: half the cores, at least 1)")
    p.add_argument("--ray", nargs="?", const="", default=None, metavar="ADDRESS",
                   help="run each run as a Ray task on the cluster at ADDRESS; alone: a local Ray instance")
    p.add_argument("--filter", default=None, metavar="REGEX", help="only runs whose name matches (re.search)")
    p.add_argument("--rerun", action="store_true", help="run every run again, even those already recorded")
    return p


def say(text):
    streams.write(sys.stderr, text + "\n")


@entry_point
def main(argv=None):
    """Entry point of ``rosrun diffbot_sim batch``; returns the exit status."""
    # `kill -USR1 <pid>` prints where every thread of a batch that seems stuck is (on standard error).
    faulthandler.register(signal.SIGUSR1, all_threads=True)
    args = _parser().parse_args(sys.argv[1:] if argv is None else argv)
    if args.jobs < 1:
        say(f"batch: --jobs {args.jobs}: must be at least 1")
        return 2
    try:
        runs = scenarios.load(args.scenarios, _find_package)
    except scenarios.ScenarioError as err:
        say(f"batch: {err}")
        return 2
    if args.filter is not None:
        try:
            pattern = re.compile(args.filter)
        except re.error as err:
            say(f"batch: --filter {args.filter!r}: not a regular expression ({err})")
            return 2
        runs = [r for r in runs if pattern.search(r.name)]
        if not runs:
            say(f"batch: --filter {args.filter!r} matches no run of {args.scenarios}")
            return 2
    out = os.path.abspath(args.out)
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as err:
        say(f"batch: --out {args.out}: cannot create it ({err.strerror})")
        return 2
    jsonl = os.path.join(out, "results.jsonl")
    if args.rerun and os.path.exists(jsonl):
        os.replace(jsonl, jsonl + ".previous")
    recorded = results.load(jsonl)
    todo = [r for r in runs if r.name not in recorded]
    where = "a local Ray instance" if args.ray == "" else f"Ray at {args.ray}" if args.ray else \
        f"this machine, {args.jobs} at once"
    say(f"[batch] {len(runs)} runs, {len(runs) - len(todo)} already recorded in {jsonl}; running {len(todo)} on "
        f"{where}")
    progress = results.Progress(sys.stderr, len(todo))

    def on_record(record):
        results.append(jsonl, record)
        recorded[record["name"]] = record
        progress.update(record)

    batch_id = uuid.uuid4().hex[:12]
    t0 = time.monotonic()
    interrupted = False
    try:
        if todo and args.ray is not None:
            executors.run_ray(todo, out, batch_id, args.ray or None, on_record, say)
        elif todo:
            executors.run_local(todo, out, batch_id, args.jobs, on_record)
    except KeyboardInterrupt:
        interrupted = True
    progress.close()
    mine = [recorded[r.name] for r in runs if r.name in recorded]
    results.write_junit(os.path.join(out, "junit.xml"), mine)
    text = results.summary(mine, time.monotonic() - t0)
    with open(os.path.join(out, "summary.txt"), "w") as f:
        f.write(text)
    streams.write(sys.stdout, text)
    if interrupted:
        say(f"[batch] interrupted: {len(mine)} of {len(runs)} runs recorded in {jsonl}; run the same command "
            f"again to go on")
        return 130
    return 0 if len(mine) == len(runs) and all(r["status"] == "passed" for r in mine) else 1


if __name__ == "__main__":
    sys.exit(main())
