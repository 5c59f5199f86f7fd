"""DT sub-planner benchmark: POUCT vs greedy vs fixed sweep vs exact on seeded random instances.

    .venv/bin/python -m bench.dt_bench [--quick] [--sims N] [--episodes N]

Instances: n view cones uniformly in a 10 m x 10 m room, robot starting in a corner, target
probabilities random with total mass in [0.5, 0.95], travel = driving time at 0.5 m/s plus turning
at 1 rad/s, sensing 2 s, detector FN 0.2 / FP 0.05, miss and false-confirm penalties 300 s.

Per policy and instance class it prints: success (correct final outcome: the right cone
confirmed when the object is there, rejected when it is not), expected cost (travel + sensing +
penalties): "enum" is exact, by enumerating observations (deterministic policies only; for
POUCT it is the belief-seeded variant `pouct_decision_rule`, a fresh search per decision, so it
is exactly evaluable where exact is feasible; the MC column runs the session policy); "MC" is
the mean over the same seeded episodes for every policy (same targets, same detector draw for
the k-th look at a cone), with the terminal penalty replaced by its expectation under the final
belief (unbiased, lower variance). Ratios /exact and /greedy are MC over MC of the same
episodes; the paired lines give POUCT's mean per-episode difference with its standard error.
Decision time per action is wall and CPU (the machine may be shared: CPU is the fairer one).
"""

from __future__ import annotations

import argparse
import math
import random
import statistics
import time
from dataclasses import dataclass, field

from avs_planner.dt import (
    DetectorModel,
    DTProblem,
    DTRewards,
    DTSession,
    DTStatus,
    PolicyConfig,
    SearchBudget,
    TravelCosts,
    ViewCone,
    make_policy,
)
from avs_planner.dt.belief import TargetBelief
from avs_planner.dt.domain import NOWHERE, ActionKind
from avs_planner.dt.errors import DtInputError
from avs_planner.dt.exact import ExactPolicy, evaluate_policy
from avs_planner.dt.pouct import pouct_decision_rule

PENALTY = 300.0


def random_problem(seed: int, n: int) -> DTProblem:
    rng = random.Random(seed)
    cones = [ViewCone(f"c{i}", (rng.uniform(0, 10), rng.uniform(0, 10), rng.uniform(-3, 3)), 0.0)
             for i in range(n)]
    weights = [rng.random() ** 2 for _ in cones]
    scale = rng.uniform(0.5, 0.95) / sum(weights)
    cones = tuple(ViewCone(c.id, c.pose, w * scale) for c, w in zip(cones, weights, strict=True))
    return DTProblem(cones, TravelCosts.from_poses((0.0, 0.0, 0.0), cones), DetectorModel(),
                     2.0, DTRewards(PENALTY, PENALTY))


class TimedPolicy:
    """Wraps a policy to record wall and CPU time of each decision."""

    def __init__(self, policy, wall: list[float], cpu: list[float]):
        self.policy, self.name, self.wall, self.cpu = policy, policy.name, wall, cpu

    def decide(self, belief, steps_left):
        w, c = time.perf_counter(), time.process_time()
        action = self.policy.decide(belief, steps_left)
        self.wall.append(time.perf_counter() - w)
        self.cpu.append(time.process_time() - c)
        return action

    def observe(self, action, observation):
        self.policy.observe(action, observation)


class _RuleAsPolicy:
    """A (belief, steps_left) -> action function with the policy interface."""

    def __init__(self, rule):
        self.decide = rule


@dataclass
class Tally:
    """Per (class, policy) results."""

    costs: list[float] = field(default_factory=list)  # Rao-Blackwellised episode costs
    success: list[bool] = field(default_factory=list)
    analytic: list[float] = field(default_factory=list)  # exact expected cost per instance
    wall: list[float] = field(default_factory=list)
    cpu: list[float] = field(default_factory=list)
    solve_s: list[float] = field(default_factory=list)  # exact: CPU s to solve the instance


class Detector:
    """Simulated detector whose k-th look at a cone uses the same random draw for every policy
    (common random numbers: paired differences between policies get small variance)."""

    def __init__(self, key: tuple, problem: DTProblem, target: int):
        self.key, self.problem, self.target, self.looks = key, problem, target, {}

    def detect(self, cone: int) -> bool:
        k = self.looks.get(cone, 0)
        self.looks[cone] = k + 1
        hit_in, hit_out = self.problem.detection_rates
        u = random.Random(hash((*self.key, cone, k))).random()
        return u < (hit_in if cone == self.target else hit_out)


def run_episode(problem: DTProblem, policy, target: int, key: tuple) -> tuple[float, bool]:
    """One closed-loop episode against a simulated detector; returns (RB cost, correct?)."""
    session = DTSession.from_problem(problem, policy)
    detector = Detector(key, problem, target)
    while True:
        action = session.next_action()
        if session.finished:
            break
        if action.kind is ActionKind.PROCESS_VIEW_CONE:
            session.update(action, detector.detect(action.cone))
        else:
            session.update(action)
    result = session.result
    final = session.belief
    if result.status is DTStatus.CONFIRMED:
        penalty = PENALTY * (1.0 - final.probs[result.final_action.cone])
        correct = target == result.final_action.cone
    else:
        penalty = PENALTY * final.p_present
        correct = target == NOWHERE
    return result.cost + penalty, correct


def sample_target(problem: DTProblem, rng: random.Random) -> int:
    index = rng.choices(range(problem.n + 1), weights=problem.prior)[0]
    return NOWHERE if index == problem.n else index


def analytic_cost(problem: DTProblem, policy) -> float:
    start = TargetBelief.initial(problem)
    try:
        return -evaluate_policy(problem, policy.decide, start, problem.horizon)
    except (DtInputError, RecursionError):
        return math.nan


def bench_class(n: int, instances: int, episodes: int, sims: int, with_exact: bool,
                seed0: int) -> dict[str, Tally]:
    names = (["exact"] if with_exact else []) + ["pouct", "greedy", "sweep"]
    tallies = {name: Tally() for name in names}
    budget = SearchBudget(num_sims=sims) if sims > 0 else SearchBudget()
    for inst in range(instances):
        problem = random_problem(seed0 + 1000 * n + inst, n)
        shared = {}
        if with_exact:
            solve = time.process_time()
            shared["exact"] = ExactPolicy(problem)
            shared["exact"].solver.solve(TargetBelief.initial(problem), problem.horizon)
            tallies["exact"].solve_s.append(time.process_time() - solve)
        for name in names:
            tally = tallies[name]
            base = shared.get(name) or make_policy(name, problem, PolicyConfig(0, budget))
            if name != "pouct":
                tally.analytic.append(analytic_cost(problem, base))
            elif with_exact:
                tally.analytic.append(analytic_cost(problem, _RuleAsPolicy(
                    pouct_decision_rule(problem, seed0 + inst, budget))))
            rng = random.Random(seed0 + 7 * inst)
            for ep in range(episodes):
                target = sample_target(problem, rng)
                policy = base
                if name == "pouct":
                    policy = make_policy(name, problem, PolicyConfig(1000 * inst + ep, budget))
                timed = TimedPolicy(policy, tally.wall, tally.cpu)
                cost, ok = run_episode(problem, timed, target, (seed0, n, inst, ep))
                tally.costs.append(cost)
                tally.success.append(ok)
    return tallies


def _mean_se(values: list[float]) -> tuple[float, float]:
    if len(values) < 2:
        return (values[0] if values else math.nan), math.nan
    return statistics.fmean(values), statistics.stdev(values) / math.sqrt(len(values))


def report(n: int, tallies: dict[str, Tally], sims: int) -> None:
    exact_mc = statistics.fmean(tallies["exact"].costs) if "exact" in tallies else math.nan
    greedy_mc = statistics.fmean(tallies["greedy"].costs)
    sims = sims if sims > 0 else SearchBudget().num_sims
    print(f"\n== {n} cones ==  (pouct: {sims} simulations/decision)")
    print(f"{'policy':8} {'success':>8} {'E[cost] enum':>14} {'E[cost] MC':>16} "
          f"{'/exact':>7} {'/greedy':>8} {'ms/dec wall':>12} {'p95':>7} {'ms/dec cpu':>11}")
    for name, t in tallies.items():
        mc, se = _mean_se(t.costs)
        analytic = statistics.fmean(t.analytic) if t.analytic else math.nan
        wall = sorted(t.wall)
        p95 = wall[int(0.95 * (len(wall) - 1))] * 1e3 if wall else math.nan
        print(f"{name:8} {100 * statistics.fmean(t.success):7.1f}% {analytic:14.2f} "
              f"{mc:9.2f} ±{se:5.2f} {mc / exact_mc:7.3f} {mc / greedy_mc:8.3f} "
              f"{1e3 * statistics.fmean(wall):12.2f} {p95:7.2f} "
              f"{1e3 * statistics.fmean(t.cpu):11.2f}")
    for ref in ("exact", "greedy"):
        if ref not in tallies:
            continue
        diffs = [p - r for p, r in zip(tallies["pouct"].costs, tallies[ref].costs, strict=True)]
        d, dse = _mean_se(diffs)
        base = statistics.fmean(tallies[ref].costs)
        print(f"pouct - {ref} (paired episodes): {d:+.2f} ± {dse:.2f} cost "
              f"({100 * d / base:+.1f}% ± {100 * dse / base:.1f}%)")
    if "exact" in tallies:
        enum = statistics.fmean(tallies["pouct"].analytic)
        ratios = [p / e for p, e in zip(tallies["pouct"].analytic, tallies["exact"].analytic,
                                        strict=True)]
        print(f"pouct (fresh search per decision) exact E[cost] {enum:.2f}: per instance "
              f"/exact mean {statistics.fmean(ratios):.3f}, worst {max(ratios):.3f}")
        print(f"exact: solved in {statistics.fmean(tallies['exact'].solve_s):.2f} s CPU per "
              "instance before the episodes (decisions are then look-ups)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer instances and episodes")
    parser.add_argument("--sims", type=int, default=0,
                        help="POUCT simulations per decision (default: SearchBudget's)")
    parser.add_argument("--episodes", type=int, default=0, help="episodes per instance")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    # (cones, instances, episodes, exact?)
    classes = [(3, 6, 25, True), (4, 4, 20, True), (8, 4, 12, False), (20, 3, 8, False)]
    if args.quick:
        classes = [(3, 3, 15, True), (8, 2, 10, False), (20, 2, 5, False)]
    start = time.perf_counter()
    for n, instances, episodes, with_exact in classes:
        tallies = bench_class(n, instances, args.episodes or episodes, args.sims, with_exact,
                              args.seed)
        report(n, tallies, args.sims)
    print(f"\ntotal wall time {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
