"""Reading benchmark: the fast builder (`up_builder`) against UP's own `PDDLReader`.

Run: `.venv/bin/python -m bench.reading_bench [--quick]`. Per IPC instance 1 (plus the pair
with the largest domain, trucks' 365 KB `domain-5`) and per generated AVS problem of 40, 80,
160 and 320 places it times, median of 3, on the text `read_text` hands to UP (translated,
repaired): UP's `PDDLReader` and the builder, side by side; then the whole `read_text`
(our checks, pre-pass and the Problem) with the fast path and with UP's reader only.
"""

from __future__ import annotations

import argparse
import re
import statistics
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from unified_planning.io import PDDLReader

from avs_planner.pddl import read_text
from avs_planner.pddl import reader as reader_module
from avs_planner.pddl.check import NAME_CLASH, PddlSource, check_read
from avs_planner.pddl.probabilistic import translate_domain
from avs_planner.pddl.reader import _names_shared, apply_repairs
from avs_planner.pddl.sexpr import parse_sexprs
from avs_planner.pddl.up_builder import build_problem
from bench.avs_generator import AvsSize, generate

ROOT = Path(__file__).resolve().parents[1]
IPC = ROOT.parent / "shared" / "ipc"  # beside the checkout
SIZES = (AvsSize(40, 8, 8, 8), AvsSize(80, 16, 16, 8), AvsSize(160, 32, 32, 8),
         AvsSize(320, 64, 64, 8))


def cases(quick: bool) -> list[tuple[str, str, str]]:
    """(label, domain text, problem text)."""
    found = []
    for folder in sorted(p for p in IPC.glob("*") if p.is_dir()):
        numbers = sorted(int(re.sub(r"\D", "", p.stem)) for p in folder.glob("instance-*.pddl"))
        picked = [numbers[0]]
        if folder.name == "trucks" and not quick:
            picked.append(numbers[-1])  # the largest domain of the set
        for n in picked:
            domain = folder / "domain.pddl"
            if not domain.exists():
                domain = folder / f"domain-{n}.pddl"
            found.append((f"{folder.name}/{n}", domain.read_text(),
                          (folder / f"instance-{n}.pddl").read_text()))
    avs = (ROOT / "domains" / "avs" / "domain.pddl").read_text()
    for size in SIZES[:2] if quick else SIZES:
        found.append((f"avs/{size.places} places", avs, generate(size, 0)))
    return found[:3] + found[-1:] if quick else found


def median_time(repeats: int, run: Callable[[], object]) -> float:
    """Median wall time of `repeats` runs, in seconds."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


@contextmanager
def ups_reader_only() -> Iterator[None]:
    """`read_text` as before the fast path: UP's reader builds every Problem."""
    fast = reader_module._fast_build
    reader_module._fast_build = lambda domain, problem: None
    try:
        yield
    finally:
        reader_module._fast_build = fast


def up_text(domain: str, problem: str) -> tuple[str, bool]:
    """The domain text `read_text` hands to UP, and whether names are shared."""
    checked = check_read(PddlSource("d", domain), [PddlSource("p", problem)])
    translated = translate_domain(domain, parse_sexprs(domain, "d"), "d").text
    repairs = checked.domain.repairs if checked.domain is not None else []
    return (apply_repairs(translated, repairs),
            any(d.code == NAME_CLASH for d in checked.lenient))


def measure(domain: str, problem: str, repeats: int) -> tuple[float, float, float, float]:
    """Seconds for UP's reader, the builder, read_text with UP's reader, read_text."""
    text, shared = up_text(domain, problem)
    with _names_shared(shared):
        up = median_time(repeats, lambda: PDDLReader().parse_problem_string(text, problem))
        built = median_time(repeats, lambda: build_problem(text, problem))
    with ups_reader_only():
        read_up = median_time(repeats, lambda: read_text(domain, problem))
    read_fast = median_time(repeats, lambda: read_text(domain, problem))
    return up, built, read_up, read_fast


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer pairs, one repeat")
    args = parser.parse_args()
    repeats = 1 if args.quick else 3
    all_cases = cases(args.quick)
    read_text(all_cases[0][1], all_cases[0][2])  # warm-up: imports, UP environment
    print("PDDL reading (median seconds): UP's PDDLReader vs the fast builder on the same "
          "text; whole read_text with each")
    print(f"{'pair':22s} {'KB':>6s} {'UP':>8s} {'builder':>8s} {'UP/bld':>7s}   "
          f"{'read(UP)':>9s} {'read':>7s} {'ratio':>6s}")  # fmt: skip
    for label, domain, problem in all_cases:
        up, built, read_up, read_fast = measure(domain, problem, repeats)
        size = (len(domain) + len(problem)) / 1024
        print(f"{label:22s} {size:6.0f} {up:8.3f} {built:8.3f} {up / built:6.0f}x   "
              f"{read_up:9.3f} {read_fast:7.3f} {read_up / read_fast:5.1f}x", flush=True)

if __name__ == "__main__":
    main()
