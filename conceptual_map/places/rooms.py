"""Rooms: places connected without crossing a door, and the free area they span.

Geometry (area, elongation) feeds the conceptual map's size and shape properties.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import networkx as nx
import numpy as np
from scipy import ndimage

from conceptual_map.metric.grid2d import OccupancyGrid
from conceptual_map.metric.logodds import CellState

Chord = tuple[tuple[float, float], tuple[float, float]]


def place_groups(graph: nx.Graph) -> list[set[str]]:
    """Connected groups of places once every edge that crosses a door is cut."""
    places = [n for n, kind in graph.nodes(data="kind") if kind == "place"]
    open_edges = [
        (u, v)
        for u, v, door in graph.edges(data="door")
        if door is None and graph.nodes[u]["kind"] == graph.nodes[v]["kind"] == "place"
    ]
    sub = nx.Graph()
    sub.add_nodes_from(places)
    sub.add_edges_from(open_edges)
    return [set(c) for c in nx.connected_components(sub)]


def free_regions(grid: OccupancyGrid, chords: list[Chord]) -> np.ndarray:
    """Labels of the known free space split along door chords (0 = not free)."""
    free = grid.state_grid() == CellState.FREE
    cut = np.zeros_like(free)
    for a, b in chords:
        length = float(np.hypot(b[0] - a[0], b[1] - a[1]))
        n = max(2, int(np.ceil(length / (0.25 * grid.resolution))) + 1)
        t = np.linspace(-0.1, 1.1, n)[:, None]  # overshoot into the jambs
        cells = grid.to_cell(np.asarray(a) * (1 - t) + np.asarray(b) * t)
        cells = cells[grid.inside(cells)]
        cut[cells[:, 0], cells[:, 1]] = True
    cut = ndimage.binary_dilation(cut)
    labels, _ = ndimage.label(free & ~cut)
    return labels


def room_geometry(
    grid: OccupancyGrid, labels: np.ndarray, positions: list[tuple[float, float]]
) -> tuple[float, float]:
    """Area (m^2) and elongation of the free regions holding these places.

    Elongation is sqrt(largest / smallest principal variance) of the free cells: 1 for a
    square, about a/b for an a x b rectangle.
    """
    cells = grid.to_cell(np.asarray(positions))
    cells = cells[grid.inside(cells)]
    ids = {int(v) for v in labels[cells[:, 0], cells[:, 1]]} - {0}
    if not ids:
        return 0.0, 1.0
    mask = np.isin(labels, list(ids))
    coords = np.argwhere(mask).astype(float)
    area = coords.shape[0] * grid.resolution**2
    if coords.shape[0] < 3:
        return area, 1.0
    variances = np.linalg.eigvalsh(np.cov(coords.T))
    low = max(float(variances[0]), 1e-9)
    return area, float(np.sqrt(max(float(variances[-1]), low) / low))


def room_extents(
    grid: OccupancyGrid,
    labels: np.ndarray,
    rooms: Mapping[str, Sequence[tuple[float, float]]],
    snap: float = 0.3,
) -> tuple[np.ndarray, list[str]]:
    """Which room each known free cell belongs to: the free regions (`free_regions`) its
    places stand in, as for a room's area. Returns an int array over the grid (k + 1 for the
    k-th of the returned sorted room ids, 0 for a cell no room holds: not free, or free space
    no place stands in, such as a room seen through a door but not entered). A region several
    rooms' places stand in (a door the free space leaks around) goes cell by cell to the room
    of the nearest of those places. A place on no free region (e.g. in a doorway, where the
    regions are cut) stands in the region of the nearest free cell within `snap` metres."""
    ids = sorted(rooms)
    owner = np.zeros(labels.shape, dtype=np.int32)
    claims: dict[int, list[tuple[int, tuple[float, float]]]] = {}
    for k, rid in enumerate(ids, start=1):
        for position in rooms[rid]:
            label = _region_at(grid, labels, position, snap)
            if label:
                claims.setdefault(label, []).append((k, position))
    for label, claim in claims.items():
        mask = labels == label
        owners = {k for k, _ in claim}
        if len(owners) == 1:
            owner[mask] = owners.pop()
            continue
        cells = np.argwhere(mask)
        centres = grid.to_world(cells)
        points = np.asarray([p for _, p in claim], dtype=float)
        nearest = np.linalg.norm(centres[:, None, :] - points[None, :, :], axis=2).argmin(axis=1)
        owner[cells[:, 0], cells[:, 1]] = np.asarray([k for k, _ in claim])[nearest]
    return owner, ids


def _region_at(
    grid: OccupancyGrid, labels: np.ndarray, position: tuple[float, float], snap: float
) -> int:
    """The free region at `position`, or of the nearest free cell within `snap` m (0: none)."""
    cell = grid.to_cell(np.asarray([position], dtype=float))[0]
    if not grid.inside(cell[None, :])[0]:
        return 0
    if labels[cell[0], cell[1]]:
        return int(labels[cell[0], cell[1]])
    r = int(np.ceil(snap / grid.resolution))
    lo = np.maximum(cell - r, 0)
    hi = np.minimum(cell + r + 1, labels.shape)
    window = labels[lo[0]:hi[0], lo[1]:hi[1]]
    found = np.argwhere(window > 0)
    if len(found) == 0:
        return 0
    d = np.linalg.norm(found + lo - cell, axis=1)
    if d.min() * grid.resolution > snap:
        return 0
    best = found[d.argmin()]
    return int(window[best[0], best[1]])
