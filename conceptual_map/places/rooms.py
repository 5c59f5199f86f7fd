"""Rooms: places connected without crossing a door, and the free area they span.

Geometry (area, elongation) feeds the conceptual map's size and shape properties.
"""

from __future__ import annotations

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
