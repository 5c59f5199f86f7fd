"""Search only: the compiled core (engine="native") vs the Python search, same run, same task.

Run: `.venv/bin/python -m bench.cp_native_bench [--quick]` (~1 min; --quick ~20 s).
Each instance is grounded once (with its symmetries); then `search(task, options)` is timed
per engine: the median of a few runs, native after one warm-up run that packs the task (the
packing is cached per task; its cold cost is printed separately). Both engines must return
the same plan and expanded/generated counts; the table says so per instance. Ratios > 1 mean
the native core is faster. Options as bench/cp_bench.py: R=500, w=2, FF.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

from unified_planning.io import PDDLReader

from avs_planner.cp import native
from avs_planner.cp.grounding import ground, world_state
from avs_planner.cp.search import PlanResult, SearchOptions, search
from avs_planner.cp.symmetry import find_symmetries
from avs_planner.pddl import read_text
from avs_planner.pddl.model import ProbabilisticProblem
from bench.avs_generator import AvsSize, generate

ROOT = Path(__file__).resolve().parents[1]
IPC = Path(__file__).resolve().parents[2] / "shared" / "ipc"  # beside the checkout
OPTIONS = SearchOptions(reward=500.0, weight=2.0, heuristic="ff", timeout_s=60.0)
IPC_CASES = (("blocks", 4), ("logistics", 2), ("elevators", 1))


def cases(quick: bool) -> list[tuple[str, ProbabilisticProblem]]:
    domain = (ROOT / "domains/avs/domain.pddl").read_text()
    out = []
    for name in ("corridor", "room3-kitchen"):
        text = (ROOT / f"domains/avs/problems/{name}.pddl").read_text()
        out.append((f"avs/{name}", read_text(domain, text, "domain.pddl", f"{name}.pddl")))
    for size in (AvsSize(8, 2, 2, 4), AvsSize(20, 5, 4, 8)):
        out.append((f"gen/p{size.places}", read_text(domain, generate(size, 0), "domain.pddl",
                                                     size.name)))
    for dom, n in IPC_CASES[:1] if quick else IPC_CASES:
        folder = IPC / dom
        if folder.is_dir():
            problem = PDDLReader().parse_problem(str(folder / "domain.pddl"),
                                                 str(folder / f"instance-{n}.pddl"))
            out.append((f"{dom}/instance-{n}", ProbabilisticProblem(problem)))
    return out


def timed(task, options, symmetries, runs: int) -> tuple[float, PlanResult]:
    times, result = [], None
    for _ in range(runs):
        start = time.perf_counter()
        result = search(task, options, symmetries)
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def same(a: PlanResult, b: PlanResult) -> bool:
    return (a.status, [s.label for s in a.plan], a.expanded, a.generated) == (
        b.status, [s.label for s in b.plan], b.expanded, b.generated)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer instances and runs")
    args = parser.parse_args()
    if not native.AVAILABLE:
        print("the native core is not built (pip install -e .)", file=sys.stderr)
        return 1
    runs = 3 if args.quick else 5
    print(f"options: R={OPTIONS.reward} w={OPTIONS.weight} h={OPTIONS.heuristic}; "
          f"median of {runs} runs (python: of {max(1, runs // 2)} above 0.5 s)")
    print(f"{'instance':22} {'actions':>7} {'pack ms':>8} {'python ms':>10} {'native ms':>10} "
          f"{'ratio':>7} {'expanded':>9} {'generated':>9}  same")
    ratios, all_same = [], True
    for label, pproblem in cases(args.quick):
        state = world_state(pproblem.problem)
        task = ground(pproblem, state)
        symmetries = find_symmetries(pproblem, state, task)
        start = time.perf_counter()
        native.pack_task(task)
        pack_ms = (time.perf_counter() - start) * 1e3
        py_s, py = timed(task, replace(OPTIONS, engine="python"), symmetries, 1)
        if py_s < 0.5:
            py_s, py = timed(task, replace(OPTIONS, engine="python"), symmetries, runs)
        elif runs // 2 > 1:
            py_s, py = timed(task, replace(OPTIONS, engine="python"), symmetries, runs // 2)
        c_s, c = timed(task, replace(OPTIONS, engine="native"), symmetries, runs)
        ok = same(py, c)
        all_same &= ok
        ratios.append(py_s / c_s)
        print(f"{label:22} {len(task.actions):7d} {pack_ms:8.1f} {py_s * 1e3:10.1f} "
              f"{c_s * 1e3:10.2f} {py_s / c_s:7.1f} {c.expanded:9d} {c.generated:9d}  {ok}")
    print(f"-- median python/native ratio {statistics.median(ratios):.1f} "
          f"(min {min(ratios):.1f}); same plans and counts on every instance: {all_same}")
    return 0 if all_same else 1


if __name__ == "__main__":
    sys.exit(main())
