"""Two baselines for the switching planner, on the same robot, maps and detector.

`exhaustive`: frontier exploration, nearest placeholder first, looking all round at every
stop; no priors. `most-likely-room`: known rooms in order of P(object in room) from the
conceptual map's category beliefs and default knowledge, each swept fully (standpoints over its
free space, all round at each); unexplored space (a placeholder) competes as a hypothetical
room weighted by the chance that it leads to one. Both give up when nothing is left, after
trying the spots the base was blocked at again (`retry_blocked` times, as the switching loop
does: a touched spot is kept out of for minutes, and what it cut off would otherwise count as
searched).
"""

from __future__ import annotations

import math

import numpy as np

from avs_planner.episode.mind import KnownObject
from avs_planner.episode.outcome import Outcome, SearchResult, StepStatus
from avs_planner.strategies.context import SearchContext
from avs_planner.strategies.looking import look_all_round
from conceptual_map.metric import distance_field

MAX_SWEEP_STOPS = 12  # standpoints per room sweep


def run_exhaustive(ctx: SearchContext) -> SearchResult:
    result = SearchResult(Outcome.GAVE_UP, "")
    ctx.executor.look_around()
    headings = ctx.options["headings"]
    for _ in range(ctx.options["max_stops"]):
        stop = ctx.budget_spent()
        if stop:
            return ctx.end(result, Outcome.TIMEOUT, stop)
        found = look_all_round(ctx, headings)
        if found is not None:
            return _found(ctx, result, found)
        target = ctx.executor.nearest_placeholder()
        if target is None and retry_blocked(ctx):
            target = ctx.executor.nearest_placeholder()
        if target is None:
            return ctx.end(result, Outcome.GAVE_UP, "explored every reachable placeholder")
        explore(ctx, target)
    return ctx.end(result, Outcome.TIMEOUT, f"{ctx.options['max_stops']} stops")


def run_most_likely_room(ctx: SearchContext) -> SearchResult:
    result = SearchResult(Outcome.GAVE_UP, "")
    ctx.executor.look_around()
    headings, swept = ctx.options["headings"], set()
    found = look_all_round(ctx, headings)
    for _ in range(ctx.options["max_stops"]):
        if found is not None:
            return _found(ctx, result, found)
        stop = ctx.budget_spent()
        if stop:
            return ctx.end(result, Outcome.TIMEOUT, stop)
        choice = most_likely(ctx, swept)
        if choice is None and retry_blocked(ctx):
            choice = most_likely(ctx, swept)
        if choice is None:
            return ctx.end(result, Outcome.GAVE_UP, "swept every known room, nothing to explore")
        kind, ident, p = choice
        ctx.trace.emit("belief", most_likely=ident, kind=kind, probability=round(p, 4))
        if kind == "room":
            swept.add(ident)
            found = sweep(ctx, ident, headings)
        else:
            explore(ctx, ident)
            found = look_all_round(ctx, headings)
    return ctx.end(result, Outcome.TIMEOUT, f"{ctx.options['max_stops']} stops")


def _found(ctx: SearchContext, result: SearchResult, obj: KnownObject) -> SearchResult:
    result.found = obj
    where = ", ".join(f"{v:.2f}" for v in obj.position)
    return ctx.end(result, Outcome.FOUND, f"{obj.label} at ({where}) in {obj.room}")


def retry_blocked(ctx: SearchContext) -> bool:
    """Nothing is left while blocked spots are kept out of: forget them (the place map
    re-derives what they cut off), at most `retry_blocked` times per episode
    (`Mind.retry_blocked`). True when something was forgotten."""
    gone = ctx.mind.retry_blocked(ctx.options["retry_blocked"])
    if not gone:
        return False
    ctx.trace.emit("belief", retry_blocked=[b.id for b in gone], reason="nothing else is left")
    return True


def explore(ctx: SearchContext, placeholder: str) -> None:
    """Drive to a placeholder (stop early once it is explored) and look around there."""
    mind, ex = ctx.mind, ctx.executor
    mind.tried_placeholders[placeholder] = mind.tried_placeholders.get(placeholder, 0) + 1
    ctx.trace.emit("action", action=f"(explore {placeholder})", status="start")
    outcome = ex.drive_to(mind.place_map.placeholders[placeholder].position,
                          stop=lambda: placeholder not in mind.place_map.placeholders)
    if outcome.status is StepStatus.DONE:
        ex.look_around()
    ctx.trace.emit("action", action=f"(explore {placeholder})", status=outcome.status.value,
                   detail=outcome.detail)


def most_likely(ctx: SearchContext, swept: set[str]) -> tuple[str, str, float] | None:
    """The unswept room or untried placeholder with the highest P(target there)."""
    mind = ctx.mind
    cmap, pm = mind.cmap, mind.place_map
    p_category = cmap.p_any(ctx.target, cmap.knowledge.total_room_lambda(ctx.target))
    names = cmap.knowledge.categories
    best: tuple[str, str, float] | None = None
    for rid in pm.rooms:
        if rid not in swept and cmap.graph.has_room(rid):
            belief = cmap.room_category(rid)
            p = float(sum(belief[c] * p_category[i] for i, c in enumerate(names)))
            best = _better(best, ("room", rid, p))
    for pid in pm.placeholders:
        if mind.tried_placeholders.get(pid, 0) >= 2 or pid not in cmap.placeholders:
            continue
        belief = cmap.placeholder_category(pid)
        p = float(sum(belief.get(c, 0.0) * p_category[i] for i, c in enumerate(names)))
        best = _better(best, ("placeholder", pid, p))
    return best


def _better(best: tuple[str, str, float] | None, candidate: tuple[str, str, float]
            ) -> tuple[str, str, float]:
    return candidate if best is None or candidate[2] > best[2] else best


def sweep(ctx: SearchContext, room: str, headings: int) -> KnownObject | None:
    """Visit standpoints spread over the room's free space, looking all round at each."""
    ctx.trace.emit("action", action=f"(sweep {room})", status="start")
    stands = standpoints(ctx, room, ctx.options["sweep_spacing"])
    for stand in stands:
        if ctx.budget_spent():
            break
        if ctx.executor.drive_to(stand).status is not StepStatus.DONE:
            continue
        found = look_all_round(ctx, headings)
        if found is not None:
            ctx.trace.emit("action", action=f"(sweep {room})", status="done", detail="found")
            return found
    ctx.trace.emit("action", action=f"(sweep {room})", status="done",
                   detail=f"{len(stands)} standpoints")
    return None


def standpoints(ctx: SearchContext, room: str, spacing: float) -> list[tuple[float, float]]:
    """Reachable free cells of the room, one per `spacing` square, nearest-first tour (cells
    a squeeze reaches when none is reachable with the full margin, as `nearest_placeholder`
    does)."""
    mind = ctx.mind
    grid, pm = mind.grid, mind.place_map
    ids = [p for p in sorted(pm.places) if pm.room_of(p) is not None]
    if not ids:
        return []
    here = ctx.robot.pose[:2]
    centres = np.array([pm.places[p].position for p in ids])
    mine_of = np.array([pm.room_of(p) == room for p in ids])
    points = np.zeros((0, 2))
    for margin in (mind.config.robot_radius, ctx.executor.squeeze_margin()):
        reach = distance_field(grid, here, margin)
        cells = np.argwhere(np.isfinite(reach))
        cells = cells[(cells % 4 == 0).all(axis=1)]  # a 4-cell lattice is dense enough here
        if len(cells) == 0:
            continue
        points = grid.to_world(cells)
        nearest = np.linalg.norm(points[:, None, :] - centres[None, :, :], axis=2).argmin(axis=1)
        points = points[mine_of[nearest]]
        if len(points):
            break
    keys = np.floor(points / spacing).astype(int)
    picked: dict[tuple[int, int], np.ndarray] = {}
    for key, point in zip(map(tuple, keys), points, strict=True):
        centre = (np.asarray(key) + 0.5) * spacing
        if key not in picked or (np.linalg.norm(point - centre)
                                 < np.linalg.norm(picked[key] - centre)):
            picked[key] = point
    return _tour([tuple(map(float, p)) for p in picked.values()], here)[:MAX_SWEEP_STOPS]


def _tour(points: list[tuple[float, float]], start: tuple[float, float]
          ) -> list[tuple[float, float]]:
    """Nearest-neighbour order from `start`."""
    order, here, left = [], start, list(points)
    while left:
        nxt = min(left, key=lambda p: math.dist(p, here))
        left.remove(nxt)
        order.append(nxt)
        here = nxt
    return order
