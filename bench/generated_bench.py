"""Success on unseen buildings: generated worlds x (two present objects, one absent label).

Run: `.venv/bin/python -m bench.generated_bench [--worlds N] [--style office] [--strategies
switching,exhaustive,most-likely-room] [--workers W] [--jsonl FILE] [--option K=V ...]`
(options go to the switching strategy, e.g. `--option reward=1000`; default 50 office worlds,
all three strategies, one process per core). Every strategy runs on the same worlds, targets
and seeds. Per strategy: found rate for present objects, correct give-up rate for absent ones,
false reports (a wrong object reported; must be 0), median and p90 simulated time and distance
over present-object episodes (an episode that failed counts with the time it spent), median
wall time; then the switching planner's median sim time over each baseline's, paired on the
same (world, target).
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

from avs_planner.harness import run_episode
from avs_planner.harness.worlds import generated_targets

STRATEGIES = ("switching", "exhaustive", "most-likely-room")


def episodes(worlds: int, style: str, strategies: list[str], first: int = 0,
             robot: str | None = None, options: dict | None = None,
             budget: float | None = None) -> list[dict]:
    """One spec per (world, target, strategy); the targets come from the generator's record.
    `options` are the switching strategy's (`--option K=V`); `budget` the simulated seconds
    per episode (default: the episode's own, 1200)."""
    specs = []
    for seed in range(first, first + worlds):
        for label, present in generated_targets(seed, style):
            for strategy in strategies:
                extra = {"strategy_options": options} if options and strategy == "switching" \
                    else {}
                specs.append({"generate": {"seed": seed, "style": style}, "target": label,
                              "seed": seed, "strategy": strategy, "present": present,
                              **({"robot": robot} if robot else {}),
                              **({"time_budget_s": budget} if budget else {}), **extra})
    return specs


def _options(pairs: list[str]) -> dict:
    """`K=V` pairs; V read as JSON when it parses (numbers, true/false), else a string."""
    out = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise SystemExit(f"--option wants KEY=VALUE, got {pair!r}")
        try:
            out[key] = json.loads(value)
        except json.JSONDecodeError:
            out[key] = value
    return out


def run_one(spec: dict) -> dict:
    present = spec.pop("present")
    start = time.perf_counter()
    try:
        summary = run_episode(spec)
    except Exception as exc:  # noqa: BLE001 - a crashed episode is a result, not the end
        summary = {"outcome": "error", "reason": f"{type(exc).__name__}: {exc}",
                   "correct": False, "sim_time_s": float("nan"), "distance_m": float("nan")}
    summary.update(world=spec["generate"]["seed"], target=spec["target"],
                   strategy=spec["strategy"], present=present,
                   wall_time_s=time.perf_counter() - start)
    return summary


def _median(values: list[float]) -> float:
    values = [v for v in values if math.isfinite(v)]
    return statistics.median(values) if values else float("nan")


def _p90(values: list[float]) -> float:
    values = sorted(v for v in values if math.isfinite(v))
    return values[min(len(values) - 1, math.ceil(0.9 * len(values)) - 1)] if values else math.nan


def table(rows: list[dict], strategies: list[str]) -> str:
    lines = [f"{'strategy':17s} {'found':>9s} {'gave up':>9s} {'false':>5s} {'errors':>6s} "
             f"{'sim s med':>9s} {'p90':>7s} {'dist m':>7s} {'wall s':>7s}"]
    for name in strategies:
        mine = [r for r in rows if r["strategy"] == name]
        present = [r for r in mine if r["present"]]
        absent = [r for r in mine if not r["present"]]
        found = sum(r["outcome"] == "found" and r["correct"] for r in present)
        gave_up = sum(r["outcome"] == "gave_up" for r in absent)
        false = sum(r["outcome"] == "found" and not r["correct"] for r in mine)
        errors = sum(r["outcome"] == "error" for r in mine)
        sims = [r["sim_time_s"] for r in present]
        lines.append(
            f"{name:17s} {found:>4d}/{len(present):<4d} {gave_up:>4d}/{len(absent):<4d} "
            f"{false:>5d} {errors:>6d} {_median(sims):9.1f} {_p90(sims):7.1f} "
            f"{_median([r['distance_m'] for r in present]):7.1f} "
            f"{_median([r['wall_time_s'] for r in mine]):7.1f}")
    return "\n".join(lines)


def paired(rows: list[dict], mine: str, other: str) -> str:
    """Median over (world, target) of mine's sim time / other's, present objects both found."""
    key = {(r["strategy"], r["world"], r["target"]): r for r in rows if r["present"]}
    ratios = []
    for (strategy, world, target), r in key.items():
        o = key.get((other, world, target))
        if strategy == mine and o and r["outcome"] == o["outcome"] == "found" \
                and o["sim_time_s"] > 0:
            ratios.append(r["sim_time_s"] / o["sim_time_s"])
    whole = [r for r in rows if r["present"]]
    a = _median([r["sim_time_s"] for r in whole if r["strategy"] == mine])
    b = _median([r["sim_time_s"] for r in whole if r["strategy"] == other])
    return (f"{mine} / {other}: median sim time {a:.1f} / {b:.1f} s = {a / b:.2f}; paired "
            f"median ratio {_median(ratios):.2f} over {len(ratios)} objects both found")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", type=int, default=50)
    parser.add_argument("--first", type=int, default=0, help="first world seed (default 0)")
    parser.add_argument("--style", default="office")
    parser.add_argument("--strategies", default=",".join(STRATEGIES))
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--quick", action="store_true", help="3 worlds")
    parser.add_argument("--jsonl", type=Path, help="write every episode's summary here")
    parser.add_argument("--robot", choices=("pioneer", "pr2"),
                        help="robot model (default: the world's, the pioneer)")
    parser.add_argument("--option", action="append", default=[], metavar="K=V",
                        help="a switching-strategy option (repeatable), e.g. reward=1000")
    parser.add_argument("--budget", type=float, default=None, metavar="S",
                        help="simulated seconds per episode (default: the episode's, 1200)")
    args = parser.parse_args(argv)
    if args.budget is not None and args.budget <= 0:
        parser.error(f"--budget must be a positive number of seconds, got {args.budget:g}")
    strategies = args.strategies.split(",")
    specs = episodes(3 if args.quick else args.worlds, args.style, strategies, args.first,
                     args.robot, _options(args.option), args.budget)
    print(f"generated bench: {len(specs)} episodes ({args.style} worlds "
          f"{args.first}..{args.first + (3 if args.quick else args.worlds) - 1}, "
          f"strategies {', '.join(strategies)}"
          f"{f', budget {args.budget:g} s' if args.budget else ''})", flush=True)
    rows, start = [], time.perf_counter()
    out = args.jsonl.open("w", encoding="utf-8") if args.jsonl else None
    with ProcessPoolExecutor(args.workers) as pool:
        futures = [pool.submit(run_one, spec) for spec in specs]
        for k, future in enumerate(as_completed(futures), start=1):
            row = future.result()
            rows.append(row)
            if out is not None:
                out.write(json.dumps(row, default=str) + "\n")
                out.flush()
            print(f"\r{k}/{len(specs)} done, {time.perf_counter() - start:.0f} s",
                  end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    print(table(rows, strategies))
    for other in strategies:
        if other != "switching" and "switching" in strategies:
            print(paired(rows, "switching", other))
    return 0


if __name__ == "__main__":
    sys.exit(main())
