"""Statistics for reports: Wilson intervals for rates, quantiles, paired bootstrap intervals."""

from __future__ import annotations

import math
import random
import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass

Z95 = 1.959963984540054  # the standard normal's 97.5% point


@dataclass(frozen=True)
class Interval:
    """An estimate with a confidence interval [low, high]."""

    estimate: float
    low: float
    high: float


def wilson(successes: int, n: int, z: float = Z95) -> Interval | None:
    """The Wilson score interval for a binomial rate (good at small n and near 0 or 1).

    In exact arithmetic the interval lies in [0, 1] and holds the observed rate; in floating
    point its ends at 0/n and n/n come out a rounding error off (e.g. 0.9999999999999999 for
    10/10), so they are clamped into [0, 1] and around the estimate: error bars drawn from
    `estimate - low` and `high - estimate` are never negative."""
    if n <= 0:
        return None
    p = successes / n
    denominator = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denominator
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denominator
    low = min(max(0.0, centre - half), p)
    high = max(min(1.0, centre + half), p)
    return Interval(p, low, high)


def quantile(values: Sequence[float], q: float) -> float | None:
    """The q-quantile with linear interpolation between order statistics (numpy's default)."""
    if not values:
        return None
    ordered = sorted(values)
    position = q * (len(ordered) - 1)
    low = math.floor(position)
    high = min(low + 1, len(ordered) - 1)
    return ordered[low] + (ordered[high] - ordered[low]) * (position - low)


def median(values: Sequence[float]) -> float | None:
    return statistics.median(values) if values else None


def bootstrap(values: Sequence[float], statistic: Callable[[Sequence[float]], float] = statistics
              .fmean, resamples: int = 2000, seed: int = 0, level: float = 0.95
              ) -> Interval | None:
    """A percentile bootstrap interval for `statistic` of `values` (e.g. paired differences,
    or `median` of paired ratios).

    Seeded, so the same table gives the same report."""
    if not values:
        return None
    rng = random.Random(seed)
    n = len(values)
    estimates = sorted(statistic(rng.choices(values, k=n)) for _ in range(resamples))
    tail = (1 - level) / 2
    return Interval(statistic(values), quantile(estimates, tail) or 0.0,
                    quantile(estimates, 1 - tail) or 0.0)
