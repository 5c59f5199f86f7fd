"""Real episodes through the campaign runner: a tiny campaign end to end, on both backends."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from avs_planner.cli import main
from avs_planner.experiment.campaign import parse_campaign
from avs_planner.experiment.results import read_results
from avs_planner.experiment.runner import RunOptions, run_campaign

TINY = {"name": "tiny", "scenarios": ["a"], "seeds": "0-1", "time_budget_s": 60,
        "wall_budget_s": 120}


def _outcomes(out: Path) -> dict[str, tuple]:
    return {r["run_id"]: (r["status"], r["outcome"], r["sim_time_s"], r["plans"],
                          r["distance_m"]) for r in read_results(out / "results.csv")}


def test_a_tiny_campaign_of_real_episodes_on_the_local_backend(tmp_path):
    result = run_campaign(parse_campaign(TINY, "tiny.yaml", Path(".")),
                          RunOptions(tmp_path, workers=2))
    outcomes = _outcomes(tmp_path)
    assert sorted(outcomes) == ["a-switching-s0", "a-switching-s1"]
    for run_id, (status, outcome, sim_time, plans, _) in outcomes.items():
        assert status == "ok" and outcome in ("found", "gave_up", "timeout"), run_id
        assert plans >= 1 and sim_time > 0
        run_dir = tmp_path / "runs" / run_id
        summary = json.loads((run_dir / "summary.json").read_text())
        assert summary["seed"] == int(run_id[-1]) and summary["target"] == "cerealbox"
        first = json.loads((run_dir / "trace.jsonl").read_text().splitlines()[0])
        assert first["type"] == "start"
    assert all(0 <= o < 1.0 for o in result.progress.overheads), result.progress.overheads


@pytest.mark.slow
def test_the_ray_backend_gives_the_local_backends_outcomes(tmp_path):
    pytest.importorskip("ray", reason="Ray is not installed (pip install '.[ray]'); the ray "
                                      "backend cannot be compared with the local one")
    campaign = parse_campaign(TINY, "tiny.yaml", Path("."))
    run_campaign(campaign, RunOptions(tmp_path / "local", workers=2))
    run_campaign(campaign, RunOptions(tmp_path / "ray", backend="ray", workers=2))
    local, ray = _outcomes(tmp_path / "local"), _outcomes(tmp_path / "ray")
    assert ray == local and len(ray) == 2
    rows = read_results(tmp_path / "ray" / "results.csv")
    assert {r["backend"] for r in rows} == {"ray"}
    assert (tmp_path / "ray" / "runs" / "a-switching-s0" / "trace.jsonl").exists()


def test_the_cli_refuses_an_unknown_campaign(tmp_path, capsys):
    assert main(["experiment", "run", "no-such-campaign", "--out", str(tmp_path)]) == 1
    assert "unknown campaign 'no-such-campaign'" in capsys.readouterr().err


def test_the_cli_refuses_a_report_without_results(tmp_path, capsys):
    assert main(["experiment", "report", str(tmp_path)]) == 1
    assert "no results.csv" in capsys.readouterr().err


def test_the_cli_reports_a_malformed_results_table_as_bad_input(tmp_path, capsys):
    from avs_planner.experiment.results import COLUMNS

    table = tmp_path / "results.csv"
    table.write_text("a,b\n1,2\n", encoding="utf-8")
    assert main(["experiment", "report", str(tmp_path)]) == 1
    assert "no column run_id" in capsys.readouterr().err
    row = {c: "" for c in COLUMNS} | {"run_id": "r", "status": "ok", "seed": "zero"}
    table.write_text(",".join(COLUMNS) + "\n" + ",".join(row[c] for c in COLUMNS) + "\n",
                     encoding="utf-8")
    assert main(["experiment", "report", str(tmp_path)]) == 1
    assert "results.csv:2: column seed: 'zero'" in capsys.readouterr().err
    table.write_bytes(b"\xff\xfe\x00")
    assert main(["experiment", "report", str(tmp_path)]) == 1
    assert "not a UTF-8 text file" in capsys.readouterr().err


def test_the_cli_refuses_an_address_without_ray(tmp_path, capsys):
    campaign = tmp_path / "c.yaml"
    campaign.write_text("scenarios: [a]\n")
    code = main(["experiment", "run", str(campaign), "--out", str(tmp_path / "o"),
                 "--address", "10.0.0.1:6379"])
    assert code == 1 and "--address is for the ray backend" in capsys.readouterr().err


def test_the_cli_lists_the_built_in_campaigns(capsys):
    assert main(["experiment", "list"]) == 0
    out = capsys.readouterr().out
    assert "seed003-fig3" in out and "120 runs" in out
    lines = {line.split()[0]: line for line in out.splitlines() if line.strip()}
    assert "432 runs" in lines["heldout"] and "120 runs" in lines["heldout-fig3"]


def test_the_cli_runs_a_campaign_and_prints_its_counts(tmp_path, capsys):
    campaign = tmp_path / "c.yaml"
    campaign.write_text("name: c\nscenarios: [a, c]\nseeds: 0-2\n")
    out = tmp_path / "out"
    assert main(["experiment", "run", str(campaign), "--out", str(out), "--limit", "0",
                 "--json"]) == 0
    counts = json.loads(capsys.readouterr().out)
    assert (counts["total"], counts["done"], counts["ran_now"]) == (6, 0, 0)
    assert (out / "results.csv").read_text().startswith("run_id,scenario,world,")
    assert json.loads((out / "campaign.json").read_text())["runs"] == 6


def test_a_generated_world_with_auto_targets_end_to_end(tmp_path):
    data = {"name": "gen", "worlds": [{"generate": {"seeds": 0, "style": "office",
                                                    "rooms": 4}}],
            "targets": "auto", "strategies": ["exhaustive"], "time_budget_s": 40,
            "wall_budget_s": 120}
    run_campaign(parse_campaign(data, "gen.yaml", Path(".")), RunOptions(tmp_path, workers=2))
    rows = read_results(tmp_path / "results.csv")
    assert len(rows) == 3 and {r["status"] for r in rows} == {"ok"}
    assert sorted(r["expected"] for r in rows) == ["found", "found", "gave_up"]
    assert {r["world"] for r in rows} == {"gen-office-0-r4"}
    summary = json.loads((tmp_path / "runs" / rows[0]["run_id"] / "summary.json").read_text())
    assert summary["strategy"] == "exhaustive" and summary["target"] == rows[0]["target"]


def test_a_real_task_episode_through_the_campaign_runner(tmp_path):
    """One short task (any of two labels gen-office-314 holds): the episode gets the task's
    form and its summary's parts reach results.csv."""
    pytest.importorskip("sim.generate", reason="the world generator is not in this build")
    data = {"name": "task", "worlds": [{"generate": {"seeds": 314, "style": "office"}}],
            "targets": {"auto": "present", "any": 2}, "time_budget_s": 120,
            "wall_budget_s": 120}
    run_campaign(parse_campaign(data, "task.yaml", Path(".")), RunOptions(tmp_path, workers=1))
    [row] = read_results(tmp_path / "results.csv")
    assert (row["status"], row["task"], row["expected"]) == ("ok", "any", "found")
    labels = row["task_labels"].split()
    assert len(labels) == 2 and row["target"] == " or ".join(labels)
    summary = json.loads((tmp_path / "runs" / row["run_id"] / "summary.json").read_text())
    assert summary["task"] == {"targets": labels, "mode": "any", "count": "one"}
    assert summary["target"] == row["target"]
    assert row["targets_outcome"] == " ".join(f"{p['label']}:{p['outcome']}"
                                              for p in summary["targets"])
    assert row["reports"] == sum(len(p["objects"]) for p in summary["targets"])
    assert row["instances"] == sum(p["instances"] for p in summary["targets"]) >= 2
