"""The service under an operator, against a real `avs serve` process: one instance per data
dir, a forged X-Forwarded-For does not escape the rate limit, SIGTERM with an open stream is
quick and the task resumes, and a plan client that hangs up frees its worker."""

from __future__ import annotations

import json
import signal
import subprocess
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest

from avs_planner.cli.serve import EXIT_DATA_DIR_BUSY
from tests.api.api_fake_planner import RUNNER as FAKE_PLANNER
from tests.api.test_api_serve import _call, _free_port, _server, _wait_state, serve_command


def _data_dir(tmp_path: Path) -> Path:
    (tmp_path / "worlds").mkdir()
    (tmp_path / "worlds" / "office.yaml").write_text("name: office\n")
    return tmp_path


def _status(url: str, method: str = "GET", body: dict | None = None,
            headers: dict[str, str] | None = None, timeout: float = 10) -> int:
    data = json.dumps(body).encode() if body is not None else None
    request = urllib.request.Request(url, data, {"Content-Type": "application/json",
                                                 **(headers or {})}, method=method)
    try:
        with urllib.request.urlopen(request, timeout=timeout) as response:
            return response.status
    except urllib.error.HTTPError as error:
        return error.code


def test_second_instance_exits_and_leaves_the_first_alone(tmp_path: Path) -> None:
    data = _data_dir(tmp_path)
    port = _free_port()
    base = f"http://127.0.0.1:{port}"
    with _server(data, port, AVS_RATE_LIMIT_BURST="4", AVS_RATE_LIMIT_PER_MINUTE="1"):
        task = _call(f"{base}/v1/tasks", {"target": "slow", "world": "office"})
        _wait_state(base, task["id"], {"running"})
        command, env = serve_command(data, _free_port())
        second = subprocess.run(command, env=env, capture_output=True, text=True, timeout=60)
        assert second.returncode == EXIT_DATA_DIR_BUSY
        assert "in use by another avs serve" in second.stderr
        assert _call(f"{base}/v1/tasks/{task['id']}")["state"] == "running"
        assert _call(f"{base}/v1/health")["running"] == 1
        assert _status(f"{base}/v1/tasks/{task['id']}", "DELETE") == 200  # 2nd limited call
        # X-Forwarded-For from a loopback peer is not trusted unless configured
        codes = [_status(f"{base}/v1/tasks/{'0' * 32}", "DELETE",
                         headers={"X-Forwarded-For": f"10.0.0.{i}"}) for i in range(3)]
        assert codes == [404, 404, 429]


@pytest.mark.slow  # two service start-ups
def test_sigterm_with_open_stream_is_quick_and_the_task_resumes(tmp_path: Path) -> None:
    data = _data_dir(tmp_path)
    port = _free_port()
    base = f"http://127.0.0.1:{port}"
    received: list[str] = []
    with _server(data, port, AVS_ON_RESTART="requeue") as process:
        task = _call(f"{base}/v1/tasks", {"target": "slow", "world": "office"})
        _wait_state(base, task["id"], {"running"})

        def read() -> None:
            with urllib.request.urlopen(f"{base}/v1/tasks/{task['id']}/events", timeout=30) as r:
                received.extend(line.decode() for line in r)

        reader = threading.Thread(target=read)
        reader.start()
        time.sleep(0.5)
        started = time.monotonic()
        process.send_signal(signal.SIGTERM)
        process.wait(timeout=30)
        took = time.monotonic() - started
        reader.join(timeout=5)
    assert took < 30, f"shutdown took {took:.1f} s"  # not the 900 s task limit
    assert process.returncode in (0, -signal.SIGTERM)  # uvicorn re-raises the signal
    assert "event: shutdown\n" in received
    last_id = max(int(line[4:]) for line in received if line.startswith("id: "))
    with _server(data, port, AVS_ON_RESTART="requeue"):
        resumed = _wait_state(base, task["id"], {"running"})
        assert resumed["attempts"] == 2
        request = urllib.request.Request(f"{base}/v1/tasks/{task['id']}/events",
                                         headers={"Last-Event-ID": str(last_id)})
        with urllib.request.urlopen(request, timeout=10) as response:
            first = [response.readline().decode() for _ in range(3)]
        assert first[0] == "event: state\n" and "requeued" in first[1]
        assert first[2] == f"id: {last_id + 1}\n"


def test_plan_client_that_hangs_up_frees_its_worker(tmp_path: Path) -> None:
    data = _data_dir(tmp_path)
    port = _free_port()
    base = f"http://127.0.0.1:{port}"
    with _server(data, port, AVS_PLAN_RUNNER=FAKE_PLANNER):
        with pytest.raises(TimeoutError):
            _status(f"{base}/v1/plans", "POST", {"domain": "d", "problem": "sleep 60"},
                    timeout=1)
        started = time.monotonic()
        code = _status(f"{base}/v1/plans", "POST", {"domain": "d", "problem": "sleep 0.1"},
                       timeout=20)
        took = time.monotonic() - started
    assert code == 200 and took < 30, f"{code} after {took:.1f} s"  # the other job takes 60 s
