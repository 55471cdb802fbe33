"""When a periodic thing is next due (pure): the one rule every plugin, controller and learning environment
schedules its updates and publications by."""


def next_due(due, period, now):
    """Next time after ``due`` (a multiple of ``period`` on from it); missed slots are skipped, not burst:
    a schedule that fell behind ``now`` restarts one period after it. ``period`` <= 0: every call (``now``)."""
    if period <= 0:
        return now
    due += period
    if due < now:
        due = now + period
    return due
