"""The trajectory picture in the style of Fig. 3 of the active visual search paper (Göbelbecker
et al.): the robot's own map, its path coloured by the room category it believed at the time,
start and end, detections, places."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from avs_planner.episode.executor import Stats  # noqa: E402
from avs_planner.episode.mind import Mind  # noqa: E402
from conceptual_map.metric import CellState  # noqa: E402

_PALETTE = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2"]


def draw_trajectory(mind: Mind, stats: Stats, out: Path, title: str = "") -> None:
    """Write the picture to `out` (PNG)."""
    fig, ax = plt.subplots(figsize=(8, 6), dpi=100)
    _draw_grid(ax, mind)
    _draw_places(ax, mind)
    handles = _draw_path(ax, stats)
    _draw_detections(ax, stats, mind)
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.legend(handles=handles, loc="upper right", fontsize=7, framealpha=0.8)
    fig.tight_layout()
    fig.savefig(out)
    plt.close(fig)


def _draw_grid(ax: plt.Axes, mind: Mind) -> None:
    grid = mind.grid
    states = grid.state_grid()
    image = np.full(states.shape, 0.75)
    image[states == CellState.FREE] = 1.0
    image[states == CellState.OCCUPIED] = 0.1
    x0, y0 = grid.origin
    x1, y1 = x0 + states.shape[0] * grid.resolution, y0 + states.shape[1] * grid.resolution
    ax.imshow(image.T, origin="lower", cmap="gray", vmin=0, vmax=1, extent=(x0, x1, y0, y1))
    known = np.argwhere(states != CellState.UNKNOWN)
    if len(known):
        lo, hi = grid.to_world(known.min(axis=0)), grid.to_world(known.max(axis=0))
        ax.set_xlim(lo[0] - 0.5, hi[0] + 0.5)
        ax.set_ylim(lo[1] - 0.5, hi[1] + 0.5)


def _draw_places(ax: plt.Axes, mind: Mind) -> None:
    pm = mind.place_map
    if pm.places:
        xy = np.array([p.position for p in pm.places.values()])
        ax.scatter(xy[:, 0], xy[:, 1], s=8, c="#555555", zorder=3)
    if pm.placeholders:
        xy = np.array([p.position for p in pm.placeholders.values()])
        ax.scatter(xy[:, 0], xy[:, 1], s=14, facecolors="none", edgecolors="#555555", zorder=3)
    for door in pm.doors.values():
        (ax_, ay), (bx, by) = door.ends
        ax.plot([ax_, bx], [ay, by], color="#ff00ff", lw=3, zorder=4)


def _draw_path(ax: plt.Axes, stats: Stats) -> list[Line2D]:
    path = stats.path
    if not path:
        return []
    categories = sorted({c for *_, c in path})
    colour = {c: _PALETTE[i % len(_PALETTE)] for i, c in enumerate(categories)}
    for a, b in zip(path, path[1:], strict=False):
        ax.plot([a[0], b[0]], [a[1], b[1]], color=colour[b[3]], lw=2, zorder=5)
    ax.plot(*path[0][:2], marker="o", ms=9, color="green", zorder=6)
    ax.plot(*path[-1][:2], marker="X", ms=10, color="black", zorder=6)
    handles = [Line2D([], [], color=colour[c], lw=2, label=c or "no room yet") for c in categories]
    handles += [Line2D([], [], marker="o", color="green", ls="", label="start"),
                Line2D([], [], marker="X", color="black", ls="", label="end")]
    return handles


def _draw_detections(ax: plt.Axes, stats: Stats, mind: Mind) -> None:
    for x, y, _label, matched in stats.detections:
        ax.plot(x, y, marker="*", ms=9 if matched else 6, color="orange" if matched else "grey",
                zorder=7)
    for obj in mind.objects.values():
        ax.annotate(f"{obj.id}:{obj.label}", obj.position[:2], fontsize=7, zorder=8,
                    xytext=(3, 3), textcoords="offset points")
