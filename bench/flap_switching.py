"""The switching planner with FLAP views on supports vs its 2D view cones (option `views`).

    .venv/bin/python -m bench.flap_switching [--seeds N] [--scenarios a,b,...] [--worlds W]
        [--out rows.jsonl] [--summarize rows.jsonl]

Per episode (scenarios a-f of the office at seeds 0..N-1, generated office worlds 0..W-1 with
the generator's present and absent targets), the same spec is run with `views: cones` and with
`views: flap`, one after the other; rows: outcome, whether it is right (found a present
object, gave up on an absent one), simulated and wall seconds, DT calls, and how many
CREATEVIEWCONES used FLAP. The table gives per group the right count, median simulated and
wall time, and the paired median ratios flap / cones.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

from avs_planner.harness import run_episode
from avs_planner.harness.scenarios import load_scenario
from avs_planner.harness.worlds import generated_targets

VIEWS = ("cones", "flap")


def specs(scenarios: list[str], seeds: int, worlds: int) -> list[tuple[str, dict, bool]]:
    """(group, episode spec, whether the target is there to be found)."""
    out: list[tuple[str, dict, bool]] = []
    for name in scenarios:
        scenario = load_scenario(name)
        for seed in range(seeds):
            out.append((f"scenario {name}", scenario.episode_spec(seed=seed),
                        scenario.expected == "found"))
    for world in range(worlds):
        for label, present in generated_targets(world, "office"):
            out.append(("generated", {"generate": {"seed": world, "style": "office"},
                                      "target": label, "seed": world}, present))
    return out


def run(group: str, spec: dict, present: bool, views: str) -> dict:
    flap_events: list[dict] = []
    spec = {**spec, "strategy": "switching",
            "strategy_options": {**spec.get("strategy_options", {}), "views": views}}
    began = time.perf_counter()
    try:
        summary = run_episode(spec, emit=lambda e: flap_events.append(e)
                              if e["type"] == "flap" else None)
    except Exception as exc:  # noqa: BLE001 - a crashed episode is a row, not the end
        summary = {"outcome": "error", "reason": f"{type(exc).__name__}: {exc}",
                   "correct": False, "sim_time_s": float("nan"), "dt_calls": 0}
    right = (summary["outcome"] == "found" and bool(summary.get("correct")) if present
             else summary["outcome"] == "gave_up")
    return {"group": group, "target": spec["target"], "seed": spec.get("seed", 0),
            "world": spec.get("generate", {}).get("seed"), "views": views,
            "outcome": summary["outcome"], "right": bool(right),
            "sim_s": summary["sim_time_s"], "wall_s": round(time.perf_counter() - began, 2),
            "dt_calls": summary.get("dt_calls", 0),
            "flap_cone_sets": sum(1 for e in flap_events if e.get("event") == "cones"
                                  and e.get("flap")),
            "reason": summary.get("reason", "")}


def summarize(rows: list[dict]) -> str:
    lines = ["| group | views | episodes | right | sim s median | wall s median | DT calls "
             "| FLAP cone sets | paired sim flap/cones | paired wall flap/cones |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    groups = sorted({r["group"] for r in rows}) + ["all"]
    for group in groups:
        mine = [r for r in rows if group in ("all", r["group"])]
        pairs = {}
        for r in mine:
            pairs.setdefault((r["group"], r["target"], r["seed"], r["world"]), {})[r["views"]] = r
        both = [p for p in pairs.values() if len(p) == 2]
        for views in VIEWS:
            cell = [r for r in mine if r["views"] == views]
            if not cell:
                continue
            ratio = ""
            if views == "flap" and both:
                sim = statistics.median(p["flap"]["sim_s"] / p["cones"]["sim_s"] for p in both)
                wall = statistics.median(p["flap"]["wall_s"] / p["cones"]["wall_s"]
                                         for p in both)
                ratio = f" {sim:.2f} | {wall:.2f}"
            else:
                ratio = " | "
            lines.append(
                f"| {group} | {views} | {len(cell)} | {sum(r['right'] for r in cell)} | "
                f"{statistics.median(r['sim_s'] for r in cell):.1f} | "
                f"{statistics.median(r['wall_s'] for r in cell):.1f} | "
                f"{sum(r['dt_calls'] for r in cell)} | "
                f"{sum(r['flap_cone_sets'] for r in cell)} |{ratio} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--scenarios", default="a,b,c,d,e,f")
    parser.add_argument("--worlds", type=int, default=3)
    parser.add_argument("--out", type=Path, help="append one JSON row per episode here")
    parser.add_argument("--summarize", type=Path, help="only print the table of a rows file")
    args = parser.parse_args(argv)
    if args.summarize:
        rows = [json.loads(line) for line in args.summarize.read_text().splitlines() if line]
        print(summarize(rows))
        return 0
    rows = []
    scenarios = [s for s in args.scenarios.split(",") if s]
    for group, spec, present in specs(scenarios, args.seeds, args.worlds):
        for views in VIEWS:  # alternating: both see the same machine load
            row = run(group, spec, present, views)
            rows.append(row)
            print(json.dumps(row), file=sys.stderr, flush=True)
            if args.out:
                with args.out.open("a", encoding="utf-8") as f:
                    f.write(json.dumps(row) + "\n")
    print(summarize(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
