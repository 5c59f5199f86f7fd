"""The service with `ray_address`: episode tasks run as Ray tasks, with the same life cycle
(events, files, errors, cancel, kill, wall-clock limit) as with local worker processes."""

from __future__ import annotations

import argparse
import importlib.util
from collections.abc import Callable

import pytest
from fastapi.testclient import TestClient

from api.config import Settings
from api.main import create_app


def _has_ray() -> bool:
    return importlib.util.find_spec("ray") is not None


@pytest.mark.slow
def test_episode_tasks_run_as_ray_tasks(make_settings: Callable[..., Settings],
                                        wait_for: Callable[..., dict]) -> None:
    pytest.importorskip("ray", reason="Ray is not installed (pip install '.[ray]')")
    settings = make_settings(ray_address="local", workers=2, task_time_limit_s=8.0)
    with TestClient(create_app(settings)) as client:
        def submit(target: str) -> str:
            return client.post("/v1/tasks", json={"target": target, "world": "office",
                                                  "seed": 7}).json()["id"]

        quick, boom = submit("quick"), submit("boom")
        done = wait_for(client, quick, {"succeeded", "failed"}, timeout=60)
        assert done["state"] == "succeeded" and done["summary"]["seed"] == 7, done
        png = client.get(f"/v1/tasks/{quick}/trajectory.png")
        assert png.status_code == 200 and png.content.startswith(b"\x89PNG")
        events = client.get(f"/v1/tasks/{quick}/events").text
        assert events.count("event: action") == 3
        failed = wait_for(client, boom, {"failed", "succeeded"}, timeout=60)
        assert "runner exploded on purpose" in failed["error"]

        slow, stubborn = submit("slow"), submit("stubborn")
        for task_id in (slow, stubborn):
            wait_for(client, task_id, {"running"}, timeout=60)
            client.delete(f"/v1/tasks/{task_id}")
        assert wait_for(client, slow, {"cancelled"}, timeout=10)["state"] == "cancelled"
        killed = wait_for(client, stubborn, {"cancelled"}, timeout=10)
        assert "killed" in killed["error"]

        late = submit("stubborn")
        timed_out = wait_for(client, late, {"timeout", "failed"}, timeout=60)
        assert timed_out["state"] == "timeout" and "wall-clock limit 8 s" in timed_out["error"]


@pytest.mark.skipif(_has_ray(), reason="Ray is installed: the refusal cannot happen here")
def test_serve_without_ray_refuses_a_ray_address(tmp_path) -> None:
    from avs_planner.cli import serve

    parser = argparse.ArgumentParser()
    serve.register(parser.add_subparsers())
    args = parser.parse_args(["serve", "--ray-address", "local", "--data-dir", str(tmp_path)])
    with pytest.raises(serve.ServeError, match=r"--ray-address needs Ray: pip install"):
        serve.run(args)
