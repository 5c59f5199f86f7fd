"""Wall layout of a world: room borders merged per line, with door openings cut out.

Shared by the physics scene and the top-down renderer, so both show the same walls.
"""

from __future__ import annotations

from dataclasses import dataclass

from sim.world_checks import shared_wall
from sim.world_spec import WorldSpec

_EPS = 1e-6


@dataclass(frozen=True)
class WallSegment:
    """A straight wall piece on the line `axis = line`, spanning [lo, hi] along the other axis."""

    axis: str  # "x": vertical line x = line; "y": horizontal line y = line
    line: float
    lo: float
    hi: float

    def endpoints(self) -> tuple[tuple[float, float], tuple[float, float]]:
        if self.axis == "x":
            return (self.line, self.lo), (self.line, self.hi)
        return (self.lo, self.line), (self.hi, self.line)


@dataclass(frozen=True)
class DoorOpening:
    """Where door `index` of the world file cuts its wall (same geometry as `WallSegment`)."""

    index: int
    segment: WallSegment
    open: bool


def door_openings(spec: WorldSpec) -> list[DoorOpening]:
    """The opening of every door of a checked world, in file order."""
    result = []
    for i, door in enumerate(spec.doors):
        a, b = spec.room(door.rooms[0]), spec.room(door.rooms[1])
        assert a is not None and b is not None
        wall = shared_wall(a, b)
        assert wall is not None, "unchecked world"
        axis, line, _, _ = wall
        along = door.at[1] if axis == "x" else door.at[0]
        half = door.width / 2.0
        segment = WallSegment(axis, line, along - half, along + half)
        result.append(DoorOpening(i, segment, door.open))
    return result


def wall_segments(spec: WorldSpec) -> list[WallSegment]:
    """All wall pieces: room borders merged along each line, minus every door opening."""
    intervals: dict[tuple[str, float], list[tuple[float, float]]] = {}
    for room in spec.rooms:
        x0, y0, x1, y1 = room.rect
        for key, span in (
            (("x", x0), (y0, y1)), (("x", x1), (y0, y1)),
            (("y", y0), (x0, x1)), (("y", y1), (x0, x1)),
        ):
            intervals.setdefault((key[0], round(key[1], 6)), []).append(span)
    cuts: dict[tuple[str, float], list[tuple[float, float]]] = {}
    for opening in door_openings(spec):
        seg = opening.segment
        cuts.setdefault((seg.axis, round(seg.line, 6)), []).append((seg.lo, seg.hi))
    segments = []
    for (axis, line), spans in sorted(intervals.items()):
        for lo, hi in _subtract(_merge(spans), cuts.get((axis, line), [])):
            segments.append(WallSegment(axis, line, lo, hi))
    return segments


def _merge(spans: list[tuple[float, float]]) -> list[tuple[float, float]]:
    merged: list[tuple[float, float]] = []
    for lo, hi in sorted(spans):
        if merged and lo <= merged[-1][1] + _EPS:
            merged[-1] = (merged[-1][0], max(merged[-1][1], hi))
        else:
            merged.append((lo, hi))
    return merged


def _subtract(spans: list[tuple[float, float]],
              holes: list[tuple[float, float]]) -> list[tuple[float, float]]:
    for h_lo, h_hi in holes:
        pieces = []
        for lo, hi in spans:
            if h_hi <= lo or h_lo >= hi:
                pieces.append((lo, hi))
                continue
            if h_lo - lo > _EPS:
                pieces.append((lo, h_lo))
            if hi - h_hi > _EPS:
                pieces.append((h_hi, hi))
        spans = pieces
    return spans
