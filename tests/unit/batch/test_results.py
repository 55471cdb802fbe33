"""What a batch writes: the resume record, JUnit for CI, the summary table, and the verdict of a run."""
import os
import xml.etree.ElementTree as ET

from diffbot_sim.batch import results, run


def rec(name, status, wall=10.0, sim=50.0, **extra):
    r = {"name": name, "args": {"seed": "1"}, "status": status, "wall_s": wall, "sim_s": sim,
         "rtf": sim / wall if wall else 0.0, "node": "host", "log_dir": f"/out/runs/{name}", "tests": 1,
         "failures": 0 if status == "passed" else 1, "test": "p/t.test", "reason": "" if status == "passed" else "why"}
    r.update(extra)
    return r


def test_load_skips_a_torn_line_and_keeps_the_last_record(tmp_path):
    path = str(tmp_path / "results.jsonl")
    results.append(path, rec("a", "failed"))
    results.append(path, rec("a", "passed"))
    results.append(path, rec("b", "timeout"))
    with open(path, "a") as f:
        f.write('{"name": "c", "stat')  # a machine lost mid-write
    loaded = results.load(path)
    assert sorted(loaded) == ["a", "b"] and loaded["a"]["status"] == "passed"
    assert results.load(str(tmp_path / "none.jsonl")) == {}


def test_junit_has_a_suite_per_run_and_counts(tmp_path):
    path = str(tmp_path / "junit.xml")
    results.write_junit(path, [rec("a", "passed"), rec("b", "failed"), rec("c", "timeout"), rec("d", "error")])
    root = ET.parse(path).getroot()
    assert [s.get("name") for s in root.iter("testsuite")] == ["a", "b", "c", "d"]
    assert (root.get("tests"), root.get("failures"), root.get("errors")) == ("4", "1", "2")
    b = root.find("testsuite[@name='b']")
    assert b.find("testcase/failure").get("message") == "why"
    assert b.find("properties/property[@name='arg.seed']").get("value") == "1"


def test_summary_table():
    text = results.summary([rec("a", "passed", 10, 50), rec("b", "passed", 20, 40), rec("c", "timeout", 30, 0)], 33.0)
    assert "runs      3" in text and "passed    2" in text and "timeouts  1" in text
    assert "median RTF 3.50" in text  # of 5.0 and 2.0 (the timeout reached no sim time)
    assert text.index("  c ") < text.index("  b ") < text.index("  a ")  # slowest first
    assert "c: timeout: why (log /out/runs/c)" in text


def test_progress_is_one_line_per_run_off_a_terminal(tmp_path):
    with open(tmp_path / "p.txt", "w") as f:
        p = results.Progress(f, 2, tty=False)
        p.update(rec("a", "passed"))
        p.update(rec("b", "failed"))
        p.close()
    assert open(tmp_path / "p.txt").read().splitlines()[1].startswith("[batch] 2/2 failed  b (10.0 s")


def junit_file(folder, name, body):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "w") as f:
        f.write(f'<?xml version="1.0"?><testsuite>{body}</testsuite>')


def test_verdicts(tmp_path):
    ok = '<testcase name="t"/><system-out>FIGURE tour: 3 s\nMETRIC time_s=3.5\n</system-out>'
    d = str(tmp_path / "pass")
    junit_file(os.path.join(d, "p"), "rosunit-t.xml", ok)
    status, tests, failures, _, figures, metrics = run.judge(d, 0, False)
    assert (status, tests, failures, figures, metrics) == ("passed", 1, 0, ["tour: 3 s"], {"time_s": 3.5})
    d = str(tmp_path / "fail")
    junit_file(os.path.join(d, "p"), "rosunit-t.xml", '<testcase name="t"><failure message="off by 2"/></testcase>')
    assert run.judge(d, 1, False)[:4] == ("failed", 1, 1, "t: off by 2")
    d = str(tmp_path / "crash")  # the test node died: only rostest's summary, with its complaint
    junit_file(os.path.join(d, "p"), "rostest-t.xml",
               '<testcase name="test_ran"><failure message="test node did not generate results"/></testcase>')
    assert run.judge(d, 1, False)[0] == "error"
    assert run.judge(str(tmp_path / "nothing"), 0, False)[0] == "error"  # exit 0 but no test case: not passed
    assert run.judge(d, None, True)[0] == "timeout"
    d = str(tmp_path / "exit")  # its cases passed but rostest said no (e.g. a required node died)
    junit_file(os.path.join(d, "p"), "rosunit-t.xml", '<testcase name="t"/>')
    assert run.judge(d, 1, False)[0] == "error"
