"""`avs serve` as a real process: refuses an open non-loopback bind; survives a SIGKILL."""

from __future__ import annotations

import argparse
import json
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from avs_planner.cli import EXIT_BAD_INPUT, main, serve

FAKE_RUNNER = f"{Path(__file__).with_name('api_fake_runner.py').resolve()}:run"


def _args(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    serve.register(parser.add_subparsers())
    return parser.parse_args(["serve", *argv])


def test_open_service_refuses_public_bind(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("AVS_API_KEY", raising=False)
    with pytest.raises(serve.ServeError, match="without an API key"):
        serve.run(_args("--host", "0.0.0.0"))


def test_bad_settings_are_bad_input() -> None:
    with pytest.raises(serve.ServeError, match="workers"):
        serve.run(_args("--workers", "0"))


def test_cli_maps_serve_errors_to_exit_1(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(serve, "_serve", lambda *args: pytest.fail("must not serve"))
    assert main(["serve", "--port", "-1"]) == EXIT_BAD_INPUT
    assert "port" in capsys.readouterr().err


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _call(url: str, body: dict | None = None) -> dict:
    data = json.dumps(body).encode() if body is not None else None
    request = urllib.request.Request(url, data, {"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=5) as response:
        return json.loads(response.read())


def serve_command(data_dir: Path, port: int, **env: str) -> tuple[list[str], dict[str, str]]:
    """`avs serve` on `data_dir` with the fake runner and no task checker, and its environment."""
    environ = {**os.environ, "AVS_EPISODE_RUNNER": FAKE_RUNNER, "AVS_PRELOAD_PLANNER": "false",
               "AVS_WORLDS_DIR": str(data_dir / "worlds"), "AVS_TASK_CHECKER": "",
               "AVS_WORKERS": "1", "AVS_PLAN_WORKERS": "1", **env}
    environ.pop("AVS_API_KEY", None)
    command = [sys.executable, "-m", "avs_planner", "serve", "--port", str(port),
               "--data-dir", str(data_dir), "--log-level", "warning"]
    return command, environ


@contextmanager
def _server(data_dir: Path, port: int, **env: str) -> Iterator[subprocess.Popen[bytes]]:
    command, environ = serve_command(data_dir, port, **env)
    process = subprocess.Popen(command, env=environ, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 30
        while True:
            try:
                _call(f"http://127.0.0.1:{port}/v1/health")
                break
            except (urllib.error.URLError, ConnectionError):
                assert process.poll() is None and time.monotonic() < deadline, "did not start"
                time.sleep(0.1)
        yield process
    finally:
        if process.poll() is None:
            process.terminate()
            process.wait(timeout=15)


def _wait_state(base: str, task_id: str, states: set[str]) -> dict:
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        task = _call(f"{base}/v1/tasks/{task_id}")
        if task["state"] in states:
            return task
        time.sleep(0.05)
    raise AssertionError(f"{task_id} never reached {states}")


@pytest.mark.slow  # two real service start-ups: ~10 s on a busy 2-core machine
def test_sigkill_mid_task_then_restart_accounts_for_it(tmp_path: Path) -> None:
    (tmp_path / "worlds").mkdir()
    (tmp_path / "worlds" / "office.yaml").write_text("name: office\n")
    port = _free_port()
    base = f"http://127.0.0.1:{port}"
    with _server(tmp_path, port) as process:
        task = _call(f"{base}/v1/tasks", {"target": "slow", "world": "office"})
        _wait_state(base, task["id"], {"running"})
        process.send_signal(signal.SIGKILL)
        process.wait(timeout=10)
    with _server(tmp_path, port):
        after = _call(f"{base}/v1/tasks/{task['id']}")
        assert after["state"] == "failed" and "interrupted" in after["error"]
        health = _call(f"{base}/v1/health")
        assert (health["queued"], health["running"]) == (0, 0)


def test_unusable_data_dir_is_bad_input(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    with pytest.raises(serve.ServeError, match="cannot use data dir"):
        serve.run(_args("--data-dir", str(blocker / "data")))


def test_busy_port_is_bad_input_before_the_app_starts(tmp_path: Path) -> None:
    """Exit 1 with a message (not uvicorn's 3, which the CLI uses for timeouts), and a fresh
    data dir is left as it was: not created, no lock file, no store."""
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        with pytest.raises(serve.ServeError, match="cannot listen on 127.0.0.1"):
            serve.run(_args("--port", str(port), "--data-dir", str(tmp_path / "data")))
    assert not (tmp_path / "data").exists()


def test_data_dir_held_by_another_process_exits_5(tmp_path: Path) -> None:
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys, time; from pathlib import Path; from api import lock; "
         "lock.acquire(Path(sys.argv[1])); print('held', flush=True); time.sleep(60)",
         str(tmp_path)], stdout=subprocess.PIPE, cwd=Path(__file__).resolve().parents[2])
    try:
        assert holder.stdout is not None and holder.stdout.readline() == b"held\n"
        assert main(["serve", "--data-dir", str(tmp_path), "--port", "0"]) == 5
        assert not (tmp_path / "avs.sqlite3").exists()  # no recovery ran
    finally:
        holder.kill()
        holder.wait()
