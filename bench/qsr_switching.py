"""The switching planner with and without QSR-weighted view cones.

Runs `switching` searches for a cup (seeds 0..N-1) per world with option `qsr_cones` set to
`on` (cones follow the QSR mixture at the perceived landmarks), `observe` (the same landmark
detections, uniform cones: isolates the weighting, since asking the detector for more labels
changes its noise draws) and optionally `off`. Prints per mode: found, views processed (the
DT's PROCESSVIEWCONE looks), simulated time, and how many searches built QSR cones; a per-seed
table shows where the modes differ.
Run: `python -m bench.qsr_switching [--seeds 10] [--worlds qsr_kitchen_b,qsr_desks_b]
[--modes on,observe]`.
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

from avs_planner.harness import run_episode


def run(world: str, seed: int, mode: str) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as tmp:
        summary = run_episode({"target": "cup", "world": world, "strategy": "switching",
                               "seed": seed, "strategy_options": {"qsr_cones": mode},
                               "output_dir": tmp})  # fmt: skip
        lines = Path(tmp, "trace.jsonl").read_text(encoding="utf-8").splitlines()
    events = [json.loads(line) for line in lines]
    weighted = [e for e in events if "qsr_cones" in e and "weights" in e]
    return {"found": summary["outcome"] == "found" and bool(summary["correct"]),
            "views": summary["views_processed"], "time": summary["sim_time_s"],
            "qsr_cones": len(weighted), "wall": summary["wall_time_s"]}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--worlds", default="qsr_kitchen_b,qsr_desks_b")
    parser.add_argument("--modes", default="on,observe")
    args = parser.parse_args(argv)
    modes = [m.strip() for m in args.modes.split(",")]
    start = time.perf_counter()
    for world in [w.strip() for w in args.worlds.split(",")]:
        rows = {m: [run(world, s, m) for s in range(args.seeds)] for m in modes}
        print(f"{world}: switching, cup, seeds 0..{args.seeds - 1}")
        print(f"{'qsr_cones':<10} {'found':>7} {'views':>6} {'mean views':>11} "
              f"{'mean time s':>12} {'weighted':>9}")
        for m in modes:
            r = rows[m]
            views = [x["views"] for x in r]
            print(f"{m:<10} {sum(x['found'] for x in r):>3}/{len(r):<3} "
                  f"{sum(views):>6} {statistics.fmean(views):>11.2f}"
                  f" {statistics.fmean(x['time'] for x in r):>12.1f} "
                  f"{sum(x['qsr_cones'] > 0 for x in r):>9}")
        differ = [s for s in range(args.seeds)
                  if len({(rows[m][s]["views"], rows[m][s]["found"]) for m in modes}) > 1]
        for s in differ:
            cells = "  ".join(f"{m}: {rows[m][s]['views']} views"
                              f"{'' if rows[m][s]['found'] else ' (not found)'}" for m in modes)
            print(f"  seed {s}: {cells}")
        print()
    print(f"wall {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
