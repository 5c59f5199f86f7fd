"""Building-scale benchmark: reading and planning generated AVS problems of 160 and 320 places
(8 object labels, the bench family) and of 160 places with 12 labels.

Run: `.venv/bin/python -m bench.scale_bench [--quick] [--runs N]`. Each (size, seed) is read
and planned in a fresh process, `runs` times (default 3), with the continual planner's
settings for these problems (weighted A*, w = 2, FF, R = 500: what `bench/cp_bench.py` uses);
the table gives the median of the runs: reading (`read_text` of domain and problem), planning
(grounding, packing and search), both together, and the expansions. Side by side, measured in
the same run: the ratio to the target (1 s for reading and planning, the planner issue's
building-scale target) and, per seed, the growth from 160 to 320 places (the same generator
and seed; what grounding's cost grows by when the building doubles). Fast Downward cannot read
these files (`:probabilistic-effects`), so no FD column: `bench/cp_bench.py --building` gives
FD a deterministic compilation up to 160 places instead.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
DOMAIN = ROOT / "domains" / "avs" / "domain.pddl"
TARGET_S = 1.0
SIZES = ((160, 8), (320, 8), (160, 12))  # (places, labels)
SEEDS = (0, 1, 2)

# one run in a fresh interpreter: generate the problem text, then time reading and planning
_CHILD = """
import json, sys, time
from pathlib import Path
from bench.avs_generator import AvsSize, generate
from avs_planner.cp.planner import plan
from avs_planner.cp.search_options import SearchOptions
from avs_planner.pddl import read_text
places, labels, seed = (int(x) for x in sys.argv[1:4])
text = generate(AvsSize(places, places // 5, places // 5, labels), seed)
domain = Path(sys.argv[4]).read_text()
t0 = time.perf_counter()
problem = read_text(domain, text)
t1 = time.perf_counter()
result = plan(problem, SearchOptions(reward=500, weight=2, heuristic="ff"))
t2 = time.perf_counter()
print(json.dumps({"read": t1 - t0, "plan": t2 - t1, "status": result.status.value,
                  "expanded": result.expanded}))
"""


def run_once(places: int, labels: int, seed: int) -> dict:
    out = subprocess.run(
        [sys.executable, "-c", _CHILD, str(places), str(labels), str(seed), str(DOMAIN)],
        capture_output=True, text=True, cwd=ROOT, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"{places} places, {labels} labels, seed {seed}: "
                           f"{out.stderr.strip().splitlines()[-1:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def measure(places: int, labels: int, seed: int, runs: int) -> dict:
    rows = [run_once(places, labels, seed) for _ in range(runs)]
    med = {k: statistics.median(r[k] for r in rows) for k in ("read", "plan")}
    med["total"] = statistics.median(r["read"] + r["plan"] for r in rows)
    med["expanded"] = rows[0]["expanded"]
    med["status"] = rows[0]["status"]
    return med


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="seed 0 only, one run each")
    parser.add_argument("--runs", type=int, default=3, help="fresh processes per problem")
    args = parser.parse_args(argv)
    runs, seeds = (1, SEEDS[:1]) if args.quick else (max(1, args.runs), SEEDS)
    print(f"read + plan in a fresh process, median of {runs}; target {TARGET_S:g} s")
    print(f"{'places':>6} {'labels':>6} {'seed':>4} {'read s':>7} {'plan s':>7} {'total s':>7} "
          f"{'/target':>7} {'expanded':>8} {'status':>8}")
    results: dict[tuple[int, int, int], dict] = {}
    for places, labels in SIZES:
        for seed in seeds:
            m = results[(places, labels, seed)] = measure(places, labels, seed, runs)
            print(f"{places:>6} {labels:>6} {seed:>4} {m['read']:>7.2f} {m['plan']:>7.2f} "
                  f"{m['total']:>7.2f} {m['total'] / TARGET_S:>7.2f} {m['expanded']:>8} "
                  f"{m['status']:>8}", flush=True)
    print()
    for places, labels in SIZES:
        totals = [results[(places, labels, s)]["total"] for s in seeds]
        print(f"{places} places, {labels} labels: median over seeds "
              f"{statistics.median(totals):.2f} s ({statistics.median(totals) / TARGET_S:.2f}x "
              f"the target)")
    growth = [results[(320, 8, s)]["total"] / results[(160, 8, s)]["total"] for s in seeds]
    print("320 / 160 places (8 labels), per seed: "
          + ", ".join(f"{g:.2f}x" for g in growth))
    return 0


if __name__ == "__main__":
    sys.exit(main())
