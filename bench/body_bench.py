"""PR2 vs Pioneer on the same worlds and seeds.

Run: `.venv/bin/python -m bench.body_bench [--worlds 20] [--scenario-seeds 3] [--jsonl FILE]`.
Runs the switching planner with each robot on the present targets of generated office worlds
0..N-1 (absent targets take the whole time budget; the give-up rule is benchmarked by
`bench.generated_bench`) and on scenarios a-f at seeds 0..S-1, and prints per robot and set:
found rate (for scenarios: outcome as the scenario expects) and mean plans per episode.
"""

from __future__ import annotations

import argparse
import json
import sys
import time

from avs_planner.harness import run_episode
from avs_planner.harness.scenarios import builtin_scenarios, load_scenario
from avs_planner.harness.worlds import generated_targets

ROBOTS = ("pioneer", "pr2")


def specs(worlds: int, scenario_seeds: int) -> list[tuple[str, str, dict, str]]:
    """(set, case, episode spec, expected outcome) for one robot."""
    out = []
    for seed in range(worlds):
        for label, present in generated_targets(seed, "office"):
            if present:
                out.append(("generated", f"w{seed}:{label}",
                            {"generate": {"seed": seed, "style": "office"}, "target": label,
                             "seed": seed, "strategy": "switching"}, "found"))
    for name in builtin_scenarios():
        scenario = load_scenario(name)
        for seed in range(scenario_seeds):
            out.append(("scenarios", f"{name}:{seed}", scenario.episode_spec(seed=seed),
                        scenario.expected))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", type=int, default=20)
    parser.add_argument("--scenario-seeds", type=int, default=3)
    parser.add_argument("--robots", default=",".join(ROBOTS))
    parser.add_argument("--jsonl", default=None)
    args = parser.parse_args(argv)
    rows = []
    sink = open(args.jsonl, "w", encoding="utf-8") if args.jsonl else None  # noqa: SIM115
    for group, case, spec, expected in specs(args.worlds, args.scenario_seeds):
        for robot in args.robots.split(","):
            start = time.perf_counter()
            try:
                summary = run_episode({**spec, "robot": robot})
            except Exception as exc:  # noqa: BLE001 - a crashed episode is a result
                summary = {"outcome": "error", "reason": f"{type(exc).__name__}: {exc}",
                           "plans": 0, "correct": False, "sim_time_s": float("nan")}
            ok = summary["outcome"] == expected and (expected != "found" or summary["correct"])
            row = {"set": group, "case": case, "robot": robot, "ok": ok,
                   "outcome": summary["outcome"], "plans": summary.get("plans", 0),
                   "sim_time_s": summary.get("sim_time_s"), "reason": summary.get("reason"),
                   "wall_s": round(time.perf_counter() - start, 1)}
            rows.append(row)
            print(json.dumps(row), file=sink or sys.stderr, flush=True)
    if sink:
        sink.close()
    print(f"{'set':10s} {'robot':8s} {'ok':>8s} {'rate':>6s} {'plans/ep':>8s}")
    for group in ("generated", "scenarios"):
        for robot in args.robots.split(","):
            mine = [r for r in rows if r["set"] == group and r["robot"] == robot]
            if mine:
                ok = sum(r["ok"] for r in mine)
                plans = sum(r["plans"] for r in mine) / len(mine)
                print(f"{group:10s} {robot:8s} {ok:>3d}/{len(mine):<4d} "
                      f"{100 * ok / len(mine):5.0f}% {plans:8.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
