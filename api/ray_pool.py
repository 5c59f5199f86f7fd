"""Episode jobs as Ray tasks (`avs serve --ray-address A`), with `WorkerPool`'s contract.

The slots, the FIFO, futures and outcomes are `WorkerPool`'s; only how one job runs differs.
Each job is a Ray task asking for one CPU. Its events and its stop request travel through one
small actor (`_Hub`): the task posts events there, the slot thread drains them every 0.1 s and
hands them to `job.on_event`; a cancel posts a stop the episode sees through `should_stop`,
and after the grace time (or at the wall-clock limit) the task is force-cancelled, which kills
its worker process. The task runs in a temporary directory and returns its files, which the
slot writes into the job's `output_dir`, so cluster nodes need no shared file system.
"""

from __future__ import annotations

import logging
import os
import tempfile
import time
import traceback
import uuid
from pathlib import Path
from typing import Any

from api.workers import Job, JobOutcome, JobResult, WorkerPool, _Slot

log = logging.getLogger("avs.api.ray_pool")
_POLL_S = 0.1
_STOP_CHECK_S = 0.25  # how often an episode's should_stop asks the hub


class _Hub:
    """The Ray actor between the service and its running tasks: events out, stops in."""

    def __init__(self) -> None:
        self.events: dict[str, list[dict[str, Any]]] = {}
        self.stops: set[str] = set()

    def put(self, key: str, event: dict[str, Any]) -> None:
        self.events.setdefault(key, []).append(event)

    def drain(self, key: str) -> list[dict[str, Any]]:
        return self.events.pop(key, [])

    def stop(self, key: str) -> None:
        self.stops.add(key)

    def stopped(self, key: str) -> bool:
        return key in self.stops

    def forget(self, key: str) -> None:
        self.events.pop(key, None)
        self.stops.discard(key)

    def flush(self) -> None:
        """A no-op: when a caller's flush returns, its earlier puts have been applied."""


def run_remote(runner: str, payload: dict[str, Any], hub: Any, key: str) -> tuple[Any, ...]:
    """The body of a Ray task: run the episode, report events to the hub, return its files."""
    import ray

    from api.worker_process import resolve

    checked = {"at": 0.0, "stop": False}

    def should_stop() -> bool:
        if not checked["stop"] and time.monotonic() - checked["at"] > _STOP_CHECK_S:
            checked["stop"] = bool(ray.get(hub.stopped.remote(key)))
            checked["at"] = time.monotonic()
        return checked["stop"]

    with tempfile.TemporaryDirectory(prefix="avs-task-") as tmp:
        spec = {**payload, "output_dir": tmp} if payload.get("output_dir") else payload
        try:
            value = resolve(runner)(spec, lambda e: hub.put.remote(key, dict(e)), should_stop)
        except Exception as exc:  # noqa: BLE001 - reported to the service, never lost
            return ("error", type(exc).__name__, str(exc) or traceback.format_exc(limit=3))
        finally:
            ray.get(hub.flush.remote())
        files = {p.name: p.read_bytes() for p in Path(tmp).iterdir() if p.is_file()}
    return ("result", value, files)


class _RaySlot(_Slot):
    """A slot whose job runs as a Ray task instead of in a child process of its own."""

    pool: RayWorkerPool

    def ensure_process(self) -> Any:  # nothing to pre-start: Ray keeps its own workers
        return None

    def kill(self) -> None:  # a running task is cancelled by `run`'s loop when stopping
        return None

    def run(self, job: Job) -> JobResult:
        key = uuid.uuid4().hex
        try:
            ref = self.pool.remote.remote(self.pool.episode_runner, job.payload,
                                          self.pool.hub, key)
            return self._watch_task(job, ref, key, time.monotonic() + job.time_limit_s)
        finally:
            self.pool.hub.forget.remote(key)

    def _watch_task(self, job: Job, ref: Any, key: str, deadline: float) -> JobResult:
        ray, stop_sent_at = self.pool.ray, None
        while True:
            if self.pool.stopping.is_set():
                ray.cancel(ref, force=True)
                return JobResult(JobOutcome.SHUTDOWN, error="service stopped")
            if job.cancel.is_set() and stop_sent_at is None:
                stop_sent_at = time.monotonic()
                self.pool.hub.stop.remote(key)
            if stop_sent_at is not None and time.monotonic() - stop_sent_at > self.pool.grace_s:
                ray.cancel(ref, force=True)
                return JobResult(JobOutcome.CANCELLED, error="cancelled; task killed")
            if time.monotonic() > deadline:
                ray.cancel(ref, force=True)
                limit = f"{job.time_limit_s:g}"
                return JobResult(JobOutcome.TIMEOUT, error=f"wall-clock limit {limit} s exceeded")
            ready, _ = ray.wait([ref], timeout=_POLL_S)
            self._relay(job, key)
            if ready:
                result = self._result(job, ref)
                if stop_sent_at is not None and result.outcome is not JobOutcome.CRASHED:
                    return JobResult(JobOutcome.CANCELLED, result.value, "cancelled")
                return result

    def _relay(self, job: Job, key: str) -> None:
        for event in self.pool.ray.get(self.pool.hub.drain.remote(key)):
            job.on_event(event)

    def _result(self, job: Job, ref: Any) -> JobResult:
        try:
            message = self.pool.ray.get(ref)
        except self.pool.ray.exceptions.RayError as exc:
            first = (str(exc).strip().splitlines() or [""])[0]
            return JobResult(JobOutcome.CRASHED, error=f"Ray task failed: {first}"[:500])
        if message[0] == "error":
            return JobResult(JobOutcome.ERROR, error=message[2], error_type=message[1])
        out = job.payload.get("output_dir")
        if out:
            Path(out).mkdir(parents=True, exist_ok=True)
            for name, data in message[2].items():
                (Path(out) / name).write_bytes(data)
        return JobResult(JobOutcome.DONE, value=message[1])


class RayWorkerPool(WorkerPool):
    """`size` episode jobs at a time as Ray tasks on the cluster at `address` ('local': start
    a Ray instance on this machine)."""

    def __init__(self, name: str, size: int, address: str, episode_runner: str, grace_s: float):
        super().__init__(name, size, 0, {"episode": episode_runner}, grace_s, warm=False)
        self.episode_runner = episode_runner
        self.address = address
        self._slots = [_RaySlot(self, i) for i in range(size)]
        self.ray: Any = None
        self.hub: Any = None
        self.remote: Any = None
        self._owns_ray = False

    def start(self) -> None:
        import ray

        self.ray = ray
        if not ray.is_initialized():
            _init(ray, self.address)
            self._owns_ray = True
        self.hub = ray.remote(num_cpus=0)(_Hub).remote()
        self.remote = ray.remote(num_cpus=1, max_retries=0)(run_remote)
        log.info("episode tasks run on Ray at %s", self.address)
        super().start()

    def stop(self) -> None:
        super().stop()
        if self._owns_ray and self.ray is not None and self.ray.is_initialized():
            self.ray.shutdown()


def _init(ray: Any, address: str) -> None:
    """Join the cluster at `address`, or start Ray here ('local'; its workers find this
    checkout on PYTHONPATH; on a cluster every node has the project installed)."""
    if address != "local":
        ray.init(address=address, log_to_driver=False)
        return
    root = str(Path(__file__).resolve().parents[1])
    path = os.pathsep.join(p for p in (root, os.environ.get("PYTHONPATH")) if p)
    ray.init(include_dashboard=False, log_to_driver=False,
             runtime_env={"env_vars": {"PYTHONPATH": path}})
