"""diffbot_sim.waiting.wait_for: returns the predicate's first true value, fails after the deadline naming what
was waited for, ends early when told to give up, and raises the caller's exception. A fake clock: no sleeping."""
import pytest

from diffbot_sim.waiting import wait_for


class FakeClock:
    """A clock that advances only when the waiter sleeps; records the sleeps."""

    def __init__(self):
        self.now, self.sleeps = 100.0, []

    def __call__(self):
        return self.now

    def sleep(self, seconds):
        self.sleeps.append(seconds)
        self.now += seconds


def values(*answers):
    """A predicate giving ``answers`` in turn, then its last answer forever; counts its calls."""
    answers = list(answers)

    def predicate():
        predicate.calls += 1
        return answers.pop(0) if len(answers) > 1 else answers[0]
    predicate.calls = 0
    return predicate


def test_returns_the_first_true_value_and_polls_at_the_period():
    clock = FakeClock()
    predicate = values(None, 0, "", [], {"x": 1})
    assert wait_for(predicate, 5.0, "x", 0.25, clock=clock, sleep=clock.sleep) == {"x": 1}
    assert predicate.calls == 5
    assert clock.sleeps == [0.25] * 4


def test_times_out_naming_what_it_waited_for():
    clock = FakeClock()
    predicate = values(False)
    with pytest.raises(TimeoutError, match=r"^timed out after 2 s waiting for the first /odom$"):
        wait_for(predicate, 2.0, "the first /odom", 0.5, clock=clock, sleep=clock.sleep)
    # asked at 0, 0.5, ... 2.0 and once past the deadline (2.5): the deadline is not cut short
    assert predicate.calls == 6
    assert clock.now == pytest.approx(102.5)


def test_asks_at_least_once_with_no_time_left():
    clock = FakeClock()
    assert wait_for(values(7), 0.0, "x", clock=clock, sleep=clock.sleep) == 7
    assert clock.sleeps == []


def test_the_callers_exception_carries_the_message():
    clock = FakeClock()
    with pytest.raises(AssertionError, match="timed out after 1 s waiting for rviz"):
        wait_for(values(None), 1.0, "rviz", error=AssertionError, clock=clock, sleep=clock.sleep)

    class LogTail(Exception):
        pass
    with pytest.raises(LogTail, match=r"waiting for rviz \(log: /tmp/x.log\)$"):
        wait_for(values(None), 1.0, "rviz", error=lambda m: LogTail(f"{m} (log: /tmp/x.log)"), clock=clock,
                 sleep=clock.sleep)


def test_give_up_ends_the_wait_at_once_with_its_reason():
    clock = FakeClock()
    stop = values(False, False, "bullet_sim died")
    with pytest.raises(TimeoutError, match=r"^bullet_sim died while waiting for /scan$"):
        wait_for(values(None), 60.0, "/scan", 0.1, give_up=stop, clock=clock, sleep=clock.sleep)
    assert stop.calls == 3 and len(clock.sleeps) == 2  # not the 60 s


def test_give_up_without_a_reason_says_so():
    clock = FakeClock()
    with pytest.raises(TimeoutError, match=r"^gave up while waiting for x$"):
        wait_for(values(None), 60.0, "x", give_up=lambda: True, clock=clock, sleep=clock.sleep)


def test_a_true_value_wins_over_giving_up():
    clock = FakeClock()
    assert wait_for(values("done"), 1.0, "x", give_up=lambda: "never asked", clock=clock, sleep=clock.sleep) == "done"


def test_a_raising_predicate_fails_at_once():
    def dead():
        raise AssertionError("roslaunch ended (exit 1)")
    with pytest.raises(AssertionError, match="roslaunch ended"):
        wait_for(dead, 60.0, "x")


def test_real_clock_and_sleep_by_default():
    with pytest.raises(TimeoutError, match="timed out after 0.03 s"):
        wait_for(lambda: None, 0.03, "x", 0.01)
