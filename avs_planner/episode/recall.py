"""Checking what the building memory says: go and look where a wanted object was seen.

A sighting from an earlier task (`episode/memory.py`) is never reported as it stands: the
object may have been moved since. Before a task's search begins, the robot checks the
sightings of the labels it wants that are more likely still there than not (weight at least
`CHECK_WEIGHT`, P = exp(-rate x days) from the knowledge's `mobility` section). Those the
camera sees from where the robot stands it looks at first by turning to them
(`_check_in_view`); then, after a look round, the rest, most likely first and, among equals,
nearest first: it drives to a standpoint that sees the spot (within the camera distance a
report's verification uses, with a free line of sight in its map), faces it and looks. An
object confirmed there, by the frames a new detection needs, becomes a known object of this
task (the strategy reports it after its own verification); one not seen is dropped, with a
`memory` trace event. Sightings it could not reach stay for a later task. Every strategy's
task starts with the same check (the harness runs it before the strategy).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection
from dataclasses import dataclass
from typing import Any

import numpy as np

from avs_planner.episode.executor import Executor
from avs_planner.episode.memory import Sighting
from avs_planner.episode.mind import KnownObject
from avs_planner.episode.outcome import StepStatus
from avs_planner.episode.sensing import SAME_SPOT
from avs_planner.episode.verifying import verify_distance
from conceptual_map.metric import PathQueryError, distance_field
from conceptual_map.metric.logodds import CellState

CHECK_WEIGHT = 0.5  # a sighting more likely moved than not is not worth a detour of its own
STANDPOINT_TURNS = 12  # directions around the spot tried for a standpoint
STANDPOINT_RANGES = (1.0, 0.7, 1.3)  # x the verification distance, tried in this order
SHORT_OF = 0.6  # m: the line of sight is tested up to this short of the spot: the laser
# maps the furniture it stands on, which the camera looks over (a wall that close is ruled
# out by standing in the spot's own room)


@dataclass(frozen=True)
class _Seen:
    """The remembered spot as the detector's `confirm` takes it."""

    label: str
    position: tuple[float, float, float]
    id: int = -1


def check_remembered(executor: Executor, labels: Collection[str],
                     emit: Callable[..., Any], budget_left: Callable[[], bool] = lambda: True
                     ) -> list[KnownObject]:
    """Check the sightings of `labels` (see the module's doc); the objects confirmed. With
    any to check, the robot first looks round where it stands, as every strategy begins: a
    wanted object in view there is found without driving to a spot remembered elsewhere
    (the look round found targets near the start in about 10 s, and a check that drove to
    another room first cost more). The strategy's own first look round is then skipped
    while the robot stands where it looked (`Sensing.resumed`)."""
    mind = executor.mind
    found: list[KnownObject] = []
    skipped: list[Sighting] = []
    if not any(s.label in labels and s.weight >= CHECK_WEIGHT for s in mind.remembered):
        return found
    here = tuple(executor.robot.pose[:2])
    known = _check_in_view(executor, labels, emit)
    if known is not None:
        # seen again where it was, from where the robot stands: the strategy's look round
        # is skipped too (the robot has not moved)
        executor.sensing.resumed = here
        return [known]
    executor.look_around()
    if any(obj.label in labels for obj in mind.objects.values()):
        executor.sensing.resumed = here  # a wanted object in view: nothing to check first
        return found
    while budget_left():
        todo = [s for s in mind.remembered if s.label in labels and s.weight >= CHECK_WEIGHT
                and s not in skipped]
        if not todo:
            break
        plan = _standpoints(executor, todo)
        for s in todo:
            if all(s is not p for p, _ in plan):
                emit("memory", unreachable=s.label, position=list(s.position))
                skipped.append(s)
        if not plan:
            break
        sighting, stand = plan[0]
        known, looked = _check(executor, sighting, stand)
        if not looked:  # the way there failed: kept for a later task, not dropped
            emit("memory", unreachable=sighting.label, position=list(sighting.position))
            skipped.append(sighting)
            continue
        mind.remembered.remove(sighting)
        _emit_checked(emit, sighting, known)
        if known is not None:
            found.append(known)
    # where the robot stands now, the look round or the check's frames have looked: the
    # strategy's first look round would add nothing while a wanted object is known, or while
    # the robot has not moved from where it looked round
    if found or math.dist(here, executor.robot.pose[:2]) <= SAME_SPOT:
        executor.sensing.resumed = tuple(executor.robot.pose[:2])
    return found


def _check_in_view(executor: Executor, labels: Collection[str], emit: Callable[..., Any]
                   ) -> KnownObject | None:
    """Before the look round: the sightings worth a check that the camera sees from where
    the robot stands (a free line of sight in the map, the same room, within the detection
    range), most likely first, are looked at by turning to them. The look round would reach
    them only at their turn of the scan, in about 10 s, and without memory the robot knows
    no direction better than another; with it, one turn and the frames of a confirmation
    tell. One seen again becomes a known object (the first returned); one not seen is
    dropped as a check drops it (missed by two frames of three, it is likelier gone than
    not)."""
    mind, robot = executor.mind, executor.robot
    here = robot.pose[:2]
    room = mind.room_at(here, floor_only=True)
    if room is None:
        return None
    far = _sight_distance(executor)
    occupied = mind.grid.state_grid() == CellState.OCCUPIED
    camera = executor.camera
    in_view = [s for s in mind.remembered if s.label in labels and s.weight >= CHECK_WEIGHT
               and math.hypot(math.dist(s.position[:2], here),
                              camera.height - s.position[2]) <= far
               and mind.room_at(s.position[:2], floor_only=True) == room
               and _in_sight(mind.grid, occupied, here, s.position[:2])]
    reach = executor.config.same_object
    for sighting in sorted(in_view, key=lambda s: (-s.weight, math.dist(s.position[:2],
                                                                          here))):
        if sighting not in mind.remembered:
            continue  # the spot of a sighting checked before
        known = _look_at(executor, sighting)
        # older sightings of the same spot are answered by the same look
        mind.remembered[:] = [s for s in mind.remembered if s.label != sighting.label
                              or math.dist(s.position[:2], sighting.position[:2]) > reach]
        _emit_checked(emit, sighting, known, in_view=True)
        if known is not None:
            executor.sensing.locate()  # the place of the remembered map the robot is at
            return known
    return None


def _emit_checked(emit: Callable[..., Any], sighting: Sighting, known: KnownObject | None,
                  **more: Any) -> None:
    """The trace's `memory` event of one check: seen again (the known object) or dropped."""
    emit("memory", checked=sighting.label, position=[round(v, 2) for v in sighting.position],
         weight=round(sighting.weight, 3), seen=known is not None, **more,
         **({"object": known.id} if known is not None else {"dropped": True}))


def _sight_distance(executor: Executor) -> float:
    """How far a look from where the robot stands counts as seeing a spot: the detection
    range (the body's, else the camera's) with the margin a standpoint keeps from it."""
    body = executor.mind.body
    return 0.9 * (body.detect_range if body is not None else executor.camera.detect_range)


def check_spot(executor: Executor, label: str, position: tuple[float, float, float]
               ) -> tuple[KnownObject | None, bool]:
    """Look at one spot where `label` was seen, as a remembered sighting is checked: from the
    nearest reachable standpoint that sees it, facing it; the known object confirmed there
    (or None), and whether the robot got to look."""
    sighting = Sighting(label, position, executor.robot.clock)
    plan = _standpoints(executor, [sighting])
    if not plan:
        return None, False
    return _check(executor, sighting, plan[0][1])


def _standpoints(executor: Executor, todo: list[Sighting]
                 ) -> list[tuple[Sighting, tuple[float, float]]]:
    """Each sighting's nearest reachable standpoint, most likely and then nearest first."""
    mind, robot = executor.mind, executor.robot
    body = mind.body
    grid = mind.grid
    try:
        reach = distance_field(grid, robot.pose[:2], mind.config.robot_radius)
    except PathQueryError:
        return []
    camera = executor.camera
    # the field of view the verification before a report uses (the body's, else the
    # camera's; a camera without a vertical one is taken as square)
    hfov = body.hfov if body is not None else camera.hfov
    vfov = body.vfov if body is not None else (camera.vfov or camera.hfov)
    far = verify_distance(executor.config.agree[0], hfov, vfov)
    occupied = grid.state_grid() == CellState.OCCUPIED
    out = []
    for s in todo:
        best: tuple[float, tuple[float, float]] | None = None
        room = mind.room_at(s.position[:2], floor_only=True)
        for scale in STANDPOINT_RANGES:
            distance = scale * far if body is None else min(scale * far,
                                                            0.9 * body.detect_range)
            flat = math.sqrt(max(distance**2 - (camera.height - s.position[2]) ** 2, 0.25))
            for k in range(STANDPOINT_TURNS):
                a = 2 * math.pi * k / STANDPOINT_TURNS
                goal = (s.position[0] + flat * math.cos(a), s.position[1] + flat * math.sin(a))
                cell = grid.cell_of(goal)
                if not grid.contains(cell) or not np.isfinite(reach[cell]):
                    continue
                if not _in_sight(grid, occupied, goal, s.position[:2]):
                    continue
                if room is not None and mind.room_at(goal, floor_only=True) != room:
                    continue
                if best is None or reach[cell] < best[0]:
                    best = (float(reach[cell]), goal)
            if best is not None:
                break
        if best is not None:
            out.append((s, best[1], best[0]))
    out.sort(key=lambda e: (-e[0].weight, e[2]))
    return [(s, stand) for s, stand, _ in out]


def _in_sight(grid, occupied: np.ndarray, a: tuple[float, float],  # noqa: ANN001 - a grid
              b: tuple[float, float]) -> bool:
    """No occupied cell on the line from `a` to `SHORT_OF` m before `b`."""
    length = math.dist(a, b)
    if length <= SHORT_OF:
        return True
    t = 1.0 - SHORT_OF / length
    end = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))
    return grid.segment_clear(a, end, ~occupied)


def _check(executor: Executor, sighting: Sighting, stand: tuple[float, float]
           ) -> tuple[KnownObject | None, bool]:
    """Drive to `stand` and look at the spot: the known object confirmed there (or None),
    and whether the robot got to look."""
    mind = executor.mind
    reach = executor.config.same_object
    outcome = executor.drive_to(stand)
    near = _known_near(mind.objects.values(), sighting, reach)
    if near is not None:  # the watch confirmed it on the way
        return near, True
    if outcome.status is not StepStatus.DONE:
        return None, False
    return _look_at(executor, sighting), True


def _look_at(executor: Executor, sighting: Sighting) -> KnownObject | None:
    """Face the spot and look: the known object confirmed there, or None."""
    mind = executor.mind
    seen = _Seen(sighting.label, sighting.position)
    x, y, _ = executor.robot.pose
    dx, dy = sighting.position[0] - x, sighting.position[1] - y
    executor.robot.turn_to(math.atan2(dy, dx))
    executor.context.look(0.0, -math.atan2(executor.camera.height - sighting.position[2],
                                           max(math.hypot(dx, dy), 0.1)))
    if not executor.confirm(seen):
        return None
    room = mind.room_at(sighting.position[:2]) or mind.nearest_room(sighting.position[:2])
    if room is None:
        return None
    return mind.add_object(sighting.label, sighting.position, room=room)


def _known_near(objects, sighting: Sighting, reach: float  # noqa: ANN001 - known objects
                ) -> KnownObject | None:
    return next((o for o in objects if o.label == sighting.label
                 and math.dist(o.position[:2], sighting.position[:2]) <= reach), None)
