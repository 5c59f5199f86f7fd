"""The numbers in a campaign report's tables, each as the text of one cell.

Rates carry 95% Wilson intervals; medians of per-pair ratios and mean paired differences carry
seeded percentile-bootstrap intervals (`stats.py`: the same table gives the same report);
spreads are median / p90, bands median [p10-p90].
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

from avs_planner.experiment.report_rows import Row, as_expected
from avs_planner.experiment.stats import Interval, bootstrap, median, quantile, wilson


def rate_cell(rows: list[Row]) -> str:
    """Share ending as expected, 95% Wilson interval and k/n: `0.80 [0.49, 0.94] (8/10)`."""
    k = sum(map(as_expected, rows))
    interval = wilson(k, len(rows))
    if interval is None:
        return "--"
    return f"{interval.estimate:.2f} [{interval.low:.2f}, {interval.high:.2f}] ({k}/{len(rows)})"


def percent_cell(rows: list[Row]) -> str:
    """The same as k/n and per cent: `8/10 = 80% [49, 94]`."""
    k = sum(map(as_expected, rows))
    interval = wilson(k, len(rows))
    if interval is None:
        return "--"
    return (f"{k}/{len(rows)} = {100 * interval.estimate:.0f}% [{100 * interval.low:.0f}, "
            f"{100 * interval.high:.0f}]")


def spread_cell(rows: list[Row], column: str, digits: int) -> str:
    """Median / p90 of a column over the runs that record it."""
    values = [r[column] for r in rows if r[column] is not None]
    if not values:
        return "--"
    return f"{num(median(values), digits)} / {num(quantile(values, 0.9), digits)}"


def band_cell(rows: list[Row], column: str, digits: int) -> str:
    """Median [p10-p90] of a column over the runs that record it."""
    values = [r[column] for r in rows if r[column] is not None]
    if not values:
        return "--"
    return (f"{num(median(values), digits)} [{num(quantile(values, 0.1), digits)}-"
            f"{num(quantile(values, 0.9), digits)}]")


@functools.lru_cache(maxsize=1024)
def median_interval(values: tuple[float, ...]) -> Interval | None:
    """The median with its bootstrap interval (a slice's ratios recur in two tables)."""
    return bootstrap(values, _median)


def _median(values: Sequence[float]) -> float:
    return float(median(values) or 0.0)


def ratio_cell(ratios: list[float]) -> str:
    """The median per-pair ratio with its bootstrap interval and the number of pairs."""
    interval = median_interval(tuple(ratios))
    if interval is None:
        return "--"
    return (f"{interval.estimate:.2f} [{interval.low:.2f}, {interval.high:.2f}] "
            f"(n {len(ratios)})")


def interval_cell(interval: Interval | None, digits: int) -> str:
    """A signed estimate with its interval (a mean paired difference)."""
    if interval is None:
        return "--"
    return (f"{interval.estimate:+.{digits}f} [{interval.low:+.{digits}f}, "
            f"{interval.high:+.{digits}f}]")


def total(rows: list[Row], column: str) -> str:
    """A count column summed over the runs that record it."""
    values = [r.get(column) for r in rows if r.get(column) is not None]
    return str(int(sum(values))) if values else "--"


def num(value: float | None, digits: int) -> str:
    """A number to `digits` places; `--` when there is none."""
    return "--" if value is None else f"{value:.{digits}f}"
