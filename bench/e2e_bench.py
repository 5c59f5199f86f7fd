"""End to end against Fast Downward: `avs plan` as a user runs it, beside lama-first.

Run: `.venv/bin/python -m bench.e2e_bench [--quick] [--timeout S] [--instances 1-3]`.
For every domain of the IPC set at ../shared/ipc (`AVS_IPC_DIR` elsewhere; a shared
`domain.pddl` or one `domain-N.pddl` per instance, `tests/ipc.py`) and each instance number
asked for (default 1-3; `--quick`: 1), back to back in one run, each a whole new process:

- ours: `python -m avs_planner plan DOMAIN PROBLEM --timeout S`, the CLI's default options
  otherwise (with a timeout, `--mode auto` runs the anytime mode: the greedy phase, then
  weighted A* restarts down to w = 1 until the last ends or S runs out); its wall time from
  the process's start to its exit (interpreter start-up, imports, reading included), its
  exit status and the plan it prints;
- FD: `fast-downward.py --alias lama-first` on the same files through `bench/fd_runner.py`:
  the driver's wall time end to end, and FD's own clocks from its log.

Both processes are killed at S + GRACE_S of wall time (ours is told S, lama-first has no
limit of its own). Every plan either side prints is checked against the problem with
unified-planning's `SequentialPlanValidator` on the problem UP's `PDDLReader` reads from the
same files (the project's reader where UP's rejects the text); a plan counts as valid only
when the validator says VALID. Its cost is the validator's evaluation of the problem's metric
(the plan's length without one).

Our side runs from bytecode, as FD's does: the checkout's packages are compiled before the
first timing (`compile_checkout`). FD's translator comes as a wheel whose modules pip compiled
at install; ours is an editable install, and where the environment forbids writing bytecode
(PYTHONDONTWRITEBYTECODE=1, as on the machine the figures before 2026-11-29 came from) every
`avs` process compiled its modules from source (`avs plan` on corridor.pddl: 0.316 s against
0.238 s with bytecode, median of 7).

Then start-up, each the median of STARTUP_RUNS whole-process runs: `avs --help`, `avs plan`
on domains/avs/problems/corridor.pddl, and FD's driver's `--help` beside them.

The table, a summary (coverage, all plans valid, median ours/FD end-to-end ratio over the
instances both solved: above 1 we are slower) and the rows go to
bench/results/e2e-<date>-<commit>.json. Timings on a shared 2-core machine are noisy: one run
per instance and side, medians in the summary.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import signal
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

from bench.cp_bench import Case, ipc_cases
from bench.fd_runner import driver, run_fd

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results"
TIMEOUT_S = 30.0
GRACE_S = 5.0  # wall time past --timeout before a process (either side) is killed
STARTUP_RUNS = 5
CORRIDOR = ("domains/avs/domain.pddl", "domains/avs/problems/corridor.pddl")
# `avs plan`'s exit codes (README): 0 solved, 1 bad input, 2 no plan, 3 timeout, 4 internal
EXIT_STATUS = {0: "solved", 1: "bad-input", 2: "no-plan", 3: "timeout", 4: "error"}

Step = tuple[str, tuple[str, ...]]


def parse_instances(text: str) -> tuple[int, ...]:
    """Instance numbers from `1-3`, `2`, `1,4-5`: sorted, each once."""
    numbers: set[int] = set()
    for part in (p.strip() for p in text.split(",")):
        if not part:
            continue
        first, dash, last = part.partition("-")
        try:
            low, high = int(first), int(last) if dash else int(first)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"instance numbers are N, N-M or a comma-separated list of those, got "
                f"{text!r}") from None
        if low < 1 or high < low:
            raise argparse.ArgumentTypeError(f"bad instance range {part!r} in {text!r}")
        numbers.update(range(low, high + 1))
    if not numbers:
        raise argparse.ArgumentTypeError(f"no instance numbers in {text!r}")
    return tuple(sorted(numbers))


def parse_plan(stdout: str) -> tuple[Step, ...]:
    """The steps `avs plan` prints, one `(name arg ...)` a line; comment lines start with `;`."""
    steps = []
    for line in stdout.splitlines():
        line = line.strip()
        if line.startswith("(") and line.endswith(")"):
            name, *args = line[1:-1].split()
            steps.append((name, tuple(args)))
    return tuple(steps)


def stopped_by(stdout: str) -> str | None:
    """`patience` / `timeout` / `node_limit` when one of them ended a search with a plan."""
    for line in stdout.splitlines():
        if line.startswith("; stopped by: "):
            return line.removeprefix("; stopped by: ").split()[0]
    return None


@dataclass(frozen=True)
class OursRun:
    status: str
    wall_s: float
    plan: tuple[Step, ...] = ()
    stopped_by: str | None = None
    message: str = ""


PACKAGES = ("avs_planner", "conceptual_map", "sim", "api")


def compile_checkout() -> bool:
    """Compile this checkout's packages to bytecode (up-to-date files are skipped), so each
    `avs` process loads them as an installed package's; True when every file compiled."""
    import compileall

    return all(compileall.compile_dir(ROOT / name, quiet=1, workers=0) for name in PACKAGES)


def _env() -> dict[str, str]:
    """The subprocess imports this checkout's avs_planner, whatever is installed."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [env.get("PYTHONPATH")])])
    return env


def timed_process(command: list[str], kill_s: float) -> tuple[float, int | None, str, str]:
    """(wall seconds, exit code or None when killed, stdout, stderr) of one new process,
    killed with its process group at `kill_s`."""
    start = time.perf_counter()
    proc = subprocess.Popen(command, cwd=ROOT, env=_env(), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=kill_s)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
        return time.perf_counter() - start, None, out, err
    return time.perf_counter() - start, proc.returncode, out, err


def run_ours(case: Case, timeout_s: float) -> OursRun:
    command = [sys.executable, "-m", "avs_planner", "plan", str(case.domain),
               str(case.problem), "--timeout", f"{timeout_s:g}"]
    wall, code, out, err = timed_process(command, timeout_s + GRACE_S)
    if code is None:
        return OursRun("killed", wall, message=f"killed at {timeout_s + GRACE_S:g} s")
    status = EXIT_STATUS.get(code, f"exit {code}")
    if status == "solved":
        return OursRun(status, wall, parse_plan(out), stopped_by(out))
    lines = (err or out).strip().splitlines() or [""]
    return OursRun(status, wall, message=lines[-1][:120])


class Validator:
    """UP's sequential plan validator on the problem of an instance's files, read once."""

    def __init__(self) -> None:
        from unified_planning.shortcuts import get_environment

        get_environment().credits_stream = None
        self._problems: dict[tuple[Path, Path], tuple[object, str]] = {}

    def problem(self, case: Case) -> tuple[object, str]:
        """(UP problem, which reader built it)."""
        key = (case.domain, case.problem)
        if key not in self._problems:
            from unified_planning.io import PDDLReader

            try:
                read = PDDLReader().parse_problem(str(case.domain), str(case.problem)), "up"
            except Exception:  # noqa: BLE001 - UP's grammar rejects it: the lenient reader
                from avs_planner.pddl import read_files

                read = read_files(str(case.domain), str(case.problem)).problem, "avs"
            self._problems[key] = read
        return self._problems[key]

    def check(self, case: Case, steps: tuple[Step, ...]) -> tuple[bool, float | None, str]:
        """(VALID?, the plan's cost by the problem's metric, a reason when not valid)."""
        from unified_planning.engines.plan_validator import SequentialPlanValidator
        from unified_planning.plans import ActionInstance, SequentialPlan

        problem, _ = self.problem(case)
        actions = {a.name.lower(): a for a in problem.actions}
        objects = {o.name.lower(): o for o in problem.all_objects}
        try:
            plan = SequentialPlan([ActionInstance(actions[name.lower()],
                                                  [objects[a.lower()] for a in args])
                                   for name, args in steps], problem.environment)
        except KeyError as exc:
            return False, None, f"unknown name {exc}"
        validator = SequentialPlanValidator()
        validator.skip_checks = True  # elevators' partially defined costs trip the kind check
        result = validator.validate(problem, plan)
        if result.status.name != "VALID":
            return False, None, str(result.reason.name if result.reason else result.status.name)
        costs = [v for v in (result.metric_evaluations or {}).values()]
        cost = float(Fraction(costs[0])) if costs else float(len(steps))
        return True, cost, ""


def bench_case(case: Case, timeout_s: float, validator: Validator) -> dict:
    ours = run_ours(case, timeout_s)
    fd = run_fd(case.domain, case.problem, timeout_s + GRACE_S)
    _, reader = validator.problem(case)
    row = {"label": case.label, "domain": str(case.domain.relative_to(case.domain.parents[1])),
           "ours_s": ours.wall_s, "ours_status": ours.status, "ours_stopped_by": ours.stopped_by,
           "ours_message": ours.message, "ours_steps": len(ours.plan),
           "fd_s": fd.wall_s, "fd_own_s": fd.own_s if fd.solved else None,
           "fd_status": "solved" if fd.solved else "timeout" if fd.timed_out else "failed",
           "fd_steps": len(fd.plan), "validated_on": reader}
    for side, steps, solved in (("ours", ours.plan, ours.status == "solved"),
                                ("fd", fd.plan, fd.solved)):
        if solved:
            ok, cost, why = validator.check(case, steps)
            row.update({f"{side}_valid": ok, f"{side}_cost": cost, f"{side}_invalid": why})
        else:
            row.update({f"{side}_valid": None, f"{side}_cost": None, f"{side}_invalid": ""})
    return row


def solved(row: dict, side: str) -> bool:
    return row[f"{side}_status"] == "solved"


def summarize(rows: list[dict]) -> dict:
    """Coverage, validity (counted: a plan is valid only when checked so), and the median
    ours/FD end-to-end ratio over the instances both solved."""
    ours = [r for r in rows if solved(r, "ours")]
    fd = [r for r in rows if solved(r, "fd")]
    both = [r for r in ours if solved(r, "fd")]
    ratios = [r["ours_s"] / r["fd_s"] for r in both]
    invalid = [f"{r['label']} ({side})" for r in rows for side in ("ours", "fd")
               if solved(r, side) and r.get(f"{side}_valid") is not True]
    return {
        "instances": len(rows), "ours_solved": len(ours), "fd_solved": len(fd),
        "ours_valid": sum(r.get("ours_valid") is True for r in ours),
        "fd_valid": sum(r.get("fd_valid") is True for r in fd),
        "all_valid": not invalid, "invalid": invalid,
        "fd_only": [r["label"] for r in fd if not solved(r, "ours")],
        "ours_only": [r["label"] for r in ours if not solved(r, "fd")],
        "both": len(both),
        "median_ratio": statistics.median(ratios) if ratios else None,
        "median_ours_s": statistics.median(r["ours_s"] for r in both) if both else None,
        "median_fd_s": statistics.median(r["fd_s"] for r in both) if both else None,
        "slower": sum(x > 1 for x in ratios),
        "ours_stopped_by_timeout": sum(r.get("ours_stopped_by") == "timeout" for r in ours),
    }


def summary_lines(s: dict) -> list[str]:
    ratio = "-" if s["median_ratio"] is None else f"{s['median_ratio']:.2f}x"
    lines = [
        f"-- coverage: ours {s['ours_solved']}/{s['instances']}, lama-first "
        f"{s['fd_solved']}/{s['instances']}; FD solved and we did not: "
        f"{', '.join(s['fd_only']) or 'none'}; we solved and FD did not: "
        f"{', '.join(s['ours_only']) or 'none'}",
        f"-- plans valid (UP's validator): ours {s['ours_valid']}/{s['ours_solved']}, FD "
        f"{s['fd_valid']}/{s['fd_solved']}: "
        + ("all valid" if s["all_valid"] else f"NOT ALL VALID: {', '.join(s['invalid'])}"),
        f"-- end to end, ours/FD, median over the {s['both']} both solved: {ratio} "
        f"(above 1: ours slower; slower on {s['slower']} of {s['both']}); median wall "
        + ("-" if s["median_ours_s"] is None else
           f"ours {s['median_ours_s']:.2f} s, FD {s['median_fd_s']:.2f} s"),
    ]
    if s["ours_stopped_by_timeout"]:
        lines.append(f"-- ours returned its best plan at --timeout on "
                     f"{s['ours_stopped_by_timeout']} (the anytime mode's restarts ran out "
                     f"of time)")
    return lines


def startup(runs: int) -> dict[str, float | None]:
    """Median whole-process seconds: `avs --help`, `avs plan` on corridor, FD's `--help`."""
    def median_of(command: list[str]) -> float | None:
        walls = []
        for _ in range(runs):
            wall, code, _, err = timed_process(command, 120.0)
            if code != 0:
                print(f"start-up run failed ({' '.join(command[1:])}): {err.strip()[-200:]}")
                return None
            walls.append(wall)
        return statistics.median(walls)

    avs = [sys.executable, "-m", "avs_planner"]
    script = driver()
    return {"avs_help_s": median_of([*avs, "--help"]),
            "avs_plan_corridor_s": median_of([*avs, "plan", *CORRIDOR]),
            "fd_help_s": median_of([sys.executable, str(script), "--help"]) if script else None}


def _git(*args: str) -> str:
    out = subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True)
    return out.stdout.strip()


def _fmt(value, spec: str) -> str:
    """`value` by `spec`; "-" for none, as wide as the spec's width."""
    if value is None:
        width = "".join(c for c in spec.split(".")[0] if c.isdigit())
        return "-".rjust(int(width or 0))
    return format(value, spec)


def _yes(value: bool | None) -> str:
    return "-" if value is None else "yes" if value else "NO"


def print_row(r: dict) -> None:
    ratio = r["ours_s"] / r["fd_s"] if solved(r, "ours") and solved(r, "fd") else None
    print(f"{r['label']:28} {r['ours_s']:7.2f} {r['fd_s']:7.2f} {_fmt(r['fd_own_s'], '7.2f')} "
          f"{_fmt(ratio, '6.2f')} {r['ours_status']:>9} {r['fd_status']:>8} "
          f"{_fmt(r['ours_cost'], '7g')} {_fmt(r['fd_cost'], '7g')} "
          f"{_yes(r['ours_valid']):>5} {_yes(r['fd_valid']):>5}"
          + (f"  [{r['ours_stopped_by']}]" if r["ours_stopped_by"] else "")
          + (f"  ours: {r['ours_message']}" if r["ours_message"] else ""), flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="instance 1 only, 3 start-up runs")
    parser.add_argument("--timeout", type=float, default=TIMEOUT_S,
                        help=f"avs plan --timeout (default {TIMEOUT_S:g}); both sides are "
                             f"killed {GRACE_S:g} s later")
    parser.add_argument("--instances", type=parse_instances, default=None,
                        help="instance numbers, e.g. 1-3 or 1,4 (default 1-3; --quick: 1)")
    parser.add_argument("--domains", default="", help="IPC domains, comma-separated (all)")
    parser.add_argument("--out", type=Path, default=None,
                        help="results file (default bench/results/e2e-<date>-<commit>.json)")
    args = parser.parse_args()
    if driver() is None:
        raise SystemExit("up-fast-downward is not installed (pip install 'up-fast-downward>=0.4',"
                         " the project's bench extra)")
    numbers = args.instances or ((1,) if args.quick else (1, 2, 3))
    domains = tuple(d.strip() for d in args.domains.split(",") if d.strip())
    cases = ipc_cases(False, domains=domains, numbers=numbers)
    cases.sort(key=lambda c: int(c.problem.stem.split("-")[1]))  # instance 1 of all first
    commit = _git("rev-parse", "--short", "HEAD") + ("-dirty" if _git("status", "--porcelain",
                                                                      "--untracked-files=no")
                                                     else "")
    date = datetime.date.today().isoformat()
    out = args.out or RESULTS / f"e2e-{date}-{commit}.json"
    compiled = compile_checkout()
    meta = {"date": date, "commit": commit, "timeout_s": args.timeout, "grace_s": GRACE_S,
            "bytecode": "compiled before timing" if compiled else "compiling failed",
            "instances": list(numbers), "cpus": os.cpu_count(), "python": platform.python_version(),
            "ours": "python -m avs_planner plan DOMAIN PROBLEM --timeout S (defaults otherwise)",
            "fd": "fast-downward.py --alias lama-first (bench/fd_runner.py)"}
    print(f"{len(cases)} IPC instances ({', '.join(map(str, numbers))} of each domain), one run "
          f"each side, each a new process; ours: avs plan --timeout {args.timeout:g}; FD: "
          f"lama-first; both killed at {args.timeout + GRACE_S:g} s; commit {commit}, {date}")
    print(f"{'instance':28} {'ours s':>7} {'FD e2e':>7} {'FD own':>7} {'o/FD':>6} "
          f"{'ours':>9} {'FD':>8} {'cost':>7} {'FD cost':>7} {'valid':>5} {'FDval':>5}")
    validator = Validator()
    rows: list[dict] = []
    for case in cases:
        rows.append(bench_case(case, args.timeout, validator))
        print_row(rows[-1])
        _write(out, meta, rows, None, None)  # a run stopped early keeps its rows
    result = summarize(rows)
    for line in summary_lines(result):
        print(line)
    times = startup(3 if args.quick else STARTUP_RUNS)
    runs = 3 if args.quick else STARTUP_RUNS
    print(f"-- start-up, median of {runs} whole-process runs: avs --help "
          f"{_fmt(times['avs_help_s'], '.3f')} s, avs plan corridor "
          f"{_fmt(times['avs_plan_corridor_s'], '.3f')} s; FD's driver --help "
          f"{_fmt(times['fd_help_s'], '.3f')} s"
          + (f" (avs --help / FD --help {times['avs_help_s'] / times['fd_help_s']:.2f}x)"
             if times["avs_help_s"] and times["fd_help_s"] else ""))
    print("-- reading vs FD's translator: python -m bench.reading_bench [--quick]")
    _write(out, meta, rows, result, times)
    print(f"-- rows and summary: {out.relative_to(ROOT) if out.is_relative_to(ROOT) else out}")


def _write(path: Path, meta: dict, rows: list[dict], result: dict | None,
           times: dict | None) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps({"meta": meta, "summary": result, "startup": times,
                                "rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
