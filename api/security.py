"""API keys with roles, who a request belongs to, and a per-client token-bucket rate limit.

Keys come from `AVS_API_KEY` (one admin key, the original setting), `AVS_API_KEYS`
(`NAME:ROLE:KEY` entries) and `AVS_KEYS_FILE` (YAML or JSON, keys in clear or as SHA-256).
Roles are ordered: `read` reads tasks and plan jobs, `submit` also creates and cancels them,
`admin` also sees and cancels everyone's. A key sees the tasks of its owner: keys with the same
`name` share an owner (e.g. a submit key and a dashboard's read key), a key without one is its
own owner; admin keys see all.
"""

from __future__ import annotations

import hashlib
import json
import logging
import re
import secrets
import threading
import time
from dataclasses import dataclass
from enum import IntEnum
from pathlib import Path
from typing import Any

import yaml

from api.config import Settings

log = logging.getLogger("avs.api.security")
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")
_HEX = re.compile(r"^[0-9a-f]{64}$")


class Role(IntEnum):
    READ = 1
    SUBMIT = 2
    ADMIN = 3

    @property
    def label(self) -> str:
        return self.name.lower()


class KeySettingsError(ValueError):
    """The key settings are wrong (raised at start-up, naming the entry)."""


@dataclass(frozen=True)
class Caller:
    """Who made a request: its owner id (tasks, idempotency keys, quotas and rate limits are
    per owner), its role, whether it sees everyone's tasks, and its quotas (None: none)."""

    owner: str
    role: Role
    name: str
    sees_all: bool = False
    max_queued: int | None = None
    max_plan_jobs: int | None = None

    def may_see(self, owner: str) -> bool:
        return self.sees_all or owner == self.owner


@dataclass(frozen=True)
class ApiKey:
    name: str
    role: Role
    digest: bytes  # SHA-256 of the key
    owner: str
    max_queued: int | None
    max_plan_jobs: int | None

    def caller(self, open_reads: bool = False) -> Caller:
        return Caller(self.owner, self.role, self.name,
                      sees_all=self.role is Role.ADMIN or open_reads,
                      max_queued=self.max_queued, max_plan_jobs=self.max_plan_jobs)


def key_matches(given: str | None, expected: str) -> bool:
    """Constant-time comparison of the client's key with a configured one."""
    return given is not None and secrets.compare_digest(given.encode(), expected.encode())


def owner_of(api_key: str | None, client_host: str) -> str:
    """Who a request belongs to (for idempotency and rate limits): the key's hash, or the host."""
    if api_key:
        return "key:" + hashlib.sha256(api_key.encode()).hexdigest()[:16]
    return "host:" + client_host


class KeyRing:
    """The configured keys; `find` looks one up by the client's key in constant time."""

    def __init__(self, keys: list[ApiKey], open_reads: bool = False):
        self.keys = keys
        self.open_reads = open_reads

    @property
    def open(self) -> bool:
        """No keys: every call is allowed (and the service must stay on loopback)."""
        return not self.keys

    def find(self, given: str | None) -> ApiKey | None:
        if not given:
            return None
        digest = hashlib.sha256(given.encode(errors="replace")).digest()
        found = None
        for key in self.keys:  # no early exit: the time does not say which key matched
            if secrets.compare_digest(digest, key.digest):
                found = key
        return found

    @classmethod
    def from_settings(cls, settings: Settings) -> KeyRing:
        """The keys of `AVS_API_KEY`, `AVS_API_KEYS` and `AVS_KEYS_FILE`; `KeySettingsError` names a
        bad entry (unknown role, a key given twice, an unreadable file)."""
        quotas = (settings.key_max_queued or None, settings.key_max_plan_jobs or None)
        keys: list[ApiKey] = []
        if settings.api_key:
            keys.append(_key("admin", "admin", settings.api_key, None, (None, None),
                             owner=owner_of(settings.api_key, "")))
        for i, entry in enumerate((settings.api_keys or "").replace(",", " ").split()):
            parts = entry.split(":", 2)
            if len(parts) != 3 or not all(parts):
                raise KeySettingsError(f"AVS_API_KEYS entry {i + 1} is not NAME:ROLE:KEY")
            keys.append(_key(parts[0], parts[1], parts[2], None, quotas,
                             where=f"AVS_API_KEYS entry {i + 1}"))
        if settings.keys_file is not None:
            keys.extend(_file_keys(settings.keys_file, quotas))
        digests = [k.digest for k in keys]
        if len(set(digests)) != len(digests):
            raise KeySettingsError("the same key is configured twice; give each key one role")
        return cls(keys, settings.open_reads)


def _key(name: str, role: str, key: str | None, key_sha256: str | None,
         quotas: tuple[int | None, int | None], owner: str | None = None,
         where: str = "AVS_API_KEY", max_queued: Any = None, max_plan_jobs: Any = None
         ) -> ApiKey:
    if not _NAME.match(str(name)):
        raise KeySettingsError(f"{where}: name {str(name)[:40]!r} must be letters, digits, "
                               "'_', '.' or '-' (at most 64)")
    try:
        parsed = Role[str(role).upper()]
    except KeyError:
        raise KeySettingsError(f"{where}: role {str(role)[:20]!r} is not read, submit or "
                               "admin") from None
    if key:
        digest = hashlib.sha256(str(key).encode()).digest()
    elif key_sha256 and _HEX.match(str(key_sha256).lower()):
        digest = bytes.fromhex(str(key_sha256).lower())
    else:
        raise KeySettingsError(f"{where}: give 'key' or 'key_sha256' (64 hex digits)")
    admin = parsed is Role.ADMIN
    limits = []
    for value, default, what in ((max_queued, quotas[0], "max_queued"),
                                 (max_plan_jobs, quotas[1], "max_plan_jobs")):
        if value is None:
            limits.append(None if admin else default)
        elif isinstance(value, int) and not isinstance(value, bool) and value >= 0:
            limits.append(value or None)
        else:
            raise KeySettingsError(f"{where}: {what} must be a whole number >= 0 (0: no limit)")
    return ApiKey(str(name), parsed, digest, owner or f"user:{name}", limits[0], limits[1])


def _file_keys(path: Path, quotas: tuple[int | None, int | None]) -> list[ApiKey]:
    try:
        text = path.read_text(encoding="utf-8")
        mode = path.stat().st_mode
    except OSError as exc:
        raise KeySettingsError(f"keys file {path}: {exc.strerror or exc}") from None
    if mode & 0o077:
        log.warning("keys file %s is readable by other users (mode %o); chmod 600 it", path,
                    mode & 0o777)
    try:
        data = json.loads(text) if path.suffix == ".json" else yaml.safe_load(text)
    except (ValueError, yaml.YAMLError) as exc:
        kind = path.suffix.lstrip(".") or "YAML"
        raise KeySettingsError(f"keys file {path} is not valid {kind}: {str(exc)[:200]}"
                               ) from None
    entries = data.get("keys") if isinstance(data, dict) else None
    if not isinstance(entries, list):
        raise KeySettingsError(f"keys file {path} must be a mapping with a list 'keys'")
    keys = []
    for i, entry in enumerate(entries):
        where = f"keys file {path}, keys[{i}]"
        if not isinstance(entry, dict):
            raise KeySettingsError(f"{where} must be a mapping (name, role, key)")
        unknown = set(entry) - {"name", "role", "key", "key_sha256", "max_queued",
                                "max_plan_jobs"}
        if unknown:
            names = ", ".join(sorted(map(str, unknown)))
            raise KeySettingsError(f"{where}: unknown field(s) {names}")
        keys.append(_key(entry.get("name", ""), entry.get("role", ""), entry.get("key"),
                         entry.get("key_sha256"), quotas, where=where,
                         max_queued=entry.get("max_queued"),
                         max_plan_jobs=entry.get("max_plan_jobs")))
    return keys


@dataclass
class _Bucket:
    tokens: float
    updated: float


class RateLimiter:
    """Token bucket per owner: `burst` calls at once, refilled at `per_minute` calls a minute."""

    def __init__(self, per_minute: float, burst: int):
        self.rate = per_minute / 60.0
        self.burst = float(burst)
        self._buckets: dict[str, _Bucket] = {}
        self._lock = threading.Lock()

    def acquire(self, owner: str) -> float:
        """Take a token; returns 0 when allowed, else seconds until the next token."""
        now = time.monotonic()
        with self._lock:
            bucket = self._buckets.setdefault(owner, _Bucket(self.burst, now))
            bucket.tokens = min(self.burst, bucket.tokens + (now - bucket.updated) * self.rate)
            bucket.updated = now
            if bucket.tokens >= 1.0:
                bucket.tokens -= 1.0
                return 0.0
            return (1.0 - bucket.tokens) / self.rate
