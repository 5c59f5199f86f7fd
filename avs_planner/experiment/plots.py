"""The report's pictures (matplotlib, Agg): sim-time distributions, success by group."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from avs_planner.experiment.stats import wilson

Row = dict[str, Any]


def sim_time_plot(rows: list[Row], key: str, names: list[str], path: Path) -> Path | None:
    """Box plots of simulated time per `key` value (strategy, or group), runs on top."""
    data = [[r["sim_time_s"] for r in rows if r[key] == name and r["sim_time_s"] is not None]
            for name in names]
    if not any(data):
        return None
    figure, axes = _figure(max(4.0, 1.1 * len(names) + 2))
    axes.boxplot(data, showfliers=False)
    for i, values in enumerate(data, start=1):
        jitter = [i + 0.25 * ((k * 0.618) % 1 - 0.5) for k in range(len(values))]
        axes.scatter(jitter, values, s=8, alpha=0.5, color="tab:blue")
    axes.set_xticks(range(1, len(names) + 1), names)
    axes.set_ylabel("simulated time (s)")
    axes.set_title(f"Simulated time per {key} (completed runs)")
    return _save(figure, path)


def success_plot(rows: list[Row], groups: list[str], strategies: list[str],
                 ok: Any, path: Path) -> Path | None:
    """Bars: share of runs ending as expected, per group and strategy, Wilson 95% error bars."""
    if not groups:
        return None
    figure, axes = _figure(max(5.0, 0.9 * len(groups) * len(strategies) + 2))
    width = 0.8 / len(strategies)
    for k, strategy in enumerate(strategies):
        xs, heights, low, high = [], [], [], []
        for g, group in enumerate(groups):
            cell = [ok(r) for r in rows if r["group"] == group and r["strategy"] == strategy]
            interval = wilson(sum(cell), len(cell))
            if interval is None:
                continue
            xs.append(g + (k - (len(strategies) - 1) / 2) * width)
            heights.append(interval.estimate)
            low.append(interval.estimate - interval.low)
            high.append(interval.high - interval.estimate)
        axes.bar(xs, heights, width, yerr=[low, high], capsize=3, label=strategy)
    axes.set_xticks(range(len(groups)), groups)
    axes.set_ylim(0, 1.05)
    axes.set_ylabel("runs ending as expected")
    axes.set_title("Found, or gave up on an absent target (95% Wilson)")
    if len(strategies) > 1:
        axes.legend()
    return _save(figure, path)


def _figure(width: float) -> tuple[Any, Any]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt.subplots(figsize=(min(width, 16.0), 4.0))


def _save(figure: Any, path: Path) -> Path:
    import matplotlib.pyplot as plt

    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return path
