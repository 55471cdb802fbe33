"""throttle.py: per-key warning rate limiter."""
from diffbot_sim.simulator.throttle import Throttle


def test_first_call_passes_then_held_for_period():
    throttle = Throttle(1.0)
    assert throttle.ready("nan", 10.0) is True
    assert throttle.ready("nan", 10.5) is False
    assert throttle.ready("nan", 10.99) is False
    assert throttle.ready("nan", 11.0) is True


def test_period_counts_from_last_release_not_last_call():
    throttle = Throttle(1.0)
    results = [throttle.ready("k", t / 10.0) for t in range(0, 31)]  # 0.0 .. 3.0
    released = [t / 10.0 for t, ok in zip(range(0, 31), results) if ok]
    assert released == [0.0, 1.0, 2.0, 3.0]


def test_keys_are_independent():
    throttle = Throttle(5.0)
    assert throttle.ready("a", 0.0)
    assert throttle.ready("b", 1.0)
    assert not throttle.ready("a", 2.0)
    assert not throttle.ready("b", 2.0)


def test_suppressed_counts_and_reset():
    throttle = Throttle(1.0)
    throttle.ready("k", 0.0)
    for t in (0.1, 0.2, 0.3):
        throttle.ready("k", t)
    throttle.ready("other", 0.0)
    throttle.ready("other", 0.5)
    assert throttle.take_suppressed("k") == 3
    assert throttle.take_suppressed("k") == 0
    assert throttle.take_suppressed("other") == 1
    assert throttle.take_suppressed("never") == 0


def test_time_going_backwards_releases():
    # a sim reset restarts the clock: the next warning must not be held for the old period
    throttle = Throttle(2.0)
    assert throttle.ready("k", 100.0)
    assert throttle.ready("k", 0.5)
    assert not throttle.ready("k", 1.0)


def test_zero_period_always_ready():
    throttle = Throttle(0.0)
    assert all(throttle.ready("k", 1.0) for _ in range(3))
    assert throttle.take_suppressed("k") == 0
