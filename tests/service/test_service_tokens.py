"""Bearer tokens: required off loopback, checked on every request but /health; run time limits."""

from __future__ import annotations

import subprocess
import sys

import httpx
import pytest
import yaml
from service_server import REPO, SCENARIOS, Server

from lynxplan.client import Client, ServiceError

TOKEN = "s3cret-token-0123456789"


@pytest.fixture(scope="module")
def guarded(tmp_path_factory: pytest.TempPathFactory) -> Server:
    folder = tmp_path_factory.mktemp("guarded")
    token_file = folder / "token"
    token_file.write_text(TOKEN + "\n")
    server = Server(folder / "data", "--token-file", str(token_file), "--run-timeout", "3")
    yield server
    server.stop()


def test_non_loopback_bind_without_token_refuses_to_start() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "lynxplan.cli", "serve", "--host", "0.0.0.0", "--port", "1"],
        capture_output=True, text=True, timeout=60, cwd=REPO,
    )  # fmt: skip
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "requires --token-file" in done.stderr


def test_unusable_data_dir_is_a_one_line_error(tmp_path) -> None:
    (tmp_path / "file").write_text("")
    done = subprocess.run(
        [sys.executable, "-m", "lynxplan.cli", "serve", "--data-dir", str(tmp_path / "file")],
        capture_output=True, text=True, timeout=60, cwd=REPO,
    )  # fmt: skip
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert "cannot use --data-dir" in done.stderr


def test_short_token_file_is_refused(tmp_path) -> None:
    (tmp_path / "t").write_text("short")
    done = subprocess.run(
        [sys.executable, "-m", "lynxplan.cli", "serve", "--token-file", str(tmp_path / "t")],
        capture_output=True, text=True, timeout=60, cwd=REPO,
    )  # fmt: skip
    assert done.returncode == 2 and "at least 16 characters" in done.stderr


@pytest.mark.parametrize("header", [None, "Bearer wrong", f"Bearer {TOKEN}x", TOKEN, "Basic abc"])
def test_missing_or_wrong_token_is_401(guarded: Server, header: str | None) -> None:
    headers = {} if header is None else {"Authorization": header}
    for method, path in (
        ("GET", "/robots"),
        ("POST", "/ik"),
        ("GET", "/runs"),
        ("GET", "/version"),
        ("GET", "/no-such-route"),
    ):
        response = httpx.request(method, guarded.url + path, headers=headers)
        assert response.status_code == 401, (path, response.text)
        assert response.headers["content-type"].startswith("application/problem+json")
        assert response.json()["field"] == "Authorization"


def test_health_needs_no_token_and_the_right_token_works(guarded: Server) -> None:
    assert httpx.get(guarded.url + "/health").status_code == 200
    # The web page, its scripts and the API description hold no data: open, and /docs works.
    for path in ("/", "/docs", "/openapi.json", "/static/app.js", "/static/docs.js"):
        assert httpx.get(guarded.url + path).status_code == 200, path
    with Client(guarded.url, token=TOKEN) as client:
        assert client.robots()[0]["name"] == "al5"
    with Client(guarded.url) as client, pytest.raises(ServiceError, match="401"):
        client.robots()


def test_a_run_over_its_time_limit_fails(guarded: Server) -> None:
    # (a replaced worker serving the next run is tested by test_cancel_a_queued_or_running_run)
    with Client(guarded.url, token=TOKEN) as client:
        # An unsolvable planning problem searches for its whole time budget: 30 s > 3 s.
        scenario = yaml.safe_load((SCENARIOS / "planning" / "u01_goal_in_jar.yaml").read_text())
        scenario["planner"].update(time_limit=30.0, max_nodes=10_000_000)
        slow = client.run(scenario, quick=True)
        assert slow.state == "failed" and "time limit of 3 s" in slow.error, slow
        assert slow.artifacts == () and slow.timings["total"] < 60


@pytest.mark.slow
def test_a_run_over_its_memory_limit_fails_and_the_next_run_works(tmp_path) -> None:
    import yaml

    server = Server(tmp_path / "data", "--run-memory", "1.5")
    try:
        scenario = yaml.safe_load((SCENARIOS / "workspace.yaml").read_text())
        scenario.update(samples=50_000_000, report_grid=False)
        with Client(server.url) as client:
            big = client.run(scenario, quick=True)
            assert big.state == "failed" and "memory" in big.error, big
            assert client.run(SCENARIOS / "straight_line.yaml", quick=True).ok
    finally:
        server.stop()
