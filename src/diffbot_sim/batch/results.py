"""What a batch leaves in its ``--out`` folder (pure: files and text, no processes).

``results.jsonl``: one JSON object per run, appended as each run ends (the resume record); ``junit.xml``: every
run a test suite, for CI; ``summary.txt``: the table a person reads. :class:`Progress` is the terminal's
progress bar, or one line per run when the output is not a terminal.
"""
import json
import os
import statistics
import xml.etree.ElementTree as ET

STATUSES = ("passed", "failed", "error", "timeout")


def load(path):
    """Records of ``results.jsonl`` by run name (a later line of one name wins; a torn last line is skipped)."""
    records = {}
    try:
        with open(path) as f:
            for line in f:
                line = line.strip()
                if not line:
                    continue
                try:
                    rec = json.loads(line)
                except ValueError:
                    continue  # a line cut short by a lost machine or a kill: that run runs again
                if isinstance(rec, dict) and isinstance(rec.get("name"), str) and rec.get("status") in STATUSES:
                    records[rec["name"]] = rec
    except FileNotFoundError:
        pass
    return records


def append(path, record):
    """Append one record and make it durable before the next run is reported."""
    with open(path, "a") as f:
        f.write(json.dumps(record, sort_keys=True) + "\n")
        f.flush()
        os.fsync(f.fileno())


def junit(records):
    """A JUnit document (ElementTree) of ``records`` (in order): every run a <testsuite> named by the run, its
    rostest test cases as <testcase>s, a timeout or error without test cases as one <testcase> with <error>."""
    suites = ET.Element("testsuites", name="batch")
    totals = {"tests": 0, "failures": 0, "errors": 0}
    for rec in records:
        status = rec["status"]
        tests = max(1, int(rec.get("tests") or 0))
        failures = int(rec.get("failures") or 0) if status == "failed" else 0
        errors = 1 if status in ("error", "timeout") else 0
        suite = ET.SubElement(suites, "testsuite", name=rec["name"], tests=str(tests), failures=str(failures),
                              errors=str(errors), time=f"{rec.get('wall_s', 0.0):.3f}",
                              hostname=str(rec.get("node", "")))
        props = ET.SubElement(suite, "properties")
        for key, value in sorted((rec.get("args") or {}).items()):
            ET.SubElement(props, "property", name=f"arg.{key}", value=str(value))
        for key in ("sim_s", "rtf", "log_dir", "test"):
            ET.SubElement(props, "property", name=key, value=str(rec.get(key, "")))
        case = ET.SubElement(suite, "testcase", classname=rec["name"], name=rec.get("test", "run"),
                             time=f"{rec.get('wall_s', 0.0):.3f}")
        if status == "failed":
            ET.SubElement(case, "failure", message=rec.get("reason") or "failed").text = rec.get("log_dir", "")
        elif errors:
            ET.SubElement(case, "error", message=rec.get("reason") or status).text = rec.get("log_dir", "")
        if rec.get("figures"):
            ET.SubElement(suite, "system-out").text = "\n".join(rec["figures"])
        totals["tests"] += tests
        totals["failures"] += failures
        totals["errors"] += errors
    for key, value in totals.items():
        suites.set(key, str(value))
    return ET.ElementTree(suites)


def write_junit(path, records):
    tree = junit(records)
    ET.indent(tree)
    tmp = path + ".part"
    tree.write(tmp, encoding="utf-8", xml_declaration=True)
    os.replace(tmp, path)


def summary(records, wall_s, slowest=5):
    """The batch's table: runs, passed, failed, errors, timeouts, wall time, median RTF, the slowest runs, and
    every run that did not pass with its reason and log folder."""
    count = {s: sum(1 for r in records if r["status"] == s) for s in STATUSES}
    rtfs = [r["rtf"] for r in records if r.get("rtf")]
    lines = [
        f"runs      {len(records)}",
        f"passed    {count['passed']}",
        f"failed    {count['failed']}",
        f"errors    {count['error']}",
        f"timeouts  {count['timeout']}",
        f"wall time {wall_s:.1f} s (this invocation); runs' own wall time {sum(r['wall_s'] for r in records):.1f} s",
        f"median RTF {statistics.median(rtfs):.2f}" if rtfs else "median RTF -  (no run reported sim time)",
        "",
        "slowest runs:",
        f"  {'run':<40} {'status':<8} {'wall s':>8} {'sim s':>8} {'RTF':>6}  node",
    ]
    for r in sorted(records, key=lambda r: -r["wall_s"])[:slowest]:
        lines.append(f"  {r['name']:<40} {r['status']:<8} {r['wall_s']:>8.1f} {r['sim_s']:>8.1f} {r['rtf']:>6.2f}  "
                     f"{r.get('node', '')}")
    bad = [r for r in records if r["status"] != "passed"]
    if bad:
        lines += ["", "not passed:"]
        for r in bad:
            lines.append(f"  {r['name']}: {r['status']}: {r.get('reason') or '-'} (log {r.get('log_dir')})")
    return "\n".join(lines) + "\n"


class Progress:
    """Reports each finished run: a progress bar redrawn in place on a terminal, else one line per run."""

    def __init__(self, stream, total, tty=None):
        self.stream, self.total, self.done = stream, total, 0
        self.counts = dict.fromkeys(STATUSES, 0)
        self.tty = stream.isatty() if tty is None else tty

    def update(self, record):
        self.done += 1
        self.counts[record["status"]] += 1
        line = (f"[batch] {self.done}/{self.total} {record['status']:<7} {record['name']} "
                f"({record['wall_s']:.1f} s, RTF {record['rtf']:.2f}, {record.get('node', '')})")
        if self.tty:
            width = 30
            filled = int(width * self.done / max(1, self.total))
            bar = "#" * filled + "-" * (width - filled)
            tally = " ".join(f"{k} {v}" for k, v in self.counts.items() if v)
            self.stream.write(f"\r\033[K{line}\n[{bar}] {self.done}/{self.total} {tally}")
        else:
            self.stream.write(line + "\n")
        self.stream.flush()

    def close(self):
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()
