"""tools/run_tests.py's report of a failed rostest case: the line CI shows must carry the assertion's text
(rosunit writes it before the traceback), not only the traceback's last source line."""
import importlib.util
import os
import xml.etree.ElementTree as ET

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def load_runner():
    spec = importlib.util.spec_from_file_location("run_tests", os.path.join(ROOT, "tools", "run_tests.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def failure(text, message=None):
    element = ET.Element("failure", type="AssertionError")
    if message is not None:
        element.set("message", message)
    element.text = text
    return element


def test_why_gives_the_assertion_text_and_where_it_was_raised():
    why = load_runner()._why(failure(
        "every display Ok: roslaunch view_multi.launch exited 1 (see x.log):\n"
        "[rviz-5] process has died [pid 1, exit code -11]\n"
        '  File "/usr/lib/python3.11/unittest/case.py", line 57, in testPartExecutor\n'
        "    yield\n"
        '  File "test_view_rviz.py", line 149, in settled\n'
        '    raise AssertionError(f"{what}: {self.why} ({err})") from None\n'))
    assert why.startswith("every display Ok: roslaunch view_multi.launch exited 1")
    assert "[rviz-5] process has died [pid 1, exit code -11]" in why
    assert why.endswith('| raise AssertionError(f"{what}: {self.why} ({err})") from None')


def test_why_keeps_a_message_attribute_and_a_bare_line():
    runner = load_runner()
    assert runner._why(failure("", message="gtest says")) == "gtest says"
    assert runner._why(failure("only one line")) == "only one line"
    assert runner._why(failure("")) == "(no message)"
