"""Small readers for campaign values (seed ranges, budgets) and where an entry sits."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from avs_planner.experiment.errors import CampaignError

_RANGE = re.compile(r"^\s*(-?\d+)\s*-\s*(-?\d+)\s*$")


@dataclass(frozen=True)
class Where:
    """A path into the campaign file, e.g. `fig3.yaml: worlds[2].generate.seeds`."""

    source: str
    path: str = ""

    def at(self, key: str | int) -> Where:
        if isinstance(key, int):
            return Where(self.source, f"{self.path}[{key}]")
        return Where(self.source, f"{self.path}.{key}" if self.path else key)

    def error(self, message: str) -> CampaignError:
        entry = f"{self.path}: " if self.path else ""
        return CampaignError(f"{self.source}: {entry}{message}")


def parse_seeds(value: Any, where: Where) -> list[int]:
    """An int, a list of ints, or a string of ranges and ints: `0-19`, `0-4,7,9`."""
    if isinstance(value, bool):
        raise where.error(f"seeds must be integers, got {value!r}")
    if isinstance(value, int):
        return [value]
    if isinstance(value, str):
        seeds = [s for part in value.split(",") for s in _seed_part(part, where)]
    elif isinstance(value, list) and value:
        seeds = [_seed(v, where.at(i)) for i, v in enumerate(value)]
    else:
        raise where.error(f"seeds are an int, a list of ints or a range like '0-19', got "
                          f"{value!r}")
    duplicates = sorted({s for s in seeds if seeds.count(s) > 1})
    if duplicates:
        raise where.error(f"seed(s) {duplicates} listed twice")
    return seeds


def _seed_part(part: str, where: Where) -> list[int]:
    match = _RANGE.match(part)
    if match:
        first, last = int(match[1]), int(match[2])
        if last < first:
            raise where.error(f"range {part.strip()!r} is empty (write low-high)")
        return list(range(first, last + 1))
    try:
        return [int(part)]
    except ValueError:
        raise where.error(f"{part.strip()!r} is not a seed or a range like '0-19'") from None


def _seed(value: Any, where: Where) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise where.error(f"a seed is an integer, got {value!r}")
    return value


def positive_number(value: Any, where: Where) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise where.error(f"must be a number of seconds, got {value!r}")
    if not math.isfinite(value) or value <= 0:
        raise where.error(f"must be a positive finite number of seconds, got {value!r}")
    return float(value)
