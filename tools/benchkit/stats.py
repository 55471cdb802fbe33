"""Figures from trials: percentiles, the median trial, the largest robot count that keeps real time."""
import statistics


def percentile(values, q):
    """Nearest-rank ``q``-th percentile of ``values`` (NaN when empty)."""
    ordered = sorted(values)
    if not ordered:
        return float("nan")
    k = min(len(ordered) - 1, max(0, int(round(q / 100.0 * (len(ordered) - 1)))))
    return ordered[k]


def median_trial(trials, key="rtf"):
    """The trial whose ``key`` is the (low) median, with ``key`` set to the median of all and ``{key}_runs`` to
    every trial's: a typical trial's other figures beside the median."""
    values = [t[key] for t in trials]
    return dict(trials[values.index(statistics.median_low(values))], **{key: statistics.median(values),
                                                                        f"{key}_runs": values})


def largest_count(trial, start, limit, say):
    """The largest robot count whose ``trial(count)`` holds RTF >= 0.99: grow by 10 from ``start`` (up to
    ``limit``) until one misses, then bisect. ``say(count, result)`` prints each trial. Returns the count (0
    when ``start`` already misses) and ``{count: result}`` of every trial."""
    trials = {}

    def ok(count):
        if count not in trials:
            trials[count] = trial(count)
            say(count, trials[count])
        return trials[count]["rtf"] >= 0.99
    good, bad, count = 0, None, start
    while count <= limit:
        if ok(count):
            good, count = count, count + 10
        else:
            bad = count
            break
    while bad is not None and bad - good > 1:
        mid = (good + bad) // 2
        good, bad = (mid, bad) if ok(mid) else (good, mid)
    return good, trials
