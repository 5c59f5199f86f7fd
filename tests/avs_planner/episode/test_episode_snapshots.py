"""Map snapshots in the trace: `map` events carry what a viewer draws, `cones` the view cones."""

from __future__ import annotations

import base64
import json
import struct
import zlib
from pathlib import Path
from typing import Any

import numpy as np

from avs_planner.episode.landmarks import landmark_labels
from avs_planner.harness.runner import run_episode
from avs_planner.harness.scenarios import load_scenario
from avs_planner.reporting.snapshots import MapSnapshots, coarsen, png_grey
from conceptual_map.knowledge import load_knowledge
from conceptual_map.metric import CellState


def _decode_png(data: bytes) -> np.ndarray:
    """The pixels of an 8-bit greyscale PNG written by `png_grey` (filter 0 rows)."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, size = 8, b"", (0, 0)
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])
        assert crc == zlib.crc32(kind + body)
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert (depth, colour) == (8, 0)
            size = (height, width)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = np.frombuffer(zlib.decompress(idat), dtype=np.uint8).reshape(size[0], size[1] + 1)
    assert not raw[:, 0].any()
    return raw[:, 1:]


def test_png_round_trip() -> None:
    image = np.array([[0, 128, 255], [255, 255, 0]], dtype=np.uint8)
    assert (_decode_png(png_grey(image)) == image).all()


def test_coarsen_keeps_thin_walls_and_free_space() -> None:
    states = np.full((5, 4), CellState.UNKNOWN, dtype=np.uint8)
    states[0, 0] = CellState.FREE
    states[2:4, 0:2] = CellState.FREE
    states[3, 1] = CellState.OCCUPIED  # one wall cell among free ones
    out = coarsen(states, 2)
    assert out.shape == (3, 2)  # padded with unknown
    assert out[0, 0] == CellState.FREE
    assert out[1, 0] == CellState.OCCUPIED
    assert out[2, 1] == CellState.UNKNOWN
    assert (coarsen(states, 1) == states).all()


def _events(tmp_path: Path) -> list[dict[str, Any]]:
    spec = load_scenario("a").episode_spec(seed=1)
    summary = run_episode({**spec, "output_dir": str(tmp_path)})
    assert summary["outcome"] == "found"
    lines = (tmp_path / "trace.jsonl").read_text().splitlines()
    return [json.loads(line) for line in lines]


def test_the_trace_carries_map_snapshots(tmp_path: Path) -> None:
    events = _events(tmp_path)
    kinds = [e["type"] for e in events]
    assert kinds[0] == "start" and kinds[1] == "map"
    # every completed step is followed by a snapshot of the map it left
    for i, event in enumerate(events):
        if event["type"] == "action" and event.get("status") not in (None, "start"):
            assert kinds[i + 1] == "map", (i, event)
    maps = [e for e in events if e["type"] == "map"]
    assert kinds[-1] == "done" and "map" in kinds[kinds.index("done") - 3:]
    # parts are left out when unchanged: a reader keeping the last value of each has them all
    state: dict[str, Any] = {}
    path: list[list[float]] = []
    for m in maps:
        state.update({k: v for k, v in m.items() if k not in ("path", "path_from")})
        if "path" in m:
            assert m["path_from"] == len(path)
            path.extend(m["path"])
    assert path, "the robot drove"
    assert state["pose"][:2] == path[-1]
    assert {p[0] for p in state["places"]} and all(p[3] for p in state["places"])
    assert set(state["rooms"]) == {p[3] for p in state["places"]}
    for beliefs in state["rooms"].values():
        ps = list(beliefs.values())
        assert ps == sorted(ps, reverse=True) and sum(ps) <= 1.0 + 1e-6
    # the target, and supports and room landmarks (furniture) seen on the way
    labels = [o[1] for o in state["objects"]]
    furniture = set(landmark_labels(load_knowledge(), []))
    assert labels.count("cerealbox") == 1 and set(labels) <= {"cerealbox", "counter", "table",
                                                               "shelf", "cupboard"} | furniture
    grid = state["grid"]
    image = _decode_png(base64.b64decode(grid["png"]))
    assert image.shape == (grid["size"][1], grid["size"][0])
    assert grid["resolution"] == 0.1
    assert {0, 128, 255} <= set(np.unique(image).tolist())
    # the robot's last position lies on free space of the snapshot's grid
    x, y = state["pose"][:2]
    col = int((x - grid["origin"][0]) / grid["resolution"])
    row = grid["size"][1] - 1 - int((y - grid["origin"][1]) / grid["resolution"])
    assert image[row, col] == 255
    # grids are sent only when they changed since the last one sent (a grid may come back to
    # how it looked earlier: a cell seen free, then occupied, then free again)
    grids = [m["grid"]["png"] for m in maps if "grid" in m]
    assert len(grids) < len(maps)
    assert all(a != b for a, b in zip(grids[:-1], grids[1:], strict=True))


def test_view_cones_are_sent_once_when_made(corridor) -> None:  # noqa: ANN001
    mind, _builder, executor = corridor
    sent: list[tuple[str, dict[str, Any]]] = []
    snapshots = MapSnapshots(executor, lambda kind, **fields: sent.append((kind, fields)))
    room = next(iter(mind.place_map.rooms))
    executor.create_cones("cerealbox", "in", room, 0.5)
    snapshots.observe({"type": "action", "action": "createviewcones", "t": 1.0})
    cones = [f for kind, f in sent if kind == "cones"]
    assert len(cones) == 1 and cones[0]["location"] == room
    made = executor.cones[("cerealbox", "in", room)]
    assert len(cones[0]["cones"]) == len(made.cones) > 0
    assert sum(c[3] for c in cones[0]["cones"]) <= 0.5 + 1e-6
    snapshots.observe({"type": "action", "action": "createviewcones", "t": 2.0})
    assert len([k for k, _ in sent if k == "cones"]) == 1  # nothing new was made


def test_snapshots_while_driving_are_rate_limited(corridor) -> None:  # noqa: ANN001
    _mind, _builder, executor = corridor
    sent: list[str] = []
    snapshots = MapSnapshots(executor, lambda kind, **fields: sent.append(kind), interval_s=3.0)
    now = executor.robot.clock  # events carry the robot's clock
    snapshots.observe({"type": "start", "t": now})
    for dt in (0.5, 1.0, 2.0):  # map changes within the interval: no new snapshot
        snapshots.observe({"type": "belief", "t": now + dt, "map_events": {"place_appeared": 1}})
    assert sent == ["map"]
    snapshots.observe({"type": "observation", "t": now + 3.5, "detected": False})
    assert sent == ["map", "map"]
    snapshots.observe({"type": "action", "action": "(move a b)", "status": "start", "t": 2.0})
    assert sent == ["map", "map"]
    snapshots.observe({"type": "action", "action": "(move a b)", "status": "done", "t": 2.0})
    snapshots.observe({"type": "map", "t": 9.0})  # its own events never trigger it
    assert sent == ["map", "map", "map"]
