"""The QSR paper's simulated experiments (Tables II and III) on our desk scenes.

The paper: "Indirect Object Search based on Qualitative Spatial Relations" (Kunze et al.).

Two scenes (`--scene`): `kitchen` (default, `sim/worlds/qsr_kitchen_{a,b,c}.yaml`), like the
QSR paper's (the TUM kitchen of MORSE): four desks with monitors and keyboards, and as much other
supporting surface no QSR points at (counters, a dining table, a meeting table, a sideboard);
and `desks` (`sim/worlds/qsr_desks_{a,b,c}.yaml`), four desks and nothing else, three of them
with a cup (there uniform over the supporting planes is nearly the QSR density, and the two
informed methods tie). Variant A: three cups where the default QSR knowledge says cups
are; B: two of them removed; C: the remaining one moved to a non-QSR location. Table II runs the
three methods (`random`, `supporting-planes`, `qsr`) on A; Table III runs `qsr` on A, B and C.
Every cell is `--trials` searches for a cup (seeds 0..N-1) through
`avs_planner.harness.run_episode`, learning switched off so that trials are independent.

As in the QSR paper, time and poses are means over the successful trials only; "found" counts
searches that ended with a confirmed cup that is a cup in the world. Time is the search
monitor's time (simulated seconds after the survey, which stands in for the QSR paper's given maps
and landmark poses); the survey's own time is printed beside it.
"±" is the half-width of a normal 95% confidence interval of the mean (over successful trials).
Table II ends with the ordering check of the issue: qsr < supporting-planes < random in mean
poses and in mean time, and whether the 95% intervals are disjoint.
Run: `python -m bench.qsr_experiment [--scene kitchen|desks] [--trials 10] [--tables II,III]
[--option KEY=VALUE] [--json FILE]`.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import time
from typing import Any

import numpy as np

from avs_planner.harness import run_episode

TABLE_II = {"random": (6, 68.5, 4.8), "supporting-planes": (10, 33.6, 2.3),
            "qsr": (10, 15.6, 1.1)}  # fmt: skip
TABLE_III = {"A": (10, 15.6, 1.1), "B": (8, 55.0, 3.1), "C": (6, 65.0, 3.2)}
SEED_TRIALS = 10


SCENES = ("kitchen", "desks")


def run_cell(method: str, variant: str, trials: int, options: dict[str, Any],
             scene: str = "kitchen") -> list[dict[str, Any]]:  # fmt: skip
    out = []
    for seed in range(trials):
        summary = run_episode({
            "target": "cup", "world": f"qsr_{scene}_{variant.lower()}", "strategy": method,
            "seed": seed, "strategy_options": {"learn": False, **options},
        })  # fmt: skip
        d = summary["details"]
        out.append({"seed": seed, "outcome": summary["outcome"], "correct": summary["correct"],
                    "search_time_s": d["search_time_s"], "survey_time_s": d["survey_time_s"],
                    "poses": d["poses"], "views": summary["views_processed"],
                    "landmarks": len(d["landmarks"]), "wall_s": summary["wall_time_s"]})
    return out


def stats(runs: list[dict[str, Any]]) -> dict[str, Any]:
    ok = [r for r in runs if r["outcome"] == "found" and r["correct"]]

    def mean(key: str, rows: list[dict[str, Any]]) -> float | None:
        return statistics.fmean(r[key] for r in rows) if rows else None

    def ci(key: str, rows: list[dict[str, Any]]) -> float | None:
        """Half-width of a normal 95% confidence interval of the mean."""
        if len(rows) < 2:
            return None
        return 1.96 * statistics.stdev(r[key] for r in rows) / math.sqrt(len(rows))

    return {"found": len(ok), "trials": len(runs), "time": mean("search_time_s", ok),
            "poses": mean("poses", ok), "survey": mean("survey_time_s", runs),
            "time_ci": ci("search_time_s", ok), "poses_ci": ci("poses", ok),
            "wrong": sum(r["outcome"] == "found" and not r["correct"] for r in runs),
            "wall": mean("wall_s", runs)}


def _fmt(value: float | None, digits: int = 1) -> str:
    return "-" if value is None else f"{value:.{digits}f}"


def print_table(title: str, rows: list[tuple[str, dict[str, Any], tuple[int, float, float]]]
                ) -> None:  # fmt: skip
    print(title)
    print(f"{'':<22} {'found':>7} {'time s':>13} {'poses':>12} | {'paper found':>11} "
          f"{'time s':>7} {'poses':>6} | {'survey s':>8} {'wrong':>5}")
    for name, s, (f, t, p) in rows:
        time_s = f"{_fmt(s['time'])} ±{_fmt(s['time_ci'])}"
        poses = f"{_fmt(s['poses'], 2)} ±{_fmt(s['poses_ci'], 2)}"
        print(f"{name:<22} {s['found']:>3}/{s['trials']:<3} {time_s:>13} {poses:>12} | "
              f"{f:>7}/{SEED_TRIALS:<3} {t:>7.1f} {p:>6.1f} | {_fmt(s['survey']):>8} "
              f"{s['wrong']:>5}")
    print()


def density_at_cups(world: str) -> dict[str, float]:
    """Where each informed method's prior density lies in variant `world`, from the world file
    (analysis only: the searches never read it): the share of the uniform density over the
    supporting tops (furniture 0.4-1.2 m high, 5 cm grid) and of the QSR density (the default
    knowledge at the true landmark poses) on supports that hold a cup, and within 0.25 m of a
    cup. A view sees a whole desk, so the first share decides how often a first view finds one."""
    from conceptual_map.qsr import build_mixture, load_qsr
    from sim.world_file import load_world_spec

    spec = load_world_spec(world)
    furniture = {f.name: f for f in spec.furniture}

    def place(obj: Any) -> tuple[float, float, float]:
        x, y, yaw = furniture[obj.on].pose
        dx, dy = obj.offset[:2]
        return (x + math.cos(yaw) * dx - math.sin(yaw) * dy,
                y + math.sin(yaw) * dx + math.cos(yaw) * dy, yaw)  # fmt: skip

    tops, holds = [], []
    for f in spec.furniture:
        if not 0.4 <= f.size[2] <= 1.2:
            continue
        lo, hi = np.min(f.footprint(), axis=0), np.max(f.footprint(), axis=0)
        xs, ys = np.meshgrid(np.arange(lo[0] + 0.025, hi[0], 0.05),
                             np.arange(lo[1] + 0.025, hi[1], 0.05))  # fmt: skip
        tops.append(np.column_stack([xs.ravel(), ys.ravel()]))
        cup = any(o.label == "cup" and o.on == f.name for o in spec.objects)
        holds.append(np.full(xs.size, cup))
    points, on_cup_support = np.vstack(tops), np.concatenate(holds)
    knowledge = load_qsr()
    marks = [knowledge.landmark(o.label, *place(o)) for o in spec.objects
             if o.on and o.label in knowledge.fronts]
    marks += [knowledge.landmark(f.label, *f.pose) for f in spec.furniture
              if f.label in knowledge.fronts]
    qsr = build_mixture(knowledge, "cup", marks, rng=0).mixture.pdf(points)
    qsr /= qsr.sum()
    uniform = np.full(len(points), 1.0 / len(points))
    cups = np.array([place(o)[:2] for o in spec.objects if o.label == "cup" and o.on])
    near = (np.linalg.norm(points[:, None, :] - cups[None, :, :], axis=2) <= 0.25).any(axis=1)
    return {"area_m2": len(points) * 0.05**2,
            "uniform_support": float(uniform[on_cup_support].sum()),
            "qsr_support": float(qsr[on_cup_support].sum()),
            "uniform_near": float(uniform[near].sum()), "qsr_near": float(qsr[near].sum())}


def ordering(table: dict[str, dict[str, Any]], variant: str = "A") -> list[str]:
    """The issue's claim, qsr < supporting-planes < random, per measure: means in order, and
    for each neighbouring pair whether their 95% intervals are disjoint."""
    names = ("qsr", "supporting-planes", "random")
    rows = [table[f"{m}/{variant}"] for m in names]
    out = []
    for key, unit in (("poses", "poses"), ("time", "s")):
        means = [r[key] for r in rows]
        if any(m is None for m in means):
            out.append(f"{key}: a method found nothing, no ordering")
            continue
        ordered = means[0] < means[1] < means[2]
        cis = [r[f"{key}_ci"] or 0.0 for r in rows]
        pairs = [f"{names[i]}/{names[i + 1]} intervals "
                 f"{'disjoint' if means[i] + cis[i] < means[i + 1] - cis[i + 1] else 'overlap'}"
                 for i in range(2)]  # fmt: skip
        text = " < ".join(f"{n} {m:.2f}±{c:.2f}" for n, m, c in zip(names, means, cis,
                                                                   strict=True))
        out.append(f"{key} ({unit}): {text}: {'holds' if ordered else 'FAILS'}; "
                   + ", ".join(pairs))
    return out


def with_failures(runs: list[dict[str, Any]], abort_s: float = 120.0) -> tuple[float, float]:
    """Mean search time and poses over all trials, a failed one counted at the monitor's
    abort time with the poses it had searched (the QSR paper's means leave failures out)."""
    ok = [r["outcome"] == "found" and r["correct"] for r in runs]
    time_s = statistics.fmean(r["search_time_s"] if good else max(abort_s, r["search_time_s"])
                              for r, good in zip(runs, ok, strict=True))  # fmt: skip
    return time_s, statistics.fmean(r["poses"] for r in runs)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=10, help="searches per cell (seeds 0..N-1)")
    parser.add_argument("--option", action="append", default=[], metavar="KEY=VALUE",
                        help="a strategy option for every run, e.g. frustums=4 (repeatable)")
    parser.add_argument("--json", help="also write every run and the tables to this file")
    parser.add_argument("--tables", default="II,III", help="which tables: II, III or II,III")
    parser.add_argument("--scene", default="kitchen", choices=SCENES,
                        help="worlds qsr_SCENE_{a,b,c} (default kitchen)")
    parser.add_argument("--from-json", metavar="FILE",
                        help="print the tables of an earlier --json run instead of running")
    args = parser.parse_args(argv)
    options = {}
    for text in args.option:
        key, _, value = text.partition("=")
        options[key] = value
    start = time.perf_counter()
    tables = {t.strip().upper() for t in args.tables.split(",")}
    cells: dict[str, list[dict[str, Any]]] = {}
    if args.from_json:
        with open(args.from_json, encoding="utf-8") as fh:
            saved = json.load(fh)
        cells, options = saved["runs"], saved["options"]
        args.scene = saved.get("scene", args.scene)
        args.trials = max(len(runs) for runs in cells.values())
        tables = {t for t, key in (("II", "random/A"), ("III", "qsr/C")) if key in cells}
    methods = ("random", "supporting-planes", "qsr") if "II" in tables else ("qsr",)
    for method in () if args.from_json else methods:
        cells[f"{method}/A"] = run_cell(method, "A", args.trials, options, args.scene)
    for variant in ("B", "C") if "III" in tables and not args.from_json else ():
        cells[f"qsr/{variant}"] = run_cell("qsr", variant, args.trials, options, args.scene)
    table = {key: stats(runs) for key, runs in cells.items()}
    print(f"QSR paper experiments, scene {args.scene}, {args.trials} trials per cell "
          f"(seeds 0..{args.trials - 1}), "
          f"options {options or 'default'}; ours beside the paper's (10 trials); time and poses "
          f"over successful trials; "
          + (f"from {args.from_json}\n" if args.from_json else
             f"wall {time.perf_counter() - start:.0f} s\n"))
    if "II" in tables:
        mass = density_at_cups(f"qsr_{args.scene}_a")
        table["density_at_cups"] = mass
        print(f"prior density in variant A ({mass['area_m2']:.1f} m2 of supporting tops): on "
              f"supports holding a cup uniform {mass['uniform_support']:.2f}, qsr "
              f"{mass['qsr_support']:.2f}; within 0.25 m of a cup uniform "
              f"{mass['uniform_near']:.3f}, qsr {mass['qsr_near']:.3f}\n")
        print_table("Table II: search methods, variant A",
                    [(m, table[f"{m}/A"], TABLE_II[m]) for m in ("random", "supporting-planes",
                                                                 "qsr")])
        print("ordering qsr < supporting-planes < random (means over successful trials, 95% "
              "intervals):")
        for line in ordering(table):
            print(f"  {line}")
        print("all trials, a failure counted at the 120 s abort: " + "; ".join(
            "{} {:.1f} s, {:.2f} poses".format(m, *with_failures(cells[f"{m}/A"]))
            for m in ("qsr", "supporting-planes", "random")))
        print()
    if "III" in tables:
        print_table("Table III: qsr under false beliefs",
                    [(f"{v} ({w})", table[f"qsr/{v}"], TABLE_III[v]) for v, w in
                     (("A", "correct QSRs"), ("B", "partially correct"), ("C", "wrong QSRs"))])
    if args.json and not args.from_json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump({"scene": args.scene, "options": options, "tables": table, "runs": cells},
                      fh, indent=1)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
