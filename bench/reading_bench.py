"""Reading benchmark: the fast builder (`up_builder`) against UP's own `PDDLReader`, and
our whole reading against Fast Downward's translator.

Run: `.venv/bin/python -m bench.reading_bench [--quick]`. Per IPC instance 1 (plus the pair
with the largest domain, trucks' 365 KB `domain-5`) and per generated AVS problem of 40, 80,
160 and 320 places it times, median of 3, on the text `read_text` hands to UP (translated,
repaired): UP's `PDDLReader` and the builder, side by side, and the same builder filling
the project's own model (`lite`, what `read_text` returns where it can); then the whole
`read_text` (our checks, pre-pass and the model) as it reads now and with UP's reader only.

Then, in the same run, Fast Downward's translator on the same domain and problem files (an
AVS problem written to a scratch file first): the very command FD's driver runs for
`--translate` (`python -m fast_downward.translate DOMAIN PROBLEM --sas-file F`, from
up-fast-downward's `fast-downward.translate` dependency, the project's bench extra), median
of 3. `FD` is that step's wall time (a new interpreter and the translator's imports
included); `FD own` is the translator's own "Done!" wall clock (after its imports) and
`FD prs` its "Parsing:" step alone. The translator does more than read (it normalizes,
grounds, finds invariants and writes SAS+), so `read/FD` (our `read_text` over `FD`) is the
cost of getting a planning model from PDDL in each tool, not of parsing alone. FD's
translator cannot read the AVS files (`:probabilistic-effects`; without it, the problems'
fractional numbers): those rows say so and get no FD number. (`bench/cp_bench.py` gives FD a
ground deterministic compilation instead, 17 MB of PDDL at 80 places: no reading
comparison.) Where the translator is not installed, or fails on a pair, the row says why
and no ratio is made up; the median is over the IPC domains' instance 1.
"""

from __future__ import annotations

import argparse
import importlib.util
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from unified_planning.io import PDDLReader

from avs_planner.pddl import read_text
from avs_planner.pddl import reader as reader_module
from avs_planner.pddl.check import NAME_CLASH, PddlSource, check_read
from avs_planner.pddl.probabilistic import translate_domain
from avs_planner.pddl.reader import _names_shared, apply_repairs
from avs_planner.pddl.sexpr import parse_sexprs
from avs_planner.pddl.up_builder import build_lite, build_problem
from bench.avs_generator import AvsSize, generate
from bench.pddl_bench import best_of
from tests.ipc import IPC  # ../shared/ipc beside the checkout, or $AVS_IPC_DIR

ROOT = Path(__file__).resolve().parents[1]
SIZES = (AvsSize(40, 8, 8, 8), AvsSize(80, 16, 16, 8), AvsSize(160, 32, 32, 8),
         AvsSize(320, 64, 64, 8))
FD_LIMIT_S = 600.0  # one translator run
_FD_DONE = re.compile(r"^Done! \[[\d.]+s CPU, ([\d.]+)s wall-clock\]", re.MULTILINE)
_FD_PARSING = re.compile(r"^Parsing: \[[\d.]+s CPU, ([\d.]+)s wall-clock\]", re.MULTILINE)


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


@contextmanager
def ups_reader_only() -> Iterator[None]:
    """`read_text` as before the fast paths: UP's reader builds every Problem."""
    fast, lite = reader_module._fast_build, reader_module._lite_read
    reader_module._fast_build = lambda domain, problem: None
    reader_module._lite_read = lambda *args: None
    try:
        yield
    finally:
        reader_module._fast_build, reader_module._lite_read = fast, lite


def up_text(domain: str, problem: str) -> tuple[str, bool]:
    """The domain text `read_text` hands to UP, and whether names are shared."""
    checked = check_read(PddlSource("d", domain), [PddlSource("p", problem)])
    translated = translate_domain(domain, parse_sexprs(domain, "d"), "d").text
    repairs = checked.domain.repairs if checked.domain is not None else []
    return (apply_repairs(translated, repairs),
            any(d.code == NAME_CLASH for d in checked.lenient))


def measure(domain: str, problem: str, repeats: int
            ) -> tuple[float, float, float, float, float]:
    """Seconds for UP's reader, the builder, the builder on `lite`, read_text with UP's
    reader, read_text."""
    text, shared = up_text(domain, problem)
    with _names_shared(shared):
        up = best_of(repeats, lambda: PDDLReader().parse_problem_string(text, problem))
        built = best_of(repeats, lambda: build_problem(text, problem))
    lite = best_of(repeats, lambda: build_lite(text, problem, shared))
    with ups_reader_only():
        read_up = best_of(repeats, lambda: read_text(domain, problem))
    read_fast = best_of(repeats, lambda: read_text(domain, problem))
    return up, built, lite, read_up, read_fast


@dataclass(frozen=True)
class FdTranslate:
    """Median seconds of FD's translator on one pair (see the module's doc), or why not."""

    wall_s: float = 0.0
    own_s: float = 0.0
    parse_s: float = 0.0
    failure: str = ""


def fd_translator() -> str:
    """Why FD's translator cannot run here, or "" when it can."""
    if importlib.util.find_spec("fast_downward") is None or importlib.util.find_spec(
            "fast_downward.translate") is None:
        return ("Fast Downward's translator is not installed (pip install -e '.[bench]': "
                "up-fast-downward and its fast-downward.translate)")
    return ""


def fd_translate(domain: str, problem: str, repeats: int, limit_s: float) -> FdTranslate:
    """FD's translator, `repeats` times, on the two texts written to files."""
    walls, owns, parses = [], [], []
    with tempfile.TemporaryDirectory(prefix="fd-translate-") as work:
        domain_file, problem_file = Path(work, "domain.pddl"), Path(work, "problem.pddl")
        domain_file.write_text(domain)
        problem_file.write_text(problem)
        command = [sys.executable, "-m", "fast_downward.translate", str(domain_file),
                   str(problem_file), "--sas-file", str(Path(work, "output.sas"))]
        for _ in range(repeats):
            start = time.perf_counter()
            try:
                proc = subprocess.run(command, cwd=work, capture_output=True, text=True,
                                      timeout=limit_s)
            except subprocess.TimeoutExpired:
                return FdTranslate(failure=f"over {limit_s:.0f} s")
            walls.append(time.perf_counter() - start)
            done, parsed = _FD_DONE.search(proc.stdout), _FD_PARSING.search(proc.stdout)
            if proc.returncode != 0 or done is None or parsed is None:
                lines = (proc.stdout + proc.stderr).strip().splitlines() or [""]
                why = next((x for x in lines if x.startswith("Reason:")), lines[-1])
                return FdTranslate(failure=f"exit {proc.returncode}: {why[:70]}")
            owns.append(float(done.group(1)))
            parses.append(float(parsed.group(1)))
    return FdTranslate(statistics.median(walls), statistics.median(owns),
                       statistics.median(parses))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer pairs, one repeat")
    args = parser.parse_args()
    repeats = 1 if args.quick else 3
    all_cases = cases(args.quick)
    read_text(all_cases[0][1], all_cases[0][2])  # warm-up: imports, UP environment
    fd_missing = fd_translator()
    print("PDDL reading (median seconds): UP's PDDLReader vs the fast builder on the same "
          "text; whole read_text with each; Fast Downward's translator on the same files")
    if fd_missing:
        print(f"NO FAST DOWNWARD: {fd_missing}; its columns are left empty")
    print(f"{'pair':22s} {'KB':>6s} {'UP':>8s} {'builder':>8s} {'UP/bld':>7s} "
          f"{'lite':>7s} {'bld/lite':>8s}   "
          f"{'read(UP)':>9s} {'read':>7s} {'ratio':>6s}   "
          f"{'FD':>7s} {'FD own':>7s} {'FD prs':>7s} {'read/FD':>8s}")  # fmt: skip
    ipc_ratios: list[float] = []
    own_ratios: list[float] = []
    for label, domain, problem in all_cases:
        up, built, lite, read_up, read_fast = measure(domain, problem, repeats)
        size = (len(domain) + len(problem)) / 1024
        row = (f"{label:22s} {size:6.0f} {up:8.3f} {built:8.3f} {up / built:6.0f}x "
               f"{lite:7.3f} {built / lite:7.1f}x   "
               f"{read_up:9.3f} {read_fast:7.3f} {read_up / read_fast:5.1f}x   ")
        if fd_missing:
            row += f"{'-':>7s} {'-':>7s} {'-':>7s} {'-':>8s}"
        else:
            fd = fd_translate(domain, problem, repeats, FD_LIMIT_S)
            if fd.failure:
                row += f"FD cannot read it: {fd.failure}"
            else:
                ratio = read_fast / fd.wall_s
                row += (f"{fd.wall_s:7.3f} {fd.own_s:7.3f} {fd.parse_s:7.3f} "
                        f"{ratio:7.2f}x")
                if label.endswith("/1") and not label.startswith("avs/"):
                    ipc_ratios.append(ratio)  # IPC instance 1, one per domain
                    own_ratios.append(read_fast / fd.own_s)
        print(row, flush=True)
    if fd_missing:
        print(f"read/FD: not measured ({fd_missing})")
    elif ipc_ratios:
        print(f"median read/FD over {len(ipc_ratios)} IPC domains (instance 1): "
              f"{statistics.median(ipc_ratios):.2f}x (below 1: read_text is faster than "
              f"FD's translator step); over FD's own clock (after its imports): "
              f"{statistics.median(own_ratios):.2f}x")


if __name__ == "__main__":
    main()
