"""The FLAP paper's experiment (§4, Fig. 6): planner vs greedy, with and without a prior map.

The paper: "FLAP for CAOS: Forward-Looking Active Perception for Clutter-Aware Object Search"
(Gedicke et al.).

    .venv/bin/python -m bench.flap_experiment [--trials N] [--out rows.jsonl]
    .venv/bin/python -m bench.flap_experiment --summarize rows.jsonl

World `flap_two_rooms` (after the FLAP paper's Fig. 4), a PR2, trials with seeds 0..N-1, each from a
random start pose (drawn by the experimenter from the world file, the same for all four cells
of a seed). Every episode runs `avs simulate --strategy flap` with `pre_explore`: the robot
surveys the building before the clock starts; with a prior map the survey also integrates depth
frames, so the 3D map exists before the search; without one only the 2D map is known (the
FLAP paper: "only walls are known"). The search region is the FLAP paper's, given by the task
(option `volumes`, as the paper's tasks give it): a box over each of the six supports of its
Fig. 4 (two shelf arrangements, one single shelf, three tables), P_i = 0.2 each; it is reset
to unknown at the start in both. Drives between views follow one path with no sensing on the
way (`sense_en_route: false`), so executed transitions are what the planner's time model
predicts, as in the FLAP paper's simulation. The target label (`stapler`) is absent, so every
trial runs until the omega test (p(V̂(S)) < 0.05) ends it, as the FLAP paper's trials do.

Measures per trial, as the FLAP paper's (its footnote 4: eq. 4 on the executed sequence): the
expected search time E[T] = sum_k S_{k-1} (t_k - t_{k-1}), S_k the probability that the target
was not among the cells revealed by the first k views, t_k the simulated clock at view k
(execution: driving, turning, torso, head, sensing), and the same sum over each cycle's wall
planning time (planning component); beside them the time to complete (omega) and the sensing
steps. Means with 95% t intervals; the planner's difference vs greedy is paired by seed.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Iterable
from pathlib import Path

import numpy as np
from matplotlib.path import Path as MplPath
from scipy import stats

from avs_planner.harness.runner import run_episode
from avs_planner.harness.sim_robot import load_spec

WORLD = "flap_two_rooms"
TARGET = "stapler"  # the knowledge puts it on shelves and tables; the world has none
CELLS = [("map", True, False), ("map", True, True), ("no map", False, False),
         ("no map", False, True)]  # (label, prior_map, greedy)
SEED_DIFF = {"map": -10.0, "no map": -7.0}  # %: the FLAP paper's planner vs greedy (§5)
OPTIONS = {"time_limit_s": 0.5, "max_views": 60, "survey_on": False,
           "sense_en_route": False,  # one region per trial; transitions as the paper models
           "depth_columns": 64}


def start_pose(seed: int) -> list[float]:
    """A random free start pose in a random room (the experimenter's choice, not the robot's)."""
    spec = load_spec(WORLD)
    rng = np.random.default_rng(1000 + seed)
    radius = 0.45  # PR2 footprint plus margin
    boxes = [MplPath(f.footprint()) for f in spec.furniture]
    while True:
        room = spec.rooms[int(rng.integers(len(spec.rooms)))]
        x0, y0, x1, y1 = room.rect
        m = radius + spec.wall_thickness
        x, y = rng.uniform(x0 + m, x1 - m), rng.uniform(y0 + m, y1 - m)
        if not any(b.contains_point((x, y), radius=2 * radius)
                   or b.contains_point((x, y), radius=-2 * radius) for b in boxes):
            return [round(float(x), 3), round(float(y), 3),
                    round(float(rng.uniform(-math.pi, math.pi)), 3)]


def seed_volumes(margin: float = 0.05, height: float = 0.3, gap: float = 0.3) -> list[dict]:
    """The FLAP paper's search region (its Fig. 4: two shelf arrangements, one single shelf,
    three tables), given by the experimenter as the paper's tasks give it: a box over each shelf's
    and table's top (footprint + `margin`, `height` high), boxes of one label closer than
    `gap` merged into one arrangement; P_i = 0.2 each."""
    spec = load_spec(WORLD)
    boxes: list[list] = []
    for f in spec.furniture:
        if f.label not in ("shelf", "table"):
            continue
        xy = np.asarray(f.footprint())
        lo, hi = xy.min(axis=0) - margin, xy.max(axis=0) + margin
        boxes.append([f.label, [*lo, f.size[2]], [*hi, f.size[2] + height], [f.name]])
    merged = True
    while merged:
        merged = False
        for i, a in enumerate(boxes):
            for b in boxes[i + 1:]:
                if a[0] == b[0] and all(a[1][k] - gap < b[2][k] and b[1][k] - gap < a[2][k]
                                        for k in range(2)):
                    a[1] = [min(a[1][k], b[1][k]) for k in range(3)]
                    a[2] = [max(a[2][k], b[2][k]) for k in range(3)]
                    a[3] += b[3]
                    boxes.remove(b)
                    merged = True
                    break
            if merged:
                break
    return [{"name": "+".join(names), "lo": [round(float(v), 3) for v in lo],
             "hi": [round(float(v), 3) for v in hi], "p": 0.2} for _, lo, hi, names in boxes]


def run_trial(seed: int, prior_map: bool, greedy: bool) -> dict:
    events: list[dict] = []
    spec = {"target": TARGET, "world": WORLD, "seed": seed, "start": start_pose(seed),
            "strategy": "flap", "pre_explore": True, "time_budget_s": 1200.0,
            "wall_budget_s": 900.0,
            "strategy_options": {**OPTIONS, "prior_map": prior_map, "greedy": greedy,
                                 "volumes": seed_volumes()}}
    began = time.perf_counter()
    summary = run_episode(spec, emit=lambda e: events.append(e) if e["type"] == "flap" else None)
    return {"seed": seed, "prior_map": prior_map, "greedy": greedy,
            "wall_s": round(time.perf_counter() - began, 2), **measure(events, summary)}


def measure(events: list[dict], summary: dict) -> dict:
    """E[T] (execution and planning) of the executed view sequence, steps, completion time."""
    regions = [k for k, e in enumerate(events) if e.get("event") == "region"]
    region = events[regions[0]]
    events = events[regions[0]:regions[1] if len(regions) > 1 else None]  # the first region
    t_prev, survival, e_exec, e_plan, steps = region["t"], 1.0, 0.0, 0.0, 0
    for e in events:
        if e.get("event") == "decision":
            e_plan += survival * e["seconds"]["total"]
        elif e.get("event") == "view":
            e_exec += survival * (e["t"] - t_prev)
            t_prev, survival, steps = e["t"], e["survival"], steps + 1
    return {"expected_exec_s": round(e_exec, 2), "expected_plan_s": round(e_plan, 2),
            "expected_total_s": round(e_exec + e_plan, 2), "steps": steps,
            "complete_s": (summary["sim_time_s"] if len(regions) == 1 else
                           round(events[-1]["t"] - region["t"], 2)),  # (from the search start)
            "p_total": region["p_total"],
            "p_revealed": round(1.0 - survival, 4), "outcome": summary["outcome"],
            "reason": summary["reason"]}


def mean_ci(values: Iterable[float]) -> tuple[float, float]:
    """Mean and the half width of its 95% t interval."""
    v = np.asarray(list(values), dtype=float)
    if v.size < 2:
        return float(v.mean()) if v.size else math.nan, math.nan
    return float(v.mean()), float(stats.t.ppf(0.975, v.size - 1) * v.std(ddof=1)
                                  / math.sqrt(v.size))


def summarize(rows: list[dict]) -> str:
    lines = ["| prior map | planner | trials | E[T] exec + plan (s) | E[T] exec (s) | "
             "sensing steps | time to omega (s) | p revealed |",
             "|---|---|---|---|---|---|---|---|"]
    for label, prior, greedy in CELLS:
        cell = [r for r in rows if r["prior_map"] == prior and r["greedy"] == greedy]
        if not cell:
            continue
        cols = []
        for key in ("expected_total_s", "expected_exec_s", "steps", "complete_s", "p_revealed"):
            m, h = mean_ci(r[key] for r in cell)
            cols.append(f"{m:.3g} ± {h:.2g}" if key == "p_revealed" else f"{m:.1f} ± {h:.1f}")
        name = "greedy" if greedy else "B&B (ξ=1, ψ=6, φ=3)"
        lines.append(f"| {label} | {name} | {len(cell)} | " + " | ".join(cols) + " |")
    lines += ["", "| prior map | paired trials | planner vs greedy, E[T] exec + plan | "
              "E[T] exec | sensing steps | FLAP paper (Fig. 6, §5) |", "|---|---|---|---|---|---|"]
    for label, prior in (("map", True), ("no map", False)):
        plan = {r["seed"]: r for r in rows if r["prior_map"] == prior and not r["greedy"]}
        greedy = {r["seed"]: r for r in rows if r["prior_map"] == prior and r["greedy"]}
        seeds = sorted(set(plan) & set(greedy))
        if not seeds:
            continue
        cols = []
        for key in ("expected_total_s", "expected_exec_s", "steps"):
            base = np.mean([greedy[s][key] for s in seeds])
            m, h = mean_ci(plan[s][key] - greedy[s][key] for s in seeds)
            cols.append(f"{100 * m / base:+.1f}% (95% CI {100 * (m - h) / base:+.1f}% .. "
                        f"{100 * (m + h) / base:+.1f}%)")
        lines.append(f"| {label} | {len(seeds)} | " + " | ".join(cols)
                     + f" | {SEED_DIFF[label]:+.0f}% |")
    outcomes: dict[str, int] = {}
    for r in rows:
        outcomes[r["outcome"]] = outcomes.get(r["outcome"], 0) + 1
    lines += ["", "outcomes: " + ", ".join(f"{k} {v}" for k, v in sorted(outcomes.items()))
              + f"; mean wall per episode {np.mean([r['wall_s'] for r in rows]):.0f} s"]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--first", type=int, default=0, help="first seed")
    parser.add_argument("--out", type=Path, help="append one JSON row per episode here")
    parser.add_argument("--summarize", type=Path, help="only print the table of a rows file")
    args = parser.parse_args(argv)
    if args.summarize:
        rows = [json.loads(line) for line in args.summarize.read_text().splitlines() if line]
        print(summarize(rows))
        return 0
    rows = []
    for seed in range(args.first, args.first + args.trials):  # seed-major: cells stay paired
        for _, prior, greedy in CELLS:
            row = run_trial(seed, prior, greedy)
            rows.append(row)
            print(json.dumps(row), file=sys.stderr, flush=True)
            if args.out:
                with args.out.open("a", encoding="utf-8") as f:
                    f.write(json.dumps(row) + "\n")
    print(summarize(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
