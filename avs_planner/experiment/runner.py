"""`run_campaign`: every episode of a campaign not yet done in DIR, on a backend, resumably.

DIR holds `campaign.json` (what ran there), `runs/<run-id>/` (the episode's summary.json,
trace.jsonl, trajectory.png and our `record.json`: status, error, timing, the spec) and
`results.csv` (one row per run, rebuilt whenever the runner stops). A run counts as done when
its record exists for the same episode spec; crashed, timed-out, failed and wall-cut runs (an
episode whose wall-clock budget ran out: see results.py) are done too (recorded with their
error) unless `retry_failed` asks for them again. Each invocation notes in campaign.json when
it ran and at which git commit (provenance.py); each record carries the commit too.

The tasks of a campaign sequence (`sequences.py`) run in order, one sequence per worker slot at
a time (`Job.then`). With memory on, each episode's run directory keeps a copy of the memory as
it left it (`runs/<run-id>/memory/`), and an episode starts from the copy of the one before
(none for the first), so a stopped sequence resumes from the right memory; when an episode of
such a sequence runs again (its directory deleted, `--retry-failed`), the episodes after it run
again too, since they read what it wrote.
"""

from __future__ import annotations

import dataclasses
import json
import socket
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from avs_planner.experiment.backends import (
    MEMORY_SNAPSHOT,
    Backend,
    Job,
    Record,
    keep_memory,
    make_backend,
)
from avs_planner.experiment.campaign import Campaign, RunSpec
from avs_planner.experiment.errors import CampaignError
from avs_planner.experiment.priors import placed_store, prepare_stores
from avs_planner.experiment.provenance import describe, git_state
from avs_planner.experiment.results import RESULTS_FILE, run_status, write_results
from avs_planner.experiment.sequences import ordered, placed
from avs_planner.experiment.worker import DEFAULT_RUNNER

RECORD_FILE = "record.json"
META_FILE = "campaign.json"
DEFAULT_WALL_BUDGET_S = 600.0  # the episode runner's default


@dataclass(frozen=True)
class RunOptions:
    out: Path
    backend: str = "local"
    workers: int | None = None
    address: str | None = None
    retry_failed: bool = False
    limit: int | None = None  # run at most this many episodes now (a trial, or a test)
    episode_runner: str = DEFAULT_RUNNER
    kill_margin_s: float = 30.0  # beyond the wall budget, before the hard kill
    # the experience store for every episode that uses one (instead of the campaign's)
    experience: Path | None = None


@dataclass
class Progress:
    """Where the campaign stands; `line()` is what the CLI shows."""

    total: int
    done: int  # including runs finished before this invocation
    failed: int
    skipped: int  # done before this invocation
    slots: int = 1
    started: float = field(default_factory=time.monotonic)
    overheads: list[float] = field(default_factory=list)

    @property
    def ran(self) -> int:
        return self.done - self.skipped

    def eta_s(self) -> float | None:
        if self.ran == 0:
            return None
        return (time.monotonic() - self.started) / self.ran * (self.total - self.done)

    def line(self) -> str:
        eta = self.eta_s()
        eta_text = "--" if eta is None else _duration(eta)
        return (f"{self.done}/{self.total} done ({self.skipped} before), {self.failed} failed, "
                f"elapsed {_duration(time.monotonic() - self.started)}, ETA {eta_text}")


@dataclass(frozen=True)
class CampaignResult:
    progress: Progress
    results: Path
    wall_s: float
    backend: str
    slots: int


def run_campaign(campaign: Campaign, options: RunOptions,
                 on_progress: Callable[[Progress], None] | None = None) -> CampaignResult:
    runs = [dataclasses.replace(run, episode=placed_store(
                placed(dict(run.episode), options.out), options.out, options.experience))
            for run in campaign.runs()]
    backend = make_backend(options.backend, options.workers, options.address,
                           options.episode_runner)
    try:
        return _run(campaign, runs, options, backend, on_progress)
    finally:
        backend.close()


def _run(campaign: Campaign, runs: list[RunSpec], options: RunOptions, backend: Backend,
         on_progress: Callable[[Progress], None] | None) -> CampaignResult:
    started = time.strftime("%Y-%m-%dT%H:%M:%S%z")
    git = git_state()
    meta = _claim(options.out, campaign, len(runs))
    prepare_stores([dict(run.episode) for run in runs])  # before any episode writes one
    records = load_records(options.out, runs)
    todo = _todo(runs, records, options.retry_failed)
    skipped = len(runs) - len(todo)
    if options.limit is not None:
        todo = todo[:options.limit]
    pending = {run.run_id for run in todo}
    failed = sum(r["status"] != "ok" for k, r in records.items() if k not in pending)
    progress = Progress(len(runs), skipped, failed, skipped, backend.slots)
    jobs = _jobs(runs, todo, options)
    table = _Table(options.out, runs, records)

    def on_done(job: Job, record: Record) -> None:
        keep_memory(job)  # before the sequence's next episode starts from it
        record = _write_record(job, record, backend.name, describe(git))
        table.add(record)
        progress.done += 1
        progress.failed += record["status"] != "ok"
        if record.get("overhead_s") is not None:
            progress.overheads.append(record["overhead_s"])
        if on_progress is not None:
            on_progress(progress)

    if on_progress is not None:
        on_progress(progress)
    try:
        backend.run(jobs, on_done)
    finally:
        results = table.write()
        _log_invocation(options.out, meta, progress, backend, started, git)
    return CampaignResult(progress, results, time.monotonic() - progress.started,
                          backend.name, backend.slots)


class _Table:
    """results.csv, kept in memory and rewritten at most every `every_s` while runs finish,
    so a report made mid-campaign (or after a hard kill) sees nearly every finished run."""

    def __init__(self, out: Path, runs: list[RunSpec], records: dict[str, Record],
                 every_s: float = 30.0):
        self.out, self.runs, self.records, self.every_s = out, runs, dict(records), every_s
        self.written = time.monotonic()

    def add(self, record: Record) -> None:
        self.records[record["run_id"]] = record
        if time.monotonic() - self.written > self.every_s:
            self.write()

    def write(self) -> Path:
        self.written = time.monotonic()
        return write_results(self.out, self.runs, self.records)


def run_dir(out: Path, run: RunSpec) -> Path:
    return out / "runs" / run.run_id


def load_records(out: Path, runs: list[RunSpec]) -> dict[str, Record]:
    """The records in `out` that belong to these runs (same id and the same episode spec)."""
    records = {}
    for run in runs:
        record = _read_record(run_dir(out, run) / RECORD_FILE)
        if record is not None and record.get("spec") == _jsonable(run.episode):
            # a record written before wall cuts had their own status says `ok`
            record["status"] = run_status(record["status"], record.get("summary"))
            records[run.run_id] = record
    return records


def _todo(runs: list[RunSpec], records: dict[str, Record], retry_failed: bool
          ) -> list[RunSpec]:
    """The runs to run now: those not done; in a sequence with memory, also every run after
    the first one to run (it reads the memory the ones before it wrote)."""
    todo = []
    again: set[str] = set()  # sequences with memory in which an earlier episode runs
    for run in runs:
        if (run.sequence in again
                or not _done(records.get(run.run_id), retry_failed)):
            todo.append(run)
            if run.sequence and "memory" in run.episode:
                again.add(run.sequence)
    return todo


def _jobs(runs: list[RunSpec], todo: list[RunSpec], options: RunOptions) -> list[Job]:
    """One job per run, the runs of a sequence chained in order into one job (`Job.then`);
    with memory, each starts from the memory the run before it in the sequence left."""
    before: dict[str, RunSpec] = {}
    previous: dict[str, RunSpec] = {}
    for run in runs:
        if run.sequence:
            if run.sequence in previous:
                before[run.run_id] = previous[run.sequence]
            previous[run.sequence] = run
    jobs = []
    for run in todo:
        memory = run.episode.get("memory")
        prior = before.get(run.run_id)
        jobs.append(Job(run, run_dir(options.out, run), _deadline(run, options),
                        memory=Path(memory) if memory else None,
                        memory_from=(run_dir(options.out, prior) / MEMORY_SNAPSHOT
                                     if memory and prior is not None else None)))
    units = []
    for group in ordered(jobs, lambda job: job.run.sequence or None):
        units.append(dataclasses.replace(group[0], then=tuple(group[1:])))
    return units


def _done(record: Record | None, retry_failed: bool) -> bool:
    return record is not None and (record["status"] == "ok" or not retry_failed)


def _deadline(run: RunSpec, options: RunOptions) -> float:
    budget = float(run.episode.get("wall_budget_s", DEFAULT_WALL_BUDGET_S))
    return budget + max(options.kill_margin_s, 0.1 * budget)


def _write_record(job: Job, record: Record, backend: str, commit: str = "unknown") -> Record:
    episode_s = record.get("episode_s")
    summary = record.get("summary")
    status = run_status(record["status"], summary)
    error = record.get("error")
    if status != record["status"] and error is None:
        error = f"cut by the wall-clock budget: {summary.get('reason')}"
    full = {"run_id": job.run.run_id, **job.run.columns(), "status": status,
            "error": error, "backend": backend, "host": socket.gethostname(), "commit": commit,
            "wall_s": _round(record.get("wall_s")), "episode_s": _round(episode_s),
            "overhead_s": _round(record["wall_s"] - episode_s if episode_s is not None
                                 and record.get("wall_s") is not None else None),
            "spec": _jsonable(job.run.episode), "summary": record.get("summary")}
    tmp = job.out_dir / (RECORD_FILE + ".tmp")
    try:
        job.out_dir.mkdir(parents=True, exist_ok=True)
        tmp.write_text(json.dumps(full, indent=1) + "\n", encoding="utf-8")
        tmp.replace(job.out_dir / RECORD_FILE)  # a record is whole or absent
    except OSError as exc:
        raise CampaignError(f"cannot write the record of {job.run.run_id}: {exc}") from None
    return full


def _read_record(path: Path) -> Record | None:
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) and "status" in record else None


def _claim(out: Path, campaign: Campaign, total: int) -> dict[str, Any]:
    """DIR belongs to one campaign; refuse to mix another one's runs into it."""
    if out.exists() and not out.is_dir():
        raise CampaignError(f"--out {out} is a file, not a directory")
    meta = _read_meta(out)
    if meta is not None and meta.get("name") != campaign.name:
        raise CampaignError(f"{out} holds campaign {meta.get('name')!r}, not "
                            f"{campaign.name!r}; choose another --out")
    meta = {"name": campaign.name, "description": campaign.description,
            "source": campaign.source, "runs": total,
            "invocations": (meta or {}).get("invocations", [])}
    _write_meta(out, meta)
    return meta


def _read_meta(out: Path) -> dict[str, Any] | None:
    try:
        meta = json.loads((out / META_FILE).read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None
    except (OSError, ValueError):
        return {}
    return meta if isinstance(meta, dict) else {}


def _write_meta(out: Path, meta: dict[str, Any]) -> None:
    try:
        out.mkdir(parents=True, exist_ok=True)
        (out / META_FILE).write_text(json.dumps(meta, indent=1) + "\n", encoding="utf-8")
    except OSError as exc:
        raise CampaignError(f"cannot write to {out}: {exc}") from None


def _log_invocation(out: Path, meta: dict[str, Any], progress: Progress, backend: Backend,
                    started: str, git: dict[str, Any]) -> None:
    """What this `run` did, for the report: when, at which commit, backend, workers, runs,
    wall time."""
    meta["invocations"].append({
        "started": started, "finished": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "commit": git["commit"], "dirty": git["dirty"], "backend": backend.name,
        "workers": backend.slots, "ran": progress.ran, "failed": progress.failed,
        "wall_s": round(time.monotonic() - progress.started, 1)})
    _write_meta(out, meta)


def _jsonable(value: Any) -> Any:
    return json.loads(json.dumps(value))


def _round(value: float | None) -> float | None:
    return None if value is None else round(float(value), 4)


def _duration(seconds: float) -> str:
    seconds = int(round(seconds))
    if seconds >= 3600:
        return f"{seconds // 3600}h{seconds % 3600 // 60:02d}m"
    return f"{seconds // 60}m{seconds % 60:02d}s"


__all__ = ["RESULTS_FILE", "CampaignResult", "Progress", "RunOptions", "load_records",
           "run_campaign", "run_dir"]
