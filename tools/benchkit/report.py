"""An item's record, the results file (bench-results/bench.json) and the printed table."""
import json
import os
from collections.abc import Callable
from dataclasses import dataclass

#: one row of the table: (measure, value, target)
Row = tuple[str, str, str]


@dataclass
class Item:
    """One ``make bench`` item.

    ``run(quick)`` measures (``quick``: shorter windows, a smoke run) and returns its figures, stored in the
    results under ``name``; with ``flat``, its keys go into the results themselves (the fast and real-time
    items, whose figures the results have kept at the top since the first bench). ``rows(results)`` gives its
    table rows from the results (none when its figures are missing). ``part_of``: the item that selects it too
    (``--only scale`` runs ``scale_rsp``)."""

    name: str
    run: Callable[[bool], dict]
    rows: Callable[[dict], list[Row]]
    flat: bool = False
    part_of: str | None = None

    def wanted(self, names):
        return self.name in names or (self.part_of is not None and self.part_of in names)


def write_results(results, results_dir):
    """bench.json in ``results_dir``; its path."""
    path = os.path.join(results_dir, "bench.json")
    with open(path, "w") as f:
        json.dump(results, f, indent=2)
    return path


def table(rows):
    """The rows as a plain-text table: measure, value (right-aligned), target."""
    if not rows:
        return "(no figures)"
    width = max(len(name) for name, _, _ in rows)
    lines = [f"{'measure'.ljust(width)}  {'value':>28}  target", "-" * (width + 40)]
    lines += [f"{name.ljust(width)}  {value:>28}  {target}" for name, value, target in rows]
    return "\n".join(lines)
