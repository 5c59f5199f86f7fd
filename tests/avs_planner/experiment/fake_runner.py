"""Stand-in episode runners for the campaign tests (loaded by file path in worker processes).

Each writes a summary.json like the real runner's, derived from the spec only, and appends
the run to `executions.log` beside the output's runs/ folder, so a test can count re-runs.
"""

from __future__ import annotations

import json
import os
import signal
import time
from pathlib import Path
from typing import Any


def summary(spec: dict[str, Any], emit: Any = None, should_stop: Any = None) -> dict[str, Any]:
    out = Path(spec["output_dir"])
    with (out.parent.parent / "executions.log").open("a", encoding="utf-8") as log:
        log.write(f"{out.name}\n")
    found = "no_tables" not in str(spec.get("world"))  # scenario e's world has no cereal box
    result = {
        "outcome": "found" if found else "gave_up", "reason": "fake", "target": spec["target"],
        "object": {"label": spec["target"]} if found else None, "correct": found,
        "sim_time_s": 100.0 + spec["seed"], "distance_m": 10.0, "plans": 3, "replans": 2,
        "cp_time_s": [0.01, 0.03], "dt_calls": 1, "dt_decision_time_s": [0.5],
        "views_processed": 4, "seed": spec["seed"], "world": spec.get("world"),
    }
    (out / "summary.json").write_text(json.dumps(result), encoding="utf-8")
    (out / "trace.jsonl").write_text('{"type": "done"}\n', encoding="utf-8")
    return result


def crash_on_seed_1(spec: dict[str, Any], emit: Any = None, should_stop: Any = None
                    ) -> dict[str, Any]:
    if spec["seed"] == 1:
        os.kill(os.getpid(), signal.SIGKILL)
    return summary(spec)


def raise_on_seed_1(spec: dict[str, Any], emit: Any = None, should_stop: Any = None
                    ) -> dict[str, Any]:
    if spec["seed"] == 1:
        raise RuntimeError("the planner fell over")
    return summary(spec)


def hang_on_seed_1(spec: dict[str, Any], emit: Any = None, should_stop: Any = None
                   ) -> dict[str, Any]:
    if spec["seed"] == 1:
        time.sleep(60)
    return summary(spec)


def crash_1_raise_2_hang_3(spec: dict[str, Any], emit: Any = None, should_stop: Any = None
                           ) -> dict[str, Any]:
    if spec["seed"] == 2:
        raise RuntimeError("the planner fell over")
    if spec["seed"] == 3:
        time.sleep(60)
    return crash_on_seed_1(spec)


def wall_cut_on_seed_1(spec: dict[str, Any], emit: Any = None, should_stop: Any = None
                       ) -> dict[str, Any]:
    """Seed 1 ends as the episode loop does when its wall-clock budget runs out."""
    result = summary(spec)
    if spec["seed"] == 1:
        result.update(outcome="timeout", reason="wall time budget 300 s spent", object=None,
                      correct=False)
    return result


def with_scores(spec: dict[str, Any], emit: Any = None, should_stop: Any = None
                ) -> dict[str, Any]:
    """Seed 0 carries map-quality scores and the DT's verdicts; other seeds do not."""
    result = summary(spec)
    if spec["seed"] == 0:
        result.update(map_score={"rooms_true": 6, "rooms_matched": 5, "merges": 1,
                                 "splits": 0, "category_accuracy": 0.75,
                                 "entered_area_m2": 40.5, "extra": "ignored"},
                      dt_confirmed=1, dt_rejected=[{"label": "table"}, {"label": "desk"}])
    return result


def tasks(spec: dict[str, Any], emit: Any = None, should_stop: Any = None) -> dict[str, Any]:
    """A single search as `summary`; a task (`targets` in the spec) ends with every label
    found once (its part ended 10 s apart, a cup report naming the wrong object), in the sum
    of the singles' times less 10%."""
    if "targets" not in spec:
        return summary(spec)
    labels = spec["targets"]
    result = summary({**spec, "target": labels[0]})
    result.update(target=" and ".join(labels), correct="cup" not in labels,
                  sim_time_s=0.9 * len(labels) * (100.0 + spec["seed"]),
                  task={k: spec[k] for k in ("targets", "mode", "count") if k in spec},
                  targets=[{"label": label, "outcome": "found", "reason": "fake",
                            "objects": [{"label": label, "truth": f"{label}1",
                                         "correct": label != "cup"}],
                            "sim_time_s": 10.0 * (i + 1), "turns": 1, "instances": 2,
                            "distinct": int(label != "cup"), "correct": label != "cup"}
                           for i, label in enumerate(labels)])
    Path(spec["output_dir"], "summary.json").write_text(json.dumps(result), encoding="utf-8")
    return result


def remembering(spec: dict[str, Any], emit: Any = None, should_stop: Any = None
                ) -> dict[str, Any]:
    """A stand-in for an episode with the building memory: it notes which days' files its
    memory held at the start (`memory_seen` in the summary) and adds its own day's."""
    seen: list[str] = []
    if spec.get("memory"):
        memory = Path(spec["memory"])
        seen = sorted(p.name for p in memory.iterdir()) if memory.is_dir() else []
        memory.mkdir(parents=True, exist_ok=True)
        (memory / f"day{spec['generate']['day']}").write_text("seen\n", encoding="utf-8")
    result = {**summary(spec), "memory_seen": seen, "since_s": spec.get("since_s")}
    (Path(spec["output_dir"]) / "summary.json").write_text(json.dumps(result), encoding="utf-8")
    return result
