"""API-key check and a per-client token-bucket rate limit for mutating calls."""

from __future__ import annotations

import hashlib
import secrets
import threading
import time
from dataclasses import dataclass


def key_matches(given: str | None, expected: str) -> bool:
    """Constant-time comparison of the client's key with the configured one."""
    return given is not None and secrets.compare_digest(given.encode(), expected.encode())


def owner_of(api_key: str | None, client_host: str) -> str:
    """Who a request belongs to (for idempotency and rate limits): the key's hash, or the host."""
    if api_key:
        return "key:" + hashlib.sha256(api_key.encode()).hexdigest()[:16]
    return "host:" + client_host


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
