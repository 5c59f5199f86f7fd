"""Continual planner vs Fast Downward lama-first, same runs, per instance, failures counted.

Run: `.venv/bin/python -m bench.cp_bench [--quick | --full] [--runs N] [--limit S]`.
Instances: the AVS problems in domains/avs/problems, generated AVS problems of growing size
(bench/avs_generator.py, seeds 0-2; `--building` adds the 80- and 160-place ones) and the IPC
set at ../shared/ipc (`AVS_IPC_DIR` elsewhere; the bench stops when it is missing).

Per instance, both sides get the same number of runs (`--runs`, median reported):
- ours, read: reading the PDDL text plus planning, cold (new problem, new grounding cache);
- ours, plan: `planning_time_s` of the same calls (grounding + search);
- FD own: the translator's and the search component's own times from FD's log, no
  interpreter start-up (bench/fd_runner.py runs FD's driver on PDDL files);
- FD e2e: the driver's wall time, start-ups included.
A failure or a timeout counts as the limit (`--limit`, default 60 s) in every time and
ratio, and the coverage line says how many each side solved. Ratios are FD / ours (> 1: we
are faster), against ours with reading. For AVS, ours is the default weighted A* (w = 2) on
c + R(1 - p), and FD plans the deterministic compilation: each ground action's cost becomes
round(100 (c + R (-ln p))) through a per-action cost fluent; both plans' true objective is
printed. For IPC, ours is the anytime mode's greedy phase (LAMA's first iteration, which is
what lama-first runs). Our plans are checked with UP's sequential plan validator.
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path

from unified_planning.engines.plan_validator import SequentialPlanValidator
from unified_planning.io import PDDLWriter
from unified_planning.model import MinimizeActionCosts, Problem
from unified_planning.shortcuts import Fluent, IntType, get_environment

from avs_planner.cp.anytime import greedy_search
from avs_planner.cp.deadline import Deadline
from avs_planner.cp.grounding import GroundingCache, gc_paused, ground
from avs_planner.cp.planner import plan
from avs_planner.cp.search import PlanResult, SearchOptions, objective, search
from avs_planner.cp.symmetry import NO_SYMMETRIES, find_symmetries
from avs_planner.cp.task import GroundTask
from avs_planner.pddl import read_text
from avs_planner.pddl.model import ProbabilisticProblem
from avs_planner.up_engine import to_up_plan
from bench.avs_generator import AvsSize, generate
from bench.cp_report import office_scale, report  # noqa: F401 - office_scale: tests
from bench.fd_runner import FdRun, run_fd
from tests.ipc import IPC, domain_for, instances, ipc_folders  # IPC: ../shared/ipc or $AVS_IPC_DIR

ROOT = Path(__file__).resolve().parents[1]
REWARD = 500.0
LIMIT_S = 60.0
PROHIBITIVE = 10**7
OPTIONS = SearchOptions(reward=REWARD, weight=2.0, heuristic="ff", timeout_s=LIMIT_S)
SIZES = (AvsSize(8, 2, 2, 4), AvsSize(12, 3, 3, 6), AvsSize(20, 5, 4, 8))
BUILDING = (AvsSize(40, 8, 8, 8), AvsSize(80, 16, 16, 8), AvsSize(160, 32, 32, 8))
RUNS = 3  # runs per instance, on both sides (median)


@dataclass(frozen=True)
class Case:
    """One instance: its PDDL text (ours reads it in the timing) and files (FD reads them)."""

    label: str
    domain: Path
    problem: Path
    probabilistic: bool

    def read(self) -> ProbabilisticProblem:
        return read_text(self.domain.read_text(), self.problem.read_text(),
                         str(self.domain), str(self.problem))


def require_ipc() -> Path:
    if not IPC.is_dir():
        raise SystemExit(f"IPC benchmark set missing at {IPC} (put it at ../shared/ipc beside "
                         f"the checkout, or set AVS_IPC_DIR)")
    return IPC


def avs_cases(quick: bool, building: bool, scratch: Path) -> list[Case]:
    domain = ROOT / "domains/avs/domain.pddl"
    cases = [Case(f"avs/{p.stem}", domain, p, True)
             for p in sorted((ROOT / "domains/avs/problems").glob("*.pddl"))]
    seeds = (0,) if quick else (0, 1, 2)  # every seed of the sizes the target names
    sizes = (SIZES[:2] if quick else SIZES) + (BUILDING if building else ())
    for size in sizes:
        for seed in seeds:
            path = scratch / f"{size.name}-s{seed}.pddl"
            path.write_text(generate(size, seed))
            cases.append(Case(f"gen/{size.name}-s{seed}", domain, path, True))
    return cases


def ipc_cases(quick: bool, full: bool = False, domains: tuple[str, ...] = (),
              numbers: tuple[int, ...] = ()) -> list[Case]:
    """The IPC instances: every other one (`quick`: the first two, `full`: all), or those
    numbered `numbers`; of every domain, or of `domains`."""
    cases = []
    found = {folder.name: folder for folder in ipc_folders(require_ipc())}
    unknown = sorted(set(domains) - set(found))
    if unknown:
        raise SystemExit(f"no IPC domain {', '.join(unknown)} in {IPC} (there are: "
                         f"{', '.join(found)})")
    for name, folder in found.items():
        if domains and name not in domains:
            continue
        numbered = instances(folder)
        if numbers:
            picked = [p for p in numbered if int(p.stem.split("-")[1]) in numbers]
        else:
            picked = numbered if full else numbered[:2] if quick else numbered[::2]
        for problem in picked:  # domain.pddl, or domain-N.pddl where one per instance
            cases.append(Case(f"{name}/{problem.stem}", domain_for(problem), problem, False))
    if full:  # instance 1 of every domain first, then 2, ...: a run stopped early is a sample
        cases.sort(key=lambda c: int(c.problem.stem.split("-")[1]))  # stable: by domain within
    return cases


def fd_problem(pproblem: ProbabilisticProblem, task: GroundTask) -> Problem:
    """The deterministic compilation: cost(a) = round(100 (c + R(-ln p))), per ground action.
    Fluents only the probabilities read (fractional, which FD rejects) are left out."""
    source = pproblem.problem
    problem = Problem(source.name)
    bool_fluents = [f for f in source.fluents if f.type.is_bool_type()]
    for fluent in bool_fluents:
        problem.add_fluent(fluent, default_initial_value=False)
    problem.add_objects(source.all_objects)
    problem.add_actions(source.actions)
    for exp, value in source.explicit_initial_values.items():
        if exp.fluent().type.is_bool_type():
            problem.set_initial_value(exp, value)
    for goal in source.goals:
        problem.add_goal(goal)
    costs = {}
    for action in problem.actions:
        fluent = Fluent(f"fdcost-{action.name}", IntType(),
                        **{p.name: p.type for p in action.parameters})
        # ground actions we pruned (p = 0, irrelevant, unreachable) get a prohibitive cost
        problem.add_fluent(fluent, default_initial_value=PROHIBITIVE)
        costs[action] = fluent(*action.parameters)
    for a in task.actions:
        value = round(100 * (a.cost + REWARD * -math.log(a.probability)))
        fluent = problem.fluent(f"fdcost-{a.name}")
        problem.set_initial_value(fluent(*[problem.object(x) for x in a.args]), value)
    problem.add_quality_metric(MinimizeActionCosts(costs))
    return problem


def true_objective(task: GroundTask, labels: list[tuple[str, tuple[str, ...]]]) -> tuple:
    steps = [task.action(name, args) for name, args in labels]
    if any(s is None for s in steps):  # FD used an action we proved useless or impossible
        return math.nan, 0.0, math.nan
    cost = math.fsum(s.cost for s in steps)
    p = math.prod(s.probability for s in steps)
    return cost, p, objective(cost, p, REWARD)


def valid(problem: Problem, up_plan) -> bool:
    validator = SequentialPlanValidator()
    validator.skip_checks = True  # elevators' partially defined costs trip the kind check
    return validator.validate(problem, up_plan).status.name == "VALID"


def ours_once(case: Case, limit_s: float) -> tuple[float, float, PlanResult, object]:
    """(read + plan seconds, plan seconds, result, problem) of one cold call; a failure
    counts as the limit."""
    gc.collect()  # each timing starts from a collected heap (the planner pauses the GC)
    start = time.perf_counter()
    pproblem = case.read()
    if case.probabilistic:
        result = plan(pproblem, replace(OPTIONS, timeout_s=limit_s), cache=GroundingCache())
    else:  # the anytime mode's greedy phase: what lama-first runs
        began = time.perf_counter()
        task = ground(pproblem, cache=GroundingCache())
        result, _ = greedy_search(task, SearchOptions(reward=REWARD), NO_SYMMETRIES,
                                  Deadline(start, limit_s))
        result = replace(result, planning_time_s=time.perf_counter() - began)
    total = time.perf_counter() - start
    if not result.solved or total > limit_s:
        return limit_s, limit_s, result, pproblem
    return total, result.planning_time_s, result, pproblem


def fd_input(case: Case, pproblem: ProbabilisticProblem, scratch: Path) -> tuple[Path, Path]:
    """FD's files: the originals, or for AVS the deterministic compilation written out."""
    if not case.probabilistic:
        return case.domain, case.problem
    writer = PDDLWriter(fd_problem(pproblem, ground(pproblem, cache=GroundingCache())))
    stem = case.label.replace("/", "-")
    domain, problem = scratch / f"{stem}-fd-domain.pddl", scratch / f"{stem}-fd-problem.pddl"
    writer.write_domain(str(domain))
    writer.write_problem(str(problem))
    return domain, problem


def bench_case(case: Case, runs: int, limit_s: float, scratch: Path) -> dict:
    """Both sides `runs` times, medians; the warm replan time for AVS (grounding structure
    and action table cached) and its cold stages beside."""
    ours = [ours_once(case, limit_s) for _ in range(runs)]
    result, pproblem = ours[0][2], ours[0][3]
    domain, problem = fd_input(case, pproblem, scratch)
    fds: list[FdRun] = [run_fd(domain, problem, limit_s) for _ in range(runs)]
    row = {"label": case.label, "ours_read_s": statistics.median(o[0] for o in ours),
           "ours_s": statistics.median(o[1] for o in ours),
           "fd_own_s": statistics.median(f.own_s for f in fds),
           "fd_s": statistics.median(f.wall_s for f in fds),
           "fd_solved": sum(f.solved for f in fds) * 2 > runs,
           "status": result.status.value, "expanded": result.expanded,
           "warm_s": math.nan, "stages": {}}
    if case.probabilistic and result.solved:
        cache = GroundingCache()
        plan(pproblem, OPTIONS, cache=cache)
        warms = [plan(pproblem, OPTIONS, cache=cache).planning_time_s for _ in range(runs)]
        row["warm_s"], row["stages"] = statistics.median(warms), cold_stages(pproblem, runs)
    if result.solved:
        row["ours_valid"] = valid(pproblem.problem, to_up_plan(pproblem.problem, result.plan))
        row["ours_cost"], row["ours_obj"] = result.cost, result.objective
    fd_plan = next((f.plan for f in fds if f.solved), None)
    if fd_plan is not None:
        task = ground(pproblem, cache=GroundingCache())
        row["fd_cost"], _, row["fd_obj"] = true_objective(task, fd_plan)
    return row


STAGES = ("structure", "instance", "symmetries", "search")


def cold_stages(pproblem: ProbabilisticProblem, runs: int) -> dict[str, float]:
    """Median seconds of each stage of a cold call, run one by one as `plan` runs them:
    structure (the :init read, schemas and the cached grounding structure), instance (the
    rest of grounding: reachability, evaluation, relevance, action table), symmetries, and
    search (packing for the C core included)."""
    times: dict[str, list[float]] = {stage: [] for stage in STAGES}
    for _ in range(runs):
        fresh, cache = replace(pproblem), GroundingCache()
        gc.collect()
        with gc_paused():
            start = time.perf_counter()
            state = cache.initial_state(fresh)
            cache.structure(fresh, state)
            marks = [time.perf_counter()]
            task = ground(fresh, state, cache)
            marks.append(time.perf_counter())
            symmetries = find_symmetries(fresh, state, task)
            marks.append(time.perf_counter())
            search(task, OPTIONS, symmetries)
            marks.append(time.perf_counter())
        for stage, begin, end in zip(STAGES, [start, *marks[:-1]], marks, strict=True):
            times[stage].append(end - begin)
    return {stage: statistics.median(t) for stage, t in times.items()}


def grounding_times(quick: bool) -> None:
    """UP's grounder and FD's reachability grounder (both through UP) vs ours, cold and warm."""
    from unified_planning.engines import CompilationKind
    from unified_planning.shortcuts import Compiler

    print("\n== grounding (ms): UP grounder | FD reachability grounder | ours cold | ours warm")
    picked = [c for c in ipc_cases(True) if c.label.endswith("instance-1")]
    for case in picked:
        label, pproblem = case.label, case.read()
        times = []
        for name in ("up_grounder", "fast-downward-reachability-grounder"):
            start = time.perf_counter()
            try:
                with Compiler(name=name, compilation_kind=CompilationKind.GROUNDING) as c:
                    c.skip_checks = True
                    c.compile(pproblem.problem, CompilationKind.GROUNDING)
                times.append(f"{(time.perf_counter() - start) * 1e3:9.1f}")
            except (Exception, SystemExit) as exc:  # noqa: BLE001 - say which one cannot
                # FD's translator calls sys.exit on input it rejects, with stdout swapped out
                sys.stdout = sys.__stdout__
                times.append(f"{type(exc).__name__[:9]:>9}")
        cache = GroundingCache()
        for _ in range(2):
            start = time.perf_counter()
            ground(pproblem, cache=cache)
            times.append(f"{(time.perf_counter() - start) * 1e3:9.1f}")
        print(f"{label:34} " + " ".join(times))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer instances")
    parser.add_argument("--full", action="store_true", help="every IPC instance")
    parser.add_argument("--building", action="store_true",
                        help="add the 40-, 80- and 160-place AVS problems")
    parser.add_argument("--runs", type=int, default=RUNS, help="runs per instance, each side")
    parser.add_argument("--limit", type=float, default=LIMIT_S,
                        help="seconds per run; a failure counts as this")
    parser.add_argument("--only", choices=("avs", "ipc"), default=None)
    parser.add_argument("--domains", type=_names, default=(),
                        help="IPC domains to run, comma-separated (default: all)")
    parser.add_argument("--instances", type=_numbers, default=(),
                        help="IPC instance numbers to run, comma-separated, e.g. 2,3 "
                             "(default: as --quick/--full say)")
    parser.add_argument("--grounding", action="store_true", help="compare the grounders too")
    parser.add_argument("--jsonl", type=Path, default=None,
                        help="append each instance's row to this file as it finishes (a long "
                             "run stopped early still leaves its rows; `--summarize FILE` "
                             "prints their tables)")
    parser.add_argument("--summarize", type=Path, default=None,
                        help="print the tables of the rows a --jsonl file holds, and stop")
    args = parser.parse_args()
    if args.summarize is not None:
        summarize(args.summarize)
        return
    get_environment().credits_stream = None
    require_ipc()
    if args.grounding:
        grounding_times(args.quick)
    print(f"runs {args.runs} per instance on both sides, limit {args.limit:g} s (a failure "
          f"counts as the limit); ours: R={OPTIONS.reward} w={OPTIONS.weight} "
          f"h={OPTIONS.heuristic} on AVS, the anytime greedy phase on IPC; FD: lama-first")
    with tempfile.TemporaryDirectory(prefix="cp-bench-") as scratch:
        def rows_of(cases: list[Case], kind: str) -> list[dict]:
            rows = []
            for case in cases:
                row = bench_case(case, args.runs, args.limit, Path(scratch))
                rows.append(row)
                if args.jsonl is not None:
                    with args.jsonl.open("a") as out:
                        out.write(json.dumps({"kind": kind, **row}) + "\n")
            return rows

        if args.only != "ipc":
            rows = rows_of(avs_cases(args.quick, args.building, Path(scratch)), "avs")
            report(rows, AVS_TITLE, True)
        if args.only != "avs":
            rows = rows_of(ipc_cases(args.quick, args.full, args.domains, args.instances),
                           "ipc")
            report(rows, IPC_TITLE, False)
    sys.stdout.flush()


def _names(text: str) -> tuple[str, ...]:
    return tuple(n.strip() for n in text.split(",") if n.strip())


def _numbers(text: str) -> tuple[int, ...]:
    try:
        return tuple(int(n) for n in _names(text))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"instance numbers must be integers, got {text!r}") from None


AVS_TITLE = "AVS problems (probabilistic; FD on -ln p costs)"
IPC_TITLE = "IPC instances (deterministic)"


def summarize(path: Path) -> None:
    """The tables of the rows a --jsonl file holds (those that finished)."""
    rows = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    for kind, title, probabilistic in (("avs", AVS_TITLE, True), ("ipc", IPC_TITLE, False)):
        picked = [r for r in rows if r.get("kind") == kind]
        if picked:
            report(picked, f"{title}: {len(picked)} rows from {path}", probabilistic)


if __name__ == "__main__":
    main()
