"""The service's one settings object, read from `AVS_*` environment variables."""

from __future__ import annotations

import ipaddress
from pathlib import Path
from typing import Literal

from pydantic import Field, model_validator
from pydantic_settings import BaseSettings, SettingsConfigDict

DEFAULT_EPISODE_RUNNER = "avs_planner.jobs:run_episode"
DEFAULT_PLAN_RUNNER = "avs_planner.jobs:plan"
DEFAULT_TASK_CHECKER = "avs_planner.harness.validate:check_task"


class Settings(BaseSettings):
    """Everything the service can be told; `AVS_API_KEY` sets `api_key`, and so on."""

    model_config = SettingsConfigDict(env_prefix="AVS_", extra="ignore")

    api_key: str | None = Field(None, description="an admin key, required in X-API-Key (the "
                                "original single-key setting; see also api_keys, keys_file)")
    api_keys: str | None = Field(
        None, description="more keys, 'NAME:ROLE:KEY' separated by commas or spaces; ROLE is "
        "read, submit or admin")
    keys_file: Path | None = Field(
        None, description="a YAML or JSON file of keys: {keys: [{name, role, key or "
        "key_sha256, max_queued, max_plan_jobs}]}")
    open_reads: bool = Field(False, description="with keys set, let GET calls without a key "
                             "read every task (as before keys had roles)")
    key_max_queued: int = Field(4, ge=0, description="queued tasks per non-admin key (its "
                                "entry may say otherwise); 0: no limit")
    key_max_plan_jobs: int = Field(2, ge=0, description="plan/check jobs in flight per "
                                   "non-admin key; 0: no limit")
    host: str = "127.0.0.1"
    port: int = Field(8000, ge=0, le=65535)
    data_dir: Path = Path(".avs-data")
    workers: int = Field(2, ge=1, le=64, description="processes running episodes")
    plan_workers: int = Field(2, ge=1, le=64, description="processes running plans/checks")
    queue_size: int = Field(16, ge=1, description="queued tasks accepted before 503")
    plan_queue_size: int = Field(8, ge=1, description="waiting plan/check jobs before 503")
    task_time_limit_s: float = Field(900.0, gt=0, description="wall clock per episode")
    plan_time_limit_s: float = Field(60.0, gt=0, description="wall clock per plan/check job")
    cancel_grace_s: float = Field(2.0, ge=0, description="time to stop before a kill")
    worker_nice: int = Field(10, ge=0, le=19, description="CPU niceness of worker processes")
    memory_limit_mb: int = Field(2048, ge=0, description="address-space limit per worker; 0=none")
    max_body_bytes: int = Field(1_000_000, ge=1024)
    rate_limit_per_minute: float = Field(120.0, gt=0, description="mutating calls per key")
    rate_limit_burst: int = Field(30, ge=1)
    on_restart: Literal["fail", "requeue"] = "fail"
    episode_runner: str = Field(
        DEFAULT_EPISODE_RUNNER, description="'module:function' or '/path/file.py:function'"
    )
    plan_runner: str = Field(DEFAULT_PLAN_RUNNER, description="the plan job's function "
                             "('module:function' or '/path/file.py:function')")
    warm_workers: bool = Field(True, description="start episode workers before the first task")
    preload_planner: bool = Field(True, description="import the planner in job workers at start")
    worlds_dir: Path | None = Field(None, description="built-in worlds; default: sim/worlds")
    task_checker: str | None = Field(
        DEFAULT_TASK_CHECKER, description="'module:function' checking a task against its world "
        "and the knowledge base at submission (422); empty: no check")
    forwarded_allow_ips: str | None = Field(
        None, description="comma-separated proxy addresses whose X-Forwarded-For/-Proto are "
        "trusted ('*' for any); default: none, the TCP peer is the client")
    plan_results_kept: int = Field(100, ge=1, le=10_000, description="finished async plan jobs "
                                   "kept for polling (oldest dropped first)")
    record: bool | None = Field(
        None, description="write a Rerun recording (recording.rrd) of each task's episode; "
        "needs memory_limit_mb=0 (the recorder reserves more address space than the limit "
        "allows and the worker dies); default: when the viewer extra (rerun-sdk) is "
        "installed, episodes run locally and there is no address-space limit")
    ray_address: str | None = Field(
        None, description="run episode tasks as Ray tasks on this cluster ('local': start Ray "
        "on this machine); default: local worker processes"
    )

    @model_validator(mode="after")
    def _recording_needs_no_address_limit(self) -> Settings:
        if self.record and self.memory_limit_mb > 0:
            raise ValueError(
                f"record (AVS_RECORD=1) needs memory_limit_mb=0 (AVS_MEMORY_LIMIT_MB=0), got "
                f"{self.memory_limit_mb}: the Rerun recorder reserves more address space than "
                f"the limit allows and the worker process dies")
        return self

    @property
    def db_path(self) -> Path:
        return self.data_dir / "avs.sqlite3"

    @property
    def tasks_dir(self) -> Path:
        return self.data_dir / "tasks"

    @property
    def buildings_dir(self) -> Path:
        """`buildings/ID/memory/`: each building's memory (docs/memory.md)."""
        return self.data_dir / "buildings"

    @property
    def experience_path(self) -> Path:
        """The experience store every building's tasks learn into (docs/learning.md)."""
        return self.data_dir / "experience.sqlite3"

    def records(self) -> bool:
        """Whether episodes write recording.rrd (AVS_RECORD, else: the viewer extra is
        installed here and episodes run here, not on a Ray cluster that may lack it)."""
        if self.record is not None:
            return self.record
        import importlib.util

        return (self.ray_address is None and self.memory_limit_mb == 0
                and importlib.util.find_spec("rerun") is not None)

    def is_open(self) -> bool:
        """True when no API key is configured (then the service must stay on loopback)."""
        return not (self.api_key or (self.api_keys or "").strip() or self.keys_file)


def is_loopback(host: str) -> bool:
    """Whether `host` names only this machine (so an open service is not reachable from outside)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False
