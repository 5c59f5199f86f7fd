"""Top-down picture of a world: rooms coloured by category, walls, doors, furniture, objects, robot.

Drawn from the world spec alone (no physics), so a user can check a world file by eye.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Circle, Polygon, Rectangle  # noqa: E402

from sim.robot_models import ROBOT_MODELS  # noqa: E402
from sim.walls import door_openings, wall_segments  # noqa: E402
from sim.world_spec import WorldSpec, box_corners  # noqa: E402

CATEGORY_COLOURS = {"kitchen": "#f4b6b6", "office": "#b6c8f4", "corridor": "#bfe8bf"}
_OTHER_COLOURS = ["#f4e1b6", "#dcb6f4", "#b6f0f0", "#e0e0e0"]


def category_colours(spec: WorldSpec) -> dict[str, str]:
    """A fill colour per room category (the red kitchen, blue office and green corridor of the
    active visual search paper by Göbelbecker et al.)."""
    colours: dict[str, str] = {}
    extra = iter(_OTHER_COLOURS * (1 + len(spec.rooms)))
    for room in spec.rooms:
        if room.category not in colours:
            colours[room.category] = CATEGORY_COLOURS.get(room.category) or next(extra)
    return colours


def render_world(spec: WorldSpec, out: str | Path,
                 robot_pose: tuple[float, float, float] | None = None,
                 trajectory: Sequence[Sequence[float]] = ()) -> Path:
    """Write a PNG of `spec` to `out`: robot at `robot_pose` (default: start), optional path."""
    w, h = spec.size
    fig, ax = plt.subplots(figsize=(max(6.0, w * 0.9), max(4.0, h * 0.9) + 0.6))
    try:
        _draw_rooms(ax, spec)
        _draw_walls_and_doors(ax, spec)
        _draw_furniture_and_objects(ax, spec)
        if len(trajectory) > 1:
            xs, ys = zip(*[(p[0], p[1]) for p in trajectory], strict=True)
            ax.plot(xs, ys, color="#1f3a93", linewidth=1.5, zorder=7, label="trajectory")
        _draw_robot(ax, spec, robot_pose or spec.robot.start)
        ax.set_xlim(-0.3, w + 0.3)
        ax.set_ylim(-0.3, h + 0.3)
        ax.set_aspect("equal")
        ax.set_title(f"{spec.name} ({w:g} x {h:g} m)")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        path = Path(out)
        fig.savefig(path, dpi=110, bbox_inches="tight")
    finally:
        plt.close(fig)
    return path


def _draw_rooms(ax: plt.Axes, spec: WorldSpec) -> None:
    colours = category_colours(spec)
    for room in spec.rooms:
        x0, y0, x1, y1 = room.rect
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, facecolor=colours[room.category],
                               edgecolor="none", zorder=0))
        ax.text(x0 + 0.12, y1 - 0.12, f"{room.name}\n({room.category})", ha="left", va="top",
                fontsize=8, color="#333333", zorder=5)


def _draw_walls_and_doors(ax: plt.Axes, spec: WorldSpec) -> None:
    for seg in wall_segments(spec):
        (ax_, ay), (bx, by) = seg.endpoints()
        ax.plot([ax_, bx], [ay, by], color="black", linewidth=3, solid_capstyle="projecting",
                zorder=3)
    for opening in door_openings(spec):
        (ax_, ay), (bx, by) = opening.segment.endpoints()
        style = {"color": "#2a9d2a", "linestyle": ":"} if opening.open else {"color": "#c0392b"}
        ax.plot([ax_, bx], [ay, by], linewidth=3, zorder=3, **style)


def _draw_furniture_and_objects(ax: plt.Axes, spec: WorldSpec) -> None:
    for item in spec.furniture:
        ax.add_patch(Polygon(item.footprint(), closed=True, facecolor="#a0825f",
                             edgecolor="#5a4630", alpha=0.85, zorder=2))
        ax.text(item.pose[0], item.pose[1], item.name, ha="center", va="center", fontsize=6,
                color="white", zorder=4)
    for obj in spec.objects:
        x, y, _, yaw = spec.object_pose(obj)
        ax.add_patch(Polygon(box_corners((x, y, yaw), (obj.size[0], obj.size[1])), closed=True,
                             facecolor="#e67e22", edgecolor="black", linewidth=0.5, zorder=6))
        ax.annotate(obj.label, (x, y), xytext=(4, 4), textcoords="offset points", fontsize=7,
                    color="#8e3b00", zorder=7)


def _draw_robot(ax: plt.Axes, spec: WorldSpec, pose: tuple[float, float, float]) -> None:
    x, y, yaw = pose
    radius = ROBOT_MODELS[spec.robot.model].footprint_radius
    ax.add_patch(Circle((x, y), radius, facecolor="#7f8c8d", edgecolor="black", zorder=8))
    ax.arrow(x, y, radius * math.cos(yaw), radius * math.sin(yaw), width=0.03,
             color="yellow", zorder=9, length_includes_head=True)
    ax.annotate(spec.robot.model, (x, y), xytext=(0, -14), textcoords="offset points",
                ha="center", fontsize=7, zorder=9)
