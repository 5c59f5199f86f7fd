"""PDDL reading benchmark: what our checks and the probabilistic pre-pass add to UP's reader.

Run: `.venv/bin/python -m bench.pddl_bench [--quick]`. For each domain/problem pair it times,
in the same run: unified-planning's own `PDDLReader` on the text it can read (the reference;
for probabilistic domains, the translated text), our `check` alone, and our full `read_text`
(check + translation + UP). The ratio `read_text / UP` is the price of exact positions.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from pathlib import Path

from unified_planning.io import PDDLReader

from avs_planner.pddl import PddlSource, check, read_text
from avs_planner.pddl.probabilistic import translate_domain
from avs_planner.pddl.sexpr import parse_sexprs
from tests.ipc import IPC, domain_for, instances, ipc_folders

ROOT = Path(__file__).resolve().parents[1]


def cases(quick: bool) -> list[tuple[str, Path, Path]]:
    """(label, domain, problem): the AVS problems and the IPC domains' first/last instances."""
    avs = ROOT / "domains" / "avs"
    found = [(f"avs/{p.stem}", avs / "domain.pddl", p) for p in sorted(avs.glob("problems/*"))]
    for folder in ipc_folders(IPC):  # domain.pddl, or domain-N.pddl per instance
        numbered = sorted(instances(folder), key=lambda p: len(p.read_text()))
        for problem in numbered[:1] if quick else [numbered[0], numbered[-1]]:
            found.append((f"{folder.name}/{problem.stem}", domain_for(problem), problem))
    return found[:4] if quick else found


def best_of(repeats: int, run: Callable[[], object]) -> float:
    """Median wall time of `repeats` runs, in seconds."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def measure(domain: Path, problem: Path, repeats: int) -> tuple[float, float, float]:
    """Seconds for UP alone, our check alone, and our full reader."""
    domain_text, problem_text = domain.read_text(), problem.read_text()
    up_text = translate_domain(domain_text, parse_sexprs(domain_text), str(domain)).text
    up = best_of(repeats, lambda: PDDLReader().parse_problem_string(up_text, problem_text))
    ours_check = best_of(
        repeats,
        lambda: check(PddlSource("d", domain_text), [PddlSource("p", problem_text)]),
    )
    ours = best_of(repeats, lambda: read_text(domain_text, problem_text))
    return up, ours_check, ours


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer pairs, one repeat")
    args = parser.parse_args()
    repeats = 1 if args.quick else 3
    all_cases = cases(args.quick)
    measure(all_cases[0][1], all_cases[0][2], 1)  # warm-up: imports, UP environment, caches
    print("PDDL reading (median seconds): UP's reader alone vs our check and full read_text")
    print(f"{'pair':28s} {'UP':>8s} {'check':>8s} {'read_text':>10s} {'check/UP':>9s} "
          f"{'read/UP':>8s}")  # fmt: skip
    for label, domain, problem in all_cases:
        up, ours_check, ours = measure(domain, problem, repeats)
        print(
            f"{label:28s} {up:8.3f} {ours_check:8.3f} {ours:10.3f} "
            f"{ours_check / up:8.3f}x {ours / up:7.2f}x"
        )


if __name__ == "__main__":
    main()
