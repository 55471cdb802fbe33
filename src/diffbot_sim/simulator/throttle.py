"""A per-key rate limiter for warnings (pure; the caller passes the time)."""


class Throttle:
    """``ready(key, now)`` is True at most once per ``period`` seconds for each key; counts what it held back."""

    def __init__(self, period):
        self.period = period
        self._last = {}
        self.suppressed = {}

    def ready(self, key, now):
        last = self._last.get(key)
        if last is None or now - last >= self.period or now < last:
            self._last[key] = now
            return True
        self.suppressed[key] = self.suppressed.get(key, 0) + 1
        return False

    def take_suppressed(self, key):
        """How many calls for ``key`` were held back since the last ones reported; resets the count."""
        return self.suppressed.pop(key, 0)
