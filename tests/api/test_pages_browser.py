"""The pages in a real browser: headless Chromium (Debian's `chromium` and `chromium-driver`)
driven by Selenium against a real `avs serve` with an API key and the real episode runner.

Opens the task list, submits a task through the form (first without the key, which the page
then asks for), watches the task page reach "found" from live events, opens the explanation;
then opens a finished 400-event task. Screenshots and the measured times (event delay, time to
open) go to `test-artifacts/browser/` (or `$AVS_TEST_ARTIFACTS/browser`); times are reported,
not asserted. Skipped, saying why, when Chromium, chromedriver or Selenium is missing (a
failure instead when AVS_REQUIRE_BROWSER=1, as in CI).
"""

from __future__ import annotations

import json
import os
import secrets
import shutil
import socket
import statistics
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from api.schemas import TaskState
from api.store import TaskStore
from avs_planner.harness.runner import run_episode
from avs_planner.harness.scenarios import load_scenario

pytestmark = pytest.mark.browser

REPO = Path(__file__).resolve().parents[2]
RUNNER = f"{Path(__file__).with_name('pages_stamped_runner.py').resolve()}:run"
CHROMIUM = next((p for p in (shutil.which("chromium"), shutil.which("chromium-browser"),
                             shutil.which("google-chrome")) if p), None)
DRIVER = shutil.which("chromedriver")
BIG_TASK_EVENTS = 400
TERMINAL = {s.value for s in TaskState if s.terminal}


def _missing() -> str | None:
    if CHROMIUM is None or DRIVER is None:
        return ("no Chromium or chromedriver on PATH (Debian: apt-get install chromium "
                "chromium-driver); the browser tests need both")
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "selenium is not installed (pip install -e '.[dev]')"
    return None


if _missing():
    if os.environ.get("AVS_REQUIRE_BROWSER") == "1":  # CI (.ci/run) installs the browser
        pytest.fail(f"AVS_REQUIRE_BROWSER=1 but {_missing()}", pytrace=False)
    pytest.skip(_missing() or "", allow_module_level=True)

from selenium import webdriver  # noqa: E402
from selenium.webdriver.chrome.options import Options  # noqa: E402
from selenium.webdriver.chrome.service import Service  # noqa: E402
from selenium.webdriver.common.by import By  # noqa: E402
from selenium.webdriver.remote.webdriver import WebDriver  # noqa: E402
from selenium.webdriver.support.ui import Select, WebDriverWait  # noqa: E402


@dataclass(frozen=True)
class Service_:
    base: str
    key: str
    big_task: str


def _artifacts() -> Path:
    root = Path(os.environ.get("AVS_TEST_ARTIFACTS", REPO / "test-artifacts"))
    path = root / "browser"
    path.mkdir(parents=True, exist_ok=True)
    return path


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _finished_task(data_dir: Path, events_dir: Path) -> str:
    """A gave-up task with 400 events in the store, made of a real episode's trace (scenario
    c, the one that gives up) repeated to 400 events, written before the service starts."""
    summary = run_episode({**load_scenario("c").episode_spec(seed=1),
                           "output_dir": str(events_dir)})
    trace = [json.loads(line) for line in (events_dir / "trace.jsonl").read_text().splitlines()]
    store = TaskStore(data_dir / "avs.sqlite3")
    try:
        task_id = secrets.token_hex(16)
        store.insert(task_id, {"target": "cerealbox", "world": "office_kitchen_closed",
                               "start": [6.0, 3.2, 0.0], "seed": 1, "strategy": "switching"},
                     "test")
        store.add_event(task_id, {"type": "state", "state": "queued", "time": time.time()})
        store.claim(task_id)
        store.add_event(task_id, {"type": "state", "state": "running", "time": time.time(),
                                  "attempt": 1})
        body = BIG_TASK_EVENTS - 3
        for i in range(body):
            event = trace[i % len(trace)]
            if i >= len(trace) and event["type"] == "done":  # only the last one is the end
                event = {**event, "type": "note"}
            store.add_event(task_id, event)
        store.finish(task_id, TaskState.GAVE_UP, summary, None)
        store.add_event(task_id, {"type": "state", "state": "gave_up", "time": time.time()})
        assert store.get(task_id).events == BIG_TASK_EVENTS  # type: ignore[union-attr]
    finally:
        store.close()
    return task_id


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Service_]:
    data = tmp_path_factory.mktemp("pages-data")
    big = _finished_task(data, tmp_path_factory.mktemp("pages-trace"))
    port, key = _free_port(), secrets.token_urlsafe(16)
    env = {**os.environ, "AVS_API_KEY": key, "AVS_EPISODE_RUNNER": RUNNER,
           "AVS_WORKERS": "1", "AVS_PLAN_WORKERS": "1", "AVS_PRELOAD_PLANNER": "false",
           "PYTHONPATH": os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")]))}
    command = [sys.executable, "-m", "avs_planner", "serve", "--port", str(port),
               "--data-dir", str(data), "--log-level", "warning"]
    log = (data / "serve.log").open("wb")
    process = subprocess.Popen(command, env=env, stdout=log, stderr=subprocess.STDOUT, cwd=REPO)
    base = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                with urllib.request.urlopen(f"{base}/v1/health", timeout=2) as answer:
                    if answer.status == 200:
                        break
            except (urllib.error.URLError, ConnectionError):
                pass
            if process.poll() is not None or time.monotonic() > deadline:
                pytest.fail(f"the service did not start: {(data / 'serve.log').read_text()}")
            time.sleep(0.2)
        yield Service_(base, key, big)
    finally:
        process.terminate()
        try:
            process.wait(timeout=15)
        except subprocess.TimeoutExpired:
            process.kill()
        log.close()


@pytest.fixture(scope="module")
def browser() -> Iterator[WebDriver]:
    options = Options()
    options.binary_location = str(CHROMIUM)
    for argument in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
                     "--disable-gpu", "--window-size=1400,1000", "--no-first-run"):
        options.add_argument(argument)
    driver = webdriver.Chrome(options=options, service=Service(str(DRIVER)))
    driver.set_page_load_timeout(30)
    try:
        yield driver
    finally:
        driver.quit()


def _record(name: str, values: dict[str, Any]) -> None:
    path = _artifacts() / "timings.json"
    data = json.loads(path.read_text()) if path.is_file() else {}
    data[name] = values
    path.write_text(json.dumps(data, indent=2) + "\n")


def _page(driver: WebDriver, name: str) -> Any:
    return driver.execute_script(f"return window.avsPage && {name};")


def test_submit_a_task_and_watch_it_find_the_object(service: Service_, browser: WebDriver) -> None:
    shots = _artifacts()
    browser.get(f"{service.base}/")
    wait = WebDriverWait(browser, 30)
    wait.until(lambda d: d.find_elements(By.CSS_SELECTOR, "#f-world option[value=office]"))
    wait.until(lambda d: "needs-key" in d.find_element(By.ID, "key-form").get_attribute("class"))
    Select(browser.find_element(By.ID, "f-world")).select_by_value("office")
    target = browser.find_element(By.ID, "f-target")
    target.clear()
    target.send_keys("cerealbox")
    for field, value in (("f-x", "6.0"), ("f-y", "3.2"), ("f-yaw", "0")):
        browser.find_element(By.ID, field).send_keys(value)
    seed = browser.find_element(By.ID, "f-seed")
    seed.clear()
    seed.send_keys("1")
    browser.save_screenshot(str(shots / "1-task-list.png"))

    # without the key the service answers 401 and the page asks for it
    browser.find_element(By.ID, "submit-button").click()
    wait.until(lambda d: "API key" in d.find_element(By.ID, "form-message").text)
    assert "/tasks/" not in browser.current_url
    browser.find_element(By.ID, "api-key").send_keys(service.key)
    browser.find_element(By.ID, "key-save").click()
    browser.find_element(By.ID, "submit-button").click()
    wait.until(lambda d: "/tasks/" in d.current_url)
    task_id = browser.current_url.rstrip("/").rsplit("/", 1)[1]
    assert service.key not in browser.current_url

    WebDriverWait(browser, 60).until(lambda d: _page(d, "avsPage.events") > 0)
    browser.save_screenshot(str(shots / "2-task-live.png"))
    WebDriverWait(browser, 180, poll_frequency=0.2).until(
        lambda d: d.find_element(By.ID, "state").get_attribute("data-state") in TERMINAL)
    WebDriverWait(browser, 30).until(lambda d: _page(d, "avsPage.complete") is not None)
    badge = browser.find_element(By.ID, "state")
    assert badge.get_attribute("data-state") == "succeeded", badge.text
    assert "found" in badge.text
    # the page followed the task as it ran (events arrived in several reads of the stream)
    # and drew the map from them
    assert _page(browser, "avsPage.batches") >= 2
    model = _page(browser, "avsPage.model()")
    assert model["grid"] and model["places"] > 0 and model["path"] > 0 and model["plan"] > 0
    assert browser.find_elements(By.CSS_SELECTOR, "#plan li")
    assert "outcome" in browser.find_element(By.ID, "summary").text
    events = browser.find_elements(By.CSS_SELECTOR, "#events li")
    assert len(events) == _page(browser, "avsPage.events")
    browser.save_screenshot(str(shots / "3-task-found.png"))

    browser.find_element(By.CSS_SELECTOR, "#explanation-section summary").click()
    WebDriverWait(browser, 10).until(lambda d: d.find_element(By.ID, "explanation")
                                     .get_attribute("data-status") in ("none", "loaded"))
    explanation = browser.find_element(By.ID, "explanation")
    if explanation.get_attribute("data-status") == "none":
        assert explanation.text == "no explanation available"
    else:
        assert explanation.text.strip()
    browser.execute_script("document.getElementById('explanation-section').scrollIntoView()")
    browser.save_screenshot(str(shots / "4-task-explanation.png"))

    # the delay from the worker emitting an event to the page having drawn it
    shown = _page(browser, "avsPage.shown")
    sent = _page(browser, "avsPage.sent")
    delays = sorted((shown[seq] - sent[seq]) / 1000 for seq in sent if seq in shown)
    assert len(delays) >= 10
    _record("event_delay", {
        "task": task_id, "events": len(delays), "median_s": round(statistics.median(delays), 3),
        "p90_s": round(delays[int(0.9 * (len(delays) - 1))], 3), "max_s": round(delays[-1], 3),
        "target_s": 0.5,
    })
    # the list shows the task in its final state
    browser.get(f"{service.base}/")
    WebDriverWait(browser, 10).until(lambda d: d.find_elements(
        By.CSS_SELECTOR, f"tr[data-id='{task_id}'] .state-succeeded"))


def test_submit_two_targets_and_see_each_ones_part(service: Service_,
                                                   browser: WebDriver) -> None:
    """Several labels typed into the form (comma-separated) with a mode become `targets`;
    the task page shows each label's part live and, once ended, the summary's."""
    browser.get(f"{service.base}/")
    wait = WebDriverWait(browser, 30)
    wait.until(lambda d: d.find_elements(By.CSS_SELECTOR, "#f-world option[value=office]"))
    Select(browser.find_element(By.ID, "f-world")).select_by_value("office")
    target = browser.find_element(By.ID, "f-target")
    target.clear()
    target.send_keys("cup, stapler")
    Select(browser.find_element(By.ID, "f-mode")).select_by_value("all")
    for field in ("f-x", "f-y", "f-yaw"):
        browser.find_element(By.ID, field).clear()
    if not browser.execute_script("return sessionStorage.getItem('avs-api-key');"):
        browser.find_element(By.ID, "api-key").send_keys(service.key)
        browser.find_element(By.ID, "key-save").click()
    browser.find_element(By.ID, "submit-button").click()
    wait.until(lambda d: "/tasks/" in d.current_url)
    WebDriverWait(browser, 180, poll_frequency=0.2).until(
        lambda d: d.find_element(By.ID, "state").get_attribute("data-state") in TERMINAL)
    WebDriverWait(browser, 30).until(lambda d: _page(d, "avsPage.complete") is not None)
    assert browser.find_element(By.ID, "state").get_attribute("data-state") == "succeeded"
    card = browser.find_element(By.ID, "targets-card")
    WebDriverWait(browser, 10).until(lambda d: card.find_elements(
        By.CSS_SELECTOR, "tr[data-label=cup][data-outcome=found]"))
    assert card.is_displayed() and "cup and stapler" in card.text
    for label in ("cup", "stapler"):
        row = card.find_element(By.CSS_SELECTOR, f"tr[data-label={label}]")
        assert row.get_attribute("data-outcome") == "found" and "found" in row.text
        assert " at (" in row.text and " s" in row.text  # where and when
    browser.execute_script("document.getElementById('targets-card').scrollIntoView()")
    browser.save_screenshot(str(_artifacts() / "6-task-of-two-targets.png"))
    # the list names the task by its form
    browser.get(f"{service.base}/")
    WebDriverWait(browser, 10).until(lambda d: any(
        "cup and stapler" in row.text for row in d.find_elements(By.CSS_SELECTOR, "#tasks tr")))


def test_open_a_finished_400_event_task(service: Service_, browser: WebDriver) -> None:
    times = []
    for _ in range(3):
        browser.get(f"{service.base}/tasks/{service.big_task}")
        WebDriverWait(browser, 30).until(lambda d: _page(d, "avsPage.complete") is not None)
        times.append(_page(browser, "avsPage.complete") / 1000)
        assert _page(browser, "avsPage.events") == BIG_TASK_EVENTS
    badge = browser.find_element(By.ID, "state")
    assert badge.get_attribute("data-state") == "gave_up" and "gave_up" in badge.text
    model = _page(browser, "avsPage.model()")
    assert model["grid"] and model["rooms"] > 0 and model["path"] > 0
    assert len(browser.find_elements(By.CSS_SELECTOR, "#events li")) == BIG_TASK_EVENTS
    browser.save_screenshot(str(_artifacts() / "5-finished-400-events.png"))
    _record("open_finished_task", {
        "events": BIG_TASK_EVENTS, "seconds": [round(t, 3) for t in times],
        "median_s": round(statistics.median(times), 3), "target_s": 1.0,
    })


def test_an_unknown_task_says_so(service: Service_, browser: WebDriver) -> None:
    browser.get(f"{service.base}/tasks/{'0' * 32}")
    WebDriverWait(browser, 10).until(
        lambda d: d.find_element(By.ID, "state").text == "no such task")
    assert "no task with id" in browser.find_element(By.ID, "task-message").text
