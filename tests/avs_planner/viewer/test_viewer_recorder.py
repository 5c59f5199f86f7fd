"""Rerun recordings of episodes: what is recorded, replaying, and the errors without the
viewer extra (those tests run whether or not rerun-sdk is installed)."""

from __future__ import annotations

import builtins
import json
from pathlib import Path

import pytest

from avs_planner.cli import main
from avs_planner.episode import EpisodeError
from avs_planner.harness import EpisodeSpec

try:
    import rerun  # noqa: F401
    HAVE_RERUN = True
except ImportError:
    HAVE_RERUN = False

needs_rerun = pytest.mark.skipif(not HAVE_RERUN, reason="rerun-sdk is not installed (the "
                                 "viewer extra: pip install 'avs-planner[viewer]')")

EXPECTED = {"/world/grid", "/world/places", "/world/placeholders",  # doors: none seen here
            "/world/rooms", "/world/robot/path", "/world/robot/pose", "/world/detections",
            "/plan", "/plan/probability", "/log"}


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Scenario a (the cereal box in the kitchen; found in ~45 simulated seconds), recorded."""
    if not HAVE_RERUN:
        pytest.skip("rerun-sdk is not installed (the viewer extra: pip install "
                    "'avs-planner[viewer]')")
    from avs_planner.harness import run_episode
    from avs_planner.harness.scenarios import load_scenario

    out = tmp_path_factory.mktemp("recorded")
    spec = dict(load_scenario("a").spec, seed=1, output_dir=str(out), record=True)
    assert run_episode(spec)["outcome"] == "found"
    return out


@needs_rerun
def test_the_recording_holds_the_maps_beliefs_path_and_plan(recorded: Path) -> None:
    from avs_planner.viewer.replay import contents

    data = contents(recorded / "recording.rrd")
    assert EXPECTED <= set(data["entities"]), sorted(data["entities"])
    last = [json.loads(line) for line in (recorded / "trace.jsonl").read_text().splitlines()][-1]
    assert data["sim_time"] == pytest.approx((0.0, last["t"]), abs=1e-3)
    plans = sum(1 for line in (recorded / "trace.jsonl").read_text().splitlines()
                if json.loads(line)["type"] == "plan")
    assert data["entities"]["/plan"] == plans  # every plan, as text


@needs_rerun
def test_the_plan_text_marks_assumptive_steps(recorded: Path) -> None:
    from rerun.chunk import RrdReader

    texts = []
    for chunk in RrdReader(str(recorded / "recording.rrd")).stream():
        if chunk.entity_path == "/plan":
            batch = chunk.to_record_batch()
            for name in batch.schema.names:
                if name.endswith("TextDocument:text"):
                    texts += [str(v) for v in batch.column(name).to_pylist()]
    assert any("**[assume]** `(assume-leads-to-room" in t for t in texts), texts[:1]


@needs_rerun
def test_recording_does_not_change_the_episode(recorded: Path, tmp_path: Path) -> None:
    from avs_planner.harness import run_episode
    from avs_planner.harness.scenarios import load_scenario

    run_episode(dict(load_scenario("a").spec, seed=1, output_dir=str(tmp_path)))

    def events(folder: Path) -> list[dict]:
        out = []
        for line in (folder / "trace.jsonl").read_text().splitlines():
            event = json.loads(line)
            event.pop("wall")
            event.pop("planning_time_s", None)
            if event.get("problem"):  # a timed-out problem kept in the run's own folder
                event["problem"] = Path(event["problem"]).name
            out.append(event)
        return out

    assert events(recorded) == events(tmp_path)
    assert not (tmp_path / "recording.rrd").exists()


@needs_rerun
def test_avs_view_checks_a_recording_and_says_why_it_cannot_open_a_window(
        recorded: Path, capsys, monkeypatch) -> None:
    assert main(["view", str(recorded), "--check"]) == 0
    out = capsys.readouterr().out
    assert "/world/grid" in out and "sim_time: 0.0 s" in out
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert main(["view", str(recorded)]) == 1
    assert "no display here" in capsys.readouterr().err
    assert main(["view", str(recorded.parent)]) == 1
    assert "has no recording.rrd" in capsys.readouterr().err


def test_without_rerun_recording_is_a_clear_error(monkeypatch, tmp_path: Path, capsys) -> None:
    real_import = builtins.__import__

    def no_rerun(name, *args, **kwargs):  # noqa: ANN001, ANN202
        if name == "rerun" or name.startswith("rerun."):
            raise ImportError("No module named 'rerun'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_rerun)
    with pytest.raises(EpisodeError, match=r"pip install 'avs-planner\[viewer\]'"):
        EpisodeSpec.from_dict({"target": "cerealbox", "record": True,
                               "output_dir": str(tmp_path)})
    code = main(["simulate", "--scenario", "a", "--record", "--out", str(tmp_path)])
    assert code == 1 and "pip install 'avs-planner[viewer]'" in capsys.readouterr().err
    (tmp_path / "recording.rrd").write_bytes(b"")
    assert main(["view", str(tmp_path)]) == 1
    assert "pip install 'avs-planner[viewer]'" in capsys.readouterr().err


@pytest.mark.parametrize(("spec", "message"), [
    ({"record": "yes"}, "'record' must be true or false"),
    ({"record": True}, "'output_dir', which is not given"),
])
def test_recording_spec_errors_name_the_key(spec: dict, message: str) -> None:
    with pytest.raises(EpisodeError, match=message):
        EpisodeSpec.from_dict({"target": "cerealbox", **spec})


@needs_rerun
def test_a_live_view_without_a_display_is_refused_before_the_run(monkeypatch) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(EpisodeError, match="no display here.*avs view RUN_DIR --web"):
        EpisodeSpec.from_dict({"target": "cerealbox", "view": True})


@needs_rerun
@pytest.mark.slow
def test_a_dt_search_records_its_cones_and_belief(tmp_path: Path) -> None:
    """Scenario f (the marker in the meeting room, one DT search over its view cones)."""
    from avs_planner.harness import run_episode
    from avs_planner.harness.scenarios import load_scenario
    from avs_planner.viewer.replay import contents

    spec = dict(load_scenario("f").spec, seed=1, output_dir=str(tmp_path), record=True)
    summary = run_episode(spec)
    assert summary["dt_calls"] >= 1
    entities = contents(tmp_path / "recording.rrd")["entities"]
    assert entities.get("/world/cones", 0) >= 2 and entities.get("/dt/belief", 0) >= 1
