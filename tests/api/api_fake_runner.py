"""An injected episode runner for testing the task machinery (queueing, events, cancel,
persistence) without the real switching loop. Its behaviour is chosen by the task's target label
(the first of `targets`); it is loaded by file path in the worker process (see
`api.worker_process.resolve`)."""

from __future__ import annotations

import struct
import time
import zlib
from pathlib import Path
from typing import Any

RUNNER = f"{Path(__file__).resolve()}:run"


def _png_1x1() -> bytes:
    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", 1, 1, 8, 2, 0, 0, 0)
    pixels = zlib.compress(b"\x00\xff\x00\x00")
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", pixels) + chunk(
        b"IEND", b""
    )


def run(spec: dict[str, Any], emit: Any, should_stop: Any) -> dict[str, Any]:
    behaviour = spec["target"] if "target" in spec else spec["targets"][0]
    for i in range(3):
        emit({"t": float(i), "wall": 0.0, "type": "action", "step": i})
    if behaviour == "quick":
        Path(spec["output_dir"], "trajectory.png").write_bytes(_png_1x1())
        return {"outcome": "found", "target": spec["target"], "seed": spec["seed"]}
    if behaviour == "hopeless":
        return {"outcome": "gave_up", "target": spec["target"]}
    if behaviour == "explained":  # a switching episode's trace and its explanation.json
        return _explained(spec, emit)
    if behaviour == "boom":
        raise RuntimeError("runner exploded on purpose")
    if behaviour == "hog":
        blocks = [bytearray(64 * 1024 * 1024) for _ in range(64)]
        return {"outcome": "found", "blocks": len(blocks)}
    if behaviour == "stubborn":  # ignores should_stop: must be killed
        time.sleep(60)
    if behaviour == "slow":
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            if should_stop():
                return {"outcome": "gave_up", "stopped": True}
            time.sleep(0.02)
    if behaviour == "stint":  # 0.8 s of work, with when it ran (building serialisation tests)
        started = time.time()
        deadline = time.monotonic() + 0.8
        while time.monotonic() < deadline and not should_stop():
            time.sleep(0.02)
        return {"outcome": "found", "started": started, "ended": time.time(), "spec": spec}
    if behaviour == "echo":  # what the episode runner was given
        return {"outcome": "found", "spec": spec}
    if behaviour == "parts":  # a task of several, summarised as the real runner does
        return _parts(spec)
    if behaviour == "drip":  # an event every 0.05 s until stopped (storage fault tests)
        deadline = time.monotonic() + 30
        step = 3
        while time.monotonic() < deadline and not should_stop():
            emit({"t": float(step), "wall": 0.0, "type": "observation", "step": step})
            step += 1
            time.sleep(0.05)
        return {"outcome": "gave_up", "stopped": True}
    if behaviour == "ticker":  # a steady stream of events, for the SSE tests
        for i in range(20):
            emit({"t": float(3 + i), "wall": 0.0, "type": "observation", "step": 3 + i})
            time.sleep(0.01)
        return {"outcome": "found"}
    return {"outcome": "nonsense"}


def _explained(spec: dict[str, Any], emit: Any) -> dict[str, Any]:
    """Writes trace.jsonl as the real runner does, from a hand-made give-up: one room
    hypothesis, refuted when its placeholder was explored. No explanation.json: the service
    rebuilds the explanation from the trace, and the worker stays light (importing the
    episode package in a niced worker took over 20 s on a loaded machine)."""
    import json

    assume = "(assume-leads-to-room placeholder3 kitchen new-room1)"
    events = [
        {"t": 0.0, "type": "start", "target": "explained", "world": "office",
         "strategy": "switching", "seed": 0},
        {"t": 1.0, "type": "plan", "why": "initial", "status": "solved",
         "plan": [assume, "(move place1 placeholder3)"], "step_p": [0.3, 1.0],
         "assumptive": [0], "probability": 0.3},
        {"t": 9.0, "type": "action", "action": "(move place1 placeholder3)", "status": "done",
         "detail": "explored on the way"},
        {"t": 9.0, "type": "monitor", "verdict": "assumption_contradicted", "confirmed": [],
         "assumptions": {assume: 0.0}},
        {"t": 9.0, "type": "replan", "status": "assumption_contradicted", "action": assume,
         "detail": "no longer possible (unreachable or probability 0)"},
        {"t": 9.0, "type": "plan", "why": "replan", "status": "unsolvable", "plan": [],
         "probability": 0.0},
        {"t": 9.0, "type": "done", "outcome": "gave_up", "reason": "no plan"},
    ]
    out = Path(spec["output_dir"])
    with (out / "trace.jsonl").open("w", encoding="utf-8") as trace:
        for event in events:
            trace.write(json.dumps(event) + "\n")
            emit(event)
    if spec.get("record"):  # the real runner writes a Rerun recording
        (out / "recording.rrd").write_bytes(b"RRF2-not-a-real-recording")
    return {"outcome": "gave_up", "target": spec["target"]}


def _parts(spec: dict[str, Any]) -> dict[str, Any]:
    """The summary of a task of several: the first label found, the second given up, any
    others not needed (the shape of `Episode.summary`'s `task` and `targets`)."""
    labels = spec["targets"]
    found = {"id": "object2", "label": labels[0], "position": [1.442, 7.58, 0.893],
             "room": "room1", "truth": f"{labels[0]}1", "correct": True}
    parts = [{"label": labels[0], "outcome": "found", "reason": f"{labels[0]} at (1.44, 7.58, "
              f"0.89) in room1", "objects": [found], "sim_time_s": 58.69, "turns": 1,
              "instances": 2, "distinct": 1, "correct": True}]
    if len(labels) > 1:
        parts.append({"label": labels[1], "outcome": "gave_up", "reason": "no plan reaches "
                      "the success threshold", "objects": [], "sim_time_s": 208.32,
                      "turns": 2, "instances": 0, "distinct": 0, "correct": True})
    parts += [{"label": label, "outcome": "not_needed", "reason": "", "objects": [],
               "sim_time_s": None, "turns": 0, "instances": 1, "distinct": 0, "correct": True}
              for label in labels[2:]]
    task = {"targets": labels, "mode": spec.get("mode", "all"),
            "count": spec.get("count", "one")}
    return {"outcome": "gave_up", "reason": "; ".join(f"{p['label']}: {p['outcome']}"
                                                      for p in parts),
            "target": " and ".join(labels), "object": found, "correct": True, "task": task,
            "targets": parts, "sim_time_s": 208.32, "seed": spec.get("seed", 0)}
