"""HTTP service load: req/s and p50/p99 latency of GET /v1/tasks/{id} while episodes run.

Starts `avs serve` on 127.0.0.1 (a free port, a temporary data dir), then measures the same
request loop in phases of one run: the idle service (the reference), then with two episodes
running. Episodes come from the real runner (`avs_planner.harness.run_episode`) when it exists;
otherwise, or with --synthetic, from the synthetic runner below, in two flavours: streaming
events but barely using the CPU, and keeping both cores busy. The output says which.

    .venv/bin/python -m bench.api_bench [--quick] [--synthetic] [--requests N] [--connections C]
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from avs_planner.jobs import episode_runner_available

TARGET_RPS = 300.0
TARGET_P99_MS = 50.0
SYNTHETIC_RUNNER = f"{Path(__file__).resolve()}:synthetic_episode"


def synthetic_episode(spec: dict[str, Any], emit: Any, should_stop: Any) -> dict[str, Any]:
    """A stand-in episode for load testing only: emits a trace event every 50 ms; target
    'busy' also spins the CPU between events. Stops when asked (or after 10 minutes)."""
    start = time.monotonic()
    step = 0
    while not should_stop() and time.monotonic() - start < 600:
        emit({"t": float(step), "wall": time.monotonic() - start, "type": "action", "step": step})
        step += 1
        until = time.monotonic() + 0.05
        while time.monotonic() < until:
            if spec["target"] != "busy":
                time.sleep(0.01)
    return {"outcome": "gave_up", "steps": step}


@dataclass(frozen=True)
class Phase:
    name: str
    requests: int
    seconds: float
    p50_ms: float
    p99_ms: float
    errors: int
    server_cpu_ms: float  # the service process's CPU time per request (load-independent)

    @property
    def rps(self) -> float:
        return self.requests / self.seconds


async def _connection(port: int, path: str, count: int, latencies: list[float]) -> int:
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    request = f"GET {path} HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n".encode()
    errors = 0
    for _ in range(count):
        began = time.perf_counter()
        writer.write(request)
        await writer.drain()
        status = await reader.readline()
        length = 0
        while (line := await reader.readline()) not in (b"\r\n", b""):
            if line.lower().startswith(b"content-length:"):
                length = int(line.split(b":", 1)[1])
        await reader.readexactly(length)
        latencies.append(time.perf_counter() - began)
        errors += not status.startswith(b"HTTP/1.1 200")
    writer.close()
    return errors


async def _load(port: int, path: str, requests: int, connections: int) -> tuple[list[float], int]:
    latencies: list[float] = []
    per = requests // connections
    errors = await asyncio.gather(
        *(_connection(port, path, per, latencies) for _ in range(connections))
    )
    return latencies, sum(errors)


def server_cpu_s(pid: int) -> float:
    """User + system CPU seconds of a process so far (Linux /proc)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def measure(
    name: str, server: int, port: int, path: str, requests: int, connections: int,
    rounds: int = 3,
) -> Phase:
    """`rounds` timed rounds after a warm-up; req/s is the median round's, latencies pooled
    (the median damps other load on a shared machine)."""
    asyncio.run(_load(port, path, max(connections, requests // 10), connections))  # warm up
    rates: list[float] = []
    latencies: list[float] = []
    errors = 0
    cpu_before = server_cpu_s(server)
    for _ in range(rounds):
        began = time.perf_counter()
        got, failed = asyncio.run(_load(port, path, requests // rounds, connections))
        rates.append(len(got) / (time.perf_counter() - began))
        latencies += got
        errors += failed
    cpu_ms = (server_cpu_s(server) - cpu_before) * 1e3 / len(latencies)
    cuts = statistics.quantiles(latencies, n=100)
    rate = statistics.median(rates)
    return Phase(name, len(latencies), len(latencies) / rate, cuts[49] * 1e3, cuts[98] * 1e3,
                 errors, cpu_ms)


def _call(port: int, path: str, body: dict | None = None, method: str | None = None) -> dict:
    data = json.dumps(body).encode() if body is not None else None
    request = urllib.request.Request(
        f"http://127.0.0.1:{port}{path}", data, {"Content-Type": "application/json"},
        method=method,
    )
    with urllib.request.urlopen(request, timeout=10) as response:
        return json.loads(response.read())


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def start_service(
    data_dir: Path, runner: str, worlds_dir: Path | None
) -> tuple[subprocess.Popen[bytes], int]:
    port = _free_port()
    env = {**os.environ, "AVS_EPISODE_RUNNER": runner, "AVS_PRELOAD_PLANNER": "false",
           "AVS_WORKERS": "2", "AVS_RATE_LIMIT_BURST": "1000",
           "AVS_TASK_CHECKER": ""}  # the probes' targets ("calm", "busy") are no labels
    if worlds_dir is not None:
        env["AVS_WORLDS_DIR"] = str(worlds_dir)
    env.pop("AVS_API_KEY", None)
    command = [sys.executable, "-m", "avs_planner", "serve", "--host", "127.0.0.1",
               "--port", str(port), "--data-dir", str(data_dir), "--log-level", "warning"]
    process = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            _call(port, "/v1/health")
            return process, port
        except OSError:
            time.sleep(0.2)
    process.kill()
    raise SystemExit("api_bench: the service did not start within 60 s")


def run_episodes(port: int, target: str, world: str) -> list[str]:
    """Submit two episodes and wait until both are running."""
    ids = [_call(port, "/v1/tasks", {"target": target, "world": world})["id"] for _ in range(2)]
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        tasks = [_call(port, f"/v1/tasks/{i}") for i in ids]
        if all(t["state"] == "running" for t in tasks):
            return ids
        if any(t["state"] not in ("queued", "running") for t in tasks):
            ended = [(t["state"], t["error"]) for t in tasks]
            raise SystemExit(f"api_bench: episodes ended early: {ended}")
        time.sleep(0.1)
    raise SystemExit("api_bench: episodes did not start")


def stop_episodes(port: int, ids: list[str]) -> None:
    for task_id in ids:
        try:
            _call(port, f"/v1/tasks/{task_id}", method="DELETE")
        except urllib.error.HTTPError as exc:  # 409: it already ended
            if exc.code != 409:
                raise


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer requests per phase")
    parser.add_argument("--requests", type=int, help="requests per phase (default 4000)")
    parser.add_argument("--connections", type=int, default=4)
    parser.add_argument("--synthetic", action="store_true",
                        help="use the synthetic episodes even when the real runner exists")
    args = parser.parse_args(argv)
    requests = args.requests or (800 if args.quick else 4000)
    real = not args.synthetic and episode_runner_available()
    runner = "avs_planner.jobs:run_episode" if real else SYNTHETIC_RUNNER
    with tempfile.TemporaryDirectory(prefix="avs-api-bench-") as tmp:
        worlds = None
        if not real:  # the synthetic runner never loads it; a name is all the API checks
            worlds = Path(tmp) / "worlds"
            worlds.mkdir()
            (worlds / "office.yaml").write_text("name: office\n")
        process, port = start_service(Path(tmp) / "data", runner, worlds)
        try:
            phases = _phases(process.pid, port, real, requests, args.connections)
        finally:
            process.terminate()
            process.wait(timeout=30)
    _report(phases, real, requests, args.connections)
    return 0


def _phases(
    server: int, port: int, real: bool, requests: int, connections: int
) -> list[Phase]:
    world = "office"
    probes = run_episodes(port, "calm", world)  # also makes sure both workers are up
    stop_episodes(port, probes)
    path = f"/v1/tasks/{probes[0]}"
    while _call(port, path)["state"] == "running":
        time.sleep(0.1)
    phases = [measure("idle service (reference)", server, port, path, requests, connections)]
    loads = [("cerealbox", "2 real episodes")] if real else [
        ("calm", "2 synthetic episodes, events only"),
        ("busy", "2 synthetic episodes, CPU-bound"),
    ]
    for target, name in loads:
        ids = run_episodes(port, target, world)
        path = f"/v1/tasks/{ids[0]}"
        phase = measure(name, server, port, path, requests, connections)
        live = sum(_call(port, f"/v1/tasks/{i}")["state"] == "running" for i in ids)
        phases.append(replace(phase, name=f"{name} ({live}/2 still running at end)"))
        stop_episodes(port, ids)
    return phases


def _report(phases: list[Phase], real: bool, requests: int, connections: int) -> None:
    source = "the real episode runner" if real else "a SYNTHETIC episode runner"
    print(f"GET /v1/tasks/{{id}}: {requests} requests/phase (3 rounds, median req/s) over "
          f"{connections} keep-alive connections; episodes from {source}; "
          f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f}")
    ref = phases[0]
    print(f"{'phase':58} {'req/s':>7} {'p50 ms':>7} {'p99 ms':>7} {'err':>4} "
          f"{'rps/ref':>7} {'p99/ref':>7} {'cpu ms/req':>10} {'cpu/ref':>7}")
    for p in phases:
        print(f"{p.name:58} {p.rps:7.0f} {p.p50_ms:7.2f} {p.p99_ms:7.2f} {p.errors:4d} "
              f"{p.rps / ref.rps:7.2f} {p.p99_ms / ref.p99_ms:7.2f} {p.server_cpu_ms:10.3f} "
              f"{p.server_cpu_ms / ref.server_cpu_ms:7.2f}")
    print(f"service CPU per request {ref.server_cpu_ms:.2f} ms idle: one free core would serve "
          f"~{1000 / ref.server_cpu_ms:.0f} req/s")
    worst = phases[1:] or phases
    ok_rps = all(p.rps >= TARGET_RPS for p in worst)
    ok_p99 = all(p.p99_ms <= TARGET_P99_MS for p in worst)
    print(f"target with episodes running: >= {TARGET_RPS:.0f} req/s "
          f"({'met' if ok_rps else 'MISSED'}), p99 <= {TARGET_P99_MS:.0f} ms "
          f"({'met' if ok_p99 else 'MISSED'})")


if __name__ == "__main__":
    sys.exit(main())
