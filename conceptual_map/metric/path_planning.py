"""A* paths on the inflated occupancy grid, and bulk travel distances for cost estimates.

MOVE drives along `plan_path`'s waypoints; the state builder prices MOVE actions with
`distance_field` (one Dijkstra sweep in C from the robot to every cell).
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass
from enum import Enum

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph

from conceptual_map.metric.errors import PathQueryError
from conceptual_map.metric.grid2d import OccupancyGrid
from conceptual_map.metric.logodds import CellState

_SQRT2 = math.sqrt(2.0)
_STEPS = (
    (1, 0, 1.0),
    (-1, 0, 1.0),
    (0, 1, 1.0),
    (0, -1, 1.0),
    (1, 1, _SQRT2),
    (1, -1, _SQRT2),
    (-1, 1, _SQRT2),
    (-1, -1, _SQRT2),
)


class PathStatus(Enum):
    FOUND = "found"
    NO_PATH = "no_path"


@dataclass(frozen=True)
class PathResult:
    """A path in world metres (start first, goal last) and its length; no waypoints if none."""

    status: PathStatus
    waypoints: tuple[tuple[float, float], ...]
    length: float
    expanded: int

    @property
    def found(self) -> bool:
        return self.status is PathStatus.FOUND


def plan_path(
    grid: OccupancyGrid,
    start: tuple[float, float],
    goal: tuple[float, float],
    robot_radius: float = 0.25,
    allow_unknown: bool = False,
    smooth: bool = True,
    comfort: float | None = None,
) -> PathResult:
    """Shortest 8-connected path keeping `robot_radius` from obstacles (no corner cutting).

    With `comfort` (a margin larger than `robot_radius`: a squeeze), the smoothed path keeps
    `comfort` wherever it can: a straight shortcut may enter cells closer to obstacles than
    that only where the grid path itself had to, so the path squeezes through a narrow door
    along the cells A* found there, not on a diagonal from the room before it that clips the
    jamb at the slim margin.

    Raises PathQueryError when start or goal lies outside the map, or the goal is blocked.
    A start inside the inflation zone (the robot brushed a wall) may escape it.
    """
    mask = _query_mask(grid, start, goal, robot_radius, allow_unknown)
    s, g = grid.cell_of(start), grid.cell_of(goal)
    squeezing = comfort is not None and comfort > robot_radius
    cells, expanded = _astar(mask, s, g, _discomfort(grid, mask, robot_radius, comfort)
                             if squeezing else None)
    if cells is None:
        return PathResult(PathStatus.NO_PATH, (), math.inf, expanded)
    if smooth:
        sight = mask
        if squeezing:
            sight = grid.traversable(comfort, allow_unknown).copy()
            along = np.asarray(cells)
            sight[along[:, 0], along[:, 1]] = True
        cells = _shortcut(grid, cells, sight)
    points = [tuple(p) for p in grid.to_world(np.asarray(cells)).tolist()]
    points[0], points[-1] = (float(start[0]), float(start[1])), (float(goal[0]), float(goal[1]))
    length = float(sum(math.dist(a, b) for a, b in zip(points, points[1:], strict=False)))
    return PathResult(PathStatus.FOUND, tuple(points), length, expanded)


def _query_mask(
    grid: OccupancyGrid,
    start: tuple[float, float],
    goal: tuple[float, float],
    robot_radius: float,
    allow_unknown: bool,
) -> np.ndarray:
    for name, point in (("start", start), ("goal", goal)):
        if not grid.contains(grid.cell_of(point)):
            raise PathQueryError(f"{name} ({point[0]:.2f}, {point[1]:.2f}) is outside the map")
    s, g = grid.cell_of(start), grid.cell_of(goal)
    states = grid.state_grid()
    if states[s] == CellState.OCCUPIED:
        raise PathQueryError(f"start ({start[0]:.2f}, {start[1]:.2f}) is in an occupied cell")
    mask = grid.traversable(robot_radius, allow_unknown)
    if not mask[g]:
        raise PathQueryError(
            f"goal ({goal[0]:.2f}, {goal[1]:.2f}) is blocked: {_why_blocked(grid, g, robot_radius)}"
        )
    if not mask[s]:
        mask = mask | _escape_zone(grid, s, robot_radius)
    return mask


def _why_blocked(grid: OccupancyGrid, cell: tuple[int, int], radius: float) -> str:
    state = CellState(int(grid.state_grid()[cell]))
    if state is not CellState.FREE:
        return f"the cell is {state.name.lower()}"
    return f"closer than the robot radius {radius:.2f} m to an obstacle"


def _escape_zone(grid: OccupancyGrid, start: tuple[int, int], radius: float) -> np.ndarray:
    """Free cells near the start no closer to obstacles than the start itself, and the
    cells under the robot's own base that are not occupied: the robot stands there (its laser
    never sees them, so they stay unknown and would wall the start in)."""
    clearance = grid.clearance()
    reach = int(math.ceil(radius / grid.resolution)) + 1
    ii, jj = np.ogrid[: grid.shape[0], : grid.shape[1]]
    d2 = (ii - start[0]) ** 2 + (jj - start[1]) ** 2
    states = grid.state_grid()
    free = states == CellState.FREE
    zone = (d2 <= reach**2) & free & (clearance >= min(clearance[start], radius) - 1e-9)
    under = d2 <= (radius / grid.resolution) ** 2
    zone |= under & (states != CellState.OCCUPIED)
    zone[start] = True
    return zone


def _discomfort(grid: OccupancyGrid, mask: np.ndarray, margin: float, comfort: float
                ) -> np.ndarray:
    """Per cell, the extra cost of a step into it on a squeeze: how far its clearance falls
    short of `comfort`, as a share of the squeeze (comfort - margin), times the number of
    cells, so that the search first minimises the shortfall summed along the path (through a
    gap on its middle line, and out of the gap straight on) and only then the length. Without
    it the path took the shortest line through the gap and round its exit at the slim margin:
    the grid's clearance is a cell-centre lower bound, and a PR2 leaving a 0.74 m gap was
    refused at a fridge corner 0.32 m from its centre (footprint 0.34 m)."""
    short = np.clip(comfort - grid.clearance(), 0.0, None) / (comfort - margin)
    return np.where(mask, short * float(mask.size), 0.0)


def _astar(
    mask: np.ndarray, start: tuple[int, int], goal: tuple[int, int],
    extra: np.ndarray | None = None,
) -> tuple[list[tuple[int, int]] | None, int]:
    """A* over the 8-connected cells of `mask` (no corner cutting); a step into a cell costs
    its length times (1 + `extra` there) when `extra` is given (`_discomfort`)."""
    rows, cols = mask.shape
    ok = mask.ravel().tolist()
    penalty = extra.ravel().tolist() if extra is not None else None
    s, g = start[0] * cols + start[1], goal[0] * cols + goal[1]
    gi, gj = goal
    best = {s: 0.0}
    parent = {s: s}
    frontier = [(_octile(start[0], start[1], gi, gj), 0.0, s)]
    closed: set[int] = set()
    while frontier:
        _, cost, node = heapq.heappop(frontier)
        if node == g:
            return _unwind(parent, g, cols), len(closed)
        if node in closed:
            continue
        closed.add(node)
        i, j = divmod(node, cols)
        for di, dj, step in _STEPS:
            ni, nj = i + di, j + dj
            if not (0 <= ni < rows and 0 <= nj < cols) or not ok[ni * cols + nj]:
                continue
            if di and dj and not (ok[ni * cols + j] and ok[i * cols + nj]):
                continue
            nxt = ni * cols + nj
            new = cost + (step if penalty is None else step * (1.0 + penalty[nxt]))
            if new < best.get(nxt, math.inf):
                best[nxt], parent[nxt] = new, node
                heapq.heappush(frontier, (new + _octile(ni, nj, gi, gj), new, nxt))
    return None, len(closed)


def _octile(i: int, j: int, gi: int, gj: int) -> float:
    di, dj = abs(i - gi), abs(j - gj)
    return max(di, dj) + (_SQRT2 - 1.0) * min(di, dj)


def _unwind(parent: dict[int, int], goal: int, cols: int) -> list[tuple[int, int]]:
    path = [goal]
    while parent[path[-1]] != path[-1]:
        path.append(parent[path[-1]])
    return [divmod(n, cols) for n in reversed(path)]


def _shortcut(
    grid: OccupancyGrid, cells: list[tuple[int, int]], mask: np.ndarray
) -> list[tuple[int, int]]:
    """Greedy string pulling: jump to the farthest cell still in straight clear sight."""
    centres = grid.to_world(np.asarray(cells))
    out, i = [cells[0]], 0
    while i < len(cells) - 1:
        j = i + 1
        while j + 1 < len(cells) and grid.segment_clear(centres[i], centres[j + 1], mask):
            j += 1
        out.append(cells[j])
        i = j
    return out


def distance_field(
    grid: OccupancyGrid,
    start: tuple[float, float],
    robot_radius: float = 0.25,
    allow_unknown: bool = False,
) -> np.ndarray:
    """Grid-path distance (m) from `start` to every cell; inf where unreachable.

    8-connected like `plan_path` before smoothing, so it can exceed the smoothed length by
    up to ~8 %; good for comparing travel costs.
    """
    cell = grid.cell_of(start)
    if not grid.contains(cell):
        raise PathQueryError(f"start ({start[0]:.2f}, {start[1]:.2f}) is outside the map")
    mask = grid.traversable(robot_radius, allow_unknown)
    if not mask[cell]:
        mask = mask | _escape_zone(grid, cell, robot_radius)
    graph = _grid_graph(mask) * grid.resolution
    source = cell[0] * grid.shape[1] + cell[1]
    dist = csgraph.dijkstra(graph, indices=source)
    return dist.reshape(grid.shape)


def distance_fields(
    grid: OccupancyGrid,
    starts: list[tuple[float, float]],
    robot_radius: float = 0.25,
    allow_unknown: bool = False,
) -> np.ndarray:
    """`distance_field` from several starts at once (k, rows, cols): one graph, one C call."""
    cells = [grid.cell_of(s) for s in starts]
    for s, cell in zip(starts, cells, strict=True):
        if not grid.contains(cell):
            raise PathQueryError(f"start ({s[0]:.2f}, {s[1]:.2f}) is outside the map")
    mask = grid.traversable(robot_radius, allow_unknown)
    for cell in cells:
        if not mask[cell]:
            mask = mask | _escape_zone(grid, cell, robot_radius)
    graph = _grid_graph(mask) * grid.resolution
    sources = [i * grid.shape[1] + j for i, j in cells]
    dist = csgraph.dijkstra(graph, indices=sources)
    return dist.reshape((len(starts),) + grid.shape)


def distances_at(
    grid: OccupancyGrid,
    starts: list[tuple[float, float]],
    cells: np.ndarray,
    robot_radius: float = 0.25,
    allow_unknown: bool = False,
) -> np.ndarray:
    """`distance_fields` read at `cells` ((m, 2) grid cells) only: (k, m) metres, inf where
    unreachable. Dijkstra runs on the traversable cells alone, so neither its graph nor its
    result spans the whole map (k full fields of a building map are tens of MB)."""
    cells = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    starts_cells = [grid.cell_of(s) for s in starts]
    for s, cell in zip(starts, starts_cells, strict=True):
        if not grid.contains(cell):
            raise PathQueryError(f"start ({s[0]:.2f}, {s[1]:.2f}) is outside the map")
    inside = np.all((cells >= 0) & (cells < np.asarray(grid.shape)), axis=1)
    if not inside.all():
        bad = cells[~inside][0]
        raise PathQueryError(f"cell ({bad[0]}, {bad[1]}) is outside the map")
    mask = grid.traversable(robot_radius, allow_unknown)
    for cell in starts_cells:
        if not mask[cell]:
            mask = mask | _escape_zone(grid, cell, robot_radius)
    nodes = np.flatnonzero(mask.ravel())
    graph = (_grid_graph(mask) * grid.resolution).tocsr()[nodes][:, nodes]
    index = np.full(mask.size, -1, dtype=np.int64)
    index[nodes] = np.arange(nodes.size)
    flat_starts = np.array([i * grid.shape[1] + j for i, j in starts_cells], dtype=np.int64)
    flat_cells = cells[:, 0] * grid.shape[1] + cells[:, 1]
    out = np.full((len(starts), cells.shape[0]), np.inf)
    out[flat_starts[:, None] == flat_cells[None, :]] = 0.0  # a start's own cell, as a field
    src = index[flat_starts]
    at = index[flat_cells]
    rows = np.flatnonzero(src >= 0)
    if rows.size and (at >= 0).any():
        dist = csgraph.dijkstra(graph, indices=src[rows])
        out[np.ix_(rows, np.flatnonzero(at >= 0))] = dist[:, at[at >= 0]]
    return out


def _grid_graph(mask: np.ndarray) -> sparse.csr_matrix:
    rows, cols = mask.shape
    index = np.arange(rows * cols).reshape(rows, cols)
    src, dst, wts = [], [], []
    for di, dj, step in _STEPS[::2]:  # one of each opposite pair; the graph is undirected
        both = mask & _neighbour(mask, di, dj)
        if di and dj:  # no cutting corners, as in A*
            both &= _neighbour(mask, di, 0) & _neighbour(mask, 0, dj)
        src.append(index[both])
        dst.append(index[both] + di * cols + dj)
        wts.append(np.full(int(both.sum()), step))
    n = rows * cols
    m = sparse.coo_matrix(
        (np.concatenate(wts), (np.concatenate(src), np.concatenate(dst))), shape=(n, n)
    )
    return (m + m.T).tocsr()


def _neighbour(a: np.ndarray, di: int, dj: int) -> np.ndarray:
    """out[i, j] = a[i + di, j + dj], False beyond the border."""
    rows, cols = a.shape
    out = np.zeros_like(a)
    out[max(0, -di) : rows - max(0, di), max(0, -dj) : cols - max(0, dj)] = a[
        max(0, di) : rows + min(0, di), max(0, dj) : cols + min(0, dj)
    ]
    return out
