"""Every endpoint of a real ``lynxplan serve`` process: answers equal the library's, bad input
gets the right status and an RFC 9457 problem naming the field, never a traceback."""

from __future__ import annotations

import io
import re
from dataclasses import fields, is_dataclass
from typing import Any

import httpx
import numpy as np
import orjson
import pytest
from service_server import SCENARIOS, Server

from lynxplan.arm import load_arm
from lynxplan.client import Client, ServiceError
from lynxplan.collision import (
    CollisionWorld,
    SphereObstacle,
    axis_aligned_box,
    check_trajectory,
    clearance_profile,
)
from lynxplan.constants import COAL_GJK_TOLERANCE
from lynxplan.robots import load_robot
from lynxplan.trajectory import MotionLimits, free_segment, ruckig_profile, toppra_profile
from lynxplan.trajectory.retime import lspb_profile

PROBLEM = "application/problem+json"
#: The IK kernels' answers differ by up to a few ulp (q ~4e-16 rad, residuals ~1e-16) between a
#: process that JIT-compiles the numba kernel and one that loads it from numba's cache, a library
#: property reproduced without the service. The server and this test are two processes, so their
#: IK floats are compared to this [m or rad]; flags, branches and statuses exactly; the wire
#: itself is checked bit for bit within one server (JSON vs binary answers, FK answers).
KERNEL_ATOL = 1e-14
RNG = np.random.default_rng(15)


def random_configurations(n: int) -> np.ndarray:
    arm = load_arm()
    return RNG.uniform(arm.limits.lower, arm.limits.upper, size=(n, 5))


def assert_problem(response: httpx.Response, status: int, field: str | None = None) -> dict:
    assert response.status_code == status, response.text
    assert response.headers["content-type"].startswith(PROBLEM)
    body = response.json()
    assert body["status"] == status and body["title"] and body["detail"]
    assert "Traceback" not in response.text and "\n" not in body["detail"]
    if field is not None:
        assert body.get("field") == field, body
    return body


@pytest.fixture(scope="module")
def client(server: Server) -> Client:
    with Client(server.url) as c:
        yield c


# -- meta --------------------------------------------------------------------------------------
def test_health_version_robots(http: httpx.Client) -> None:
    assert http.get("/health").json() == {"status": "ok"}
    assert http.get("/version").json()["api"] == 1
    names = [r["name"] for r in http.get("/robots").json()["robots"]]
    assert "al5" in names
    al5 = http.get("/robots/al5").json()
    limits = load_arm().limits
    assert [j["lower"] for j in al5["joints"]] == limits.lower.tolist()
    assert al5["dof"] == 5 and al5["tool"] == "tool"


def test_unknown_robot_is_404(http: httpx.Client) -> None:
    assert_problem(http.get("/robots/puma"), 404, "robot")
    assert_problem(http.post("/fk", json={"robot": "puma", "q": [0, 0, 0, 0, 0]}), 404, "robot")


def test_openapi_document_and_docs(http: httpx.Client) -> None:
    spec = http.get("/openapi.json").json()
    for path in ("/fk", "/ik", "/check", "/trajectory", "/runs", "/runs/{run_id}", "/robots"):
        assert path in spec["paths"], path
    ik_body = spec["paths"]["/ik"]["post"]["requestBody"]["content"]
    assert {"application/json", "application/x-npy", "application/octet-stream"} <= set(ik_body)
    docs = http.get("/docs")
    assert docs.status_code == 200 and "/static/docs.js" in docs.text
    assert not re.search(r"(https?:)?//[a-z0-9.-]+\.[a-z]{2,}/", docs.text)  # no CDN
    assert http.get("/redoc").status_code == 404


def test_unknown_route_and_method(http: httpx.Client) -> None:
    assert_problem(http.get("/nowhere"), 404)
    assert_problem(http.get("/fk"), 405)


# -- kinematics ---------------------------------------------------------------------------------
def test_fk_equals_library_bit_for_bit(client: Client, http: httpx.Client) -> None:
    arm, q = load_arm(), random_configurations(3000)
    np.testing.assert_array_equal(client.fk(q[0]), arm.fk(q[0]))
    np.testing.assert_array_equal(client.fk(q[:10]), arm.fk(q[:10]))
    np.testing.assert_array_equal(client.fk(q), arm.fk(q))  # binary both ways
    answer = http.post("/fk", json={"q": q[:5].tolist()}).json()
    assert answer["residual"] < 1e-12


def test_ik_single_equals_library(client: Client, http: httpx.Client) -> None:
    arm = load_arm()
    for q in random_configurations(20):
        T = arm.fk(q)
        remote, local = client.ik(T, q_reference=q), arm.ik(T, q_reference=q)
        assert remote.selected == local.selected
        assert remote.orientation_residual == pytest.approx(
            local.orientation_residual, abs=KERNEL_ATOL
        )
        for a, b in zip(remote.solutions, local.solutions, strict=True):
            np.testing.assert_allclose(a.q, b.q, rtol=0, atol=KERNEL_ATOL)
            assert (a.branch, a.within_limits) == (b.branch, b.within_limits)
            assert a.position_error == pytest.approx(b.position_error, abs=KERNEL_ATOL)
            assert a.orientation_error == pytest.approx(b.orientation_error, abs=KERNEL_ATOL)
        assert type(remote) is type(local)  # one result type (lynxplan.branches.IkResult)
        assert (remote.reachable, remote.solver) == (True, "AL5 closed form")
        assert remote.distance == pytest.approx(local.distance, abs=KERNEL_ATOL)
    answer = http.post("/ik", json={"T": arm.fk(q).tolist()}).json()
    assert answer["position_residual"] < 1e-12 and answer["branch"]


def test_ik_single_of_a_robot_says_when_the_target_is_out_of_reach(client: Client) -> None:
    """A Robot answers an unreachable target with its nearest solution: the answer says so
    (``reachable``, ``distance``), as the library's result."""
    so101 = load_robot("so101")
    T = so101.fk(np.radians([10.0, -20.0, 30.0, 40.0, 5.0]))
    T[:3, 3] *= 3.0
    remote, local = client.ik(T, robot="so101"), so101.ik(T)
    assert not remote.reachable and not local.reachable
    assert remote.distance == pytest.approx(local.distance, rel=1e-12) and remote.distance > 0.1
    assert remote.solver == local.solver and remote.selected == local.selected


def test_ik_batch_json_and_binary_equal_library(client: Client, http: httpx.Client) -> None:
    arm = load_arm()
    T = arm.fk(random_configurations(2500))
    T[7, :3, 3] += 5.0  # out of reach: NaN q, status != 0, as in the library
    local = arm.ik_batch(T)
    for poses in (T[:50], T):  # JSON, then raw float64 in / npz out
        remote = client.ik(poses)
        expected = arm.ik_batch(poses)
        for name in expected._fields:
            got, want = getattr(remote, name), getattr(expected, name)
            if got.dtype.kind == "f":
                np.testing.assert_allclose(got, want, rtol=0, atol=KERNEL_ATOL, err_msg=name)
            else:
                np.testing.assert_array_equal(got, want, name)
    assert local.status[7] != 0
    npy = io.BytesIO()
    np.save(npy, T[:100])
    answer = http.post(
        "/ik", content=npy.getvalue(), headers={"Content-Type": "application/x-npy"}
    ).json()
    assert answer["count"] == 100
    assert np.nanmax(np.array(answer["position_error"], dtype=float)) < 1e-9


def test_json_and_binary_answers_are_identical_bit_for_bit(client: Client) -> None:
    """The wire loses nothing: one server's JSON and binary answers, decoded by the client, are
    the same bits (orjson writes shortest round-trip floats, binary is raw float64)."""
    arm = load_arm()
    q = random_configurations(1500)
    T = arm.fk(q)
    by_json = [client.ik(T[i : i + 500]) for i in range(0, 1500, 500)]  # JSON (< 1000 poses)
    by_binary = client.ik(T)  # raw float64 in, npy stream out
    for name in by_binary._fields:
        joined = np.concatenate([getattr(b, name) for b in by_json])
        np.testing.assert_array_equal(joined, getattr(by_binary, name), name)
        assert joined.tobytes() == getattr(by_binary, name).tobytes(), name
    np.testing.assert_array_equal(client.fk(q[:999]), client.fk(q)[:999])  # JSON vs binary FK


def test_ik_position_and_approach_target(http: httpx.Client) -> None:
    arm = load_arm()
    T = arm.fk(np.array([0.7, 1.0, -1.2, 1.1, 0.4]))
    body = {"position": T[:3, 3].tolist(), "approach": T[:3, 2].tolist()}
    answer = http.post("/ik", json=body).json()
    reached = arm.fk(np.array(answer["q"]))
    np.testing.assert_allclose(reached[:3, 3], T[:3, 3], atol=1e-9)
    np.testing.assert_allclose(reached[:3, 2], T[:3, 2], atol=1e-9)


# -- bad input ----------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("body", "field"),
    [
        (b'{"T": [[1, 0, 0', "body"),
        (b"[1, 2, 3]", "body"),
        (b"", "body"),
        (b'{"T": "eye"}', "T"),
        (b'{"T": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]}', "T"),
        (b'{"T": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, null]]}', "T"),
        (b'{"T": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, "1"]]}', "T"),
        (b'{"T": [[1, 0, 0, 1e999], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}', "body"),
        (b'{"T": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], "select": 3}', "select"),
        (
            b'{"robot": "so101", "T": [[1, 0, 0, 0.2], [0, 1, 0, 0], [0, 0, 1, 0.1], [0, 0, 0, 1]],'
            b' "select": "report"}',  # the AL5's rule
            "select",
        ),
        (b'{"position": [0.2, 0, 0.1], "approach": [0, 0, 0]}', "approach"),
        (b'{"q_reference": [0, 0]}', "T"),
    ],
)
def test_ik_bad_json_is_422_with_field(http: httpx.Client, body: bytes, field: str) -> None:
    response = http.post("/ik", content=body, headers={"Content-Type": "application/json"})
    detail = assert_problem(response, 422)
    assert detail["field"].replace(" ", "") == field.replace(" ", "")


def test_fk_wrong_types(http: httpx.Client) -> None:
    assert_problem(http.post("/fk", json={"q": [0, 0, 0, 0]}), 422, "q")
    assert_problem(http.post("/fk", json={"q": [0, 0, True, 0, {}]}), 422, "q")
    assert_problem(http.post("/fk", json={"q": [[0, 0, 0, 0, 0], [0, 0]]}), 422, "q")
    assert_problem(http.post("/fk", json={"robot": 5, "q": [0, 0, 0, 0, 0]}), 422, "robot")
    assert_problem(http.post("/fk", json={}), 422, "q")


def test_binary_bodies_are_checked(http: httpx.Client) -> None:
    raw = np.zeros((10, 4, 4)).tobytes()
    headers = {"Content-Type": "application/octet-stream"}
    assert_problem(http.post("/ik", content=raw, headers=headers), 422, "X-Shape")
    assert_problem(
        http.post("/ik", content=raw, headers={**headers, "X-Shape": "9,4,4"}), 422, "X-Shape"
    )
    assert_problem(
        http.post("/ik", content=raw, headers={**headers, "X-Shape": "10,4,a"}), 422, "X-Shape"
    )
    assert_problem(
        http.post("/ik", content=b"not npy", headers={"Content-Type": "application/x-npy"}),
        422,
        "T",
    )
    bad = np.full((2, 4, 4), np.nan)
    assert_problem(
        http.post("/ik", content=bad.tobytes(), headers={**headers, "X-Shape": "2,4,4"}), 422
    )


def test_huge_bodies_and_batches_are_413(http: httpx.Client) -> None:
    big = b"0" * (2 * 1024**2)  # the session server takes at most 1 MiB
    assert_problem(http.post("/fk", content=big, headers={"Content-Type": "application/json"}), 413)

    def chunks():
        for _ in range(40):
            yield b" " * 65536  # no Content-Length: counted while streaming

    assert_problem(
        http.post("/fk", content=chunks(), headers={"Content-Type": "application/json"}), 413
    )
    many = orjson.dumps({"q": np.zeros((25_000, 5)).tolist()})
    assert len(many) < 1024**2
    assert_problem(
        http.post("/fk", content=many, headers={"Content-Type": "application/json"}), 413, "q"
    )


def test_unreachable_and_domain_errors_are_422(client: Client) -> None:
    T = np.eye(4)
    T[0, 3] = 3.0
    with pytest.raises(ServiceError, match="out of reach") as info:
        client.ik(T)
    assert info.value.status == 422


# -- collision and trajectories ------------------------------------------------------------------
def _leaves(value: Any) -> list[Any]:
    """The fields of a report (dataclasses and tuples of them), flattened, in order."""
    if is_dataclass(value) and not isinstance(value, type):
        return [leaf for f in fields(value) for leaf in _leaves(getattr(value, f.name))]
    if isinstance(value, tuple):
        return [leaf for item in value for leaf in _leaves(item)]
    return [value]


def assert_same_report(remote: Any, local: Any) -> None:
    """The same report from the service and the library: every field equal, distances to coal's
    GJK tolerance (their last digits depend on the process's earlier queries, GJK warm starts:
    the server is another process, and under ``pytest -n`` which tests ran before here varies)."""
    a, b = _leaves(remote), _leaves(local)
    assert len(a) == len(b), (remote, local)
    for x, y in zip(a, b, strict=True):
        if isinstance(x, float) and isinstance(y, float):
            near = pytest.approx(y, abs=COAL_GJK_TOLERANCE, rel=0, nan_ok=True)
            assert x == near, (remote, local)
        else:
            assert x == y, (remote, local)


def test_check_configurations_and_trajectory_equal_library(client: Client) -> None:
    arm = load_arm()
    obstacles = [
        SphereObstacle("ball", [0.25, 0.05, 0.0], 0.04),
        axis_aligned_box("wall", [0.1, -0.3, -0.2], [0.3, 0.05, 0.4]),
    ]
    world = CollisionWorld(arm, obstacles)
    q = np.linspace([0.3, 0.8, -1.4, 1.0, 0.2], [1.4, 1.2, -0.8, 1.6, 1.0], 40)
    t = np.linspace(0.0, 2.0, 40)
    np.testing.assert_allclose(client.check(q, obstacles), clearance_profile(world, q),
                               rtol=0, atol=COAL_GJK_TOLERANCE)  # fmt: skip
    assert_same_report(client.check(q, obstacles, t), check_trajectory(world, q, t))


def test_check_bad_obstacle(http: httpx.Client) -> None:
    body = {"q": [0.5, 0.5, -0.5, 0.3, 0.2], "obstacles": [{"type": "cone"}]}
    assert_problem(http.post("/check", json=body), 422, "obstacles")
    body["obstacles"] = [{"type": "sphere", "centre": [0, 0, 0], "radius": -1}]
    assert_problem(http.post("/check", json=body), 422)


@pytest.mark.parametrize("method", ["lspb", "ruckig", "toppra"])
def test_trajectory_equals_library(client: Client, method: str) -> None:
    arm = load_arm()
    waypoints = np.array(
        [[0.2, 0.5, -0.5, 0.3, 0.2], [1.0, 1.0, -1.0, 1.0, 0.5], [0.5, 0.6, -0.3, 0.2, 0.9]]
    )
    limits = MotionLimits.from_joint_limits(arm.limits)
    remote = client.trajectory(waypoints, method, rate=50.0)
    for profile, a, b in zip(remote, waypoints[:-1], waypoints[1:], strict=True):
        segment = free_segment(a, b, limits=limits)
        if method == "lspb":
            local = lspb_profile(segment, segment.timing, 50.0)
        elif method == "ruckig":
            local = ruckig_profile(a, b, limits, 50.0)
        else:
            local = toppra_profile(segment, limits, 50.0)
        for x, y in zip(profile, local, strict=True):
            np.testing.assert_array_equal(x, y)


def test_trajectory_bad_input(http: httpx.Client) -> None:
    one = {"waypoints": [[0, 0, 0, 0, 0]]}
    assert_problem(http.post("/trajectory", json=one), 422, "waypoints")
    two = {"waypoints": [[0, 0, 0, 0, 0], [1, 1, -1, 1, 1]]}
    assert_problem(http.post("/trajectory", json={**two, "method": "spline"}), 422, "method")
    assert_problem(http.post("/trajectory", json={**two, "rate": 1e9}), 422, "rate")
    assert_problem(http.post("/trajectory", json={**two, "timing": {"tt": 1.0, "ta": 0.9}}), 422)
    assert_problem(
        http.post("/trajectory", json={**two, "limits": {"speed": 1}}), 422, "limits.speed"
    )


# -- runs ---------------------------------------------------------------------------------------
def test_run_through_the_client_matches_a_local_run(client: Client, tmp_path) -> None:
    from lynxplan.scenarios import run_scenario

    source = SCENARIOS / "free_motion.yaml"
    remote = client.run(source, quick=True, out_dir=tmp_path / "remote")
    local = run_scenario(source, tmp_path / "local", quick=True)
    assert remote.state == "succeeded" and remote.ok is True
    assert remote.summary == local.summary
    assert set(remote.artifacts) == set(local.artifacts)
    for name in remote.artifacts:
        if name != "report.json":  # holds wall times
            assert (tmp_path / "remote" / name).read_bytes() == (
                tmp_path / "local" / name
            ).read_bytes()
    result = remote.result
    assert result.metrics == orjson.loads(orjson.dumps(dict(local.metrics)))
    assert result.expectations == local.expectations
    assert remote.timings["run"] > 0


def test_run_listing_artifacts_and_errors(http: httpx.Client, client: Client) -> None:
    run_id = client.submit(SCENARIOS / "free_motion.yaml", quick=True)
    result = client.wait(run_id)
    page = http.get("/runs", params={"limit": 1}).json()
    assert page["total"] >= 1 and len(page["items"]) == 1
    assert_problem(http.get("/runs/nope"), 404, "run_id")
    assert_problem(http.get(f"/runs/{run_id}/artifacts/../../lynxplan.sqlite3"), 404)
    assert_problem(http.get(f"/runs/{run_id}/artifacts/nothing.csv"), 404, "name")
    assert http.get(f"/runs/{run_id}/artifacts/report.json").json()
    assert_problem(http.delete(f"/runs/{run_id}"), 409)
    assert result.report is not None
    assert_problem(http.get("/runs", params={"limit": 0}), 422, "limit")


def test_bad_scenarios_are_rejected_before_running(http: httpx.Client) -> None:
    yaml = {"Content-Type": "application/yaml"}
    assert_problem(
        http.post("/runs", content=b"kind: nothing\nname: x\n", headers=yaml), 422, "kind"
    )
    body = (SCENARIOS / "free_motion.yaml").read_text().replace("tt: 3.0", "tt: -3.0")
    assert_problem(http.post("/runs", content=body.encode(), headers=yaml), 422)
    assert_problem(http.post("/runs", content=b"kind: [unclosed", headers=yaml), 422)
    assert_problem(
        http.post("/runs", content=b"{bad json", headers={"Content-Type": "application/json"}), 422
    )
    task = (SCENARIOS / "ok_task.yaml").read_text()
    with_urdf = re.sub(r"(?m)^robot: \{\}", "robot: {urdf: /etc/hostname}", task, count=1)
    assert with_urdf != task
    assert_problem(http.post("/runs", content=with_urdf.encode(), headers=yaml), 422, "robot.urdf")
    assert_problem(
        http.post("/runs", content=b"\x00\x01", headers={"Content-Type": "image/png"}), 415
    )


def test_cancel_a_queued_or_running_run(client: Client) -> None:
    first = client.submit(SCENARIOS / "ok_task.yaml")  # with plots: long enough to cancel
    second = client.submit(SCENARIOS / "ok_task.yaml")
    assert client.cancel(second).state == "cancelled"
    assert client.cancel(first).state == "cancelled"
    after = client.run(SCENARIOS / "free_motion.yaml", quick=True)  # the worker was replaced
    assert after.state == "succeeded"


def test_view_is_a_self_contained_meshcat_page(http: httpx.Client) -> None:
    response = http.post("/view", json={"q": [0.5, 1.0, -1.0, 1.0, 0.3]})
    assert response.status_code == 200 and response.headers["content-type"].startswith("text/html")
    assert "meshcat" in response.text.lower() and "<script" in response.text
    assert_problem(http.post("/view", json={"q": [[0.5, 1.0, -1.0, 1.0, 0.3]]}), 422, "q")


def test_plan_equals_library(client: Client, http: httpx.Client) -> None:
    from lynxplan.planning import plan

    arm = load_arm()
    wall = axis_aligned_box("wall", [0.15, -0.02, -0.1], [0.05, 0.04, 0.3])
    start = np.array([0.3, 1.2, -1.6, 1.2, 0.5])
    goal = np.array([2.6, 1.2, -1.6, 1.2, 0.5])
    remote = client.plan(start, goal, [wall], seed=3, time_limit=5.0)
    local = plan(arm, [wall], start, goal, seed=3, time_limit=5.0)
    for name in ("waypoints", "t", "q", "qd", "qdd", "segment"):
        np.testing.assert_array_equal(getattr(remote, name), getattr(local, name), name)
    assert_same_report(remote.verification, local.verification)
    assert (remote.goal_label, remote.path_length, remote.options) == (
        local.goal_label,
        local.path_length,
        local.options,
    )
    bad = {"start": start.tolist(), "goal": goal.tolist(), "options": {"speed": 1}}
    assert_problem(http.post("/plan", json=bad), 422, "options")
    assert_problem(
        http.post("/plan", json={**bad, "options": {}, "time_limit": 999}), 422, "time_limit"
    )
    assert_problem(http.post("/plan", json={"start": [0, 0], "goal": goal.tolist()}), 422, "start")


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(p.name for p in SCENARIOS.glob("*.yaml")))
def test_every_shipped_scenario_remotely_equals_local(client: Client, tmp_path, name) -> None:
    from lynxplan.scenarios import run_scenario

    remote = client.run(SCENARIOS / name, quick=True, out_dir=tmp_path / "remote")
    local = run_scenario(SCENARIOS / name, tmp_path / "local", quick=True)
    assert remote.state == "succeeded", remote.error
    assert remote.summary == local.summary and remote.ok == local.ok
    assert remote.result.metrics == orjson.loads(
        orjson.dumps(dict(local.metrics), option=orjson.OPT_SERIALIZE_NUMPY)
    )
    for artifact in local.artifacts:
        if artifact != "report.json":
            assert (tmp_path / "remote" / artifact).read_bytes() == (
                tmp_path / "local" / artifact
            ).read_bytes(), artifact


def test_cli_run_with_server_and_a_json_scenario(server: Server, client: Client, tmp_path) -> None:
    import subprocess
    import sys

    import yaml
    from service_server import REPO

    done = subprocess.run(
        [sys.executable, "-m", "lynxplan.cli", "run", "--server", server.url, "--quick",
         "--out", str(tmp_path / "out"), str(SCENARIOS / "straight_line.yaml")],
        capture_output=True, text=True, timeout=120, cwd=REPO,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "expectations:" in done.stdout and (tmp_path / "out" / "report.json").is_file()
    mapping = yaml.safe_load((SCENARIOS / "straight_line.yaml").read_text())
    result = client.run(mapping, quick=True)
    assert result.state == "succeeded" and result.ok
    broken = subprocess.run(
        [sys.executable, "-m", "lynxplan.cli", "run", "--server", "http://127.0.0.1:9",
         str(SCENARIOS / "straight_line.yaml")],
        capture_output=True, text=True, timeout=120, cwd=REPO,
    )  # fmt: skip
    assert broken.returncode == 2 and broken.stderr.count("\n") == 1, broken.stderr


def test_long_poll_returns_when_the_run_ends(http: httpx.Client, client: Client) -> None:
    import time

    run_id = client.submit(SCENARIOS / "straight_line.yaml", quick=True)
    start = time.monotonic()
    record = http.get(f"/runs/{run_id}", params={"wait": 60}).json()
    assert record["state"] == "succeeded" and time.monotonic() - start < 30
    assert_problem(http.get(f"/runs/{run_id}", params={"wait": 61}), 422, "wait")
