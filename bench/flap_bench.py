"""FLAP view planning benchmark: sampling, transition table, planner quality and speed.

    .venv/bin/python -m bench.flap_bench [--quick]

The maps are synthetic (bench/flap_scene.py): a 6 m x 5 m room with two cluttered tables and a
two-level shelf, mapped by ray casting laser scans and depth frames from three poses into an
OccupancyGrid and a VoxelMap; the four target volumes (P_i = 0.2 each, as in the FLAP paper,
"FLAP for CAOS: Forward-Looking Active Perception for Clutter-Aware Object Search", Gedicke et
al.) are reset to unknown. Robot: PR2 numbers (the FLAP paper's robot) unless a line says
Pioneer. Times are median wall seconds with the process CPU seconds beside them (the machine
may be shared). The FLAP paper's figures (Table 1) were measured on an Intel Core i7 870; its
text gives no planner decision times (Fig. 6 plots them as bars).
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np

from avs_planner.body import RobotBody
from avs_planner.flap.planner import (
    EXACT,
    PlannerOptions,
    plan_exhaustive,
    plan_greedy,
    plan_views,
)
from avs_planner.flap.problem import SequencingProblem
from avs_planner.flap.sampling import ViewPose, ViewSampler
from avs_planner.flap.target import TargetBelief
from avs_planner.flap.transitions import build_table, exact_time
from bench.flap_scene import PIONEER_BODY, PR2_BODY, Scene, build_scene

SEED_SAMPLING_S = 2.4  # Table 1: view sampling, 200 views
SEED_TABLE_S = 6.4  # Table 1: transition time prediction, 50 clusters


def timed(fn: Callable[[], object], repeats: int) -> tuple[float, float, object]:
    """Median wall and CPU seconds of fn over repeats, and its last result."""
    walls, cpus, out = [], [], None
    for _ in range(repeats):
        w, c = time.perf_counter(), time.process_time()
        out = fn()
        walls.append(time.perf_counter() - w)
        cpus.append(time.process_time() - c)
    return statistics.median(walls), statistics.median(cpus), out


def bench_sampling(scene: Scene, belief: TargetBelief, body: RobotBody, repeats: int) -> list:
    def run() -> list:
        return ViewSampler(scene.voxels, scene.grid, body, belief).sample(200, seed=0)

    wall, cpu, views = timed(run, repeats)
    cover = belief.p_views(v.cells for v in views)
    print(f"view sampling, 200 views ({body.name}): {wall:.3f} s wall, {cpu:.3f} s CPU"
          f"  (FLAP paper {SEED_SAMPLING_S} s: {SEED_SAMPLING_S / wall:.0f}x)  "
          f"p(V̂(S)) = {cover:.3f} of {1 - 0.8 ** len(scene.volumes):.3f} possible")
    return views


def bench_table(scene: Scene, body: RobotBody, views: list, repeats: int) -> tuple:
    start = ViewPose(*scene.start, 0.0, 0.0, 0.0)
    poses = [v.pose for v in views]
    wall, cpu, table = timed(lambda: build_table(body, scene.grid, start, poses, 50), repeats)
    rng = np.random.default_rng(0)
    errors = [abs(table.times[i, j] / exact_time(body, scene.grid, poses[table.kept[i]],
                                                 poses[table.kept[j]]) - 1.0)
              for i, j in rng.integers(table.kept.size, size=(60, 2)) if i != j]  # fmt: skip
    print(f"transition table, 50 clusters ({body.name}): {wall:.3f} s wall, {cpu:.3f} s CPU"
          f"  (FLAP paper {SEED_TABLE_S} s: {SEED_TABLE_S / wall:.0f}x)  vs exact A* times: mean "
          f"|error| {np.mean(errors):.1%}, worst {np.max(errors):.1%} ({len(errors)} pairs)")
    return table


def bench_gap(problem: SequencingProblem, instances: int, size: int) -> None:
    rng = np.random.default_rng(1)
    rows: dict[str, list[float]] = {"B&B exact": [], "B&B default": [],
                                    "B&B xi,psi,phi": [], "greedy": []}
    brute_s, bb_s, exact = [], [], 0
    heuristic = PlannerOptions(exact_nodes=0)  # xi = 1, psi = 6, phi = 3 at every size
    for _ in range(instances):
        sub = problem.subset(rng.choice(problem.size, size, replace=False))
        best = plan_exhaustive(sub)
        brute_s.append(best.seconds)
        for name, result in (("B&B exact", plan_views(sub, EXACT)),
                             ("B&B default", plan_views(sub)),
                             ("B&B xi,psi,phi", plan_views(sub, heuristic)),
                             ("greedy", plan_greedy(sub))):
            gap = result.expected_time / best.expected_time - 1.0
            rows[name].append(0.0 if abs(gap) < 1e-12 else gap)  # rounding, not a gain
            if name == "B&B default":
                bb_s.append(result.seconds)
                exact += result.exact
    print(f"B&B vs brute force, {instances} instances of {size} views from the room "
          f"(brute force {statistics.median(brute_s):.3f} s, B&B default "
          f"{statistics.median(bb_s):.4f} s median; the default searched {exact} of them "
          f"exactly: their sequence trees fit exact_nodes):")
    for name, gaps in rows.items():
        target = "  (target <= 2%)" if name == "B&B default" else ""
        print(f"  {name:14s} E[T] above the optimum: mean {np.mean(gaps):.2%}, "
              f"worst {np.max(gaps):.2%}{target}")


def bench_decisions(problem: SequencingProblem, sizes: tuple[int, ...], repeats: int) -> None:
    o = PlannerOptions()
    print(f"B&B decision time (xi={int(o.xi)}, psi={o.psi}, phi={o.phi}, omega={o.omega}); "
          "the FLAP paper: no number in the text")
    for n in sizes:
        walls, cpus, ratios, nodes = [], [], [], []
        for k in range(repeats):
            sub = problem.subset(np.random.default_rng(100 + k).choice(problem.size, n,
                                                                       replace=False))
            wall, cpu, result = timed(lambda sub=sub: plan_views(sub), 1)
            walls.append(wall)
            cpus.append(cpu)
            nodes.append(result.nodes)
            ratios.append(result.expected_time / plan_greedy(sub).expected_time - 1.0)
        print(f"  {n:3d} views: {statistics.median(walls):.3f} s wall, "
              f"{statistics.median(cpus):.3f} s CPU, {int(statistics.median(nodes))} nodes; "
              f"planned E[T] vs greedy {np.mean(ratios):+.1%} (mean of {repeats})")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.flap_bench", description=__doc__)
    parser.add_argument("--quick", action="store_true", help="fewer repeats and instances")
    args = parser.parse_args(argv)
    repeats = 3 if args.quick else 5
    began = time.perf_counter()
    scene = build_scene()
    belief = TargetBelief(scene.voxels, scene.volumes)
    print(f"scene: {scene.voxels.shape} voxels at {scene.voxels.resolution} m, "
          f"{belief.size} target cells, built in {time.perf_counter() - began:.1f} s")
    views = bench_sampling(scene, belief, PR2_BODY, repeats)
    pioneer_views = bench_sampling(scene, belief, PIONEER_BODY, repeats)
    table = bench_table(scene, PR2_BODY, views, repeats)
    bench_table(scene, PIONEER_BODY, pioneer_views, repeats)
    problem = SequencingProblem.build([views[k].cells for k in table.kept], belief.log_miss(),
                                      table.start, table.times)  # fmt: skip
    bench_gap(problem, 8 if args.quick else 20, 8)
    bench_decisions(problem, (20, 50, 100), 2 if args.quick else 3)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
