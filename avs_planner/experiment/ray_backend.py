"""The Ray backend: each episode a Ray task (one CPU); worker processes are reused a while.

`ray.init()` starts Ray on this machine, or `address` joins a running cluster (then every node
needs this package installed, as on the driver). At most `slots` tasks are in flight (default:
the cluster's CPUs), so a task starts when it is submitted and its wall-clock deadline counts
from then; results stream back as tasks finish. A task returns its files (summary, trace,
picture) with its record, so nodes need no shared file system. A job with followers
(`Job.then`, a campaign sequence) submits each follower when the one before has finished; a
sequence with memory needs the output directory at the same path on every node (a shared file
system), since its episodes read and write their memory there.
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections import deque
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from avs_planner.experiment.backends import Job, OnDone, Record, start_dir, timeout_record
from avs_planner.experiment.errors import CampaignError
from avs_planner.experiment.worker import DEFAULT_RUNNER, execute_collect, preload

# A Ray worker process runs up to this many episodes, then a fresh one takes over: the 2 s of
# imports are paid once per 20 episodes, not per episode (each episode builds its own world,
# robot and mind from its seed; results equal the local backend's, see the tests). The first
# workers import before the first episode starts (`_warm`).
MAX_CALLS = 20
_PROJECT_ROOT = str(Path(__file__).resolve().parents[2])


class RayBackend:
    name = "ray"

    def __init__(self, workers: int | None, address: str | None, runner: str = DEFAULT_RUNNER):
        try:
            import ray
        except ImportError:
            raise CampaignError("the ray backend needs Ray: pip install '.[ray]'") from None
        self._ray = ray
        self._owns = not ray.is_initialized()
        if self._owns:
            _init(ray, address)
        cpus = int(ray.cluster_resources().get("CPU", 1))
        self.slots = workers or max(1, cpus)
        self.runner = runner
        self._remote = ray.remote(num_cpus=1, max_calls=MAX_CALLS, max_retries=0)(execute_collect)
        self._flying: dict[Any, tuple[Job, float]] = {}

    def run(self, jobs: Iterable[Job], on_done: OnDone) -> None:
        pending = deque(jobs)
        if pending:
            self._warm(min(self.slots, len(pending)))
        try:
            while pending or self._flying:
                while pending and len(self._flying) < self.slots:
                    self._submit(pending.popleft())
                for job in self._collect(on_done):  # a sequence's next episode goes first
                    pending.appendleft(dataclasses.replace(job.then[0], then=job.then[1:]))
        finally:
            for ref in list(self._flying):
                self._ray.cancel(ref, force=True)
            self._flying.clear()

    def close(self) -> None:
        if self._owns and self._ray.is_initialized():
            self._ray.shutdown()

    def _warm(self, workers: int) -> None:
        """Import the episode stack in `workers` Ray workers at once, before any episode's
        clock starts (they are then reused for the episodes)."""
        warm = self._ray.remote(num_cpus=1, max_retries=0)(preload)
        try:
            self._ray.get([warm.remote(self.runner) for _ in range(workers)], timeout=600)
        except self._ray.exceptions.RayError as exc:
            raise CampaignError(f"Ray workers cannot import the episode runner: {exc}") from None

    def _submit(self, job: Job) -> None:
        start_dir(job)
        ref = self._remote.remote(dict(job.run.episode), self.runner)
        self._flying[ref] = (job, time.perf_counter())

    def _collect(self, on_done: OnDone) -> list[Job]:
        """Hand back the episodes that finished or passed their deadline; those among them
        that have followers."""
        ended: list[Job] = []
        now = time.perf_counter()
        soonest = min(start + job.deadline_s for job, start in self._flying.values())
        ready, _ = self._ray.wait(list(self._flying), num_returns=1,
                                  timeout=max(0.0, min(soonest - now, 5.0)))
        for ref in ready:
            job, start = self._flying.pop(ref)
            record = self._result(ref, job)
            record["wall_s"] = time.perf_counter() - start
            on_done(dataclasses.replace(job, then=()), record)
            ended.append(job)
        for ref, (job, start) in list(self._flying.items()):
            if time.perf_counter() - start > job.deadline_s:
                self._ray.cancel(ref, force=True)
                del self._flying[ref]
                on_done(dataclasses.replace(job, then=()),
                        {**timeout_record(job.deadline_s), "wall_s": time.perf_counter() - start})
                ended.append(job)
        return [job for job in ended if job.then]

    def _result(self, ref: Any, job: Job) -> Record:
        try:
            record = self._ray.get(ref)
        except self._ray.exceptions.RayError as exc:
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
            return {"status": "crashed", "summary": None,
                    "error": f"{type(exc).__name__}: {first}"[:500]}
        for name, data in record.pop("files", {}).items():
            (job.out_dir / name).write_bytes(data)
        return record


def _init(ray: Any, address: str | None) -> None:
    """Start Ray here (workers find this checkout on PYTHONPATH), or join `address`."""
    try:
        if address is None:
            path = os.pathsep.join(p for p in (_PROJECT_ROOT, os.environ.get("PYTHONPATH"))
                                   if p)
            ray.init(include_dashboard=False, log_to_driver=False,
                     runtime_env={"env_vars": {"PYTHONPATH": path}})
        else:
            ray.init(address=address, log_to_driver=False)
    except (ConnectionError, RuntimeError, ValueError) as exc:
        where = address or "this machine"
        raise CampaignError(f"cannot start or reach Ray at {where}: {exc}") from None
