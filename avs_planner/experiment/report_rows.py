"""Which runs a campaign report counts, and how: the rows of results.csv as the report reads them.

A run ends as expected when it found its target (or gave up on an absent one); a run that
crashed, was killed or raised is not a success; a run cut by its wall-clock budget
(`wall_cut`: the machine, not the strategy) is left out of rates and pairs. The report breaks
the runs into slices (by robot and by world group when a campaign has several) and pairs the
runs of two strategies on the same world, target, robot and seed, whose simulated times it
compares as per-pair ratios.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

from avs_planner.experiment.results import WALL_CUT, is_wall_cut

Row = dict[str, Any]
Pair = tuple[Row, Row]
VERDICT_COLUMNS = ("correct", "success", "correct_give_up", "false_report")


def normalised(row: Row) -> Row:
    """A table written before wall cuts had their own status records them as `ok`."""
    if row["status"] == "ok" and is_wall_cut(row.get("outcome"), row.get("reason")):
        return {**row, "status": WALL_CUT, **dict.fromkeys(VERDICT_COLUMNS)}
    return row


def as_expected(row: Row) -> bool:
    """Found the target (or, for an absent target, gave up); failed runs are not successes."""
    if row["status"] != "ok":
        return False
    if row["expected"] == "gave_up":
        return bool(row["correct_give_up"])
    return bool(row["success"])


def comparable(rows: Iterable[Row]) -> list[Row]:
    """The runs a strategy answers for: all but those cut by the wall-clock budget."""
    return [r for r in rows if r["status"] != WALL_CUT]


def is_failed(row: Row) -> bool:
    """Crashed, killed or raised (a wall cut is not a failure of the strategy)."""
    return row["status"] not in ("ok", WALL_CUT)


def is_present(row: Row) -> bool:
    """The target is in the world (or its absence is not known)."""
    return row["expected"] != "gave_up"


def is_timeout(row: Row) -> bool:
    """The strategy used up its simulated time budget (a completed run)."""
    return row["status"] == "ok" and row["outcome"] == "timeout"


# ---- slices and pairs --------------------------------------------------------------------


def slices(rows: list[Row]) -> list[tuple[str, list[Row]]]:
    """All runs, then each robot and each world group when the campaign has several."""
    out = [("all", rows)]
    robots = sorted({_robot(r) for r in rows})
    groups = sorted({r["group"] for r in rows})
    if len(robots) > 1:
        out += [(f"robot {x}", [r for r in rows if _robot(r) == x]) for x in robots]
    if len(groups) > 1:
        out += [(f"group {g}", [r for r in rows if r["group"] == g]) for g in groups]
    return out


def _robot(row: Row) -> str:
    return row["robot"] or "world's own"


def runs_by_key(rows: list[Row]) -> dict[tuple[Any, ...], Row]:
    """Each run by (strategy, scenario, world, target, robot, seed, and for a campaign
    sequence's task its index and memory arm, and the priors arm): what pairs are made of."""
    return {(r["strategy"], *_pair_key(r)): r for r in rows}


def _pair_key(row: Row) -> tuple[Any, ...]:
    return (row["scenario"], row["world"], row["target"], row["robot"], row["seed"],
            row.get("task_index"), row.get("memory") or "", row.get("priors") or "")


def pairs_of(by_key: dict[tuple[Any, ...], Row], a: str, b: str) -> list[Pair]:
    """(A's run, B's run) on the same (world, target, robot, seed), neither cut by the wall
    clock."""
    return [(row, by_key[(b, *key[1:])]) for key, row in by_key.items()
            if key[0] == a and (b, *key[1:]) in by_key
            and WALL_CUT not in (row["status"], by_key[(b, *key[1:])]["status"])]


def time_ratios(pairs: list[Pair], kind: str) -> list[float]:
    """Per-pair sim-time ratios A/B: `found` where both found a present target, `gave_up`
    where both gave up on an absent one."""
    def ended(row: Row) -> bool:
        if row["status"] != "ok" or not row["sim_time_s"] or row["sim_time_s"] <= 0:
            return False
        if kind == "found":
            return is_present(row) and bool(row["success"])
        return not is_present(row) and row["outcome"] == "gave_up"

    return [x["sim_time_s"] / y["sim_time_s"] for x, y in pairs if ended(x) and ended(y)]


def arm_pairs(rows: list[Row], strategy: str, column: str, arms: tuple[str, str],
              same: Callable[[Row], tuple[Any, ...]]) -> list[Pair]:
    """(first arm, second arm) runs of one strategy that agree on `same(row)`, neither cut
    by the wall clock: the pairs a campaign's two arms (`column` = arms[0] or arms[1]: memory
    on / off, learned / default priors) are compared over."""
    second = {same(r): r for r in rows
              if r["strategy"] == strategy and r.get(column) == arms[1]}
    return [(r, second[same(r)]) for r in rows
            if r["strategy"] == strategy and r.get(column) == arms[0] and same(r) in second
            and WALL_CUT not in (r["status"], second[same(r)]["status"])]
