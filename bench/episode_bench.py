"""Episode benchmark: the active visual search paper's office runs (Fig. 3 a-f) over several
sensor-noise seeds. The paper: "A Planning Approach to Active Visual Search in Large
Environments" (Göbelbecker et al.).

Run: `.venv/bin/python -m bench.episode_bench [--quick] [--seeds N] [--scenarios a,b,...]`.
Per scenario: success rate (the paper's outcome: found where the object exists, gave up where it
does not), median simulated time, distance, number of plans, CP time per plan, DT time per
decision and wall time per episode; a last line sums up every CP call (median, p90, max, the
share within the CP's 20 ms target). The reference, measured in the same run on the same seeds,
is an uninformed searcher: frontier exploration (nearest placeholder) that looks for the
target all round at every stop, with the same maps and detector; the ratio column is the
switching planner's median simulated time over the reference's. `--jsonl FILE` keeps every
episode's summary.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import time
from pathlib import Path

from avs_planner.harness import Episode, EpisodeSpec, run_episode
from avs_planner.harness.scenarios import builtin_scenarios, load_scenario


def reference_search(spec: dict, budget_s: float = 900.0) -> dict:
    """Explore nearest-placeholder first, looking around for the target at every stop."""
    episode = Episode(EpisodeSpec.from_dict(spec))
    executor, mind, robot = episode.executor, episode.mind, episode.robot
    try:
        executor.look_around()
        start = robot.clock
        while robot.clock - start < budget_s:
            if _look_all_round(executor, spec["target"]):
                return {"outcome": "found", "sim_time_s": robot.clock - start}
            target = executor.nearest_placeholder()
            if target is None:
                return {"outcome": "gave_up", "sim_time_s": robot.clock - start}
            mind.tried_placeholders[target] = mind.tried_placeholders.get(target, 0) + 1
            executor.drive_to(mind.place_map.placeholders[target].position,
                              stop=lambda t=target: t not in mind.place_map.placeholders)
        return {"outcome": "timeout", "sim_time_s": robot.clock - start}
    finally:
        episode.trace.close()
        robot.world.close()


def _look_all_round(executor, label: str) -> bool:  # noqa: ANN001 - an Executor
    robot = executor.robot
    yaw = robot.pose[2]
    tilt = -math.atan2(executor.camera.height - 0.7, 2.0)
    for k in range(6):
        robot.turn_to(yaw + k * math.pi / 3)
        robot.look(0.0, tilt)
        first = [s for s in robot.detect([label]) if s.label == label]
        if first and any(s.label == label and math.dist(s.position, first[0].position) < 0.6
                         for s in robot.detect([label])):
            return True
    return False


def _median(values: list[float]) -> float:
    return statistics.median(values) if values else float("nan")


def run(scenarios: list[str], seeds: list[int], with_reference: bool, jsonl: Path | None,
        robot: str | None = None) -> None:
    print(f"{'scen':4s} {'ok':>6s} {'sim s':>7s} {'ref s':>7s} {'ratio':>6s} {'dist m':>7s} "
          f"{'plans':>5s} {'CP s/plan':>9s} {'DT ms/dec':>9s} {'wall s':>7s}")
    every: list[dict] = []
    for name in scenarios:
        scenario = load_scenario(name)
        rows, refs = [], []
        for seed in seeds:
            start = time.perf_counter()
            summary = run_episode(scenario.episode_spec(seed=seed, robot=robot), None, None)
            summary["wall_time_s"] = time.perf_counter() - start
            summary["scenario"] = name
            rows.append(summary)
            if jsonl is not None:
                with jsonl.open("a", encoding="utf-8") as f:
                    f.write(json.dumps(summary) + "\n")
            if with_reference and scenario.expected == "found":
                refs.append(reference_search(scenario.episode_spec(seed=seed, robot=robot)))
        _print_row(name, scenario.expected, rows, refs)
        every.extend(rows)
    _print_cp_calls(every)


def _print_cp_calls(rows: list[dict], target_s: float = 0.020) -> None:
    """Every CP call of every episode (first plans and replans): the planning times the
    switching loop actually waits for, against the CP's 20 ms target."""
    calls = sorted(t for r in rows for t in r["cp_time_s"])
    if not calls:
        return
    firsts = [r["cp_time_s"][0] for r in rows if r["cp_time_s"]]
    p90 = calls[min(len(calls) - 1, math.ceil(0.9 * len(calls)) - 1)]
    within = sum(t <= target_s for t in calls) / len(calls)
    print(f"-- CP calls in {len(rows)} episodes: {len(calls)}, median "
          f"{1000 * statistics.median(calls):.1f} ms, p90 {1000 * p90:.1f} ms, max "
          f"{1000 * calls[-1]:.1f} ms, {100 * within:.0f}% within {1000 * target_s:.0f} ms; "
          f"first plans median {1000 * statistics.median(firsts):.1f} ms")


def _print_row(name: str, expected: str, rows: list[dict], refs: list[dict]) -> None:
    ok = [r for r in rows if r["outcome"] == expected and (expected != "found" or r["correct"])]
    sim = _median([r["sim_time_s"] for r in ok])
    ref = _median([r["sim_time_s"] for r in refs if r["outcome"] == "found"])
    cp = [t for r in rows for t in r["cp_time_s"]]
    dt = [t for r in rows for t in r["dt_decision_time_s"]]
    ratio = sim / ref if refs and math.isfinite(ref) and ref > 0 else float("nan")
    print(f"{name:4s} {len(ok):>3d}/{len(rows):<2d} {sim:7.1f} {ref:7.1f} {ratio:6.2f} "
          f"{_median([r['distance_m'] for r in ok]):7.1f} "
          f"{_median([r['plans'] for r in ok]):5.0f} {_median(cp):9.3f} "
          f"{1000 * _median(dt):9.1f} {_median([r['wall_time_s'] for r in rows]):7.1f}",
          flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="scenarios a and c, one seed")
    parser.add_argument("--seeds", type=int, default=2, help="seeds per scenario (default 2)")
    parser.add_argument("--scenarios", default="a,c,d", help="comma-separated (default a,c,d)")
    parser.add_argument("--no-reference", action="store_true")
    parser.add_argument("--jsonl", type=Path, help="append every episode's summary here")
    parser.add_argument("--robot", choices=("pioneer", "pr2"),
                        help="robot model (default: the scenario's world's)")
    args = parser.parse_args()
    scenarios = ["a", "c"] if args.quick else args.scenarios.split(",")
    unknown = set(scenarios) - set(builtin_scenarios())
    if unknown:
        parser.error(f"unknown scenarios {sorted(unknown)}")
    seeds = [1] if args.quick else list(range(1, args.seeds + 1))
    print(f"episode bench: scenarios {','.join(scenarios)}, seeds {seeds[0]}..{seeds[-1]}; "
          "sim/ref/dist: medians over successful runs; ref = frontier exploration looking "
          "around at every stop")
    run(scenarios, seeds, not args.no_reference, args.jsonl, args.robot)


if __name__ == "__main__":
    main()
