"""The service under an operator: shutdown time with open event streams, and a
short plan's latency behind a long one.

1. `avs serve` with 2 running episodes (a stand-in runner that runs until stopped) and N open
   event streams gets SIGTERM: seconds until the process is gone (target <= 5 s), whether each
   stream got its `shutdown` event, and whether the tasks run again after a restart with
   AVS_ON_RESTART=requeue.
2. With 2 plan workers, a plan request behind a long search (a stand-in that sleeps L s): its
   latency minus its own planning time (target <= 1 s).

    .venv/bin/python -m bench.api_ops [--streams 100] [--long 60]
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path
from typing import Any

from bench.api_bench import SYNTHETIC_RUNNER

ROOT = Path(__file__).resolve().parents[1]
SLEEPY_PLANNER = f"{Path(__file__).resolve()}:sleepy_plan"
WORLD = "name: office\n"


def sleepy_plan(domain_text: str, problem_text: str, options: dict | None = None) -> dict:
    """Stand-in plan job: `sleep S` sleeps S seconds (a long search); else the real planner."""
    if problem_text.startswith("sleep "):
        time.sleep(float(problem_text.split()[1]))
        return {"status": "timeout", "plan": [], "planning_time_s": 0.0}
    from avs_planner import jobs

    return jobs.plan(domain_text, problem_text, options)


def _port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _call(url: str, body: dict | None = None, timeout: float = 30) -> Any:
    data = json.dumps(body).encode() if body is not None else None
    request = urllib.request.Request(url, data, {"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=timeout) as response:
        return json.loads(response.read())


def _status(url: str, body: dict) -> None:
    """POST and print the status (the long search's answer when the service stops)."""
    try:
        _call(url, body, timeout=300)
    except urllib.error.HTTPError as error:
        print(f"the long search's request ended with {error.code} when the service stopped")


def _start(data: Path, port: int, **env: str) -> subprocess.Popen[bytes]:
    environ = {**os.environ, "AVS_EPISODE_RUNNER": SYNTHETIC_RUNNER, "AVS_TASK_CHECKER": "",
               "AVS_WORLDS_DIR": str(data / "worlds"), "AVS_RATE_LIMIT_BURST": "1000",
               "PYTHONPATH": str(ROOT), **env}
    environ.pop("AVS_API_KEY", None)
    command = [sys.executable, "-m", "avs_planner", "serve", "--port", str(port),
               "--data-dir", str(data), "--log-level", "warning"]
    process = subprocess.Popen(command, env=environ, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while True:
        try:
            _call(f"http://127.0.0.1:{port}/v1/health", timeout=2)
            return process
        except (urllib.error.URLError, ConnectionError):
            if process.poll() is not None or time.monotonic() > deadline:
                raise SystemExit("the service did not start") from None
            time.sleep(0.1)


def _wait(base: str, task_id: str, state: str, timeout: float = 60) -> dict:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        task = _call(f"{base}/v1/tasks/{task_id}")
        if task["state"] == state:
            return task
        time.sleep(0.1)
    raise SystemExit(f"task {task_id} never reached {state}")


def shutdown(streams: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp)
        (data / "worlds").mkdir()
        (data / "worlds" / "office.yaml").write_text(WORLD)
        port = _port()
        base = f"http://127.0.0.1:{port}"
        env = {"AVS_WORKERS": "2", "AVS_ON_RESTART": "requeue", "AVS_PRELOAD_PLANNER": "false"}
        process = _start(data, port, **env)
        ids = [_call(f"{base}/v1/tasks", {"target": "idle", "world": "office"})["id"]
               for _ in range(2)]
        for task_id in ids:
            _wait(base, task_id, "running")
        ended: list[bool] = []

        def listen(task_id: str) -> None:
            try:
                with urllib.request.urlopen(f"{base}/v1/tasks/{task_id}/events",
                                            timeout=60) as response:
                    ended.append(b"event: shutdown" in response.read())
            except OSError:
                ended.append(False)

        readers = [threading.Thread(target=listen, args=(ids[i % 2],)) for i in range(streams)]
        for reader in readers:
            reader.start()
        time.sleep(2.0)
        started = time.monotonic()
        process.send_signal(signal.SIGTERM)
        process.wait(timeout=120)
        took = time.monotonic() - started
        for reader in readers:
            reader.join(timeout=10)
        print(f"shutdown with {streams} open streams and 2 running tasks: {took:.2f} s "
              f"(target <= 5 s); streams ended with a shutdown event: {sum(ended)}/{streams}; "
              f"exit status {process.returncode}")
        process = _start(data, port, **env)
        try:
            again = [_wait(base, task_id, "running") for task_id in ids]
            print(f"after restart (requeue): {len(again)} tasks running again, attempts "
                  f"{[t['attempts'] for t in again]}")
        finally:
            process.terminate()
            process.wait(timeout=30)


def fairness(long_s: float) -> None:
    domain = (ROOT / "domains/avs/domain.pddl").read_text()
    problem = (ROOT / "domains/avs/problems/corridor.pddl").read_text()
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp)
        (data / "worlds").mkdir()
        port = _port()
        base = f"http://127.0.0.1:{port}"
        process = _start(data, port, AVS_PLAN_WORKERS="2", AVS_PLAN_RUNNER=SLEEPY_PLANNER,
                         AVS_PLAN_TIME_LIMIT_S=str(long_s + 30))
        try:
            warm = [threading.Thread(target=_call, args=(f"{base}/v1/plans",
                                                         {"domain": domain, "problem": problem}))
                    for _ in range(2)]
            for thread in warm:
                thread.start()
            for thread in warm:
                thread.join()
            started = time.monotonic()
            alone = _call(f"{base}/v1/plans", {"domain": domain, "problem": problem})
            print(f"the short plan alone: {time.monotonic() - started:.2f} s (planning "
                  f"{alone['planning_time_s']:.2f} s)")
            long = threading.Thread(target=_status, args=(f"{base}/v1/plans", {
                "domain": domain, "problem": f"sleep {long_s:g}"}))
            long.start()
            time.sleep(1.0)
            started = time.monotonic()
            answer = _call(f"{base}/v1/plans", {"domain": domain, "problem": problem})
            took = time.monotonic() - started
            own = answer["planning_time_s"]
            print(f"short plan behind a {long_s:g} s search: {took:.2f} s, of which planning "
                  f"{own:.2f} s; the rest {took - own:.2f} s (target <= 1 s)")
        finally:
            process.terminate()
            process.wait(timeout=30)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--streams", type=int, default=100)
    parser.add_argument("--long", type=float, default=60.0)
    args = parser.parse_args()
    shutdown(args.streams)
    fairness(args.long)


if __name__ == "__main__":
    main()
