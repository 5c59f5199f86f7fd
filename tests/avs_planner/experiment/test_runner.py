"""`run_campaign` on the local backend: every run once, resumable, failures recorded."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from avs_planner.experiment import CampaignError
from avs_planner.experiment.campaign import parse_campaign
from avs_planner.experiment.results import read_results
from avs_planner.experiment.runner import RunOptions, run_campaign

FAKE = Path(__file__).with_name("fake_runner.py")


def campaign(seeds: str = "0-2", **extra):
    data = {"name": "tiny", "scenarios": ["a", "e"], "seeds": seeds, **extra}
    return parse_campaign(data, "tiny.yaml", Path("."))


def run(out: Path, runner: str = "summary", **options):
    progress = []
    result = run_campaign(campaign(**options.pop("campaign", {})),
                          RunOptions(out, workers=2, episode_runner=f"{FAKE}:{runner}",
                                     **options),
                          lambda p: progress.append((p.done, p.failed)))
    return result, progress


def executions(out: Path) -> list[str]:
    log = out / "executions.log"
    return sorted(log.read_text().split()) if log.exists() else []


def test_every_run_once_with_its_files_a_record_and_a_table_row(tmp_path):
    result, progress = run(tmp_path)
    assert executions(tmp_path) == sorted(f"{s}-switching-s{k}" for s in "ae" for k in range(3))
    assert progress[0] == (0, 0) and progress[-1] == (6, 0)
    rows = read_results(result.results)
    assert [r["run_id"] for r in rows] == [f"{s}-switching-s{k}" for k in range(3) for s in "ae"]
    a0 = rows[0]
    assert (a0["status"], a0["outcome"], a0["success"], a0["expected"]) == (
        "ok", "found", True, "found")
    assert a0["cp_s_per_plan"] == pytest.approx(0.02) and a0["dt_s_per_action"] == 0.5
    e0 = rows[1]
    assert (e0["outcome"], e0["correct_give_up"], e0["success"]) == ("gave_up", True, None)
    run_dir = tmp_path / "runs" / "a-switching-s0"
    assert {p.name for p in run_dir.iterdir()} == {"summary.json", "trace.jsonl", "record.json"}
    record = json.loads((run_dir / "record.json").read_text())
    assert record["overhead_s"] >= 0 and record["spec"]["seed"] == 0
    assert result.progress.overheads and max(result.progress.overheads) < 2.0


def test_a_stopped_campaign_resumes_without_rerunning_finished_episodes(tmp_path):
    run(tmp_path, limit=2)
    assert len(executions(tmp_path)) == 2
    result, _ = run(tmp_path)
    assert len(executions(tmp_path)) == 6  # 2 then the other 4, none twice
    assert len(set(executions(tmp_path))) == 6
    assert result.progress.skipped == 2 and result.progress.done == 6
    shutil.rmtree(tmp_path / "runs" / "e-switching-s1")  # a run lost: only it runs again
    run(tmp_path)
    assert executions(tmp_path).count("e-switching-s1") == 2
    assert len(executions(tmp_path)) == 7
    assert len(read_results(tmp_path / "results.csv")) == 6
    invocations = json.loads((tmp_path / "campaign.json").read_text())["invocations"]
    assert [i["ran"] for i in invocations] == [2, 4, 1]
    assert {i["backend"] for i in invocations} == {"local"}


def test_a_changed_episode_spec_is_run_again(tmp_path):
    run(tmp_path, campaign={"seeds": "0"})
    run(tmp_path, campaign={"seeds": "0", "time_budget_s": 50})
    assert executions(tmp_path) == sorted(["a-switching-s0", "e-switching-s0"] * 2)


@pytest.mark.parametrize(("runner", "status", "error"), [
    ("crash_on_seed_1", "crashed", "killed by signal 9"),
    ("raise_on_seed_1", "error", "RuntimeError: the planner fell over"),
])
def test_a_failing_episode_is_recorded_and_the_campaign_goes_on(tmp_path, runner, status, error):
    result, _ = run(tmp_path, runner)
    rows = {r["run_id"]: r for r in read_results(result.results)}
    assert len(rows) == 6 and result.progress.failed == 2
    bad = rows["a-switching-s1"]
    assert bad["status"] == status and error in bad["error"] and not bad["outcome"]
    assert rows["a-switching-s2"]["status"] == "ok"
    again, _ = run(tmp_path, runner)  # recorded failures count as done...
    assert again.progress.ran == 0 and again.progress.failed == 2
    retried, _ = run(tmp_path, runner, retry_failed=True)  # ...unless asked to retry them
    assert retried.progress.ran == 2 and len(executions(tmp_path)) == 4


def test_an_episode_past_its_wall_budget_is_killed_and_recorded(tmp_path):
    result, _ = run(tmp_path, "hang_on_seed_1", campaign={"seeds": "0-1", "wall_budget_s": 1},
                    kill_margin_s=0.5)
    rows = {r["run_id"]: r for r in read_results(result.results)}
    assert rows["a-switching-s1"]["status"] == "timeout"
    assert "wall-clock limit of 1.5 s" in rows["a-switching-s1"]["error"]
    assert rows["a-switching-s1"]["wall_s"] < 10
    assert rows["e-switching-s0"]["status"] == "ok"


def test_an_episode_cut_by_its_wall_budget_is_recorded_as_such_and_retried(tmp_path):
    result, _ = run(tmp_path, "wall_cut_on_seed_1", campaign={"seeds": "0-1"})
    rows = {r["run_id"]: r for r in read_results(result.results)}
    cut = rows["a-switching-s1"]
    assert cut["status"] == "wall_cut" and result.progress.failed == 2
    assert (cut["outcome"], cut["reason"]) == ("timeout", "wall time budget 300 s spent")
    assert cut["success"] is None and cut["false_report"] is None  # no verdict on a cut run
    assert cut["sim_time_s"] == 101.0  # how far it got
    assert "wall-clock budget" in cut["error"]
    assert rows["a-switching-s0"]["status"] == "ok"
    record = json.loads((tmp_path / "runs" / "a-switching-s1" / "record.json").read_text())
    assert record["status"] == "wall_cut"
    again, _ = run(tmp_path, "wall_cut_on_seed_1", campaign={"seeds": "0-1"})
    assert again.progress.ran == 0  # done, like any recorded failure...
    retried, _ = run(tmp_path, "summary", campaign={"seeds": "0-1"}, retry_failed=True)
    assert retried.progress.ran == 2 and retried.progress.failed == 0  # ...until retried
    assert {r["status"] for r in read_results(retried.results)} == {"ok"}


def test_an_old_record_of_a_wall_cut_episode_as_ok_is_retried(tmp_path):
    run(tmp_path, "wall_cut_on_seed_1", campaign={"seeds": "0-1"})
    path = tmp_path / "runs" / "e-switching-s1" / "record.json"
    record = json.loads(path.read_text())
    path.write_text(json.dumps({**record, "status": "ok"}))  # as written before wall_cut
    result, _ = run(tmp_path, "summary", campaign={"seeds": "0-1"}, limit=0)
    status = {r["run_id"]: r["status"] for r in read_results(result.results)}
    assert status["e-switching-s1"] == "wall_cut"
    retried, _ = run(tmp_path, "summary", campaign={"seeds": "0-1"}, retry_failed=True)
    assert retried.progress.ran == 2


def test_each_run_records_the_git_commit_it_ran_at(tmp_path, monkeypatch):
    from avs_planner.experiment import runner as runner_module

    monkeypatch.setattr(runner_module, "git_state",
                        lambda: {"commit": "abc1234", "dirty": True})
    result, _ = run(tmp_path, campaign={"seeds": "0"})
    assert {r["commit"] for r in read_results(result.results)} == {"abc1234+dirty"}
    invocation = json.loads((tmp_path / "campaign.json").read_text())["invocations"][0]
    assert (invocation["commit"], invocation["dirty"]) == ("abc1234", True)
    assert invocation["started"] <= invocation["finished"]


def test_the_git_state_of_this_checkout_and_of_no_checkout(tmp_path):
    from avs_planner.experiment.provenance import describe, git_state

    assert git_state(tmp_path) == {"commit": "unknown", "dirty": None}
    assert describe(git_state(tmp_path)) == "unknown"
    here = git_state()
    if here["commit"] != "unknown":  # a git checkout with git installed
        assert len(here["commit"]) >= 7 and here["dirty"] in (True, False)
    assert describe({"commit": "abc1234", "dirty": False}) == "abc1234"


def test_map_scores_and_dt_verdicts_become_columns_when_the_summary_has_them(tmp_path):
    result, _ = run(tmp_path, "with_scores", campaign={"seeds": "0-1"})
    rows = {r["run_id"]: r for r in read_results(result.results)}
    scored, plain = rows["a-switching-s0"], rows["a-switching-s1"]
    assert (scored["map_rooms_true"], scored["map_rooms_matched"], scored["map_merges"],
            scored["map_splits"]) == (6, 5, 1, 0)
    assert (scored["map_category_accuracy"], scored["map_entered_area_m2"]) == (0.75, 40.5)
    assert (scored["dt_confirmed"], scored["dt_rejected"]) == (1, 2)  # a count, or a list
    assert all(plain[c] is None for c in ("map_rooms_true", "map_category_accuracy",
                                          "dt_confirmed", "dt_rejected"))


def test_a_directory_of_another_campaign_is_refused(tmp_path):
    (tmp_path / "campaign.json").write_text(json.dumps({"name": "other"}))
    with pytest.raises(CampaignError, match="holds campaign 'other', not 'tiny'"):
        run(tmp_path)
    (tmp_path / "file").write_text("")
    with pytest.raises(CampaignError, match="is a file, not a directory"):
        run(tmp_path / "file")


def test_the_progress_line_counts_and_estimates():
    from avs_planner.experiment.runner import Progress

    progress = Progress(total=10, done=4, failed=1, skipped=2)
    assert progress.line().startswith("4/10 done (2 before), 1 failed, elapsed 0m00s, ETA ")
    progress.started -= 20  # 2 runs in 20 s: 6 to go take 60 s
    assert progress.eta_s() == pytest.approx(60, abs=1)
    assert Progress(total=3, done=0, failed=0, skipped=0).line().endswith("ETA --")


def test_a_record_that_cannot_be_written_stops_the_campaign_with_its_error(tmp_path,
                                                                          monkeypatch):
    from avs_planner.experiment import runner as runner_module

    def full_disk(job, record, *args):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(runner_module, "_write_record", full_disk)
    with pytest.raises(OSError, match="No space left"):
        run(tmp_path)
    assert read_results(tmp_path / "results.csv") == []


@pytest.mark.slow
def test_the_ray_backend_records_crashes_errors_and_timeouts(tmp_path):
    pytest.importorskip("ray", reason="Ray is not installed (pip install '.[ray]')")
    result, _ = run(tmp_path, "crash_1_raise_2_hang_3", backend="ray", kill_margin_s=1.0,
                    campaign={"seeds": "0-3", "wall_budget_s": 8})  # a new Ray worker
    # (after a crash) takes seconds to start, and the deadline counts from submission
    status = {r["run_id"]: r["status"] for r in read_results(result.results)}
    assert status == {f"{s}-switching-s{k}": v for s in "ae" for k, v in
                      enumerate(["ok", "crashed", "error", "timeout"])}
    assert (tmp_path / "runs" / "a-switching-s0" / "summary.json").exists()


def test_a_campaign_of_tasks_passes_their_form_and_records_each_labels_part(tmp_path):
    data = {"name": "tasks", "worlds": ["office"], "seeds": "0-1", "targets": [
        {"targets": ["cerealbox", "stapler"], "singles": True},
        {"targets": ["cup", "stapler"], "mode": "any"}]}
    result = run_campaign(parse_campaign(data, "tasks.yaml", Path(".")),
                          RunOptions(tmp_path, workers=2, episode_runner=f"{FAKE}:tasks"))
    rows = {(r["target"], r["seed"]): r for r in read_results(result.results)}
    assert sorted({t for t, _ in rows}) == ["cerealbox", "cerealbox and stapler",
                                           "cup or stapler", "stapler"]
    task = rows[("cerealbox and stapler", 1)]
    assert (task["task"], task["task_labels"], task["outcome"], task["success"]) == (
        "all", "cerealbox stapler", "found", True)
    assert (task["targets_outcome"], task["targets_found"], task["reports"],
            task["reports_correct"], task["instances"], task["distinct"],
            task["false_report"]) == ("cerealbox:found stapler:found", 2, 2, 2, 4, 2, False)
    assert json.loads(task["targets_json"])[1] == {
        "label": "stapler", "outcome": "found", "sim_time_s": 20.0, "reports": 1,
        "correct_reports": 1, "instances": 2, "distinct": 1}
    wrong = rows[("cup or stapler", 0)]  # its cup report names the wrong object
    assert (wrong["task"], wrong["success"], wrong["false_report"], wrong["reports_correct"]
            ) == ("any", False, True, 1)
    single = rows[("stapler", 0)]
    assert (single["task"], single["task_labels"], single["targets_outcome"],
            single["reports"]) == ("", "", "", None)
    record = json.loads((tmp_path / "runs" / task["run_id"] / "record.json").read_text())
    assert record["spec"]["targets"] == ["cerealbox", "stapler"] and "target" not in record["spec"]
    assert (record["spec"]["mode"], record["spec"]["count"]) == ("all", "one")
