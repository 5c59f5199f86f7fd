"""Multi-label DT benchmark: the lookahead's decision time at 3 labels x 20 cones, one search
for every label against one single-label DT search per label, and the gap to the optimum.

    .venv/bin/python -m bench.dt_multi_bench [--quick] [--episodes N] [--seed S]

Instances: as in bench/dt_bench.py (cones uniformly in a 10 m x 10 m room, robot starting in a
corner, travel = driving at 0.5 m/s plus turning at 1 rad/s, sensing 2 s, detector FN 0.2 / FP
0.05, miss and false-confirm penalties 300 s), each label with its own random prior over the
same cones (total mass in [0.5, 0.95]). Every episode draws each label's true cone (or none)
from its prior; the simulated detector gives the k-th look at a cone the same random draw per
label whichever search looks (common random numbers).

1. Decision time: `MultiLabelSession` episodes with 3 labels and 20 cones, modes "all" and
   "any"; wall and CPU time of each decision of the "lookahead" policy (forced stops at the
   step budget are not decisions). The requirement is a median of at most 50 ms.
2. One search or one per label (mode "all", same episodes; 3 labels, then 1): the
   multi-label session against single-label `DTSession`s run one after another, each starting
   where the previous ended ("pouct", the default, and "greedy"). Cost = travel + sensing +
   every label's terminal penalty in expectation under the final belief (as in dt_bench);
   "correct" counts labels confirmed in their true cone or rejected when in none.
3. Gap to the optimum (2 labels, 3 cones, 6 steps, per mode): the lookahead's exact expected
   cost (by enumerating observations) over the exact solver's.
"""

from __future__ import annotations

import argparse
import math
import random
import statistics
import time
from dataclasses import dataclass, field

from avs_planner.dt import (
    ActionKind,
    DetectorModel,
    DTRewards,
    DTSession,
    DTStatus,
    LabelStatus,
    LabelTarget,
    MultiLabelProblem,
    MultiLabelSession,
    TravelCosts,
    ViewCone,
)
from avs_planner.dt.domain import NOWHERE
from avs_planner.dt.multi import MultiExactSolver, MultiLabelBelief, MultiLookaheadPolicy
from avs_planner.dt.multi.exact import evaluate_multi_policy

PENALTY = 300.0
SENSING = 2.0
START = (0.0, 0.0, 0.0)


def random_cones(rng: random.Random, n: int) -> tuple[ViewCone, ...]:
    return tuple(ViewCone(f"c{i}", (rng.uniform(0, 10), rng.uniform(0, 10), rng.uniform(-3, 3)),
                          0.0) for i in range(n))


def random_prior(rng: random.Random, n: int) -> tuple[float, ...]:
    weights = [rng.random() ** 2 for _ in range(n)]
    scale = rng.uniform(0.5, 0.95) / sum(weights)
    return tuple(w * scale for w in weights)


def random_problem(seed: int, n: int, labels: int, mode: str, horizon: int = 0
                   ) -> MultiLabelProblem:
    rng = random.Random(seed)
    cones = random_cones(rng, n)
    targets = tuple(LabelTarget(f"label{j}", random_prior(rng, n), DetectorModel(),
                                DTRewards(PENALTY, PENALTY)) for j in range(labels))
    return MultiLabelProblem(cones, targets, TravelCosts.from_poses(START, cones), SENSING,
                             mode, horizon)


class Detector:
    """The k-th look at a cone gives each label the same draw in every search."""

    def __init__(self, key: tuple, problem: MultiLabelProblem, truth: list[int]):
        self.key, self.problem, self.truth = key, problem, truth
        self.looks: dict[tuple[int, int], int] = {}

    def detect(self, label: int, cone: int) -> bool:
        k = self.looks.get((label, cone), 0)
        self.looks[(label, cone)] = k + 1
        rate = self.problem.single(label).detector.p_detect(self.truth[label] == cone)
        return random.Random(hash((*self.key, label, cone, k))).random() < rate


class TimedLookahead(MultiLookaheadPolicy):
    """The lookahead, recording wall and CPU time of each decision, and whether it was one
    right after a MOVE (where only the look there is left to choose)."""

    def __init__(self, problem: MultiLabelProblem, times: list[tuple[float, float, bool]]):
        super().__init__(problem)
        self.times = times

    def decide(self, belief, steps_left):
        w, c = time.perf_counter(), time.process_time()
        action = super().decide(belief, steps_left)
        self.times.append((time.perf_counter() - w, time.process_time() - c, belief.after_move))
        return action


@dataclass
class Tally:
    costs: list[float] = field(default_factory=list)
    correct: list[float] = field(default_factory=list)
    looks: list[int] = field(default_factory=list)


def sample_truth(problem: MultiLabelProblem, rng: random.Random) -> list[int]:
    truth = []
    for single in problem.singles:
        index = rng.choices(range(problem.n + 1), weights=single.prior)[0]
        truth.append(NOWHERE if index == problem.n else index)
    return truth


def run_multi(problem: MultiLabelProblem, policy, detector: Detector) -> tuple[float, float, int]:
    """One multi-label episode: (cost incl. expected penalties, share of labels right, looks)."""
    session = MultiLabelSession.from_problem(problem, policy)
    looks = 0
    while not session.finished:
        action = session.next_action()
        if action.terminal:
            continue
        if action.kind is ActionKind.PROCESS_VIEW_CONE:
            looks += 1
            open_labels = session.belief.open_labels
            session.update(action, {problem.labels[i]: detector.detect(i, action.cone)
                                    for i in open_labels})
        else:
            session.update(action)
    result, penalty, right = session.result, 0.0, 0
    for i, label in enumerate(problem.labels):
        outcome, truth = result.labels[label], detector.truth[i]
        if outcome.status is LabelStatus.CONFIRMED:
            penalty += PENALTY * (1.0 - outcome.probability)
            right += session.belief.claims[i] == truth
        elif outcome.status is LabelStatus.REJECTED:
            penalty += PENALTY * outcome.probability
            right += truth == NOWHERE
    return result.cost + penalty, right / problem.k, looks


def run_singles(problem: MultiLabelProblem, policy: str, detector: Detector,
                seed: int) -> tuple[float, float, int]:
    """The labels searched one after another by single-label sessions, each starting where the
    previous one ended."""
    pose, total, right, looks = START, 0.0, 0, 0
    for i in range(problem.k):
        single = problem.single(i)
        session = DTSession(single.cones, single.detector, pose, sensing_cost=SENSING,
                            rewards=single.rewards, policy=policy, seed=seed + i)
        while True:
            action = session.next_action()
            if session.finished:
                break
            if action.kind is ActionKind.PROCESS_VIEW_CONE:
                looks += 1
                session.update(action, detector.detect(i, action.cone))
            else:
                session.update(action)
                pose = problem.cones[action.cone].pose
        result = session.result
        if result.status is DTStatus.CONFIRMED:
            total += PENALTY * (1.0 - result.probability)
            right += result.final_action.cone == detector.truth[i]
        else:
            total += PENALTY * result.probability
            right += detector.truth[i] == NOWHERE
        total += result.cost
    return total, right / problem.k, looks


def _pct(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[int(q * (len(ordered) - 1))]


def bench_time(instances: int, episodes: int, seed0: int) -> None:
    print("\n== 1. decision time: 3 labels x 20 cones, lookahead ==")
    print("(all decisions; \"free\": not right after a MOVE, where only the look is left)")
    print(f"{'mode':5} {'decisions':>9} {'median ms':>10} {'cpu ms':>7} {'p90 cpu':>8} "
          f"{'max cpu':>8} {'free':>5} {'free median cpu':>16} {'looks/episode':>14}")
    for mode in ("all", "any"):
        times: list[tuple[float, float, bool]] = []
        looks = []
        for inst in range(instances):
            problem = random_problem(seed0 + inst, 20, 3, mode)
            rng = random.Random(seed0 + 7 * inst)
            for ep in range(episodes):
                detector = Detector((seed0, inst, ep), problem, sample_truth(problem, rng))
                looks.append(run_multi(problem, TimedLookahead(problem, times), detector)[2])
        wall = [w for w, _, _ in times]
        cpu = [c for _, c, _ in times]
        free = [c for _, c, after_move in times if not after_move]
        print(f"{mode:5} {len(times):9d} {1e3 * statistics.median(wall):10.2f} "
              f"{1e3 * statistics.median(cpu):7.2f} {1e3 * _pct(cpu, 0.9):8.2f} "
              f"{1e3 * max(cpu):8.2f} {len(free):5d} {1e3 * statistics.median(free):16.2f} "
              f"{statistics.fmean(looks):14.1f}")


def _mean_se(values: list[float]) -> tuple[float, float]:
    if len(values) < 2:
        return (values[0] if values else math.nan), math.nan
    return statistics.fmean(values), statistics.stdev(values) / math.sqrt(len(values))


def bench_shared_looks(labels: int, instances: int, episodes: int, seed0: int,
                       singles: list[str]) -> None:
    print(f"\n== 2. one search for {labels} label(s) vs one single-label search per label "
          "(20 cones, mode all) ==")
    tallies = {name: Tally() for name in ["multi lookahead", *singles]}
    for inst in range(instances):
        problem = random_problem(seed0 + 100 * labels + inst, 20, labels, "all")
        rng = random.Random(seed0 + 11 * inst)
        for ep in range(episodes):
            truth = sample_truth(problem, rng)
            key = (seed0, labels, inst, ep)
            results = {"multi lookahead": run_multi(problem, MultiLookaheadPolicy(problem),
                                                    Detector(key, problem, truth))}
            for name in singles:
                results[name] = run_singles(problem, name, Detector(key, problem, truth),
                                            1000 * inst + ep)
            for name, (cost, right, looks) in results.items():
                tallies[name].costs.append(cost)
                tallies[name].correct.append(right)
                tallies[name].looks.append(looks)
    base = tallies["multi lookahead"].costs
    print(f"{'search':22} {'E[cost] MC':>16} {'/multi':>7} {'correct':>8} {'looks':>6}")
    for name, t in tallies.items():
        mean, se = _mean_se(t.costs)
        label = name if name.startswith("multi") else f"per label, {name}"
        print(f"{label:22} {mean:9.1f} ±{se:5.1f} {mean / statistics.fmean(base):7.3f} "
              f"{100 * statistics.fmean(t.correct):7.1f}% {statistics.fmean(t.looks):6.1f}")
    for name in singles:
        diffs = [s - m for s, m in zip(tallies[name].costs, base, strict=True)]
        d, dse = _mean_se(diffs)
        print(f"per label ({name}) - multi (paired episodes): {d:+.1f} ± {dse:.1f}")


def bench_gap(seeds: int, seed0: int) -> None:
    print("\n== 3. gap to the optimum: 2 labels x 3 cones, 6 steps ==")
    print(f"{'mode':5} {'instances':>9} {'mean /exact':>12} {'worst /exact':>13} "
          f"{'exact s':>8}")
    for mode in ("all", "any"):
        ratios, solve = [], []
        for seed in range(seeds):
            problem = random_problem(seed0 + 500 + seed, 3, 2, mode, horizon=6)
            start = MultiLabelBelief.initial(problem)
            t = time.process_time()
            optimum = -MultiExactSolver(problem).solve(start, problem.horizon).value
            solve.append(time.process_time() - t)
            policy = MultiLookaheadPolicy(problem)
            cost = -evaluate_multi_policy(problem, policy.decide, start, problem.horizon)
            ratios.append(cost / optimum if optimum > 0 else 1.0)
        print(f"{mode:5} {seeds:9d} {statistics.fmean(ratios):12.3f} {max(ratios):13.3f} "
              f"{statistics.fmean(solve):8.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer instances and episodes")
    parser.add_argument("--episodes", type=int, default=0, help="episodes per instance")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    start = time.perf_counter()
    if args.quick:
        bench_time(3, args.episodes or 3, args.seed)
        bench_shared_looks(3, 2, args.episodes or 3, args.seed, ["greedy"])
        bench_gap(4, args.seed)
    else:
        bench_time(6, args.episodes or 6, args.seed)
        for labels in (3, 1):
            bench_shared_looks(labels, 5, args.episodes or 8, args.seed, ["pouct", "greedy"])
        bench_gap(16, args.seed)
    print(f"\ntotal wall time {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
