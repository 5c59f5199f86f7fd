"""The report's map-quality table: how well the robot's room map matched the world's rooms.

From the `map_score` of the episodes' summaries (the harness's score, never seen by the mind):
rooms matched of the true rooms and of those the robot entered, merges and splits, and the
room-category accuracy weighted by the area entered.
"""

from __future__ import annotations

from avs_planner.experiment.report_cells import num, total
from avs_planner.experiment.report_header import stamped
from avs_planner.experiment.report_rows import Row, slices
from avs_planner.experiment.stats import median


def map_table(rows: list[Row], strategies: list[str], stamp: str) -> list[str]:
    """Room-map scores, where the episodes' summaries carry them (`map_score`)."""
    scored = [r for r in rows if r["status"] == "ok" and any(
        r.get(c) is not None for c in ("map_rooms_true", "map_category_accuracy"))]
    if not scored:
        return []
    lines = stamped(
        "Map quality", stamp,
        "Over completed runs whose summary scores the room map: rooms matched, summed over "
        "runs, of the true rooms, summed (a search that ends early never sees some rooms), "
        "and of the true rooms the robot entered; merges and splits (a mapped room covering "
        "several true ones, a true room mapped as several), summed; room-category accuracy "
        "weighted by the area the robot entered (sum of accuracy x entered area / sum of entered "
        "area); the entered area, median per run.", "",
        "| slice | strategy | runs scored | rooms matched | of rooms entered | merges | splits "
        "| category accuracy (area-weighted) | entered m² per run |",
        "|---|---|---|---|---|---|---|---|---|")
    for name, part in slices(scored):
        for strategy in strategies:
            mine = [r for r in part if r["strategy"] == strategy]
            if mine:
                lines.append(f"| {name} | {strategy} | {len(mine)} | {_matched(mine)} | "
                             f"{_matched(mine, 'map_entered_rooms', 'map_entered_matched')} | "
                             f"{total(mine, 'map_merges')} | {total(mine, 'map_splits')} | "
                             f"{_accuracy(mine)} | "
                             f"{num(median(_values(mine, 'map_entered_area_m2')), 1)} |")
    return lines + [""]


def _values(rows: list[Row], column: str) -> list[float]:
    return [r[column] for r in rows if r.get(column) is not None]


def _matched(rows: list[Row], of: str = "map_rooms_true",
             matched_column: str = "map_rooms_matched") -> str:
    """Rooms matched (`matched_column`), summed over runs, of `of`, summed."""
    both = [r for r in rows if r.get(of) is not None and r.get(matched_column) is not None]
    true = sum(r[of] for r in both)
    if not true:
        return "--"
    matched = sum(r[matched_column] for r in both)
    return f"{matched:g}/{true:g} = {100 * matched / true:.0f}%"


def _accuracy(rows: list[Row]) -> str:
    """Room-category accuracy weighted by the area entered, over the runs that entered some."""
    both = [r for r in rows if r.get("map_category_accuracy") is not None
            and (r.get("map_entered_area_m2") or 0) > 0]
    area = sum(r["map_entered_area_m2"] for r in both)
    if not area:
        return "--"
    weighted = sum(r["map_category_accuracy"] * r["map_entered_area_m2"] for r in both)
    return f"{100 * weighted / area:.0f}% (over {area:.0f} m²)"
